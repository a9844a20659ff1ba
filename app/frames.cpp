#include "frames.hpp"

#include "errors.hpp"
#include "pipeline.hpp"
#include "renderer.hpp"

namespace aortasph {

namespace {

class PipelineSink : public FrameSink {
 public:
  PipelineSink(const Scene& scene, const std::filesystem::path& out_dir)
      : fields_(scene.render.fields()), pipeline_(scene.render, out_dir, scene.output_interval) {}

  // The snapshot is copied here, on the simulation thread; drawing and PNG encoding happen on the render
  // thread.
  void push(const World& world, int frame) override {
    if (pipeline_.failed()) throw InputError("rendering failed: " + pipeline_.error());
    try {
      pipeline_.push(world.snapshot(fields_, frame));
    } catch (const RenderError& e) {
      throw InputError(std::string("rendering failed: ") + e.what());
    }
  }
  void finish() override {
    try {
      pipeline_.finish();
    } catch (const std::exception& e) {
      throw InputError(std::string("rendering failed: ") + e.what());
    }
    if (pipeline_.failed()) throw InputError("rendering failed: " + pipeline_.error());
  }
  void flush() override {
    try {
      pipeline_.flush();
    } catch (const std::exception& e) {
      throw InputError(std::string("rendering failed: ") + e.what());
    }
  }
  std::optional<std::pair<double, double>> field_range() const override { return pipeline_.field_range(); }
  std::vector<std::optional<std::pair<double, double>>> camera_ranges() const override {
    return pipeline_.camera_ranges();
  }
  void adopt_existing_frames(int count) override {
    try {
      pipeline_.adopt_existing_frames(count);
    } catch (const std::exception& e) {
      throw InputError(std::string("resume: ") + e.what());
    }
  }
  void finish_quietly() override {
    try {
      pipeline_.finish();
    } catch (const std::exception&) {
      // A failed run's frames so far are on disk; the render error is secondary to the run's own.
    }
  }

 private:
  std::vector<std::string> fields_;  // what the cameras colour by, each once
  FramePipeline pipeline_;
};

}  // namespace

std::unique_ptr<FrameSink> make_frame_sink(const Scene& scene, const std::filesystem::path& out_dir) {
  if (scene.render.cameras.empty()) return nullptr;
  try {
    return std::make_unique<PipelineSink>(scene, out_dir);
  } catch (const std::exception& e) {
    throw InputError(std::string("render: ") + e.what());
  }
}

void validate_render(const Scene& scene) {
  try {
    validate_render_settings(scene.render);
  } catch (const RenderError& e) {
    throw InputError(e.what());
  }
}

}  // namespace aortasph
