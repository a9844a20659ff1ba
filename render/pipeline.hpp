// Frame pipeline: the simulation thread hands snapshots to a render thread through a bounded queue.
//
// The render thread owns the GL context (created on it), draws every camera, writes
// out_dir/frames/<camera>/frame_NNNNN.png (NNNNN = Snapshot::frame) and keeps reduced copies of the frames
// that figures need; finish() composes out_dir/figures/<figure>.png. PNG encoding happens on the render
// thread, so the simulation only waits when it is `capacity` snapshots ahead (back-pressure instead of
// unbounded memory).
//
// A figure time t is frame round(t / output_interval). A time the run never reached is left out of its figure
// with a warning on stderr (a run shortened with --end-time still gets its figures).
#pragma once

#include <condition_variable>
#include <deque>
#include <filesystem>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "image.hpp"
#include "io/snapshot.hpp"
#include "render_error.hpp"
#include "scene.hpp"

namespace aortasph {

class Renderer;

class FramePipeline {
 public:
  // Validates the settings and figures, creates the output folders and starts the render thread; waits until
  // that thread has its GL context and shaders, so every setup error (bad colormap, camera along up,
  // unwritable folder, shader failure) is thrown here as RenderError, before any simulation.
  FramePipeline(const RenderSettings& settings, std::filesystem::path out_dir, double output_interval,
                std::size_t capacity = 2);
  // Stops the render thread without writing figures if finish() was not called; never throws.
  ~FramePipeline();
  FramePipeline(const FramePipeline&) = delete;
  FramePipeline& operator=(const FramePipeline&) = delete;

  // Queues a snapshot (called at every output time). Blocks while the queue is full; throws RenderError if
  // the render thread has failed (the message names the frame and the cause).
  void push(Snapshot snapshot);
  // Renders what is queued, joins the render thread and writes the figure sheets. Throws RenderError if any
  // render or write error happened. Calling it twice is harmless.
  void finish();

  // Waits until every queued snapshot is rendered and written (a checkpoint counts only the frames on disk).
  // Throws RenderError if the render thread has failed.
  void flush();
  // The colour range chosen so far (settings.range or the one picked from the first non-constant field);
  // a resumed run passes it back in settings.range so its frames keep the same colours.
  std::optional<std::pair<double, double>> field_range() const;
  // The same per camera (Renderer::field_range(camera)), in the order of settings.cameras; a resumed run
  // passes them back as the cameras' own ranges.
  std::vector<std::optional<std::pair<double, double>>> camera_ranges() const;
  // Resuming: frames 0 .. count-1 are already on disk; the ones that figures need are read back from
  // out_dir/frames/<camera>/. Call before the first push(). Throws RenderError when such a frame is missing.
  void adopt_existing_frames(int count);

  bool failed() const;
  std::string error() const;
  // Largest panel width kept for figures; larger frames are scaled down (area average).
  static constexpr int kMaxPanelWidth = 640;

 private:
  void thread_main(std::promise<void>* ready);
  void render_one(Renderer& renderer, const Snapshot& snapshot);
  void fail(const std::string& message);
  void write_figures();
  void record_ranges(const Renderer& renderer);  // called with mutex_ held

  RenderSettings settings_;
  std::filesystem::path out_dir_;
  double output_interval_;
  std::size_t capacity_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Snapshot> queue_;
  bool closing_ = false;
  bool failed_ = false;
  bool finished_ = false;
  std::string error_;
  std::thread thread_;

  // Render-thread state, read by finish() after the join.
  std::map<std::pair<std::string, int>, std::pair<double, Image>>
      panels_;                                      // (camera, frame) -> (time, image)
  std::map<std::string, std::vector<int>> wanted_;  // camera -> frames for figures
  std::optional<std::pair<double, double>> range_;  // guarded by mutex_ while the thread runs
  std::vector<std::optional<std::pair<double, double>>> camera_ranges_;  // the same, per camera
  std::map<std::string, std::string> units_;                             // field name -> unit
};

}  // namespace aortasph
