#include "frames.hpp"

namespace aortasph {

// Until the renderer lands, runs write no frames.
std::unique_ptr<FrameSink> make_frame_sink(const Scene&, const std::filesystem::path&) { return nullptr; }

}  // namespace aortasph
