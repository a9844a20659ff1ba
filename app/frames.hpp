// Frame output of a run: snapshots of the World go to the renderer's pipeline (render thread, bounded queue),
// which writes frames/<camera>/frame_NNNNN.png and, at the end, figures/<name>.png.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "world.hpp"

namespace aortasph {

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  // Called at every output time by the simulation thread; blocks only while the queue is full.
  virtual void push(const World& world, int frame) = 0;
  // Drains the queue and writes the figure sheets; throws on a render or write error.
  virtual void finish() = 0;
  // Same, after a failed run: writes what it can, never throws.
  virtual void finish_quietly() = 0;
  // Waits until every pushed frame is on disk (before a checkpoint); throws on a render or write error.
  virtual void flush() = 0;
  // The colour range in use (recorded in checkpoints; empty for color_by material or before one is chosen).
  virtual std::optional<std::pair<double, double>> field_range() const = 0;
  // The same per camera, in the order of render.cameras (recorded in checkpoints too).
  virtual std::vector<std::optional<std::pair<double, double>>> camera_ranges() const = 0;
  // Resuming: frames 0 .. count-1 are on disk already (figures read back the ones they need).
  virtual void adopt_existing_frames(int count) = 0;
};

// The render settings' checks (renderer's validate_render_settings: sizes, colormaps, ranges, cameras), as an
// InputError naming the key; `run` calls it before anything is built or written, `check` always.
void validate_render(const Scene& scene);

// nullptr when the scene has no camera.
std::unique_ptr<FrameSink> make_frame_sink(const Scene& scene, const std::filesystem::path& out_dir);

}  // namespace aortasph
