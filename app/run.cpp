// aortasph run / check: load the scene, build the World, step it to every output time, write probes,
// diagnostics, frames and run.json.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "commands.hpp"
#include "core/parallel.hpp"
#include "core/sim_errors.hpp"
#include "cycle_report.hpp"
#include "errors.hpp"
#include "frames.hpp"
#include "geometry/aortic_root.hpp"
#include "io/checkpoint.hpp"
#include "io/probes.hpp"
#include "output.hpp"
#include "resources.hpp"
#include "scene_loader.hpp"
#include "world.hpp"

namespace aortasph {

namespace {

// Set by SIGINT and SIGTERM; the run loop finishes the step in hand, writes a checkpoint and exits 130.
std::atomic<bool> g_interrupted{false};
extern "C" void on_signal(int) {
  g_interrupted = true;
}

using Clock = std::chrono::steady_clock;

double parse_double(const std::string& flag, const std::string& text) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used != text.size() || !std::isfinite(v)) throw std::invalid_argument("");
    return v;
  } catch (const std::exception&) {
    throw InputError(flag + ": expected a number, got '" + text + "'");
  }
}

int parse_int(const std::string& flag, const std::string& text) {
  try {
    std::size_t used = 0;
    const int v = std::stoi(text, &used);
    if (used != text.size()) throw std::invalid_argument("");
    return v;
  } catch (const std::exception&) {
    throw InputError(flag + ": expected an integer, got '" + text + "'");
  }
}

std::string hms(double s) {
  if (!std::isfinite(s) || s < 0) return "--";
  char buf[32];
  const long t = std::lround(s);
  std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  return buf;
}

// Progress: on a terminal one line updated in place; otherwise (or --quiet) a plain line per 10 %.
class Progress {
 public:
  Progress(double t_end, bool quiet) : t_end_(t_end), tty_(!quiet && isatty(2)), start_(Clock::now()) {}
  void update(const World& w) {
    const double frac = t_end_ > 0 ? w.time() / t_end_ : 1.0;
    const double wall = std::chrono::duration<double>(Clock::now() - start_).count();
    if (tty_) {
      if (wall - last_ < 0.2 && frac < 1.0) return;
      last_ = wall;
      std::fprintf(stderr, "\r  t = %.4f / %.4f s  steps %ld  dt %.2e s  particles %zu  wall %s  ETA %s   ",
                   w.time(), t_end_, w.steps(), w.last_dt(), w.particles().size(), hms(wall).c_str(),
                   frac > 0 ? hms(wall * (1.0 - frac) / frac).c_str() : "--");
    } else {
      const int decile = static_cast<int>(std::floor(frac * 10.0 + 1e-9));
      if (decile <= decile_) return;
      decile_ = decile;
      std::fprintf(stderr, "  %3d %%  t = %.4f s  steps %ld  dt %.2e s  particles %zu  wall %s\n",
                   decile * 10, w.time(), w.steps(), w.last_dt(), w.particles().size(), hms(wall).c_str());
    }
  }
  void done() {
    if (tty_) std::fprintf(stderr, "\n");
  }

 private:
  double t_end_;
  bool tty_;
  Clock::time_point start_;
  double last_ = -1.0;
  int decile_ = 0;
};

std::vector<std::string> diagnostics_columns() {
  // shell_crossings: the guard's put-backs since t = 0 (fluid particles stopped at a sheet; 0 without
  // shells). volume_ratio: the mean summation density over the continuity density of the fluid whose support
  // holds only fluid (sim/fluid/volume_check.hpp; NaN where no fluid particle has a full support).
  std::vector<std::string> cols = {"steps",       "dt",        "particles",         "fluid",
                                   "boundary",    "max_speed", "max_density_error", "shell_crossings",
                                   "volume_ratio"};
  for (const auto& [name, sec] : Profile{}.phases()) cols.push_back("wall_" + name);
  cols.push_back("wall_total");
  return cols;
}

std::vector<double> diagnostics_row(const World& w) {
  const double n = static_cast<double>(w.particles().size());
  const double fluid = static_cast<double>(w.count(Kind::Fluid));
  std::vector<double> row = {w.time(),
                             static_cast<double>(w.steps()),
                             w.last_dt(),
                             n,
                             fluid,
                             n - fluid,
                             w.max_speed(),
                             w.max_density_error(),
                             static_cast<double>(w.shell_crossings()),
                             w.fluid_volume_check().mean};
  for (const auto& [name, sec] : w.profile().phases()) row.push_back(sec);
  row.push_back(w.profile().total());
  return row;
}

// shell_putbacks.csv: one row per fluid particle the shell coupling's guard put back on its side of a sheet
// (World::last_shell_put_backs), appended as they happen. A new run starts the file with its header; a
// resumed one keeps the whole rows up to its checkpoint's time (keep_until >= 0) and drops the rest.
std::ofstream open_put_backs(const std::filesystem::path& file, double keep_until) {
  std::string kept = "time,id,x,y,z,body,depth,sheet\n";
  if (keep_until >= 0.0) {
    std::ifstream in(file, std::ios::binary);
    std::string line;
    if (in && std::getline(in, line))  // runs before stop 57 wrote none: a new file then
      while (std::getline(in, line) && !in.eof())
        if (std::strtod(line.c_str(), nullptr) <= keep_until * (1.0 + 1e-12)) kept += line + "\n";
  }
  replace_file(file, kept);
  std::ofstream out(file, std::ios::binary | std::ios::app);
  if (!out) throw InputError(file.string() + ": cannot open for writing");
  return out;
}

void write_put_backs(std::ofstream& out, const World& w) {
  const auto& put_backs = w.last_shell_put_backs();
  for (const auto& p : put_backs)
    out << format_number(w.time()) << ',' << p.id << ',' << format_number(p.x.x()) << ','
        << format_number(p.x.y()) << ',' << format_number(p.x.z()) << ',' << p.body << ','
        << format_number(p.depth) << ',' << (p.sheet ? 1 : 0) << '\n';
  if (!put_backs.empty()) out.flush();
}

// Creates the output folder and proves it is writable before anything is simulated.
void prepare_out_dir(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw InputError("--out " + dir.string() + ": cannot create the output folder" +
                     (ec ? ": " + ec.message() : std::string()));
  const auto probe = dir / ".write_test";
  {
    std::ofstream f(probe);
    f << "ok";
    if (!f) throw InputError("--out " + dir.string() + ": the output folder is not writable");
  }
  std::filesystem::remove(probe, ec);
}

}  // namespace

RunOptions parse_run_options(const std::vector<std::string>& args) {
  RunOptions o;
  bool have_scene = false;
  for (std::size_t k = 0; k < args.size(); ++k) {
    const std::string& a = args[k];
    auto value = [&]() -> const std::string& {
      if (k + 1 >= args.size()) throw InputError(a + ": missing value");
      return args[++k];
    };
    if (a == "--out")
      o.out = value();
    else if (a == "--threads") {
      o.threads = parse_int(a, value());
      if (o.threads < 1 || o.threads > 1024) throw InputError("--threads: expected 1..1024, got " + args[k]);
    } else if (a == "--end-time") {
      o.end_time = parse_double(a, value());
      if (*o.end_time <= 0) throw InputError("--end-time: must be positive, got " + args[k]);
    } else if (a == "--set")
      o.sets.push_back(value());
    else if (a == "--no-render")
      o.no_render = true;
    else if (a == "--vtk")
      o.vtk = true;
    else if (a == "--vtk-every") {
      o.vtk_every = parse_int(a, value());
      if (o.vtk_every < 1)
        throw InputError("--vtk-every: expected a positive number of outputs, got " + args[k]);
      o.vtk = true;
    } else if (a == "--quiet")
      o.quiet = true;
    else if (a == "--checkpoint-every") {
      o.checkpoint_every = parse_double(a, value());
      if (*o.checkpoint_every <= 0) throw InputError("--checkpoint-every: must be positive, got " + args[k]);
    } else if (!a.empty() && a[0] == '-')
      throw InputError(a + ": unknown option (see aortasph --help)");
    else if (!have_scene) {
      o.scene = a;
      have_scene = true;
    } else
      throw InputError(a + ": unexpected argument (one scene file per run)");
  }
  if (!have_scene) throw InputError("run: missing the scene file (aortasph run SCENE.json)");
  return o;
}

// The scene as this program resolves it, less the keys the recorded resolution lacks: keys a later program
// added, which it fills with defaults that keep the older program's behaviour (a new key's default must: a
// cycle metric may read differently, the simulation may not). Objects keep the recorded keys only; arrays of
// the recorded length are pruned element by element; anything else is compared as it is.
nlohmann::json pruned_to(const nlohmann::json& now, const nlohmann::json& recorded) {
  if (now.is_object() && recorded.is_object()) {
    nlohmann::json out = nlohmann::json::object();
    for (auto it = now.begin(); it != now.end(); ++it)
      if (recorded.contains(it.key())) out[it.key()] = pruned_to(it.value(), recorded[it.key()]);
    return out;
  }
  if (now.is_array() && recorded.is_array() && now.size() == recorded.size()) {
    nlohmann::json out = nlohmann::json::array();
    for (std::size_t k = 0; k < now.size(); ++k) out.push_back(pruned_to(now[k], recorded[k]));
    return out;
  }
  return now;
}

namespace {

constexpr const char* kCheckpointFile = "checkpoint.bin";

uint64_t scene_hash(const nlohmann::json& resolved) {
  const std::string text = resolved.dump();
  return fnv1a64(text.data(), text.size());
}

// What a checkpoint records besides the World: the program version, the resolved scene and the run's
// options, how many outputs are on disk, and the renderer's colour ranges (run-wide and per camera).
struct RunRecord {
  std::string version = AORTASPH_VERSION;
  std::string scene;  // resolved scene JSON
  uint64_t hash = 0;
  std::string scene_file;
  std::vector<std::string> sets;
  bool no_render = false, vtk = false;
  int32_t vtk_every = 1;
  double checkpoint_every = 0.0, next_checkpoint = 0.0;
  // --end-time: the end the run uses and the scene file's own (figures are validated against the latter).
  double end_override = 0.0, file_end = 0.0;
  int32_t frames = 0;
  // Rows of probes.csv and diagnostics.csv (section "rows"; a checkpoint without it wrote a row per frame).
  int32_t rows = 0;
  std::optional<std::pair<double, double>> range;
  // Per camera (name, range): cameras may colour by their own field, colormap or hidden bodies (section
  // "camera_ranges"; a checkpoint without it was written before cameras had overrides).
  std::vector<std::pair<std::string, std::optional<std::pair<double, double>>>> camera_ranges;

  void save(StateWriter& out) const {
    SectionWriter& w = out.section("run", 1);
    w.string(version);
    w.string(scene);
    w.value(hash);
    w.string(scene_file);
    w.value(static_cast<uint64_t>(sets.size()));
    for (const auto& set : sets) w.string(set);
    w.value(no_render);
    w.value(vtk);
    w.value(checkpoint_every);
    w.value(next_checkpoint);
    w.value(end_override);
    w.value(file_end);
    w.value(frames);
    w.value(range.has_value());
    w.value(range ? range->first : 0.0);
    w.value(range ? range->second : 0.0);
    out.section("vtk_every", 1).value(vtk_every);
    out.section("rows", 1).value(rows);
    SectionWriter& c = out.section("camera_ranges", 1);
    c.value(static_cast<uint64_t>(camera_ranges.size()));
    for (const auto& [name, r] : camera_ranges) {
      c.string(name);
      c.value(r.has_value());
      c.value(r ? r->first : 0.0);
      c.value(r ? r->second : 0.0);
    }
  }
  // The version is read and checked first: a checkpoint of another version is refused before anything of
  // its layout is trusted.
  static RunRecord load(const StateReader& in, const std::filesystem::path& file) {
    SectionReader r = in.section("run");
    RunRecord rec;
    rec.version = r.string();
    if (rec.version != AORTASPH_VERSION)
      throw InputError(file.string() + ": written by aortasph " + rec.version + ", this is aortasph " +
                       AORTASPH_VERSION + "; a checkpoint resumes only with the version that wrote it");
    rec.scene = r.string();
    rec.hash = r.value<uint64_t>();
    rec.scene_file = r.string();
    const auto n = r.value<uint64_t>();
    for (uint64_t k = 0; k < n; ++k) rec.sets.push_back(r.string());
    rec.no_render = r.value<bool>();
    rec.vtk = r.value<bool>();
    rec.checkpoint_every = r.value<double>();
    rec.next_checkpoint = r.value<double>();
    rec.end_override = r.value<double>();
    rec.file_end = r.value<double>();
    rec.frames = r.value<int32_t>();
    const bool has_range = r.value<bool>();
    const double lo = r.value<double>(), hi = r.value<double>();
    if (has_range) rec.range = std::pair{lo, hi};
    r.done();
    if (in.has("vtk_every")) {  // a checkpoint without it wrote every output's frame
      SectionReader v = in.section("vtk_every");
      rec.vtk_every = v.value<int32_t>();
      v.done();
      if (rec.vtk_every < 1) throw InputError(file.string() + ": a VTK stride below 1 (damaged checkpoint)");
    }
    rec.rows = rec.frames;
    if (in.has("rows")) {
      SectionReader v = in.section("rows");
      rec.rows = v.value<int32_t>();
      v.done();
      if (rec.rows < rec.frames)
        throw InputError(file.string() + ": fewer rows than frames (damaged checkpoint)");
    }
    if (in.has("camera_ranges")) {
      SectionReader c = in.section("camera_ranges");
      const auto count = c.value<uint64_t>();
      for (uint64_t k = 0; k < count; ++k) {
        std::string name = c.string();
        const bool has = c.value<bool>();
        const double clo = c.value<double>(), chi = c.value<double>();
        rec.camera_ranges.emplace_back(std::move(name),
                                       has ? std::optional(std::pair{clo, chi}) : std::nullopt);
      }
      c.done();
    }
    if (fnv1a64(rec.scene.data(), rec.scene.size()) != rec.hash)
      throw InputError(file.string() + ": the recorded scene does not match its hash (damaged checkpoint)");
    if (rec.frames < 1) throw InputError(file.string() + ": records no output (damaged checkpoint)");
    return rec;
  }
};

// The run itself, fresh or resumed (resume: the checkpoint and its record; the World is built from the scene
// and then given the checkpoint's state, so it continues exactly where the interrupted run stopped).
int execute(LoadedScene loaded, const RunOptions& o, const std::filesystem::path& dir, double file_end,
            const StateReader* resume, const RunRecord* record) {
  Scene& scene = loaded.scene;
  if (!o.no_render) validate_render(scene);  // before the folder, the World and the CSV files
  prepare_out_dir(dir);
  if (o.threads > 0) set_threads(o.threads);
  const int threads = max_threads();
  const long outputs = static_cast<long>(std::floor(scene.t_end / scene.output_interval + 1e-9));
  // Probe rows at j * probe_interval, a whole number `per_output` of them per output interval: row j is frame
  // j / per_output where that divides, and the end off the grid has a row and a frame.
  const long per_output = std::max(1L, std::lround(scene.output_interval / scene.probe_interval));
  const long rows_on_grid = static_cast<long>(std::floor(scene.t_end / scene.probe_interval + 1e-9));
  int first_frame = record ? record->frames : 0;
  int first_row = record ? record->rows : 0;
  const bool render = !o.no_render && !scene.render.cameras.empty();
  check_resources(scene, dir, outputs + 1 - first_frame + (scene.t_end > outputs * scene.output_interval),
                  render, o.vtk ? o.vtk_every : 0);

  if (!resume) {
    // A checkpoint left by an earlier run in this folder would no longer match the files this run writes.
    std::error_code ec;
    std::filesystem::remove(dir / kCheckpointFile, ec);
  }

  const auto wall_start = Clock::now();
  World world(scene);
  ProbeSet probes(scene, world);  // resolved on the state at t = 0, as in the run that wrote the checkpoint
  check_cycle_columns(scene, probes.columns());
  if (resume) world.load_state(*resume);
  if (resume && world.time() > scene.t_end * (1.0 + 1e-12))
    throw InputError(dir.string() + ": the checkpoint is at t = " + format_number(world.time()) +
                     " s, past the end " + format_number(scene.t_end) +
                     " s (resume --end-time T with T later)");
  if (resume && world.time() < scene.t_end) {
    // A run that ended between two outputs wrote a last row and frame at its end, off the grid of
    // k * output_interval. Run on to a later end, that output is dropped (its row, and its frame number is
    // the next grid output's), so that frame k stays at t = k * output_interval and the rows match the
    // frames: the outputs are those of one run to the new end.
    const int on_grid = static_cast<int>(std::floor(world.time() / scene.output_interval + 1e-9)) + 1;
    if (first_frame > on_grid) first_frame = on_grid;
    const int rows_on = static_cast<int>(std::floor(world.time() / scene.probe_interval + 1e-9)) + 1;
    if (first_row > rows_on) first_row = rows_on;
  }
  std::optional<CsvWriter> probe_csv, diag_csv;
  std::optional<VtkWriter> vtk;
  std::optional<std::ofstream> put_backs;  // scenes with shells
  if (!world.shells().empty())
    put_backs = open_put_backs(dir / "shell_putbacks.csv", resume ? world.time() : -1.0);
  if (resume) {
    probe_csv.emplace(dir / "probes.csv", probes.columns(), first_row);
    diag_csv.emplace(dir / "diagnostics.csv", diagnostics_columns(), first_row);
    if (o.vtk) vtk.emplace(dir / "vtk", first_frame, o.vtk_every);
  } else {
    probe_csv.emplace(dir / "probes.csv", probes.columns());
    diag_csv.emplace(dir / "diagnostics.csv", diagnostics_columns());
    if (o.vtk) vtk.emplace(dir / "vtk");
  }
  std::unique_ptr<FrameSink> frames;
  if (!o.no_render) {
    // The colour ranges of the interrupted run, so the resumed frames are coloured alike: each camera's as
    // its own range (a camera whose range was not chosen yet must not inherit the run-wide one: it chooses
    // its own later, as the uninterrupted run does); a checkpoint without per-camera ranges has the run-wide
    // one only.
    Scene render_scene = scene;
    if (record && record->camera_ranges.empty() && record->range) render_scene.render.range = record->range;
    if (record)
      for (const auto& [name, range] : record->camera_ranges)
        for (Camera& camera : render_scene.render.cameras)
          if (camera.name == name && range) camera.range = range;
    frames = make_frame_sink(render_scene, dir);
    if (frames && resume) frames->adopt_existing_frames(first_frame);
  }
  const double setup_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();

  if (!o.quiet)
    std::fprintf(stderr, "aortasph: %s: %zu particles (%zu fluid), h = %g m, %d thread(s) -> %s%s\n",
                 scene.name.c_str(), world.particles().size(), world.count(Kind::Fluid), world.kernel().h,
                 threads, dir.string().c_str(),
                 resume ? (" (resumed at t = " + format_number(world.time()) + " s)").c_str() : "");

  // Cycle metrics (scene block `cycle`): after each output that completes a cycle, every complete cycle is
  // measured again from probes.csv (so a resumed run counts the rows before the checkpoint too), cycles.csv
  // rewritten and the new cycles reported on standard output.
  std::vector<CycleMetrics> cycles;
  std::size_t cycles_reported = 0;
  bool cycles_changed = false;  // run.json is rewritten after an output that completed a cycle
  auto cycles_of_run = [&]() {
    const CsvTable diagnostics = read_csv(dir / "diagnostics.csv");
    return cycle_metrics_of(scene, read_csv(dir / "probes.csv"), &diagnostics);
  };
  auto update_cycles = [&]() {
    if (!scene.cycle) return;
    cycles_changed = true;
    cycles = cycles_of_run();
    write_cycles_csv(dir / "cycles.csv", cycles, scene);
    for (; cycles_reported < cycles.size(); ++cycles_reported)
      std::printf("aortasph: %s\n", cycle_line(cycles[cycles_reported]).c_str());
    std::fflush(stdout);
  };
  double next_cycle_end = scene.cycle ? scene.cycle->start + scene.cycle->period : 0.0;
  if (resume && scene.cycle) {
    // The cycles completed before the checkpoint were reported by the interrupted run (probes.csv holds
    // their rows): measured again for run.json, not printed again.
    while (next_cycle_end <= world.time() + 1e-9 * scene.cycle->period) next_cycle_end += scene.cycle->period;
    cycles = cycles_of_run();
    cycles_reported = cycles.size();
  }

  int frame = first_frame, rows_done = first_row;
  // A row of probes.csv and diagnostics.csv; with `with_frame`, the frame and VTK file of this output too.
  auto output = [&](bool with_frame) {
    std::vector<double> row{world.time()};
    const auto values = probes.measure(world);
    row.insert(row.end(), values.begin(), values.end());
    probe_csv->row(row);
    diag_csv->row(diagnostics_row(world));
    if (scene.cycle && world.time() >= next_cycle_end - 1e-9 * scene.cycle->period) {
      while (next_cycle_end <= world.time() + 1e-9 * scene.cycle->period)
        next_cycle_end += scene.cycle->period;
      update_cycles();
    }
    ++rows_done;
    if (!with_frame) return;
    // --vtk-every N: frames 0, N, 2N, ... and the last output (the end state, which a study's stress map
    // reads).
    if (vtk && (frame % o.vtk_every == 0 || world.time() >= scene.t_end - 1e-9 * scene.probe_interval))
      vtk->write(world, frame);
    if (frames) frames->push(world, frame);
    ++frame;
  };

  RunRecord rec;
  rec.scene = loaded.resolved.dump();
  rec.hash = scene_hash(loaded.resolved);
  // Absolute, so that `resume` finds the scene's files (waveforms) from any working directory.
  rec.scene_file = std::filesystem::weakly_canonical(std::filesystem::absolute(o.scene)).string();
  rec.sets = o.sets;
  rec.no_render = o.no_render;
  rec.vtk = o.vtk;
  rec.vtk_every = o.vtk_every;
  rec.checkpoint_every = o.checkpoint_every.value_or(0.0);
  rec.next_checkpoint = record ? record->next_checkpoint : rec.checkpoint_every;
  rec.end_override = o.end_time.value_or(0.0);
  rec.file_end = file_end;

  // A checkpoint counts only what is on disk: the frames pushed so far are written first (the CSV rows are
  // flushed row by row). Written atomically, so a kill at any moment leaves the previous or this one.
  double checkpoint_time = -1.0;  // the time of the last checkpoint this run wrote
  auto write_checkpoint = [&]() {
    if (frames) frames->flush();
    rec.frames = frame;
    rec.rows = rows_done;
    rec.range = frames ? frames->field_range() : std::nullopt;
    rec.camera_ranges.clear();
    if (frames) {
      const auto ranges = frames->camera_ranges();
      for (std::size_t c = 0; c < ranges.size() && c < scene.render.cameras.size(); ++c)
        rec.camera_ranges.emplace_back(scene.render.cameras[c].name, ranges[c]);
    }
    StateWriter out;
    rec.save(out);
    world.save_state(out);
    out.write_file(dir / kCheckpointFile);
    checkpoint_time = world.time();
  };

  auto write_run_json = [&](const std::string& status, const std::string& message) {
    nlohmann::json j;
    j["program"] = "aortasph";
    j["version"] = AORTASPH_VERSION;
    j["status"] = status;
    if (!message.empty()) j["message"] = message;
    j["threads"] = threads;
    j["scene"] = loaded.resolved;
    j["scene_file"] = rec.scene_file;
    j["sets"] = o.sets;
    if (o.checkpoint_every) j["checkpoint_every"] = *o.checkpoint_every;
    if (resume) j["resumed_at"] = {{"time", world.time()}, {"frame", first_frame}, {"row", first_row}};
    j["particles"] = {{"total", world.particles().size()},
                      {"fluid", world.count(Kind::Fluid)},
                      {"boundary", world.particles().size() - world.count(Kind::Fluid)}};
    j["time"] = {{"simulated", world.time()},
                 {"steps", world.steps()},
                 {"frames", frame},
                 {"probe_rows", rows_done},
                 {"neighbour_list_builds", world.list_builds()}};
    if (!world.shells().empty())  // fluid particles put back on their side of a sheet (0 when it holds)
      j["shells"] = {{"particles", world.shells().size()},
                     {"fluid_crossings", world.shell_crossings()},
                     {"label_disagreements", world.shell_label_disagreements()},
                     {"masked_pairs", world.shell_masked_pairs()},
                     {"rim_particles", world.shell_rim_particles()}};
    j["timings_s"] = {{"setup", setup_seconds},
                      {"wall", std::chrono::duration<double>(Clock::now() - wall_start).count()}};
    for (const auto& [name, sec] : world.profile().phases()) j["timings_s"][name] = sec;
    if (scene.cycle) j["cycles"] = cycles_json(scene, cycles);
    std::ofstream f(dir / "run.json", std::ios::trunc);
    f << std::setw(2) << j << '\n';
    f.close();
    if (!f) throw InputError((dir / "run.json").string() + ": write failed (disk full?)");
  };

  g_interrupted = false;
  auto previous_int = std::signal(SIGINT, on_signal);
  auto previous_term = std::signal(SIGTERM, on_signal);
  struct RestoreSignals {
    decltype(previous_int) i, t;
    ~RestoreSignals() {
      std::signal(SIGINT, i);
      std::signal(SIGTERM, t);
    }
  } restore{previous_int, previous_term};

  Progress progress(scene.t_end, o.quiet);
  int code = 0;
  try {
    write_run_json("running", "");
    if (!resume) output(true);
    // Outputs at exactly k * output_interval (SPEC section 2), probe rows at exactly j * probe_interval
    // between them, then at t_end if that is not one of them. Row j is the j-th row, so a resumed run
    // continues at j = the rows already written.
    for (long j = std::max(1, first_row); j <= rows_on_grid + 1 && !g_interrupted; ++j) {
      const bool on_frame = j <= rows_on_grid && j % per_output == 0;
      const double target = j > rows_on_grid ? scene.t_end
                            : on_frame       ? static_cast<double>(j / per_output) * scene.output_interval
                                             : static_cast<double>(j) * scene.probe_interval;
      if (target <= world.time()) break;
      const bool reached = world.advance_to(target, [&] {
        progress.update(world);
        if (put_backs) write_put_backs(*put_backs, world);
        return !g_interrupted.load();
      });
      if (!reached) break;  // interrupted between outputs: no partial row, everything before stays valid
      // The end has a frame, on the grid of outputs or not.
      output(on_frame || target >= scene.t_end - 1e-9 * scene.probe_interval);
      if (cycles_changed) {
        write_run_json("running", "");
        cycles_changed = false;
      }
      if (rec.checkpoint_every > 0.0 && world.time() >= rec.next_checkpoint && !g_interrupted) {
        while (rec.next_checkpoint <= world.time()) rec.next_checkpoint += rec.checkpoint_every;
        write_checkpoint();
      }
    }
    progress.done();
    if (frames) frames->finish();
    // A run that writes checkpoints, or a resumed one, leaves one of its end state: its run.json names the
    // scene as run (time.end included), and `resume --end-time` runs it on from its end, not from an earlier
    // checkpoint (an older checkpoint of a resumed run would describe another time.end than run.json).
    if (!g_interrupted && (rec.checkpoint_every > 0.0 || resume) && checkpoint_time != world.time())
      write_checkpoint();
    if (g_interrupted) {
      // SIGINT / SIGTERM: the step in hand is finished, the frames in the queue are written, then the state.
      write_checkpoint();
      std::fprintf(
          stderr,
          "aortasph: interrupted at t = %g s; checkpoint written, everything written so far is valid "
          "(continue with: aortasph resume %s)\n",
          world.time(), dir.string().c_str());
      update_cycles();  // the cycles complete so far, for `aortasph plot` and the resumed run
      write_run_json("interrupted", "");
      code = 130;
    } else {
      update_cycles();
      write_run_json("ok", "");
      // The Wiggers plot of a run with a cycle block; a missing python3 / matplotlib is a warning here (the
      // run's results stand) and an error for `aortasph plot`.
      if (scene.cycle) {
        std::string error;
        if (make_wiggers_plot(dir, error) != 0)
          std::fprintf(stderr,
                       "aortasph: warning: no Wiggers plot: %s (make it later with: aortasph plot %s)\n",
                       error.c_str(), dir.string().c_str());
      }
    }
  } catch (const InstabilityError& e) {
    progress.done();
    if (frames) frames->finish_quietly();
    // The cycles complete before the blow-up (cycles.csv, for `aortasph plot`); the blow-up's own message
    // is what the run reports, whatever happens here.
    try {
      update_cycles();
    } catch (const std::exception&) {
    }
    write_run_json("unstable", e.what());
    throw;
  } catch (const std::exception& e) {
    // A write error (disk full) or a render failure: stop with every file as complete as it can be.
    progress.done();
    if (frames) frames->finish_quietly();
    try {
      write_run_json("failed", e.what());
    } catch (const std::exception&) {
      // The run's own error is the one to report.
    }
    throw;
  }
  if (!o.quiet && code == 0) {
    const double wall = std::chrono::duration<double>(Clock::now() - wall_start).count();
    std::fprintf(stderr, "aortasph: done: %ld steps, %d outputs, %.1f s wall (%.3g particle-steps/s) -> %s\n",
                 world.steps(), frame, wall,
                 static_cast<double>(world.particles().size()) * static_cast<double>(world.steps()) /
                     std::max(world.profile().total(), 1e-9),
                 dir.string().c_str());
  }
  return code;
}

}  // namespace

int cmd_run(const RunOptions& o) {
  LoadedScene loaded = load_scene(o.scene, o.sets);
  const double file_end = loaded.scene.t_end;
  if (o.end_time) {
    loaded.scene.t_end = *o.end_time;
    loaded.resolved["time"]["end"] = *o.end_time;
  }
  const std::filesystem::path dir = o.out ? *o.out : std::filesystem::path("out") / loaded.scene.name;
  return execute(std::move(loaded), o, dir, file_end, nullptr, nullptr);
}

ResumeOptions parse_resume_options(const std::vector<std::string>& args) {
  ResumeOptions o;
  bool have_dir = false;
  for (std::size_t k = 0; k < args.size(); ++k) {
    const std::string& a = args[k];
    if (a == "--threads") {
      if (k + 1 >= args.size()) throw InputError(a + ": missing value");
      o.threads = parse_int(a, args[++k]);
      if (o.threads < 1 || o.threads > 1024) throw InputError("--threads: expected 1..1024, got " + args[k]);
    } else if (a == "--quiet") {
      o.quiet = true;
    } else if (a == "--end-time") {
      if (k + 1 >= args.size()) throw InputError(a + ": missing value");
      o.end_time = parse_double(a, args[++k]);
      if (*o.end_time <= 0) throw InputError("--end-time: must be positive, got " + args[k]);
    } else if (!a.empty() && a[0] == '-') {
      throw InputError(a + ": unknown option for resume (see aortasph --help)");
    } else if (!have_dir) {
      o.dir = a;
      have_dir = true;
    } else {
      throw InputError(a + ": unexpected argument (one output folder)");
    }
  }
  if (!have_dir) throw InputError("resume: missing the output folder (aortasph resume DIR)");
  return o;
}

namespace {

// A run folder's checkpoint opened as `resume` opens it: the state, its run record and the recorded scene
// resolved again by this program (refused where it no longer resolves to the recorded values).
struct OpenedCheckpoint {
  StateReader state;
  RunRecord record;
  LoadedScene loaded;
};

// sets: --set overrides applied after the check (bench --from), on the scene as it was recorded.
OpenedCheckpoint open_checkpoint(const std::filesystem::path& dir,
                                 const std::vector<std::string>& sets = {}) {
  const std::filesystem::path file = dir / kCheckpointFile;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    throw InputError(file.string() +
                     ": no checkpoint here (write one with run --checkpoint-every T, or stop " +
                     "a run with Ctrl-C / SIGTERM)");
  StateReader state = [&] {
    try {
      return StateReader::from_file(file);
    } catch (const SetupError& e) {
      throw InputError(e.what());
    }
  }();
  RunRecord record = RunRecord::load(state, file);
  nlohmann::json resolved = nlohmann::json::parse(record.scene, nullptr, false);
  if (resolved.is_discarded()) throw InputError(file.string() + ": the recorded scene is not valid JSON");
  // run.json names the scene this folder's files belong to: a checkpoint of another scene is refused.
  std::ifstream run_json(dir / "run.json");
  if (run_json) {
    const nlohmann::json j = nlohmann::json::parse(run_json, nullptr, false);
    if (j.is_discarded() || !j.contains("scene") || scene_hash(j["scene"]) != record.hash)
      throw InputError((dir / "run.json").string() + " describes another scene than " + file.string() +
                       " (scene hash mismatch); refusing to mix two runs in one folder");
  }
  // Loaded as the file was (figure times are checked against the file's time.end), then --end-time again.
  nlohmann::json as_file = resolved;
  if (record.end_override > 0.0) as_file["time"]["end"] = record.file_end;
  // Files the scene names (waveforms) are relative to the scene file's folder, as when it was run.
  const std::filesystem::path base = std::filesystem::path(record.scene_file).parent_path();
  const auto load = [&](const std::vector<std::string>& overrides) {
    LoadedScene l = load_scene_json(as_file, overrides, base);
    if (record.end_override > 0.0) {
      l.scene.t_end = record.end_override;
      l.resolved["time"]["end"] = record.end_override;
    }
    return l;
  };
  LoadedScene loaded = load({});
  // The same values as when it ran; keys this program added since are left out of the comparison
  // (pruned_to): a run of an older program resumes with them at their defaults.
  if (scene_hash(loaded.resolved) != record.hash &&
      scene_hash(pruned_to(loaded.resolved, resolved)) != record.hash)
    throw InputError(file.string() + ": the recorded scene no longer resolves to the same values with this " +
                     "program; cannot resume");
  if (!sets.empty()) loaded = load(sets);
  return {std::move(state), std::move(record), std::move(loaded)};
}

}  // namespace

CheckpointScene load_checkpoint(const std::filesystem::path& dir, const std::vector<std::string>& sets) {
  OpenedCheckpoint c = open_checkpoint(dir, sets);
  return {std::move(c.loaded), std::move(c.state)};
}

int cmd_resume(const ResumeOptions& ro) {
  OpenedCheckpoint c = open_checkpoint(ro.dir);
  StateReader& state = c.state;
  const RunRecord& record = c.record;
  LoadedScene& loaded = c.loaded;
  RunOptions o;
  o.scene = record.scene_file;
  o.out = ro.dir;
  o.threads = ro.threads;
  o.sets = record.sets;
  o.no_render = record.no_render;
  o.vtk = record.vtk;
  o.vtk_every = record.vtk_every;
  o.quiet = ro.quiet;
  if (record.checkpoint_every > 0.0) o.checkpoint_every = record.checkpoint_every;
  if (record.end_override > 0.0) o.end_time = record.end_override;
  if (ro.end_time) {  // a new end, after the hash check (the recorded scene is the one that was run)
    loaded.scene.t_end = *ro.end_time;
    loaded.resolved["time"]["end"] = *ro.end_time;
    o.end_time = ro.end_time;
  }
  try {
    return execute(std::move(loaded), o, ro.dir, record.file_end, &state, &record);
  } catch (const SetupError& e) {
    throw InputError(std::string("resume: ") + e.what());
  }
}

int cmd_check(const std::filesystem::path& file, const std::vector<std::string>& sets) {
  const LoadedScene loaded = load_scene(file, sets);
  const Scene& scene = loaded.scene;
  validate_render(scene);
  const World world(scene);
  check_cycle_columns(scene, ProbeSet(scene, world).columns());
  std::printf("scene %s: spacing %g m, h = %g m (ratio %g), domain [%g %g %g] .. [%g %g %g]\n",
              scene.name.c_str(), scene.spacing, world.kernel().h, scene.smoothing_ratio,
              scene.domain.min.x(), scene.domain.min.y(), scene.domain.min.z(), scene.domain.max.x(),
              scene.domain.max.y(), scene.domain.max.z());
  std::printf("  %-20s %-12s %-8s %10s\n", "body", "material", "type", "particles");
  static const char* kTypes[] = {"fluid", "elastic", "rigid", "wall", "shell"};
  for (const BodyInfo& b : world.bodies())
    std::printf("  %-20s %-12s %-8s %10zu\n", b.name.c_str(), scene.materials[b.material].name.c_str(),
                kTypes[static_cast<int>(b.type)], b.count);
  const std::size_t n = world.particles().size();
  const std::size_t nf = world.count(Kind::Fluid);
  const std::size_t nin = world.count(Kind::Inflow), nout = world.count(Kind::Outflow);
  if (scene.open_boundaries.empty())
    std::printf("  total %zu particles (%zu fluid, %zu boundary)\n", n, nf, n - nf);
  else
    std::printf("  total %zu particles (%zu fluid, %zu inflow buffer, %zu outflow buffer, %zu boundary)\n", n,
                nf, nin, nout, n - nf - nin - nout);
  for (const OpenBoundarySpec& o : scene.open_boundaries) {
    if (o.type == OpenBoundaryType::Inflow && o.pressure_inlet)
      std::printf("  inflow  %-12s radius %g m, %d layers, pressure inlet, pressure %g Pa at t = 0\n",
                  o.name.c_str(), o.radius, o.layers, o.inlet_pressure.at(0.0));
    else if (o.type == OpenBoundaryType::Outflow && o.windkessel)
      std::printf(
          "  outflow %-12s radius %g m, %d layers, RCR Windkessel (R_p %g, C %g, R_d %g, P_d %g), "
          "P_c %g Pa at t = 0\n",
          o.name.c_str(), o.radius, o.layers, o.windkessel->proximal_resistance, o.windkessel->capacitance,
          o.windkessel->distal_resistance, o.windkessel->distal_pressure, o.windkessel->initial_pressure);
    else if (o.type == OpenBoundaryType::Inflow)
      std::printf("  inflow  %-12s radius %g m, %d layers, %s profile, velocity %g m/s at t = 0\n",
                  o.name.c_str(), o.radius, o.layers, o.parabolic ? "parabolic" : "uniform",
                  o.velocity.at(0.0));
    else
      std::printf("  outflow %-12s radius %g m, %d layers, pressure %g Pa at t = 0\n", o.name.c_str(),
                  o.radius, o.layers, o.pressure.at(0.0));
  }
  if (!scene.open_boundaries.empty())
    std::printf("  prescribed inflow: %g m^3/s at t = 0\n",
                world.open_boundaries().prescribed_inflow_rate(0.0));
  // Aortic leaflets are layers x dx thick, far thicker than a real leaflet: the modulus that bends alike.
  for (const Body& b : scene.bodies)
    if (b.shape.kind == ShapeKind::AorticRoot && b.shape.aortic_part == AorticPart::Leaflet) {
      if (b.shape.aortic.shell_leaflets) {  // one layer at the material's thickness (issue 16)
        const Material& m = scene.materials[b.material];
        std::printf("  aortic leaflets: shells %g mm thick (one layer), E = %.3g MPa\n", m.thickness * 1e3,
                    m.youngs_modulus / 1e6);
        break;
      }
      const double t = b.shape.aortic.leaflet_layers * scene.spacing;
      const double E = scene.materials[b.material].youngs_modulus;
      // E_real = E (t / t_real)^3: the inverse of bending_equivalent_modulus, t_real = 0.4 mm.
      const double E_real = E / bending_equivalent_modulus(1.0, 0.4e-3, t);
      std::printf(
          "  aortic leaflets %g mm thick (%d layers): E = %.3g kPa here bends like a real 0.4 mm leaflet "
          "of E = %.3g MPa (E t^3 kept; docs/scenes.md)\n",
          t * 1e3, b.shape.aortic.leaflet_layers, E / 1e3, E_real / 1e6);
      break;
    }
  const double dt = world.stable_dt();
  const double steps = std::ceil(scene.t_end / dt);
  const double neighbors = n ? static_cast<double>(world.neighbors().pairs()) / static_cast<double>(n) : 0.0;
  std::printf(
      "  dt estimate %.3g s (cfl %g, max_dt %g), about %.0f steps to t = %g s, %.0f neighbours/particle\n",
      dt, scene.cfl, scene.max_dt, steps, scene.t_end, neighbors);
  // Cost model, fitted at stop 14 to the per-phase profiles (diagnostics.csv) of runs on 2 threads without
  // rendering: per step, 0.0107 us per neighbour pair when there is fluid (the fluid's neighbour, density and
  // force phases; pairs of two fixed particles are not listed), 0.075 us per particle, and 1.6 us per elastic
  // particle (TL-SPH). dam_break 18.6 ms per step (measured 18.6), fluid_cubes 14.7 (14.6), flexible_pole 3.7
  // (4.0); with open boundaries about 1.4 times optimistic (tube_flow 5.3 against 7.2, aortic_root 32.5
  // against 41). A first guess: the dt adapts during the run, and rendering shares the cores (it nearly
  // doubled the aortic root's wall time).
  const bool has_fluid = nf + nin + nout > 0;
  const double pairs = has_fluid ? static_cast<double>(world.neighbors().pairs()) : 0.0;
  const double step_2threads =
      1.07e-8 * pairs + 7.5e-8 * static_cast<double>(n) +
      1.6e-6 * static_cast<double>(world.count(Kind::Elastic)) +
      0.6e-6 * static_cast<double>(world.count(Kind::Shell));  // shells: a guess from the [shell] tests
  const int threads = max_threads();
  const double seconds = steps * step_2threads * 2.0 / threads;
  std::printf(
      "  cost estimate: %.3g s per step, about %s on %d thread(s) without rendering; memory about %.0f MB\n",
      step_2threads * 2.0 / threads, hms(seconds).c_str(), threads,
      static_cast<double>(world.memory_bytes()) / 1e6);
  if (scene.cycle) {
    std::string cols;
    // Appended piecewise: " " + std::string trips GCC 12's -Wstringop-overflow false positive at -O3.
    for (const auto& [key, col] : cycle_columns(scene)) {
      cols += ' ';
      cols.append(key, 6);
      cols += '=';
      cols += col;
    }
    std::printf("  cycle: period %g s, %zu complete cycle(s) to t = %g s;%s\n", scene.cycle->period,
                cycle_windows(scene.t_end, {scene.cycle->period, scene.cycle->start}).size(), scene.t_end,
                cols.c_str());
  }
  std::printf("  outputs: %ld (every %g s), probe rows: %ld (every %g s), probes: %zu, cameras: %zu\n",
              static_cast<long>(std::floor(scene.t_end / scene.output_interval + 1e-9)) + 1,
              scene.output_interval,
              static_cast<long>(std::floor(scene.t_end / scene.probe_interval + 1e-9)) + 1,
              scene.probe_interval, scene.probes.size(), scene.render.cameras.size());
  return 0;
}

}  // namespace aortasph
