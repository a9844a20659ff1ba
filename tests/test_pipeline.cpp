// The simulation-render pipeline: the simulation thread steps a World and hands snapshots to the render
// thread through the bounded queue, waits for it at checkpoints (flush), reads its colour ranges (run-wide
// and per camera) and, when resuming, hands it frames already on disk. The ThreadSanitizer build
// (scripts/test.sh) runs this file.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "builders.hpp"
#include "core/parallel.hpp"
#include "image.hpp"
#include "pipeline.hpp"
#include "world.hpp"

using namespace aortasph;
using namespace aortasph::test;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("aortasph_pipe_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

RenderSettings settings() {
  RenderSettings r;
  r.width = 48;
  r.height = 32;
  r.color_by = "speed";
  Camera c;
  c.name = "front";
  c.eye = Vec3(0, 0, 0.5);
  c.target = Vec3::Zero();
  // A second camera with its own field and range chosen at run time (displacement is 0 at t = 0).
  Camera shift = c;
  shift.name = "shift";
  shift.color_by = "displacement";
  r.cameras = {c, shift};
  r.figures = {Figure{"sheet", "front", {0.0, 0.002, 0.012}, 3}};
  return r;
}

using Range = std::optional<std::pair<double, double>>;

// Steps the cubes to every output time and pushes a snapshot; flushes at `flush_at` like a checkpoint.
// Returns the run-wide range and the shift camera's; a resumed part is given both back.
std::pair<Range, Range> run_frames(const fs::path& out, int first, int last,
                                   std::pair<Range, Range> ranges = {}) {
  const double interval = 0.002;
  RenderSettings r = settings();
  r.range = ranges.first;
  r.cameras[1].range = ranges.second;
  World world(fluid_cubes(0.02));
  FramePipeline pipeline(r, out, interval, 2);
  if (first > 0) pipeline.adopt_existing_frames(first);
  for (int k = 0; k <= last; ++k) {
    world.advance_to(k * interval, [] { return true; });
    if (k < first) continue;
    pipeline.push(world.snapshot(r.fields(), k));
    if (k == 2) {
      pipeline.flush();
      // Every pushed frame is on disk after a flush.
      for (int j = first; j <= k; ++j) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%05d.png", j);
        CHECK(fs::exists(out / "frames" / "front" / name));
        CHECK(fs::exists(out / "frames" / "shift" / name));
      }
    }
  }
  pipeline.flush();  // as before a checkpoint: the range of every frame pushed
  const auto chosen = pipeline.field_range();
  const auto per_camera = pipeline.camera_ranges();
  pipeline.finish();
  CHECK_FALSE(pipeline.failed());
  REQUIRE(per_camera.size() == 2);
  CHECK(per_camera[0] == chosen);
  return {chosen, per_camera[1]};
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

}  // namespace

TEST_CASE("pipeline: simulation and render threads, flush, colour range and resumed frames", "[pipeline]") {
  set_threads(1);  // the OpenMP runtime is not instrumented for ThreadSanitizer: one simulation thread
  const fs::path whole = scratch("whole"), split = scratch("split");
  const auto ranges = run_frames(whole, 0, 6);
  const Range& range = ranges.first;
  REQUIRE(range.has_value());
  CHECK(range->first < range->second);
  REQUIRE(ranges.second.has_value());
  CHECK(ranges.second != range);

  // Frames 0..3 by one pipeline (the range is chosen there: the speeds differ once the cubes touch); 4..6
  // by a second one, given the first one's range and frames, as a resumed run does.
  const auto first_ranges = run_frames(split, 0, 3);
  const Range& first_range = first_ranges.first;
  INFO("whole " << range->first << ".." << range->second << ", split "
                << (first_range ? first_range->first : -1) << ".."
                << (first_range ? first_range->second : -1));
  REQUIRE(first_range == range);
  REQUIRE(first_ranges.second == ranges.second);
  fs::remove(split / "figures" / "sheet.png");
  run_frames(split, 4, 6, first_ranges);
  for (int k = 0; k <= 6; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", k);
    INFO(name);
    CHECK(slurp(whole / "frames" / "front" / name) == slurp(split / "frames" / "front" / name));
    CHECK(slurp(whole / "frames" / "shift" / name) == slurp(split / "frames" / "shift" / name));
  }
  CHECK(slurp(whole / "figures" / "sheet.png") == slurp(split / "figures" / "sheet.png"));
  set_threads(2);
}
