// The aortasph command end to end (SPEC.md section 1): exit codes, messages naming the problem, outputs,
// and bitwise identical probes for 1 and 2 threads.
#include <sys/wait.h>

#include <array>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace {

struct Result {
  int code = -1;
  std::string err;
};

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("aortasph_cli_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// Runs the aortasph binary with the arguments; returns the exit code and stderr.
Result aortasph(const std::string& args) {
  const fs::path err = fs::temp_directory_path() / ("aortasph_cli_err_" + std::to_string(::getpid()));
  const std::string cmd = std::string(AORTASPH_BINARY) + " " + args + " > /dev/null 2> " + err.string();
  const int status = std::system(cmd.c_str());
  Result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = slurp(err);
  return r;
}

std::string scene_path(const std::string& name) {
  return std::string(AORTASPH_TEST_DIR) + "/../scenes/" + name;
}

fs::path write_file(const fs::path& dir, const std::string& name, const std::string& text) {
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p;
}

// A small valid scene; the bad-input cases below break one thing each.
const char* kGood = R"({
  "name": "tiny",
  "domain": { "min": [-0.1, -0.1, -0.1], "max": [0.3, 0.3, 0.2] },
  "resolution": { "spacing": 0.01 },
  "time": { "end": 0.002, "output_interval": 0.001 },
  "materials": { "water": { "type": "fluid", "density": 1000, "viscosity": 1e-6, "sound_speed": 10 },
                 "wall": { "type": "wall" } },
  "bodies": [
    { "name": "column", "material": "water", "shape": { "box": { "min": [0, 0, 0], "max": [0.05, 0.1, 0.03] } } },
    { "name": "tank", "material": "wall", "shape": { "container": { "min": [0, 0, 0], "max": [0.2, 0.15, 0.03], "layers": 3, "open": ["+y"] } } }
  ],
  "probes": [ { "name": "front", "type": "extent", "bodies": ["column"], "axis": "x", "stat": "max" } ]
})";

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  REQUIRE(at != std::string::npos);
  return s.replace(at, from.size(), to);
}

}  // namespace

TEST_CASE("cli: a small scene runs and writes probes, diagnostics and run.json", "[cli]") {
  const fs::path dir = scratch("good");
  const fs::path scene = write_file(dir, "tiny.json", kGood);
  const Result r = aortasph("run " + scene.string() + " --out " + (dir / "out").string() + " --quiet --vtk");
  INFO(r.err);
  REQUIRE(r.code == 0);
  const std::string probes = slurp(dir / "out" / "probes.csv");
  CHECK(probes.rfind("time,front\n", 0) == 0);
  CHECK(std::count(probes.begin(), probes.end(), '\n') == 4);  // header + t = 0, 0.001, 0.002
  CHECK(probes.find("\n0.002,") != std::string::npos);         // output times are exact
  // diagnostics.csv holds the volume check (fluid/volume_check.hpp) beside the density error.
  CHECK(slurp(dir / "out" / "diagnostics.csv").find(",max_density_error,shell_crossings,volume_ratio,") !=
        std::string::npos);
  CHECK(slurp(dir / "out" / "run.json").find("\"status\": \"ok\"") != std::string::npos);
  CHECK(fs::exists(dir / "out" / "vtk" / "particles_00002.vtp"));
  CHECK(slurp(dir / "out" / "vtk" / "particles.pvd").find("particles_00002.vtp") != std::string::npos);
}

TEST_CASE("cli: bad input exits 2 with a message naming the problem", "[cli][bad-input]") {
  const fs::path dir = scratch("bad");
  struct Case {
    std::string what, scene, extra, expect;
  };
  const std::vector<Case> cases = {
      {"malformed JSON", replace(kGood, "\"tiny\",", "\"tiny\""), "", "JSON"},
      {"wrong type", replace(kGood, "\"spacing\": 0.01", "\"spacing\": \"fine\""), "", "resolution.spacing"},
      {"missing key", replace(kGood, "\"density\": 1000, ", ""), "", "density"},
      {"negative spacing", replace(kGood, "\"spacing\": 0.01", "\"spacing\": -0.01"), "", "spacing"},
      {"unknown --set path", kGood, "--set resolution.spacin=0.004", "resolution.spacin"},
      {"--set index out of range", kGood, "--set bodies.5.velocity=[1,0,0]", "bodies"},
      {"unknown material", replace(kGood, "\"material\": \"water\"", "\"material\": \"blood\""), "", "blood"},
      {"empty body", replace(kGood, "\"max\": [0.05, 0.1, 0.03]", "\"max\": [0.001, 0.1, 0.03]"), "",
       "column"},
      {"overlapping bodies",
       replace(kGood, "\"min\": [0, 0, 0], \"max\": [0.05", "\"min\": [-0.02, 0, 0], \"max\": [0.05"), "",
       "overlap"},
      {"unwritable --out", kGood, "--out /proc/aortasph_cannot_write", "/proc/aortasph_cannot_write"},
      {"bad --threads", kGood, "--threads zero", "--threads"},
      {"unknown option", kGood, "--fast", "--fast"},
  };
  for (const Case& c : cases) {
    const fs::path scene = write_file(dir, "scene.json", c.scene);
    std::string args = "run " + scene.string() + " --quiet " + c.extra;
    if (c.extra.find("--out") == std::string::npos) args += " --out " + (dir / "out").string();
    const Result r = aortasph(args);
    INFO(c.what << ": exit " << r.code << ", stderr: " << r.err);
    CHECK(r.code == 2);
    CHECK(r.err.find(c.expect) != std::string::npos);
  }
  // A missing scene file.
  const Result r = aortasph("run " + (dir / "no_such_scene.json").string() + " --quiet");
  INFO(r.err);
  CHECK(r.code == 2);
  CHECK(r.err.find("no_such_scene.json") != std::string::npos);
}

TEST_CASE("cli: probes.csv is bitwise identical for --threads 1 and 2", "[cli][determinism][heavy]") {
  const fs::path dir = scratch("threads");
  std::string csv[2];
  for (int t = 1; t <= 2; ++t) {
    const fs::path out = dir / ("t" + std::to_string(t));
    const Result r = aortasph("run " + scene_path("dam_break.json") + " --quiet --no-render --end-time 0.02" +
                              " --set resolution.spacing=0.0057 --threads " + std::to_string(t) + " --out " +
                              out.string());
    INFO(r.err);
    REQUIRE(r.code == 0);
    csv[t - 1] = slurp(out / "probes.csv");
  }
  CHECK(csv[0].size() > 100);
  CHECK(csv[0] == csv[1]);
}

TEST_CASE("cli: an unstable run exits 3, names time and particle, keeps the rows written",
          "[cli][unstable]") {
  const fs::path dir = scratch("unstable");
  // A time step forced 30 times beyond the acoustic CFL limit (time.fixed_dt bypasses the adaptive step).
  const fs::path scene = write_file(dir, "scene.json", replace(kGood, "\"end\": 0.002", "\"end\": 0.5"));
  const Result r = aortasph("run " + scene.string() + " --quiet --out " + (dir / "out").string() +
                            " --set time.fixed_dt=0.01 --set time.output_interval=0.05");
  INFO(r.err);
  CHECK(r.code == 3);
  CHECK(r.err.find("unstable at t = ") != std::string::npos);
  CHECK(r.err.find("particle") != std::string::npos);
  const std::string probes = slurp(dir / "out" / "probes.csv");
  CHECK(probes.rfind("time,front\n0,", 0) == 0);  // the row of t = 0 is there and intact
  CHECK(slurp(dir / "out" / "run.json").find("unstable") != std::string::npos);
}

TEST_CASE("cli: check prints bodies, counts, h, dt and cost, --help and --version", "[cli]") {
  const Result r = aortasph("check " + scene_path("dam_break.json"));
  CHECK(r.code == 0);
  CHECK(aortasph("--help").code == 0);
  CHECK(aortasph("--version").code == 0);
  CHECK(aortasph("frobnicate").code == 2);
  CHECK(aortasph("").code == 2);
}

TEST_CASE("cli: bench --scene steps any scene and reports particle-steps, phases and peak RSS", "[cli]") {
  const fs::path dir = scratch("bench");
  const fs::path scene = write_file(dir, "tiny.json", kGood);
  const fs::path json = dir / "bench.json";
  const Result r = aortasph("bench --scene " + scene.string() + " --steps 3 --threads 1 --json " +
                            json.string() + " --set resolution.spacing=0.008");
  INFO(r.err);
  REQUIRE(r.code == 0);
  const std::string j = slurp(json);
  CHECK(j.find("\"scene\": \"tiny\"") != std::string::npos);
  CHECK(j.find("\"steps\": 3") != std::string::npos);
  for (const char* key : {"fluid_particle_steps_per_s", "particle_steps_per_s", "peak_rss_bytes",
                          "peak_rss_bytes_per_fluid_particle", "bytes_per_fluid_particle", "phases_s"})
    CHECK(j.find(std::string("\"") + key + "\"") != std::string::npos);
  // The --set took effect: the 0.05 x 0.1 x 0.03 column holds 150 particles at 10 mm (5 x 10 x 3), about
  // twice as many at 8 mm.
  const auto fluid_particles = [](const std::string& text) {
    const std::string key = "\"fluid_particles\": ";
    const auto at = text.find(key);
    return at == std::string::npos ? -1.0 : std::stod(text.substr(at + key.size()));
  };
  const Result coarse = aortasph("bench --scene " + scene.string() + " --steps 1 --json " + json.string());
  REQUIRE(coarse.code == 0);
  CHECK(fluid_particles(slurp(json)) == 150.0);
  CHECK(fluid_particles(j) > 1.8 * 150.0);
  // Bad bench arguments exit 2 naming the problem.
  struct Case {
    std::string args, expect;
  };
  for (const Case& c :
       std::vector<Case>{{"bench --case nosuch", "nosuch"},
                         {"bench --scene " + (dir / "missing.json").string(), "missing.json"},
                         {"bench --steps 0", "--steps"},
                         {"bench --scene " + scene.string() + " --case aortic_root", "--case"},
                         {"bench --set resolution.spacing=0.004", "--set"},
                         {"bench --from " + (dir / "norun").string(), "checkpoint.bin"},
                         {"bench --from " + dir.string() + " --scene " + scene.string(), "--from"}}) {
    const Result b = aortasph(c.args + " --json " + (dir / "x.json").string());
    INFO(c.args << ": exit " << b.code << ", stderr: " << b.err);
    CHECK(b.code == 2);
    CHECK(b.err.find(c.expect) != std::string::npos);
  }

  // --from: the state of a run folder's checkpoint, here the tiny run's at its end (t = 2 ms), stepped on
  // with the recorded scene and a --set on top (a skin of 30 % lists more neighbours than the default 10 %).
  const Result run = aortasph("run " + scene.string() + " --out " + (dir / "run").string() +
                              " --quiet --no-render --checkpoint-every 0.001");
  REQUIRE(run.code == 0);
  const auto number = [](const std::string& text, const std::string& name) {
    const std::string key = "\"" + name + "\": ";
    const auto at = text.find(key);
    return at == std::string::npos ? -1.0 : std::stod(text.substr(at + key.size()));
  };
  double listed[2] = {0.0, 0.0};  // neighbours per particle at skins 0.1 and 0.3
  for (const double skin : {0.1, 0.3}) {
    const Result from = aortasph("bench --from " + (dir / "run").string() + " --steps 2 --threads 1 --json " +
                                 json.string() + " --set resolution.skin=" + std::to_string(skin));
    INFO(from.err);
    REQUIRE(from.code == 0);
    const std::string b = slurp(json);
    CHECK(number(b, "from_time_s") == Approx(0.002));
    CHECK(number(b, "skin") == Approx(skin));
    CHECK(number(b, "fluid_particles") == 150.0);
    listed[skin > 0.2] = number(b, "neighbours_per_particle");
  }
  CHECK(listed[0] > 1.0);
  CHECK(listed[1] > 1.2 * listed[0]);  // the same state listed with a 30 % skin instead of 10 %
}

TEST_CASE("scripts/wall_leak.py: a fluid particle inside a wall is counted, the fluid beside it is not",
          "[cli]") {
  // The small scene's column stands in its tank (floor and side walls three layers deep): no particle is
  // inside a wall, though the ones in the tank's corners have the most wall in their support. One more fluid
  // particle placed in the floor's second layer (y = -1.5 dx), between its particles, must be counted
  // (docs/validation.md, "Stop 45").
  if (std::system("/usr/bin/python3 -c 'import numpy' > /dev/null 2>&1") != 0) {
    WARN("/usr/bin/python3 with numpy not found: scripts/wall_leak.py not tested");
    return;
  }
  const fs::path dir = scratch("wall_leak");
  const std::string script = std::string(AORTASPH_TEST_DIR) + "/../scripts/wall_leak.py";
  // First frame's row: fluid particles, inside a wall, the largest wall fraction.
  auto leak = [&](const std::string& name, const std::string& scene_text) {
    const fs::path scene = write_file(dir, name + ".json", scene_text), out = dir / name;
    REQUIRE(
        aortasph("run " + scene.string() + " --out " + out.string() + " --vtk --no-render --quiet").code ==
        0);
    const fs::path report = dir / (name + ".txt");
    REQUIRE(std::system(
                ("/usr/bin/python3 " + script + " " + out.string() + " > " + report.string()).c_str()) == 0);
    std::istringstream text(slurp(report));
    for (std::string line; std::getline(text, line);)
      if (line.rfind("particles_00000.vtp", 0) == 0) {
        std::istringstream cells(line.substr(line.find(' ')));
        std::array<double, 3> row{};
        cells >> row[0] >> row[1] >> row[2];
        INFO(name << ": " << line);
        return row;
      }
    FAIL(name << ": no row for the first frame in " << slurp(report));
    return std::array<double, 3>{};
  };
  const auto clean = leak("clean", kGood);
  CHECK(clean[0] == 150);  // the column: 5 x 10 x 3 particles
  CHECK(clean[1] == 0);
  CHECK(clean[2] > 0.3);  // the corner particles see floor and two side walls
  CHECK(clean[2] < 0.8);
  const auto stray = leak("stray", replace(kGood, R"("bodies": [)", R"("bodies": [
    { "name": "stray", "material": "water", "shape": { "box": { "min": [0.095, -0.02, 0.01], "max": [0.105, -0.01, 0.02] } } },)"));
  CHECK(stray[0] == 151);
  CHECK(stray[1] == 1);
  CHECK(stray[2] > 0.8);
}
