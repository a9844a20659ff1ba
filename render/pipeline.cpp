#include "pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "figure.hpp"
#include "renderer.hpp"

namespace aortasph {

namespace fs = std::filesystem;

namespace {

// A frame reduced to figure-panel size (at most kMaxPanelWidth wide, even height).
Image panel_of(const Image& image) {
  int w = image.w, h = image.h;
  if (w > FramePipeline::kMaxPanelWidth) {
    h = std::max(
        2, static_cast<int>(std::lround(static_cast<double>(h) * FramePipeline::kMaxPanelWidth / w)) & ~1);
    w = FramePipeline::kMaxPanelWidth;
  }
  return resize(image, w, h);
}

}  // namespace

FramePipeline::FramePipeline(const RenderSettings& settings, fs::path out_dir, double output_interval,
                             std::size_t capacity)
    : settings_(settings),
      out_dir_(std::move(out_dir)),
      output_interval_(output_interval),
      capacity_(std::max<std::size_t>(capacity, 1)) {
  validate_render_settings(settings_);
  if (!(output_interval_ > 0.0)) throw RenderError("time.output_interval must be positive for rendering");
  for (const Figure& fig : settings_.figures) {
    const std::string who = "render.figures \"" + fig.name + "\": ";
    if (fig.name.empty()) throw RenderError("render.figures: a figure without a name");
    if (std::none_of(settings_.cameras.begin(), settings_.cameras.end(),
                     [&](const Camera& c) { return c.name == fig.camera; }))
      throw RenderError(who + "unknown camera \"" + fig.camera + "\"");
    if (fig.columns < 1) throw RenderError(who + "columns must be at least 1");
    if (fig.times.empty()) throw RenderError(who + "no times");
    for (double t : fig.times) {
      if (!(t >= 0.0) || !std::isfinite(t)) throw RenderError(who + "times must be finite and >= 0");
      wanted_[fig.camera].push_back(static_cast<int>(std::lround(t / output_interval_)));
    }
  }
  std::error_code ec;
  for (const Camera& camera : settings_.cameras) {
    const fs::path dir = out_dir_ / "frames" / camera.name;
    fs::create_directories(dir, ec);
    if (ec) throw RenderError("cannot create " + dir.string() + ": " + ec.message());
  }
  std::promise<void> ready;
  std::future<void> started = ready.get_future();
  thread_ = std::thread(&FramePipeline::thread_main, this, &ready);
  try {
    started.get();
  } catch (...) {
    thread_.join();
    throw;
  }
}

FramePipeline::~FramePipeline() {
  {
    std::lock_guard lock(mutex_);
    closing_ = true;
    if (!finished_) queue_.clear();  // abandoned run: stop quickly
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void FramePipeline::fail(const std::string& message) {
  {
    std::lock_guard lock(mutex_);
    if (!failed_) error_ = message;
    failed_ = true;
    queue_.clear();
  }
  changed_.notify_all();
}

bool FramePipeline::failed() const {
  std::lock_guard lock(mutex_);
  return failed_;
}

std::string FramePipeline::error() const {
  std::lock_guard lock(mutex_);
  return error_;
}

void FramePipeline::push(Snapshot snapshot) {
  std::unique_lock lock(mutex_);
  if (closing_) throw RenderError("frame pipeline: push() after finish()");
  changed_.wait(lock, [&] { return failed_ || queue_.size() < capacity_; });
  if (failed_) throw RenderError(error_);
  queue_.push_back(std::move(snapshot));
  lock.unlock();
  changed_.notify_all();
}

void FramePipeline::thread_main(std::promise<void>* ready) {
  std::optional<Renderer> renderer;
  try {
    renderer.emplace(settings_);
  } catch (...) {
    ready->set_exception(std::current_exception());
    return;
  }
  ready->set_value();  // `ready` dies with the constructor's frame: not touched after this
  for (;;) {
    Snapshot snapshot;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return closing_ || failed_ || !queue_.empty(); });
      if (failed_ || queue_.empty()) break;  // closing with nothing left
      snapshot = std::move(queue_.front());
    }
    try {
      render_one(*renderer, snapshot);
    } catch (const std::exception& e) {
      fail("rendering frame " + std::to_string(snapshot.frame) + " (t = " + std::to_string(snapshot.time) +
           " s): " + e.what());
      break;
    }
    {
      // Popped only after the frame is written, so the queue bound also counts the frame in hand.
      std::lock_guard lock(mutex_);
      if (!queue_.empty()) queue_.pop_front();
      record_ranges(*renderer);
    }
    changed_.notify_all();
  }
  std::lock_guard lock(mutex_);
  record_ranges(*renderer);
}

void FramePipeline::record_ranges(const Renderer& renderer) {
  range_ = renderer.field_range();
  camera_ranges_.clear();
  for (const Camera& camera : settings_.cameras) camera_ranges_.push_back(renderer.field_range(camera));
}

void FramePipeline::flush() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return failed_ || queue_.empty(); });
  if (failed_) throw RenderError(error_);
}

std::optional<std::pair<double, double>> FramePipeline::field_range() const {
  std::lock_guard lock(mutex_);
  return range_;
}

std::vector<std::optional<std::pair<double, double>>> FramePipeline::camera_ranges() const {
  std::lock_guard lock(mutex_);
  return camera_ranges_;
}

void FramePipeline::adopt_existing_frames(int count) {
  std::lock_guard lock(mutex_);
  for (const auto& [camera, frames] : wanted_)
    for (int frame : frames) {
      if (frame >= count || panels_.count({camera, frame})) continue;
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05d.png", frame);
      panels_[{camera, frame}] = {frame * output_interval_,
                                  panel_of(read_png(out_dir_ / "frames" / camera / name))};
    }
}

void FramePipeline::render_one(Renderer& renderer, const Snapshot& snapshot) {
  for (const SnapshotField& field : snapshot.fields) units_[field.name] = field.unit;
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", snapshot.frame);
  for (const Camera& camera : settings_.cameras) {
    Image image = renderer.render(snapshot, camera);
    write_png(out_dir_ / "frames" / camera.name / name, image);
    const auto it = wanted_.find(camera.name);
    if (it != wanted_.end() && std::count(it->second.begin(), it->second.end(), snapshot.frame)) {
      panels_[{camera.name, snapshot.frame}] = {snapshot.time, panel_of(image)};
    }
  }
}

void FramePipeline::finish() {
  {
    std::lock_guard lock(mutex_);
    if (finished_) {
      if (failed_) throw RenderError(error_);
      return;
    }
    finished_ = true;
    closing_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (failed()) throw RenderError(error());
  try {
    write_figures();
  } catch (const std::exception& e) {
    fail(e.what());
    throw RenderError(e.what());
  }
}

void FramePipeline::write_figures() {
  if (settings_.figures.empty()) return;
  const fs::path dir = out_dir_ / "figures";
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw RenderError("cannot create " + dir.string() + ": " + ec.message());
  for (const Figure& fig : settings_.figures) {
    // The colour bar of the figure's camera: its field, colormap and range.
    std::optional<ColorBar> bar;
    for (std::size_t c = 0; c < settings_.cameras.size() && c < camera_ranges_.size(); ++c) {
      const Camera& camera = settings_.cameras[c];
      const std::string& field = settings_.color_by_of(camera);
      if (camera.name != fig.camera || field == "material" || !camera_ranges_[c]) continue;
      const std::pair<double, double>& range = *camera_ranges_[c];
      const auto unit = units_.find(field);
      // A resumed run that renders nothing new (resumed at its end) has seen no snapshot: the field's unit.
      bar = ColorBar{settings_.colormap_of(camera), range.first, range.second, field,
                     unit != units_.end() ? unit->second : std::string(field_unit(field))};
    }
    std::vector<FigurePanel> panels;
    for (double t : fig.times) {
      const int frame = static_cast<int>(std::lround(t / output_interval_));
      const auto it = panels_.find({fig.camera, frame});
      if (it == panels_.end()) {
        std::cerr << "aortasph: warning: figure \"" << fig.name << "\": no frame at t = " << t
                  << " s (the run ended earlier); left out\n";
        continue;
      }
      char caption[64];
      std::snprintf(caption, sizeof caption, "t = %.4g s", it->second.first);
      panels.push_back({it->second.second, caption});
    }
    if (panels.empty()) {
      std::cerr << "aortasph: warning: figure \"" << fig.name
                << "\": none of its times was rendered; not written\n";
      continue;
    }
    write_png(dir / (fig.name + ".png"), compose_figure(panels, fig.columns, bar));
  }
}

}  // namespace aortasph
