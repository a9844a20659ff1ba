// Bad input never crashes (SPEC.md section 5, issue 7): each malformed scene or argument below exits 2 with a
// message that names the problem (the JSON path, the option, the file, the resource).
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_helpers.hpp"
#include "resources.hpp"

namespace fs = std::filesystem;
using aortasph::test::run_cli;
using aortasph::test::scratch;
using aortasph::test::slurp;

namespace {

// A small valid scene with a camera; each row below breaks one thing.
const char* kGood = R"({
  "name": "tiny",
  "domain": { "min": [-0.1, -0.1, -0.1], "max": [0.3, 0.3, 0.2], "max_leave_fraction": 0.0 },
  "resolution": { "spacing": 0.01, "smoothing_ratio": 1.3 },
  "time": { "end": 0.002, "output_interval": 0.001, "cfl": 0.25 },
  "gravity": [0, -9.81, 0],
  "materials": { "water": { "type": "fluid", "density": 1000, "viscosity": 1e-6, "sound_speed": 10 },
                 "rubber": { "type": "elastic", "density": 1100, "youngs_modulus": 2e6, "poisson_ratio": 0.45 },
                 "wall": { "type": "wall" } },
  "bodies": [
    { "name": "column", "material": "water", "velocity": [0, 0, 0],
      "shape": { "box": { "min": [0, 0, 0], "max": [0.05, 0.1, 0.03] } } },
    { "name": "tank", "material": "wall", "shape": { "container": { "min": [0, 0, 0], "max": [0.2, 0.15, 0.03], "layers": 3, "open": ["+y"] } } }
  ],
  "probes": [ { "name": "front", "type": "extent", "bodies": ["column"], "axis": "x", "stat": "max" } ],
  "render": { "width": 64, "height": 48,
              "cameras": [ { "name": "front", "eye": [0.1, 0.08, 0.5], "target": [0.1, 0.05, 0.015], "fov_deg": 35 } ],
              "figures": [ { "name": "fig", "camera": "front", "times": [0, 0.002] } ] }
})";

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  if (at == std::string::npos) throw std::runtime_error("test table: '" + from + "' not in the scene");
  return s.replace(at, from.size(), to);
}

struct Case {
  std::string what;
  std::string scene;   // file content
  std::string args;    // extra arguments
  std::string expect;  // a substring of the message that names the problem
};

}  // namespace

TEST_CASE("bad input: malformed scenes and arguments exit 2 naming the problem", "[bad-input][cli]") {
  const fs::path dir = scratch("table");
  const std::string good = kGood;
  const std::vector<Case> cases = {
      // Syntax errors.
      {"trailing comma", replace(good, "\"tiny\",", "\"tiny\",,"), "", "not valid JSON"},
      {"unterminated string", replace(good, "\"tiny\"", "\"tiny"), "", "not valid JSON"},
      {"empty file", "", "", "not valid JSON"},
      {"not an object", "[1, 2, 3]", "", "scene: expected an object, got a list"},
      // The transport-velocity formulation (materials.<fluid>.transport_velocity).
      {"transport velocity not an object",
       replace(good, "\"sound_speed\": 10 }", "\"sound_speed\": 10, \"transport_velocity\": 1e5 }"), "",
       "materials.water.transport_velocity: expected an object"},
      {"transport velocity without a background pressure",
       replace(good, "\"sound_speed\": 10 }", "\"sound_speed\": 10, \"transport_velocity\": {} }"), "",
       "materials.water.transport_velocity.background_pressure: missing"},
      {"transport velocity with a zero background pressure",
       replace(good, "\"sound_speed\": 10 }",
               "\"sound_speed\": 10, \"density_summation\": true, "
               "\"transport_velocity\": { \"background_pressure\": 0 } }"),
       "", "materials.water.transport_velocity.background_pressure: must be positive"},
      {"transport velocity with an unknown key",
       replace(good, "\"sound_speed\": 10 }",
               "\"sound_speed\": 10, \"transport_velocity\": { \"background_presure\": 1e5 } }"),
       "", "materials.water.transport_velocity.background_presure: unknown key"},
      {"transport velocity with the continuity equation",
       replace(good, "\"sound_speed\": 10 }",
               "\"sound_speed\": 10, \"transport_velocity\": { \"background_pressure\": 1e5 } }"),
       "", "materials.water.transport_velocity: needs \"density_summation\": true"},
      {"transport velocity with a huge background pressure",
       replace(good, "\"sound_speed\": 10 }",
               "\"sound_speed\": 10, \"density_summation\": true, "
               "\"transport_velocity\": { \"background_pressure\": 1e12 } }"),
       "", "materials.water.transport_velocity.background_pressure: must not exceed 1000 rho0 c0^2"},
      // Whether the shift enters the density (materials.<fluid>.shifting_ale).
      {"shifting_ale not a boolean",
       replace(good, "\"sound_speed\": 10 }", "\"sound_speed\": 10, \"shifting\": 2, \"shifting_ale\": 1 }"),
       "", "materials.water.shifting_ale: expected"},
      // Whether the masks' changes beside shells enter the density (materials.<fluid>.mask_density).
      {"mask_density not a boolean",
       replace(good, "\"sound_speed\": 10 }", "\"sound_speed\": 10, \"mask_density\": \"yes\" }"), "",
       "materials.water.mask_density: expected"},
      // A fluid body's jitter (bodies[].jitter, issue 20).
      {"jitter too large",
       replace(good, "\"velocity\": [0, 0, 0],", "\"velocity\": [0, 0, 0], \"jitter\": 0.3,"), "",
       "bodies[0].jitter: must lie in 0..0.25 (a fraction of the spacing), got 0.3"},
      {"negative jitter",
       replace(good, "\"velocity\": [0, 0, 0],", "\"velocity\": [0, 0, 0], \"jitter\": -0.1,"), "",
       "bodies[0].jitter: must lie in 0..0.25"},
      {"jitter not a number",
       replace(good, "\"velocity\": [0, 0, 0],", "\"velocity\": [0, 0, 0], \"jitter\": \"0.1\","), "",
       "bodies[0].jitter: expected a number, got a string"},
      {"jitter on a wall",
       replace(good, "\"layers\": 3, \"open\": [\"+y\"] } }",
               "\"layers\": 3, \"open\": [\"+y\"] } }, \"jitter\": 0.1"),
       "", "bodies[1].jitter: only a fluid body takes a jitter"},
      // Periodic domains (domain.periodic).
      {"unknown periodic axis",
       replace(good, "\"max_leave_fraction\": 0.0",
               "\"max_leave_fraction\": 0.0, \"periodic\": [\"x\", \"w\"]"),
       "", "domain.periodic[1]: unknown axis 'w'"},
      {"periodic axis twice",
       replace(good, "\"max_leave_fraction\": 0.0",
               "\"max_leave_fraction\": 0.0, \"periodic\": [\"z\", \"z\"]"),
       "", "domain.periodic[1]: axis 'z' listed twice"},
      {"periodic period too short",
       replace(good, "\"max_leave_fraction\": 0.0", "\"max_leave_fraction\": 0.0, \"periodic\": [\"z\"]"),
       "--set resolution.spacing=0.05", "domain.periodic: the domain is 0.3 m long along periodic axis z"},
      {"elastic body in a periodic domain",
       replace(
           replace(good, "\"max_leave_fraction\": 0.0", "\"max_leave_fraction\": 0.0, \"periodic\": [\"z\"]"),
           "\"material\": \"wall\"", "\"material\": \"rubber\""),
       "", "bodies[1].material: elastic and rigid bodies are not supported in a periodic domain"},
      // Wrong types.
      {"spacing is a string", replace(good, "\"spacing\": 0.01", "\"spacing\": \"fine\""), "",
       "resolution.spacing: expected a number, got a string"},
      {"gravity has 2 numbers", replace(good, "[0, -9.81, 0]", "[0, -9.81]"), "",
       "gravity: expected 3 numbers, got 2"},
      {"velocity entry not a number",
       replace(good, "\"velocity\": [0, 0, 0]", "\"velocity\": [0, \"up\", 0]"), "",
       "bodies[0].velocity[1]: expected a number"},
      {"bodies is an object", good, "--set 'bodies={}'", "bodies: expected a non-empty list"},
      {"boolean where a string belongs", replace(good, "\"axis\": \"x\"", "\"axis\": true"), "",
       "probes[0].axis: expected a string, got a boolean"},
      // Missing keys and typos.
      {"missing density", replace(good, "\"density\": 1000, ", ""), "", "materials.water.density: missing"},
      {"missing domain",
       replace(good,
               "\"domain\": { \"min\": [-0.1, -0.1, -0.1], \"max\": [0.3, 0.3, 0.2], \"max_leave_fraction\": "
               "0.0 },",
               ""),
       "", "domain: missing"},
      {"misspelt key", replace(good, "\"gravity\"", "\"gravitee\""), "", "gravitee: unknown key"},
      {"missing shape", replace(good, "\"shape\": { \"box\"", "\"form\": { \"box\""), "", "bodies[0].form"},
      // Out-of-range values.
      {"negative spacing", replace(good, "\"spacing\": 0.01", "\"spacing\": -0.01"), "",
       "resolution.spacing: must be positive"},
      {"smoothing ratio 5", replace(good, "\"smoothing_ratio\": 1.3", "\"smoothing_ratio\": 5"), "",
       "resolution.smoothing_ratio: must lie in 1..3"},
      {"skin 0.9", replace(good, "\"smoothing_ratio\": 1.3", "\"smoothing_ratio\": 1.3, \"skin\": 0.9"), "",
       "resolution.skin: must lie in 0.02..0.5"},
      {"cfl above 1", replace(good, "\"cfl\": 0.25", "\"cfl\": 2"), "", "time.cfl"},
      {"Poisson ratio 0.6", replace(good, "\"poisson_ratio\": 0.45", "\"poisson_ratio\": 0.6"), "",
       "materials.rubber.poisson_ratio: must lie in (-1, 0.5)"},
      {"Poisson ratio -1", replace(good, "\"poisson_ratio\": 0.45", "\"poisson_ratio\": -1"), "",
       "materials.rubber.poisson_ratio: must lie in (-1, 0.5)"},
      {"Poisson ratio 0.5", replace(good, "\"poisson_ratio\": 0.45", "\"poisson_ratio\": 0.5"), "",
       "materials.rubber.poisson_ratio: must lie in (-1, 0.5)"},
      {"Young's modulus 0", replace(good, "\"youngs_modulus\": 2e6", "\"youngs_modulus\": 0"), "",
       "materials.rubber.youngs_modulus: must be positive"},
      {"negative Young's modulus", replace(good, "\"youngs_modulus\": 2e6", "\"youngs_modulus\": -5"), "",
       "materials.rubber.youngs_modulus: must be positive"},
      {"unknown solid model",
       replace(good, "\"poisson_ratio\": 0.45", "\"poisson_ratio\": 0.45, \"model\": \"ogden\""), "",
       "materials.rubber.model: unknown value 'ogden'"},
      {"unknown gradient correction",
       replace(good, "\"poisson_ratio\": 0.45", "\"poisson_ratio\": 0.45, \"gradient\": \"third_order\""), "",
       "materials.rubber.gradient: unknown value 'third_order'"},
      {"fixed region without particles",
       replace(
           good, "\"bodies\": [",
           "\"bodies\": [ { \"name\": \"bar\", \"material\": \"rubber\", \"shape\": { \"box\": { \"min\": "
           "[0.255, 0.1, 0], \"max\": [0.29, 0.12, 0.03] } }, \"fixed\": { \"box\": { \"min\": [1, 1, 1], "
           "\"max\": [2, 2, 2] } } },"),
       "", "bodies[0] 'bar'.fixed: the region holds no particle of the body"},
      {"leave fraction 2", replace(good, "\"max_leave_fraction\": 0.0", "\"max_leave_fraction\": 2"), "",
       "domain.max_leave_fraction"},
      {"inverted domain", replace(good, "\"max\": [0.3, 0.3, 0.2]", "\"max\": [0.3, -0.3, 0.2]"), "",
       "domain.max: must be greater than min"},
      {"zero layers", replace(good, "\"layers\": 3", "\"layers\": 0"), "",
       "bodies[1].shape.container.layers"},
      {"unknown open face", replace(good, "[\"+y\"]", "[\"+w\"]"), "", "bodies[1].shape.container.open[0]"},
      {"odd frame width", replace(good, "\"width\": 64", "\"width\": 65"), "", "render.width: must be even"},
      {"field of view 180", replace(good, "\"fov_deg\": 35", "\"fov_deg\": 180"), "",
       "render.cameras[0].fov_deg"},
      {"figure time after the end", replace(good, "\"times\": [0, 0.002]", "\"times\": [0, 0.5]"), "",
       "render.figures[0].times[1]"},
      // Per-camera overrides (render.cameras[].color_by, colormap, range, hide, clip).
      {"camera hides an unknown body",
       replace(good, "\"fov_deg\": 35 }", "\"fov_deg\": 35, \"hide\": [\"colum\"] }"), "",
       "render.cameras[0].hide[0]: unknown body 'colum'"},
      {"camera hide is a string",
       replace(good, "\"fov_deg\": 35 }", "\"fov_deg\": 35, \"hide\": \"column\" }"), "",
       "render.cameras[0].hide: expected a list of strings, got a string"},
      {"camera hide entry is a number",
       replace(good, "\"fov_deg\": 35 }", "\"fov_deg\": 35, \"hide\": [\"tank\", 3] }"), "",
       "render.cameras[0].hide[1]: expected a string, got a number"},
      {"camera colours by an unknown field",
       replace(good, "\"fov_deg\": 35 }", "\"fov_deg\": 35, \"color_by\": \"velocity\" }"), "",
       "render.cameras[0].color_by: unknown value 'velocity'"},
      {"camera color_by is a number",
       replace(good, "\"fov_deg\": 35 }", "\"fov_deg\": 35, \"color_by\": 1 }"), "",
       "render.cameras[0].color_by: expected a string, got a number"},
      {"camera range decreasing", replace(good, "\"fov_deg\": 35 }", "\"fov_deg\": 35, \"range\": [2, 1] }"),
       "", "render.cameras[0].range: low must be below high"},
      {"camera range of one number", replace(good, "\"fov_deg\": 35 }", "\"fov_deg\": 35, \"range\": [1] }"),
       "", "render.cameras[0].range: expected two numbers [low, high]"},
      {"camera range of strings",
       replace(good, "\"fov_deg\": 35 }", "\"fov_deg\": 35, \"range\": [\"0\", \"1\"] }"), "",
       "render.cameras[0].range: expected two numbers [low, high]"},
      {"camera range is a number", replace(good, "\"fov_deg\": 35 }", "\"fov_deg\": 35, \"range\": 1 }"), "",
       "render.cameras[0].range: expected two numbers [low, high]"},
      {"camera clip is a string", replace(good, "\"fov_deg\": 35 }", "\"fov_deg\": 35, \"clip\": \"no\" }"),
       "", "render.cameras[0].clip: expected true or false, got a string"},
      {"camera colormap unknown",
       replace(good, "\"fov_deg\": 35 }", "\"fov_deg\": 35, \"colormap\": \"jet\" }"), "",
       "render.cameras[0].colormap: unknown colormap \"jet\""},
      {"camera colormap is a list",
       replace(good, "\"fov_deg\": 35 }", "\"fov_deg\": 35, \"colormap\": [\"viridis\"] }"), "",
       "render.cameras[0].colormap: expected a string, got a list"},
      {"camera override set to a bad value", good, "--set 'render.cameras.0.hide=[\"nobody\"]'",
       "render.cameras[0].hide[0]: unknown body 'nobody'"},
      {"number beyond the double range", replace(good, "\"density\": 1000", "\"density\": 1e999"), "",
       "number overflow parsing '1e999'"},
      {"negative density-error limit", good, "--set time.max_density_error=-1", "time.max_density_error"},
      {"negative Riemann dissipation", good, "--set materials.water.riemann_dissipation=-1",
       "materials.water.riemann_dissipation: must not be negative"},
      {"tensile correction beyond 1", good, "--set materials.water.tensile_correction=1.5",
       "materials.water.tensile_correction: must lie in 0..1"},
      {"Riemann dissipation beyond 100", good, "--set materials.water.riemann_dissipation=101",
       "materials.water.riemann_dissipation: must lie in 0..100"},
      // References that do not resolve.
      {"unknown material", replace(good, "\"material\": \"water\"", "\"material\": \"blood\""), "",
       "bodies[0].material: unknown material 'blood'"},
      {"unknown probe body", replace(good, "\"bodies\": [\"column\"]", "\"bodies\": [\"colum\"]"), "",
       "probes[0].bodies[0]: unknown body 'colum'"},
      {"unknown extent stat", replace(good, "\"stat\": \"max\"", "\"stat\": \"front\""), "",
       "probes[0].stat"},
      {"extent link without stat extent",
       replace(good, "\"stat\": \"max\"", "\"stat\": \"max\", \"link\": 0.02"), "",
       "probes[0].link: only for \"stat\": \"extent\""},
      {"slip on a fluid body",
       replace(good, "\"name\": \"column\",", "\"name\": \"column\", \"slip\": \"free_slip\","), "",
       "bodies[0].slip: only a wall, rigid or elastic body takes a slip condition"},
      {"unknown slip", replace(good, "\"name\": \"tank\",", "\"name\": \"tank\", \"slip\": \"partial\","), "",
       "bodies[1].slip: unknown value 'partial'"},
      {"pressure sensor radius not positive",
       replace(
           good, R"("probes": [ {)",
           R"("probes": [ { "name": "s", "type": "pressure", "point": [0, 0, 0], "radius": 0, "normal": [1, 0, 0] }, {)"),
       "", "probes[0].radius: must be positive"},
      {"pressure sensor without a normal",
       replace(good, R"("probes": [ {)",
               R"("probes": [ { "name": "s", "type": "pressure", "point": [0, 0, 0], "radius": 0.003 }, {)"),
       "", "probes[0].normal"},
      {"pressure normal without a radius",
       replace(
           good, R"("probes": [ {)",
           R"("probes": [ { "name": "s", "type": "pressure", "point": [0, 0, 0], "normal": [1, 0, 0] }, {)"),
       "", "probes[0].normal: only with \"radius\""},
      {"extent link not positive", replace(good, "\"stat\": \"max\"", "\"stat\": \"extent\", \"link\": 0"),
       "", "probes[0].link: must be positive"},
      {"duplicate body name", replace(good, "\"name\": \"tank\"", "\"name\": \"column\""), "",
       "duplicate body name 'column'"},
      {"overlapping bodies",
       replace(good, "\"min\": [0, 0, 0], \"max\": [0.05", "\"min\": [-0.02, 0, 0], \"max\": [0.05"), "",
       "overlap"},
      // Huge particle counts and outputs: refused before anything is allocated or written.
      {"lattice of 1e15 points", replace(good, "\"spacing\": 0.01", "\"spacing\": 1e-5"), "",
       "too many particles"},
      {"more memory than the machine has",
       replace(replace(good, "\"max\": [0.05, 0.1, 0.03]", "\"max\": [0.57, 0.57, 0.57]"),
               "\"spacing\": 0.01", "\"spacing\": 0.001"),
       "--set domain.max=[1,1,1]", "of memory"},
      {"more frames than the disk holds",
       replace(replace(good, "\"width\": 64, \"height\": 48", "\"width\": 16384, \"height\": 16384"),
               "\"output_interval\": 0.001", "\"output_interval\": 0.00001"),
       "--set time.end=1", "are free on"},
      {"probe interval not dividing the output interval", good, "--set time.probe_interval=0.0003",
       "time.probe_interval: 0.0003 s must divide time.output_interval 0.001 s a whole number of times"},
      {"probe interval beyond the output interval", good, "--set time.probe_interval=0.002",
       "time.probe_interval: 0.002 s must divide"},
      {"probe interval zero", good, "--set time.probe_interval=0", "time.probe_interval: must be positive"},
      // Files and arguments.
      {"missing scene file", "", "MISSING", "no_such_scene.json: no such scene file"},
      {"unknown --set path", good, "--set resolution.spacin=0.004", "resolution.spacin"},
      {"--set value of the wrong type", good, "--set time.end=soon",
       "time.end: expected a number, got a string"},
      {"negative --end-time", good, "--end-time -1", "--end-time"},
      {"zero --checkpoint-every", good, "--checkpoint-every 0", "--checkpoint-every"},
      {"unwritable --out", good, "--out /proc/aortasph_cannot_write", "/proc/aortasph_cannot_write"},
  };
  REQUIRE(cases.size() >= 20);
  for (const Case& c : cases) {
    const fs::path scene = dir / "scene.json";
    std::ofstream(scene, std::ios::trunc) << c.scene;
    std::string args = "run " + scene.string() + " --quiet " + c.args;
    if (c.args == "MISSING") args = "run " + (dir / "no_such_scene.json").string() + " --quiet";
    if (c.args.find("--out") == std::string::npos) args += " --out " + (dir / "out").string();
    std::string err;
    const int code = run_cli(args, err);
    INFO(c.what << ": exit " << code << ", stderr: " << err);
    CHECK(code == 2);
    CHECK(err.find(c.expect) != std::string::npos);
    CHECK(err.find("internal error") == std::string::npos);
  }
  // resume without a checkpoint.
  std::string err;
  CHECK(run_cli("resume " + (dir / "nothing_here").string(), err) == 2);
  CHECK(err.find("no checkpoint") != std::string::npos);
}

TEST_CASE("bad input: render settings are refused by check, and by run before anything is written",
          "[bad-input][cli]") {
  const fs::path dir = scratch("render_settings");
  std::ofstream(dir / "scene.json") << kGood;
  const std::string scene = (dir / "scene.json").string();
  struct Row {
    const char* set;
    const char* expect;
  };
  const Row rows[] = {
      {"'render.colormap=\"jet\"'", "render.colormap: unknown colormap \"jet\""},
      {"'render.cameras.0.colormap=\"hot\"'", "render.cameras[0].colormap: unknown colormap"}};
  for (const Row& r : rows) {
    std::string err;
    const int check = run_cli("check " + scene + " --set " + r.set, err);
    INFO(r.set << ": check exit " << check << ", stderr: " << err);
    CHECK(check == 2);
    CHECK(err.find(r.expect) != std::string::npos);
    const fs::path out = dir / "out";
    fs::remove_all(out);
    const int run = run_cli("run " + scene + " --quiet --out " + out.string() + " --set " + r.set, err);
    INFO("run exit " << run << ", stderr: " << err);
    CHECK(run == 2);
    CHECK(err.find(r.expect) != std::string::npos);
    CHECK_FALSE(fs::exists(out / "probes.csv"));
    CHECK_FALSE(fs::exists(out / "diagnostics.csv"));
    // Without rendering the settings are unused: the run goes ahead.
    CHECK(run_cli("run " + scene + " --quiet --no-render --out " + out.string() + " --set " + r.set, err) ==
          0);
  }
}

TEST_CASE("disk estimate: --vtk-every N counts every N-th VTK frame and the last", "[bad-input]") {
  aortasph::Scene scene;  // no cameras: only the VTK frames count
  const double per_frame = 170.0 * 1000.0;
  CHECK(aortasph::estimate_output_bytes(scene, 1000.0, 100, false, 0) == 0.0);
  CHECK(aortasph::estimate_output_bytes(scene, 1000.0, 100, false, 1) == Approx(100 * per_frame));
  // Frames 0, 25, 50, 75 and the last: 5 of 100, not 100.
  CHECK(aortasph::estimate_output_bytes(scene, 1000.0, 100, false, 25) == Approx(5 * per_frame));
  CHECK(aortasph::estimate_output_bytes(scene, 1000.0, 3, false, 100) == Approx(2 * per_frame));
}

TEST_CASE("bad input: a write error during a run (disk full) exits 2 naming the file", "[bad-input][cli]") {
  const fs::path dir = scratch("full");
  std::ofstream(dir / "scene.json") << kGood;
  fs::create_directories(dir / "out");
  // probes.csv is a link to /dev/full: every write fails with ENOSPC, as on a full disk.
  fs::create_symlink("/dev/full", dir / "out" / "probes.csv");
  std::string err;
  const int code =
      run_cli("run " + (dir / "scene.json").string() + " --quiet --out " + (dir / "out").string(), err);
  INFO(err);
  CHECK(code == 2);
  CHECK(err.find("probes.csv: write failed") != std::string::npos);
}

TEST_CASE("bad input: a frame that cannot be written stops the run with exit 2, no partial PNG",
          "[bad-input][cli]") {
  const fs::path dir = scratch("frame");
  std::ofstream(dir / "scene.json") << kGood;
  // A directory where the PNG's temporary file must go: the write of frame 1 fails (as on a full disk).
  fs::create_directories(dir / "out" / "frames" / "front" / "frame_00001.png.tmp");
  std::string err;
  const int code =
      run_cli("run " + (dir / "scene.json").string() + " --quiet --out " + (dir / "out").string(), err);
  INFO(err);
  CHECK(code == 2);
  CHECK(err.find("rendering failed") != std::string::npos);
  CHECK(err.find("frame_00001.png") != std::string::npos);
  CHECK(fs::exists(dir / "out" / "frames" / "front" / "frame_00000.png"));
  CHECK_FALSE(fs::exists(dir / "out" / "frames" / "front" / "frame_00001.png"));
  CHECK(slurp(dir / "out" / "run.json").find("\"status\": \"failed\"") != std::string::npos);
}
