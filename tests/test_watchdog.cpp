// Instability watchdog (issue 7): a deliberately unstable run exits 3 with a message naming time, step, body
// and particle, and everything written before stays valid (whole CSV rows, complete PNG frames).
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_helpers.hpp"
#include "image.hpp"

namespace fs = std::filesystem;
using aortasph::test::run_cli;
using aortasph::test::scratch;
using aortasph::test::slurp;

namespace {

const char* kScene = R"({
  "name": "unstable",
  "domain": { "min": [-0.1, -0.1, -0.1], "max": [0.3, 0.3, 0.2] },
  "resolution": { "spacing": 0.01 },
  "time": { "end": 0.5, "output_interval": 0.002 },
  "materials": { "water": { "type": "fluid", "density": 1000, "viscosity": 1e-6, "sound_speed": 10 },
                 "wall": { "type": "wall" } },
  "bodies": [
    { "name": "column", "material": "water", "shape": { "box": { "min": [0, 0, 0], "max": [0.05, 0.1, 0.03] } } },
    { "name": "tank", "material": "wall", "shape": { "container": { "min": [0, 0, 0], "max": [0.2, 0.15, 0.03], "layers": 3, "open": ["+y"] } } }
  ],
  "probes": [ { "name": "front", "type": "extent", "bodies": ["column"], "axis": "x", "stat": "max" } ],
  "render": { "width": 64, "height": 48,
              "cameras": [ { "name": "front", "eye": [0.1, 0.08, 0.5], "target": [0.1, 0.05, 0.015] } ] }
})";

// Every row whole, one complete PNG per row.
void check_outputs_valid(const fs::path& out) {
  const std::string probes = slurp(out / "probes.csv");
  REQUIRE(!probes.empty());
  CHECK(probes.back() == '\n');
  const auto rows = std::count(probes.begin(), probes.end(), '\n') - 1;
  CHECK(rows >= 1);
  for (long k = 0; k < rows; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05ld.png", k);
    INFO(name);
    const aortasph::Image image = aortasph::read_png(out / "frames" / "front" / name);
    CHECK(image.w == 64);
    CHECK(image.h == 48);
  }
  for (const auto& e : fs::recursive_directory_iterator(out)) CHECK(e.path().extension() != ".tmp");
  CHECK(slurp(out / "run.json").find("\"status\": \"unstable\"") != std::string::npos);
}

}  // namespace

TEST_CASE("watchdog: a time step forced too large exits 3 naming time, step, body and particle",
          "[watchdog][cli]") {
  const fs::path dir = scratch("dt");
  std::ofstream(dir / "scene.json") << kScene;
  std::string err;
  // About 10 times the acoustic CFL step: grows for a few outputs, then blows up.
  const int code =
      run_cli("run " + (dir / "scene.json").string() + " --quiet --out " + (dir / "out").string() +
                  " --set time.fixed_dt=0.003 --set time.output_interval=0.008",
              err);
  INFO(err);
  CHECK(code == 3);
  CHECK(err.find("unstable at t = ") != std::string::npos);
  CHECK(err.find(", step ") != std::string::npos);
  CHECK(err.find("of body 'column'") != std::string::npos);
  CHECK(err.find("particle ") != std::string::npos);
  check_outputs_valid(dir / "out");
}

TEST_CASE("watchdog: a density error over time.max_density_error exits 3 naming the limit",
          "[watchdog][cli]") {
  const fs::path dir = scratch("density");
  std::ofstream(dir / "scene.json") << kScene;
  std::string err;
  // The column starts hydrostatic: about 1 % denser at its bottom than at rest (sound speed 10 m/s), which a
  // limit of 0.2 % refuses; the default limit (0.5) lets the same scene run.
  const std::string base = "run " + (dir / "scene.json").string() + " --quiet --out " +
                           (dir / "out").string() + " --end-time 0.004";
  const int code = run_cli(base + " --set time.max_density_error=0.002", err);
  INFO(err);
  CHECK(code == 3);
  CHECK(err.find("density error of 0.0") != std::string::npos);
  CHECK(err.find("time.max_density_error") != std::string::npos);
  CHECK(err.find("of body 'column'") != std::string::npos);
  check_outputs_valid(dir / "out");
  CHECK(run_cli(base, err) == 0);
}
