// Checkpoints (issue 7): a World saved and loaded continues bitwise as the original; the file format refuses
// damage and foreign layouts; end to end, a run killed (SIGKILL) or interrupted (SIGINT, SIGTERM) and resumed
// gives probes.csv and frames bitwise identical to an uninterrupted run.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "builders.hpp"
#include "cli_helpers.hpp"
#include "commands.hpp"
#include "core/sim_errors.hpp"
#include "image.hpp"
#include "io/checkpoint.hpp"
#include "world.hpp"

using namespace aortasph;
using namespace aortasph::test;
namespace fs = std::filesystem;

namespace {

// Everything a step reads or writes, as bits: equal vectors mean bitwise equal states.
std::vector<double> state_of(const World& w) {
  std::vector<double> s = {w.time(), static_cast<double>(w.steps()), w.last_dt(), w.max_speed(),
                           static_cast<double>(w.list_builds())};
  const Particles& P = w.particles();
  for (std::size_t i = 0; i < P.size(); ++i) {
    for (int d = 0; d < 3; ++d) s.insert(s.end(), {P.x[i][d], P.v[i][d], P.a[i][d]});
    s.insert(s.end(), {P.rho[i], P.p[i], static_cast<double>(P.id[i])});
  }
  for (const RigidBody& b : w.rigid_bodies())
    s.insert(s.end(), {b.com.x(), b.com.y(), b.com.z(), b.q.w(), b.q.x(), b.P.x(), b.P.y(), b.L.z()});
  return s;
}

Scene fluid_and_block() {
  Scene s = fluid_cubes(0.01);
  // Shifting on, counted in the density: each particle's shift of the last step (Particles::shift) enters the
  // next step's density, so it is part of the state the checkpoint must carry.
  s.materials[0].shifting = 2.0;
  s.materials[0].shifting_ale = true;
  Material steel;
  steel.name = "steel";
  steel.type = MaterialType::Rigid;
  steel.density = 3000;
  s.materials.push_back(steel);
  s.contact = {1e4, 2.0, 1.0, 0.5};
  s.bodies.push_back(box_body("block", 1, Vec3(-0.02, -0.15, -0.02), Vec3(0.02, -0.08, 0.02), Vec3(0, 1, 0)));
  // A drop that flies out of the domain: particles that leave are removed, so the checkpoint must carry the
  // shorter arrays.
  s.bodies.push_back(box_body("drop", 0, Vec3(0.29, 0.2, 0), Vec3(0.30, 0.21, 0.01), Vec3(5, 0, 0)));
  s.domain = {Vec3(-1, -1, -1), Vec3(0.305, 1, 1)};
  s.max_leave_fraction = 0.5;
  return s;
}

}  // namespace

TEST_CASE("checkpoint: a loaded World continues bitwise as the saved one", "[checkpoint][heavy]") {
  const Scene s = fluid_and_block();
  World a(s);
  for (int k = 0; k < 60; ++k) a.step(a.stable_dt());
  StateWriter out;
  a.save_state(out);
  const StateReader in(out.bytes());

  World b(s);
  b.load_state(in);
  CHECK(state_of(b) == state_of(a));
  const std::size_t at_checkpoint = a.particles().size();
  // More steps cross Verlet-list rebuilds and a spatial sort (every 4th build).
  const long builds = a.list_builds();
  for (int k = 0; k < 150; ++k) {
    a.step(a.stable_dt());
    b.step(b.stable_dt());
  }
  INFO("list builds " << builds << " -> " << a.list_builds() << ", particles " << at_checkpoint << " -> "
                      << a.particles().size());
  CHECK(a.list_builds() >= builds + 4);                       // so one of them sorted
  CHECK(a.particles().size() < World(s).particles().size());  // the drop left the domain
  CHECK(state_of(b) == state_of(a));
}

TEST_CASE("checkpoint: an elastic body (its slot map and stress) continues bitwise",
          "[checkpoint][solid][heavy]") {
  // The cubes collide while a clamped elastic plate below them swings: the spatial sort permutes the
  // elastic particles, so the solid's particle map must follow the stored order on load.
  Scene s = fluid_cubes(0.01);
  Material gel;
  gel.name = "gel";
  gel.type = MaterialType::Elastic;
  gel.density = 1000;
  gel.youngs_modulus = 2e4;
  gel.poisson_ratio = 0.3;
  s.materials.push_back(gel);
  Body plate = box_body("plate", 1, Vec3(-0.1, -0.2, -0.02), Vec3(0.1, -0.17, 0.02));
  plate.fixed = Box{Vec3(-1, -1, -1), Vec3(-0.08, 1, 1)};
  s.bodies.push_back(plate);
  World a(s);
  a.set_initial_velocity(2, [](const Vec3& x) { return Vec3(0, 2.0 * (x.x() + 0.1), 0); });
  for (int k = 0; k < 60; ++k) a.step(a.stable_dt());
  StateWriter out;
  a.save_state(out);
  const StateReader in(out.bytes());

  World b(s);
  b.load_state(in);
  CHECK(state_of(b) == state_of(a));
  const long builds = a.list_builds();
  double max_vm = 0;
  for (int k = 0; k < 150; ++k) {
    a.step(a.stable_dt());
    b.step(b.stable_dt());
  }
  const Snapshot sa = a.snapshot("stress", 0), sb = b.snapshot("stress", 0);
  for (float v : sa.fields.at(0).values) max_vm = std::max(max_vm, static_cast<double>(v));
  INFO("list builds " << builds << " -> " << a.list_builds() << ", max von Mises " << max_vm);
  CHECK(a.list_builds() >= builds + 4);  // so one of them sorted
  CHECK(max_vm > 100.0);                 // the plate is bent: its stress is part of the state compared
  CHECK(state_of(b) == state_of(a));
  CHECK(sa.fields.at(0).values == sb.fields.at(0).values);
}

TEST_CASE("checkpoint: damaged files and other scenes are refused", "[checkpoint]") {
  const Scene s = fluid_and_block();
  World a(s);
  a.step(a.stable_dt());
  StateWriter out;
  a.save_state(out);
  const std::vector<char> good = out.bytes();

  auto refused = [](std::vector<char> bytes, const std::string& expect) {
    try {
      const StateReader in(std::move(bytes));
      World w(fluid_and_block());
      w.load_state(in);
    } catch (const SetupError& e) {
      INFO(e.what());
      CHECK(std::string(e.what()).find(expect) != std::string::npos);
      return;
    }
    FAIL("accepted a bad checkpoint, expected: " << expect);
  };
  std::vector<char> flipped = good;
  flipped[flipped.size() / 2] ^= 1;
  refused(flipped, "checksum");
  refused(std::vector<char>(good.begin(), good.begin() + good.size() / 3), "checksum");
  refused(std::vector<char>(good.begin(), good.begin() + 10), "header");

  // A checkpoint of another scene (more particles) does not load into this one.
  Scene other = s;
  other.bodies[0].shape.box.max.x() += 0.02;
  World c(other);
  StateWriter other_out;
  c.save_state(other_out);
  refused(other_out.bytes(), "another scene");

  // A checkpoint without a section this version needs names it.
  StateWriter partial;
  partial.section("world", 1).value(1.0);
  refused(partial.bytes(), "section");
}

// ---- End to end: the aortasph binary ----

namespace {

int run_cli(const std::string& args, std::string* err = nullptr) {
  const fs::path e = fs::temp_directory_path() / ("aortasph_ckpt_err_" + std::to_string(::getpid()));
  const std::string cmd = std::string(AORTASPH_BINARY) + " " + args + " > /dev/null 2> " + e.string();
  const int status = std::system(cmd.c_str());
  if (err) *err = slurp(e);
  fs::remove(e);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Starts the binary without a shell, so the signal reaches aortasph itself.
pid_t spawn(const std::vector<std::string>& args) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv;
    static const std::string bin = AORTASPH_BINARY;
    argv.push_back(const_cast<char*>(bin.c_str()));
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execv(bin.c_str(), argv.data());
    ::_exit(127);
  }
  return pid;
}

// Exit code, or 128 + signal.
int wait_for(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// A small dam break with a camera, a colour range chosen at run time (speed) and a figure, so that a resume
// must restore the colour range and read frames back for the figure.
const char* kScene = R"({
  "name": "ckpt",
  "domain": { "min": [-0.1, -0.1, -0.1], "max": [0.3, 0.3, 0.2] },
  "resolution": { "spacing": 0.01 },
  "time": { "end": 0.06, "output_interval": 0.004 },
  "materials": { "water": { "type": "fluid", "density": 1000, "viscosity": 1e-6, "sound_speed": 10 },
                 "wall": { "type": "wall" } },
  "bodies": [
    { "name": "column", "material": "water", "shape": { "box": { "min": [0, 0, 0], "max": [0.05, 0.1, 0.03] } } },
    { "name": "tank", "material": "wall", "shape": { "container": { "min": [0, 0, 0], "max": [0.2, 0.15, 0.03], "layers": 3, "open": ["+y"] } } }
  ],
  "probes": [ { "name": "front", "type": "extent", "bodies": ["column"], "axis": "x", "stat": "max" },
              { "name": "e", "type": "energy" } ],
  "render": { "width": 64, "height": 48, "color_by": "speed",
              "cameras": [ { "name": "front", "eye": [0.1, 0.08, 0.5], "target": [0.1, 0.05, 0.015] } ],
              "figures": [ { "name": "fig", "camera": "front", "times": [0, 0.02, 0.06], "columns": 3 } ] }
})";

struct Outputs {
  std::string probes;
  std::vector<std::string> frames;
  std::string figure;
};

Outputs outputs_of(const fs::path& out) {
  Outputs o;
  o.probes = slurp(out / "probes.csv");
  for (int k = 0;; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", k);
    if (!fs::exists(out / "frames" / "front" / name)) break;
    o.frames.push_back(slurp(out / "frames" / "front" / name));
  }
  o.figure = slurp(out / "figures" / "fig.png");
  return o;
}

const Outputs& reference(const fs::path& scene) {
  static Outputs ref;
  if (ref.probes.empty()) {
    const fs::path out = scratch("reference");
    std::string err;
    REQUIRE(run_cli("run " + scene.string() + " --quiet --out " + out.string(), &err) == 0);
    ref = outputs_of(out);
    REQUIRE(ref.frames.size() == 16);  // t = 0, 0.004, ..., 0.06
  }
  return ref;
}

fs::path scene_file() {
  const fs::path dir = scratch("scene");
  std::ofstream(dir / "ckpt.json") << kScene;
  return dir / "ckpt.json";
}

// The time column of OUT/probes.csv.
std::vector<double> row_times(const fs::path& out) {
  std::vector<double> t;
  std::istringstream in(slurp(out / "probes.csv"));
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) t.push_back(std::stod(line.substr(0, line.find(','))));
  return t;
}

void check_same(const Outputs& got, const Outputs& ref) {
  CHECK(got.probes == ref.probes);
  REQUIRE(got.frames.size() == ref.frames.size());
  for (std::size_t k = 0; k < ref.frames.size(); ++k) {
    INFO("frame " << k);
    CHECK(got.frames[k] == ref.frames[k]);
  }
  CHECK(got.figure == ref.figure);
}

void wait_for_file(const fs::path& p, pid_t pid) {
  for (int k = 0; k < 3000 && !fs::exists(p); ++k) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) FAIL("the run ended before writing " << p);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

}  // namespace

TEST_CASE("checkpoint: a run killed by SIGKILL at a random moment resumes to identical outputs",
          "[checkpoint][cli][heavy]") {
  const fs::path scene = scene_file();
  const Outputs& ref = reference(scene);
  std::random_device seed;
  std::mt19937 rng(seed());
  for (int attempt = 0; attempt < 2; ++attempt) {
    const fs::path out = scratch("killed" + std::to_string(attempt));
    const pid_t pid =
        spawn({"run", scene.string(), "--quiet", "--out", out.string(), "--checkpoint-every", "0.008"});
    wait_for_file(out / "checkpoint.bin", pid);
    const int delay_ms = std::uniform_int_distribution<int>(0, 400)(rng);
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
    ::kill(pid, SIGKILL);
    const int killed = wait_for(pid);
    const std::string before = slurp(out / "probes.csv");
    INFO("killed after the first checkpoint + " << delay_ms << " ms: status " << killed << ", "
                                                << std::count(before.begin(), before.end(), '\n')
                                                << " lines in probes.csv");
    std::string err;
    const int code = run_cli("resume " + out.string() + " --quiet", &err);
    INFO(err);
    REQUIRE(code == 0);
    check_same(outputs_of(out), ref);
    // diagnostics.csv: no gap, no duplicate: one row per output, times as in probes.csv.
    const std::string diag = slurp(out / "diagnostics.csv");
    CHECK(std::count(diag.begin(), diag.end(), '\n') ==
          std::count(ref.probes.begin(), ref.probes.end(), '\n'));
  }
}

TEST_CASE("checkpoint: SIGINT and SIGTERM exit 130 with a valid checkpoint and no truncated file",
          "[checkpoint][cli]") {
  const fs::path scene = scene_file();
  const Outputs& ref = reference(scene);
  for (int sig : {SIGINT, SIGTERM}) {
    const fs::path out = scratch(sig == SIGINT ? "sigint" : "sigterm");
    const pid_t pid = spawn({"run", scene.string(), "--quiet", "--out", out.string()});
    wait_for_file(out / "frames" / "front" / "frame_00002.png", pid);
    ::kill(pid, sig);
    const int code = wait_for(pid);
    INFO("signal " << sig);
    REQUIRE(code == 130);
    CHECK(fs::exists(out / "checkpoint.bin"));
    CHECK(slurp(out / "run.json").find("\"status\": \"interrupted\"") != std::string::npos);
    // No truncated file: every CSV line is whole, every frame a complete PNG, no temporary file left.
    const std::string probes = slurp(out / "probes.csv");
    CHECK(!probes.empty());
    CHECK(probes.back() == '\n');
    const Outputs partial = outputs_of(out);
    CHECK(partial.frames.size() + 1 ==
          static_cast<std::size_t>(std::count(probes.begin(), probes.end(), '\n')));
    for (std::size_t k = 0; k < partial.frames.size(); ++k) CHECK(partial.frames[k] == ref.frames[k]);
    for (const auto& e : fs::recursive_directory_iterator(out)) CHECK(e.path().extension() != ".tmp");
    // The checkpoint is valid: the resumed run ends as the uninterrupted one.
    std::string err;
    REQUIRE(run_cli("resume " + out.string() + " --quiet", &err) == 0);
    check_same(outputs_of(out), ref);
  }
}

TEST_CASE("checkpoint: resume refuses another version, another scene, no checkpoint", "[checkpoint][cli]") {
  const fs::path scene = scene_file();
  const fs::path out = scratch("refuse");
  const pid_t pid = spawn({"run", scene.string(), "--quiet", "--out", out.string()});
  wait_for_file(out / "frames" / "front" / "frame_00001.png", pid);
  ::kill(pid, SIGINT);
  REQUIRE(wait_for(pid) == 130);
  const std::string good = slurp(out / "checkpoint.bin");
  std::string err;

  // Another program version: the same file with the version string replaced and the checksum redone.
  std::string bytes = good;
  const std::string version = AORTASPH_VERSION;
  const auto at = bytes.find(version);
  REQUIRE(at != std::string::npos);
  bytes.replace(at, version.size(), std::string(version.size(), '9'));
  const uint64_t sum = fnv1a64(bytes.data(), bytes.size() - 8);
  std::memcpy(bytes.data() + bytes.size() - 8, &sum, 8);
  std::ofstream(out / "checkpoint.bin", std::ios::binary) << bytes;
  CHECK(run_cli("resume " + out.string(), &err) == 2);
  CHECK(err.find("written by aortasph " + std::string(version.size(), '9')) != std::string::npos);

  // A damaged file.
  bytes = good;
  bytes[bytes.size() / 2] ^= 4;
  std::ofstream(out / "checkpoint.bin", std::ios::binary) << bytes;
  CHECK(run_cli("resume " + out.string(), &err) == 2);
  CHECK(err.find("checksum") != std::string::npos);

  // A folder whose run.json belongs to another scene.
  std::ofstream(out / "checkpoint.bin", std::ios::binary) << good;
  std::string run_json = slurp(out / "run.json");
  const auto spacing = run_json.find("\"spacing\": 0.01");
  REQUIRE(spacing != std::string::npos);
  run_json.replace(spacing, 15, "\"spacing\": 0.02");
  std::ofstream(out / "run.json") << run_json;
  CHECK(run_cli("resume " + out.string(), &err) == 2);
  CHECK(err.find("another scene") != std::string::npos);

  // No checkpoint at all.
  CHECK(run_cli("resume " + scratch("empty").string(), &err) == 2);
  CHECK(err.find("no checkpoint") != std::string::npos);
}

TEST_CASE("checkpoint: resume --end-time runs a finished run on to a later end, as one run would",
          "[checkpoint][cli][heavy]") {
  const fs::path scene = scene_file();
  const Outputs& ref = reference(scene);  // the scene's own end, 0.06
  const fs::path out = scratch("extended");
  std::string err;
  REQUIRE(run_cli("run " + scene.string() + " --quiet --end-time 0.04 --checkpoint-every 0.02 --out " +
                      out.string(),
                  &err) == 0);
  const std::string short_probes = slurp(out / "probes.csv");
  CHECK(std::count(short_probes.begin(), short_probes.end(), '\n') == 12);  // header + t = 0 .. 0.04
  // An end before the checkpoint's time is refused, and leaves the run as it was.
  CHECK(run_cli("resume " + out.string() + " --quiet --end-time 0.03", &err) == 2);
  CHECK(err.find("past the end") != std::string::npos);
  CHECK(slurp(out / "probes.csv") == short_probes);
  CHECK(run_cli("resume " + out.string() + " --quiet --end-time -1", &err) == 2);
  CHECK(err.find("--end-time") != std::string::npos);
  const int code = run_cli("resume " + out.string() + " --quiet --end-time 0.06", &err);
  INFO(err);
  REQUIRE(code == 0);
  check_same(outputs_of(out), ref);  // probes, every frame and the figure whose t = 0.06 lay beyond 0.04
  CHECK(slurp(out / "run.json").find("\"end\": 0.06") != std::string::npos);
}

TEST_CASE("checkpoint: a run that ended between two outputs runs on with the output grid, resumable again",
          "[checkpoint][cli]") {
  // Outputs every 0.004 s: a run to 0.01 writes its last row and frame at 0.01, off the grid. Run on to
  // 0.014 and then to 0.02, the outputs are those of one run: t = 0, 0.004, ..., with the 0.01 and 0.014 ends
  // dropped. (Until stop 60 the resume skipped the grid time 0.012, one to before the next grid time did
  // nothing, and a resumed run left its older checkpoint, which the next resume refused: run.json named
  // another end.)
  const fs::path scene = scene_file();
  const Outputs& ref = reference(scene);
  const fs::path out = scratch("off_grid");
  std::string err;
  REQUIRE(run_cli("run " + scene.string() + " --quiet --end-time 0.01 --checkpoint-every 0.01 --out " +
                      out.string(),
                  &err) == 0);
  CHECK(row_times(out) == std::vector<double>{0, 0.004, 0.008, 0.01});
  REQUIRE(run_cli("resume " + out.string() + " --quiet --end-time 0.014", &err) == 0);
  CHECK(row_times(out) == std::vector<double>{0, 0.004, 0.008, 0.012, 0.014});
  INFO(err);  // the second resume: from the end at 0.014 (no checkpoint was due there)
  REQUIRE(run_cli("resume " + out.string() + " --quiet --end-time 0.02", &err) == 0);
  const std::vector<double> t = row_times(out);
  REQUIRE(t.size() == 6);
  for (std::size_t k = 0; k < t.size(); ++k) CHECK(std::abs(t[k] - 0.004 * static_cast<double>(k)) < 1e-12);
  const Outputs got = outputs_of(out);
  CHECK(got.frames.size() == 6);  // frame k at t = k * 0.004, no frame left from the earlier ends
  // Up to the first end the run is the uninterrupted one, bitwise (the header and rows 0, 0.004, 0.008).
  auto head = [](const std::string& csv, int rows) {
    std::size_t at = 0;
    for (int k = 0; k <= rows; ++k) at = csv.find('\n', at) + 1;
    return csv.substr(0, at);
  };
  CHECK(head(got.probes, 3) == head(ref.probes, 3));
  for (std::size_t k = 0; k < 3; ++k) CHECK(got.frames[k] == ref.frames[k]);
  // The run left a checkpoint of its end: resumed there it has nothing to do and leaves every output as it
  // was, the figure's colour bar included (its unit came from the rendered frames until stop 60).
  REQUIRE(run_cli("resume " + out.string() + " --quiet", &err) == 0);
  const Outputs again = outputs_of(out);
  CHECK(again.probes == got.probes);
  CHECK(again.frames == got.frames);
  CHECK(again.figure == got.figure);
}

TEST_CASE("checkpoint: probe rows between the frames (time.probe_interval) resume as one run",
          "[checkpoint][cli]") {
  // Rows every 0.002 s, frames every 0.004 s. A run to 0.006 ends on a row, between two frames: it has rows
  // 0 .. 0.006 and frames at 0, 0.004 and its end. Run on to 0.014, the rows and frames are those of one
  // run to 0.014: the 0.006 row stays (it is on the rows' grid), the 0.006 frame is dropped, and the end
  // 0.014 (off the frames' grid) has a frame.
  const fs::path scene = scene_file();
  const std::string rows = " --set time.probe_interval=0.002";
  const fs::path one = scratch("rows_one"), two = scratch("rows_two");
  std::string err;
  REQUIRE(run_cli("run " + scene.string() + " --quiet --end-time 0.014" + rows + " --out " + one.string(),
                  &err) == 0);
  REQUIRE(run_cli("run " + scene.string() + " --quiet --end-time 0.006 --checkpoint-every 0.006" + rows +
                      " --out " + two.string(),
                  &err) == 0);
  CHECK(row_times(two) == std::vector<double>{0, 0.002, 0.004, 0.006});
  CHECK(outputs_of(two).frames.size() == 3);
  const int code = run_cli("resume " + two.string() + " --quiet --end-time 0.014", &err);
  INFO(err);
  REQUIRE(code == 0);
  const std::vector<double> t = row_times(one);
  REQUIRE(t.size() == 8);
  for (std::size_t k = 0; k < t.size(); ++k) CHECK(std::abs(t[k] - 0.002 * static_cast<double>(k)) < 1e-12);
  const Outputs a = outputs_of(one), b = outputs_of(two);
  CHECK(a.frames.size() == 5);  // t = 0, 0.004, 0.008, 0.012 and the end 0.014
  CHECK(b.probes == a.probes);
  REQUIRE(b.frames.size() == a.frames.size());
  for (std::size_t k = 0; k < a.frames.size(); ++k) CHECK(b.frames[k] == a.frames[k]);
  const std::string diagnostics = slurp(two / "diagnostics.csv");  // a row with each probe row
  CHECK(std::count(diagnostics.begin(), diagnostics.end(), '\n') == 9);
}

TEST_CASE("checkpoint: resume keeps --end-time (figure times beyond it) and --vtk-every",
          "[checkpoint][cli]") {
  const fs::path scene = scene_file();
  const fs::path whole = scratch("end_whole"), out = scratch("end_resumed");
  // The figure's t = 0.06 lies beyond --end-time; a VTK frame every third output and the last.
  const std::string args = " --quiet --vtk-every 3 --end-time 0.04";
  std::string err;
  REQUIRE(run_cli("run " + scene.string() + args + " --out " + whole.string(), &err) == 0);
  const pid_t pid = spawn(
      {"run", scene.string(), "--quiet", "--vtk-every", "3", "--end-time", "0.04", "--out", out.string()});
  wait_for_file(out / "frames" / "front" / "frame_00002.png", pid);
  ::kill(pid, SIGINT);
  REQUIRE(wait_for(pid) == 130);
  const int code = run_cli("resume " + out.string() + " --quiet", &err);
  INFO(err);
  REQUIRE(code == 0);
  const std::string probes = slurp(out / "probes.csv");
  CHECK(probes == slurp(whole / "probes.csv"));
  CHECK(std::count(probes.begin(), probes.end(), '\n') == 12);  // header + t = 0, 0.004, ..., 0.04
  // Outputs 0..10: frames 0, 3, 6, 9 and the last, 10, in both runs (the resumed one kept the stride).
  auto vtp = [](int f) {
    char name[32];
    std::snprintf(name, sizeof name, "particles_%05d.vtp", f);
    return std::string(name);
  };
  for (const fs::path& dir : {whole, out}) {
    for (int f : {0, 3, 6, 9, 10}) CHECK(fs::exists(dir / "vtk" / vtp(f)));
    for (int f : {1, 2, 4, 5, 7, 8}) CHECK_FALSE(fs::exists(dir / "vtk" / vtp(f)));
  }
  CHECK(slurp(out / "vtk" / "particles.pvd") == slurp(whole / "vtk" / "particles.pvd"));
  CHECK(slurp(out / "vtk" / "particles_00010.vtp") == slurp(whole / "vtk" / "particles_00010.vtp"));
}

TEST_CASE("checkpoint: a camera's own colour range (color_by, hide) survives SIGINT and resume",
          "[checkpoint][cli]") {
  // The dam break of the tests above with a second camera that colours the column by displacement with the
  // tank hidden: its range is chosen at run time (displacement is 0 everywhere at t = 0) apart from the
  // run-wide speed range, so a resumed run must restore it from the checkpoint or colour its frames anew.
  std::string text = kScene;
  const std::string cameras =
      R"("cameras": [ { "name": "front", "eye": [0.1, 0.08, 0.5], "target": [0.1, 0.05, 0.015] } ],)";
  const auto at = text.find(cameras);
  REQUIRE(at != std::string::npos);
  text.replace(at, cameras.size(),
               R"("cameras": [ { "name": "front", "eye": [0.1, 0.08, 0.5], "target": [0.1, 0.05, 0.015] },
                           { "name": "shift", "eye": [0.1, 0.08, 0.5], "target": [0.1, 0.05, 0.015],
                             "color_by": "displacement", "hide": ["tank"] } ],)");
  const std::string figures =
      R"("figures": [ { "name": "fig", "camera": "front", "times": [0, 0.02, 0.06], "columns": 3 } ])";
  const auto fat = text.find(figures);
  REQUIRE(fat != std::string::npos);
  text.replace(fat, figures.size(),
               R"("figures": [ { "name": "fig", "camera": "front", "times": [0, 0.02, 0.06], "columns": 3 },
                           { "name": "shift_fig", "camera": "shift", "times": [0, 0.02, 0.06], "columns": 3 } ])");
  const fs::path dir = scratch("camera_range");
  std::ofstream(dir / "scene.json") << text;
  const fs::path whole = dir / "whole", out = dir / "resumed";
  std::string err;
  // To t = 0.024 (frames 0..6): enough to interrupt after the ranges are chosen, and quick.
  REQUIRE(
      run_cli("run " + (dir / "scene.json").string() + " --quiet --end-time 0.024 --out " + whole.string(),
              &err) == 0);
  const pid_t pid =
      spawn({"run", (dir / "scene.json").string(), "--quiet", "--end-time", "0.024", "--out", out.string()});
  wait_for_file(out / "frames" / "shift" / "frame_00003.png", pid);
  ::kill(pid, SIGINT);
  REQUIRE(wait_for(pid) == 130);
  const int code = run_cli("resume " + out.string() + " --quiet", &err);
  INFO(err);
  REQUIRE(code == 0);
  for (const std::string camera : {"front", "shift"})
    for (int k = 0; k <= 6; ++k) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05d.png", k);
      INFO(camera << "/" << name);
      const std::string a = slurp(whole / "frames" / camera / name);
      REQUIRE(!a.empty());
      CHECK(slurp(out / "frames" / camera / name) == a);
    }
  CHECK(slurp(out / "figures" / "fig.png") == slurp(whole / "figures" / "fig.png"));
  CHECK(slurp(out / "figures" / "shift_fig.png") == slurp(whole / "figures" / "shift_fig.png"));
  // The two cameras' sheets differ (the shift camera's colour bar names displacement [m]).
  CHECK(slurp(whole / "figures" / "shift_fig.png") != slurp(whole / "figures" / "fig.png"));
}

TEST_CASE("resume: keys a later program added are left out of the recorded scene's comparison",
          "[checkpoint][cli]") {
  // A run recorded by an older program lacks the keys added since (stop 57: cycle.pressure_zero and the
  // max_speed probe's smoothed, both at defaults that keep the simulation as it was): the scene this program
  // resolves, pruned to the recorded keys, is the recorded one; a changed value still differs.
  const nlohmann::json recorded = nlohmann::json::parse(R"({
    "cycle": {"period": 0.8, "lv_pressure": "p_lvot"},
    "probes": [{"name": "jet", "type": "max_speed"}, {"name": "p", "type": "pressure", "point": [0, 0, 0]}],
    "materials": {"blood": {"type": "fluid", "density": 1060}}})");
  nlohmann::json now = recorded;
  now["cycle"]["pressure_zero"] = 2000.0;
  now["probes"][0]["smoothed"] = false;
  now["materials"]["blood"]["mask_density"] = false;
  CHECK(now != recorded);
  CHECK(pruned_to(now, recorded) == recorded);
  CHECK(pruned_to(now, recorded).dump() == recorded.dump());  // what the hash reads
  nlohmann::json changed = now;
  changed["materials"]["blood"]["density"] = 1000;
  CHECK(pruned_to(changed, recorded) != recorded);
  // A key the recorded scene has and this program no longer resolves is not made up: still different.
  nlohmann::json lost = now;
  lost["probes"][1].erase("point");
  CHECK(pruned_to(lost, recorded) != recorded);
  // An array of another length (a probe more or less) is compared whole.
  nlohmann::json more = now;
  more["probes"].push_back({{"name", "q"}, {"type", "pressure"}});
  CHECK(pruned_to(more, recorded) != recorded);
}
