// Studies (issue 19 items 2-5; docs/studies.md): `aortasph study` runs the shipped CI study end to end
// through Snakemake (metrics.csv = the last cycle of each variant, report.html with its plots), a second call
// runs nothing, an interrupted study finishes only the missing variant (resumed from its checkpoint), bad
// study files exit 2 naming the JSON path before anything is written (also a variant the World refuses, as
// `check` would), and zipped / range / scale parameters cross into the variants of a dry run. The two
// end-to-end cases run a few thousand steps of real runs: tagged [long], so the sanitizer step of
// scripts/test.sh leaves them out (the Release CTest step runs them: 7 s each measured, up to 22 s on busy
// cores).
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_helpers.hpp"
#include "cycle_report.hpp"

namespace fs = std::filesystem;
using aortasph::test::scratch;
using aortasph::test::slurp;

namespace {

const std::string kRepo = std::string(AORTASPH_TEST_DIR) + "/..";

// Runs `aortasph ARGS`, stdout and stderr together into `output`; the exit code.
int run_study(const std::string& args, std::string& output) {
  const auto f = fs::temp_directory_path() / ("aortasph_study_out_" + std::to_string(::getpid()));
  const std::string cmd = std::string(AORTASPH_BINARY) + " " + args + " > " + f.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  output = slurp(f);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool have_snakemake() {
  return std::system("snakemake --version > /dev/null 2>&1") == 0;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
  if (!line.empty() && line.back() == ',') cells.push_back("");
  return cells;
}

// A CSV file (no quoted cells) as rows of cells.
std::vector<std::vector<std::string>> csv_rows(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) rows.push_back(split(line));
  return rows;
}

std::map<std::string, std::string> row_map(const std::vector<std::string>& header,
                                           const std::vector<std::string>& row) {
  std::map<std::string, std::string> m;
  for (std::size_t k = 0; k < header.size(); ++k) m[header[k]] = k < row.size() ? row[k] : "";
  return m;
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("study: the CI study runs end to end through Snakemake, and a second call runs nothing",
          "[study][long]") {
  INFO("needs snakemake on PATH (scripts/install-deps.sh installs it)");
  REQUIRE(have_snakemake());
  const fs::path out = scratch("study_ci") / "out";
  std::string output;
  REQUIRE(run_study("study " + kRepo + "/studies/ci_tiny.json --out " + out.string() + " -j 2", output) == 0);
  INFO(output);
  CHECK(output.find("4 of 4 steps (100%) done") != std::string::npos);
  CHECK(output.find("--slurm") != std::string::npos);  // the cluster command is printed

  // variants.csv: id -> the swept value.
  const auto variants = csv_rows(out / "variants.csv");
  REQUIRE(variants.size() == 3);
  CHECK(variants[0] == std::vector<std::string>{"id", "outlet_pressure_Pa"});
  CHECK(variants[1] == std::vector<std::string>{"v000", "41.6"});
  CHECK(variants[2] == std::vector<std::string>{"v001", "141.6"});

  // metrics.csv: one row per variant, the requested metrics exactly as in the last row of its cycles.csv.
  const auto metrics = csv_rows(out / "metrics.csv");
  REQUIRE(metrics.size() == 3);
  const auto& header = metrics[0];
  const std::vector<std::string> requested{
      "stroke_volume_ml",          "peak_forward_flow_ml_s", "mean_gradient_mmHg", "aortic_diastolic_mmHg",
      "aortic_end_diastolic_mmHg", "peak_jet_velocity_m_s",  "closing_time_ms",    "effective_height_mm"};
  CHECK(std::vector<std::string>(header.begin(), header.begin() + 5) ==
        std::vector<std::string>{"id", "outlet_pressure_Pa", "spacing_mm", "status", "cycles"});
  CHECK(std::vector<std::string>(header.begin() + 5, header.end()) == requested);
  std::vector<double> outlet_mean;
  for (int v = 0; v < 2; ++v) {
    const auto row = row_map(header, metrics[1 + v]);
    const std::string id = v == 0 ? "v000" : "v001";
    CHECK(row.at("id") == id);
    CHECK(row.at("status") == "ok");
    CHECK(row.at("cycles") == "2");
    CHECK(row.at("spacing_mm") == "2");
    const auto cycles = csv_rows(out / "variants" / id / "cycles.csv");
    REQUIRE(cycles.size() == 3);  // two cycles: the metrics are the last one's
    const auto last = row_map(cycles[0], cycles[2]);
    for (const auto& m : requested) CHECK(row.at(m) == last.at(m));
    CHECK(!row.at("stroke_volume_ml").empty());
    CHECK(row.at("effective_height_mm").empty());  // a tube has no coaptation probe: empty, not faked
    // The mean of the aortic pressure probe (p_out, next to the outlet) over the last cycle, 0.06-0.12 s.
    const CsvTable probes = read_csv(out / "variants" / id / "probes.csv");
    const int tc = probes.column("time"), pc = probes.column("p_out");
    REQUIRE(tc >= 0);
    REQUIRE(pc >= 0);
    double sum = 0.0;
    int n = 0;
    for (const auto& r : probes.rows)
      if (r[tc] > 0.06 && r[tc] <= 0.12 + 1e-9) {
        sum += r[pc];
        ++n;
      }
    REQUIRE(n > 10);
    outlet_mean.push_back(sum / n);
    // The variant ran with its --set.
    const auto run = nlohmann::json::parse(slurp(out / "variants" / id / "run.json"));
    const std::string set = std::string("open_boundaries.1.pressure=") + (v == 0 ? "41.6" : "141.6");
    CHECK(std::find(run["sets"].begin(), run["sets"].end(), set) != run["sets"].end());
    // run.vtk = 20: VTK frames of outputs 0, 20, 40 and the last, 60 (0.12 s at 2 ms), for the stress maps.
    const std::string pvd = slurp(out / "variants" / id / "vtk" / "particles.pvd");
    CHECK(count_of(pvd, "<DataSet ") == 4);
    CHECK(fs::exists(out / "variants" / id / "vtk" / "particles_00060.vtp"));
    CHECK_FALSE(fs::exists(out / "variants" / id / "vtk" / "particles_00001.vtp"));
  }
  // The outlet pressure reached the runs: 100 Pa (0.75 mmHg) more at the outlet raises the aortic pressure by
  // about as much over the cycle (86 Pa measured at stop 43). The mean, not the end-diastolic sample: the
  // tube rings by about +-1 mmHg, and one sample put the two variants in either order with small changes
  // elsewhere.
  CHECK(outlet_mean[1] - outlet_mean[0] > 50.0);

  // report.html: offline, relative links to plots that exist; the header names the model and the BCs.
  const std::string html = slurp(out / "report.html");
  CHECK(html.find("src='plots/parameter_0.png'") != std::string::npos);
  CHECK(fs::file_size(out / "plots" / "parameter_0.png") > 1000);
  CHECK(html.find("src='variants/v001/figures/wiggers.png'") != std::string::npos);
  CHECK(fs::exists(out / "variants" / "v001" / "figures" / "wiggers.png"));
  CHECK(html.find("velocity inlet") != std::string::npos);
  CHECK(html.find("pressure outlet (constant 141.6 Pa)") != std::string::npos);
  CHECK(html.find("Leaflet model: no deformable leaflets") != std::string::npos);
  CHECK(html.find("http") == std::string::npos);  // nothing fetched from the network

  // A second call: Snakemake has nothing to do, metrics.csv is kept (same bytes, not rewritten).
  const std::string before = slurp(out / "metrics.csv");
  const auto mtime = fs::last_write_time(out / "metrics.csv");
  REQUIRE(run_study("study " + kRepo + "/studies/ci_tiny.json --out " + out.string() + " -j 2", output) == 0);
  CHECK(output.find("Nothing to be done") != std::string::npos);
  CHECK(slurp(out / "metrics.csv") == before);
  CHECK(fs::last_write_time(out / "metrics.csv") == mtime);

  // The traffic light of the report: an effective height (a tube has none: written in by hand here) inside
  // the 9-10 mm target is green, outside red.
  for (const auto& [id, value] : {std::pair{"v000", "9.5"}, {"v001", "7.2"}}) {
    auto cycles = csv_rows(out / "variants" / id / "cycles.csv");
    const auto col = std::find(cycles[0].begin(), cycles[0].end(), "effective_height_mm") - cycles[0].begin();
    cycles.back()[col] = value;
    std::ofstream f(out / "variants" / id / "cycles.csv");
    for (const auto& row : cycles)
      for (std::size_t k = 0; k < row.size(); ++k) f << row[k] << (k + 1 < row.size() ? "," : "\n");
  }
  REQUIRE(std::system(("cd " + out.string() + " && /usr/bin/python3 study_report.py . 2>&1").c_str()) == 0);
  const std::string lit = slurp(out / "report.html");
  CHECK(lit.find("<td class='good'>9.5</td>") != std::string::npos);
  CHECK(lit.find("<td class='bad'>7.2</td>") != std::string::npos);
}

TEST_CASE("study: an interrupted study finishes only the missing variant, resumed from its checkpoint",
          "[study][long]") {
  INFO("needs snakemake on PATH (scripts/install-deps.sh installs it)");
  REQUIRE(have_snakemake());
  const fs::path dir = scratch("study_resume"), out = dir / "out";
  const fs::path study = dir / "study.json";
  std::ofstream(study) << R"({ "name": "resume", "scene": ")" << kRepo << R"(/scenes/tube_pulse.json",
    "parameters": [ { "path": "open_boundaries.1.pressure", "values": [41.6, 141.6] } ],
    "metrics": [ "stroke_volume_ml" ], "run": { "threads": 1, "checkpoint_every": 0.01 } })";
  // Started in its own process group, then Ctrl-C (SIGINT to the group) once one variant is complete and the
  // other has written a checkpoint.
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    const std::string bin = AORTASPH_BINARY;
    ::execl(bin.c_str(), bin.c_str(), "study", study.c_str(), "--out", out.c_str(), "-j", "1", nullptr);
    ::_exit(127);
  }
  ::setpgid(pid, pid);
  std::string done, running;
  // Up to 3 minutes: the first variant takes about 10 s on a quiet machine, several times that on a loaded
  // one.
  for (int k = 0; k < 18000 && running.empty(); ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    done.clear();
    for (const char* id : {"v000", "v001"}) {
      if (fs::exists(out / "variants" / id / "complete")) done = id;
    }
    if (done.empty()) continue;
    const std::string other = done == "v000" ? "v001" : "v000";
    if (fs::exists(out / "variants" / other / "checkpoint.bin")) running = other;
  }
  REQUIRE(!running.empty());
  ::kill(-pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 130);
  CHECK(!fs::exists(out / "variants" / running / "complete"));
  CHECK(slurp(out / "variants" / running / "run.json").find("\"status\": \"interrupted\"") !=
        std::string::npos);
  CHECK(!fs::exists(out / "metrics.csv"));

  const std::string done_run = slurp(out / "variants" / done / "run.json");
  const auto done_time = fs::last_write_time(out / "variants" / done / "run.json");
  std::string output;
  REQUIRE(run_study("study " + study.string() + " --out " + out.string() + " -j 1", output) == 0);
  INFO(output);
  CHECK(count_of(output, "rule variant:") == 1);
  CHECK(output.find("wildcards: id=" + running) != std::string::npos);
  CHECK(slurp(out / "variants" / done / "run.json") == done_run);
  CHECK(fs::last_write_time(out / "variants" / done / "run.json") == done_time);
  const auto run = nlohmann::json::parse(slurp(out / "variants" / running / "run.json"));
  CHECK(run["status"] == "ok");
  CHECK(run.contains("resumed_at"));
  const auto metrics = csv_rows(out / "metrics.csv");
  REQUIRE(metrics.size() == 3);
  for (std::size_t r = 1; r < 3; ++r) CHECK(!metrics[r].back().empty());
}

TEST_CASE("study: bad study files exit 2 naming the JSON path, before anything is written", "[study][cli]") {
  const fs::path dir = scratch("study_bad");
  const std::string scene = "\"scene\": \"" + kRepo + "/scenes/tube_pulse.json\"";
  const std::string spacing = R"("parameters": [ { "path": "resolution.spacing", "values": [0.002] } ])";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"{ " + scene + ", " + spacing + ", \"bogus\": 1 }", "study.json: bogus: unknown key"},
      {"{ " + scene + R"(, "parameters": [] })", "study.json: parameters: empty sweep"},
      {"{ " + scene + R"(, "parameters": [ { "path": "resolution.spacing", "values": [] } ] })",
       "study.json: parameters[0].values: empty sweep"},
      {"{ " + scene +
           R"(, "parameters": [ { "path": "resolution.spacing", "range": { "from": 0.003, "to": 0.002, "step": 0.001 } } ] })",
       "study.json: parameters[0].range.to: below range.from"},
      {"{ " + scene +
           R"(, "parameters": [ { "path": "aortic_root.commissure_height", "values": [0.01] } ] })",
       "study.json: parameters[0].path: --set aortic_root.commissure_height=0.01: unknown path"},
      {"{ " + scene + R"(, "parameters": [ { "path": "resolution.spacing", "values": [0.002, -1] } ] })",
       "study.json: parameters[0].values[1]: resolution.spacing: must be positive"},
      {"{ " + scene + R"(, "parameters": [ { "path": "resolution.spacing", "valuez": [1] } ] })",
       "study.json: parameters[0].valuez: unknown key"},
      {R"({ "scene": "missing.json", )" + spacing + " }", "study.json: scene: no such file"},
      {"{ \"scene\": \"" + kRepo + "/scenes/tube_flow.json\", " + spacing + " }",
       "study.json: scene: '" + fs::path(kRepo + "/scenes/tube_flow.json").lexically_normal().string() +
           "' has no cycle block"},
      {"{ " + scene + ", " + spacing + R"(, "fixed": { "time.bogus": 1 } })",
       "study.json: fixed: --set time.bogus=1: unknown path"},
      {"{ " + scene + ", " + spacing + R"(, "metrics": [ "stroke_volume_ml", "sv" ] })",
       "study.json: metrics[1]: 'sv' is not a cycles.csv column"},
      {"{ " + scene + ", " + spacing + R"(, "run": { "threads": 0 } })", "study.json: run.threads: expected"},
      {"{ " + scene + ", " + spacing + R"(, "run": { "vtk": 0 } })",
       "study.json: run.vtk: expected true, false or a whole number of outputs >= 1, got 0"},
      {"{ " + scene + ", " + spacing + R"(, "run": { "vtk": "last" } })", "study.json: run.vtk: expected"},
      {"[1, 2", "study.json: not valid JSON"},
      {"{ " + scene + R"(, "parameters": [ { "path": "resolution.spacing", "values": [0.002, 0.0025] } ] })",
       "study.json: parameters (variant v001: resolution.spacing=0.0025): open_boundaries[1] 'aorta': the "
       "buffer "
       "(4 layers) reaches outside the domain"},
      {"{ " + scene +
           R"(, "parameters": [ { "paths": [ "resolution.spacing", "time.cfl" ], "values": [ [0.002] ] } ] })",
       "study.json: parameters[0].values[0]: expected a list of 2 values, one per path"},
      {"{ " + scene +
           R"(, "parameters": [ { "paths": [ "resolution.spacing", "time.kfl" ], "values": [ [0.002, 0.2] ] } ] })",
       "study.json: parameters[0].paths[1]: --set time.kfl=0.2: unknown path"},
  };
  for (const auto& [text, message] : cases) {
    std::ofstream(dir / "study.json") << text;
    std::string output;
    INFO(text);
    CHECK(run_study("study " + (dir / "study.json").string() + " --out " + (dir / "out").string(), output) ==
          2);
    CHECK(output.find(message) != std::string::npos);
    CHECK(!fs::exists(dir / "out"));
  }
}

TEST_CASE("study: zipped, range and scale parameters cross into the variants of a dry run", "[study]") {
  INFO("needs snakemake on PATH (scripts/install-deps.sh installs it)");
  REQUIRE(have_snakemake());
  const fs::path dir = scratch("study_zip"), out = dir / "out";
  std::ofstream(dir / "study.json") << R"({ "scene": ")" << kRepo << R"(/scenes/tube_pulse.json",
    "parameters": [
      { "paths": [ "time.cfl", "time.max_dt" ], "labels": [ "cfl", "max_dt" ], "values": [ [0.25, 0.001], [0.2, 0.0005] ] },
      { "path": "open_boundaries.1.pressure", "range": { "from": 40, "to": 60, "step": 10 } },
      { "path": "materials.blood.viscosity", "label": "nu", "scale": [1, 2] } ] })";
  std::string output;
  REQUIRE(run_study("study " + (dir / "study.json").string() + " --out " + out.string() + " --dry-run",
                    output) == 0);
  INFO(output);
  CHECK(count_of(output, "rule variant:") == 12);
  CHECK(output.find("This was a dry-run") != std::string::npos);
  std::ifstream in(out / "variants.csv");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  REQUIRE(lines.size() == 13);
  CHECK(lines[0] == "id,cfl,max_dt,open_boundaries.1.pressure,nu");
  CHECK(lines[1] == "v000,0.25,0.001,40,3.3e-06");  // the last parameter varies fastest
  CHECK(lines[2] == "v001,0.25,0.001,40,6.6e-06");  // scale: the scene's 3.3e-6 times 2
  CHECK(lines[6] == "v005,0.25,0.001,60,6.6e-06");
  CHECK(lines[12] == "v011,0.2,0.0005,60,6.6e-06");
  const auto info = nlohmann::json::parse(slurp(out / "study.json"));
  CHECK(info["variants"][9]["sets"] ==
        nlohmann::json({"time.cfl=0.2", "time.max_dt=0.0005", "open_boundaries.1.pressure=50",
                        "materials.blood.viscosity=6.6e-06"}));
  CHECK(fs::exists(out / "Snakefile"));
  CHECK(!fs::exists(out / "variants" / "v000" / "run.json"));  // nothing ran
  CHECK(!fs::exists(out / "metrics.csv"));
}

namespace {

// A synthetic study folder, as `aortasph study` leaves it after its runs, for scripts/study_report.py:
// study.json, variants.csv and per variant run.json and cycles.csv (two cycles: the report reads the last).
struct FakeVariant {
  std::vector<nlohmann::json> values;  // per parameter (a list for a zipped one)
  std::map<std::string, double> last;  // cycles.csv columns of the last cycle
};

void write_fake_study(const fs::path& dir, const nlohmann::json& parameters,
                      const std::vector<FakeVariant>& vs) {
  fs::create_directories(dir);
  nlohmann::json study = {{"name", "fake"},
                          {"title", "fake study"},
                          {"description", ""},
                          {"scene", "x.json"},
                          {"fixed", nlohmann::json::array()},
                          {"metrics", {"effective_height_mm"}},
                          {"report", nlohmann::json::object()},
                          {"parameters", parameters}};
  std::ofstream(dir / "study.json") << study.dump(1);
  std::ofstream table(dir / "variants.csv");
  table << "id";
  for (const auto& p : parameters)
    for (const auto& l : p["labels"]) table << "," << l.get<std::string>();
  table << "\n";
  const nlohmann::json scene = {
      {"resolution", {{"spacing", 0.001}}},
      {"materials", {{"blood", {{"type", "fluid"}}}, {"leaf", {{"type", "shell"}, {"youngs_modulus", 2e6}}}}},
      {"bodies", {{{"name", "blood"}, {"material", "blood"}}, {{"name", "leaflet0"}, {"material", "leaf"}}}},
      {"open_boundaries", nlohmann::json::array()}};
  for (std::size_t v = 0; v < vs.size(); ++v) {
    char id[32];
    std::snprintf(id, sizeof id, "v%03zu", v);
    table << id;
    for (const auto& val : vs[v].values)
      for (const auto& x : val.is_array() ? val : nlohmann::json::array({val}))
        table << "," << (x.is_string() ? x.get<std::string>() : x.dump());
    table << "\n";
    const fs::path vd = dir / "variants" / id;
    fs::create_directories(vd);
    std::ofstream(vd / "run.json") << nlohmann::json({{"status", "ok"}, {"scene", scene}}).dump();
    std::ofstream c(vd / "cycles.csv");
    c << "cycle";
    for (const auto& [k, x] : vs[v].last) c << "," << k;
    c << "\n0";
    for (std::size_t k = 0; k < vs[v].last.size(); ++k) c << ",-999";  // the first cycle: not reported
    c << "\n1";
    for (const auto& [k, x] : vs[v].last) c << "," << x;
    c << "\n";
  }
}

int run_report(const fs::path& dir, std::string& output) {
  const char* env = std::getenv("AORTASPH_PYTHON");
  const std::string python = env && *env ? env : "/usr/bin/python3";
  const auto f = dir / "report_log.txt";
  const std::string cmd =
      python + " " + kRepo + "/scripts/study_report.py " + dir.string() + " > " + f.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  output = slurp(f);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// validation.csv as (sweep, metric) -> row.
std::map<std::pair<std::string, std::string>, std::map<std::string, std::string>> validation_of(
    const fs::path& dir) {
  // Cells may hold commas inside quotes (csv module): read with a small quote-aware split.
  std::ifstream in(dir / "validation.csv");
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells(1);
    bool quoted = false;
    for (char ch : line) {
      if (ch == '"')
        quoted = !quoted;
      else if (ch == ',' && !quoted)
        cells.emplace_back();
      else
        cells.back() += ch;
    }
    rows.push_back(cells);
  }
  std::map<std::pair<std::string, std::string>, std::map<std::string, std::string>> out;
  for (std::size_t r = 1; r < rows.size(); ++r) {
    const auto m = row_map(rows[0], rows[r]);
    out[{m.at("sweep"), m.at("metric")}] = m;
  }
  return out;
}

}  // namespace

TEST_CASE("study report: nomograms, stress maps and the validation table from synthetic graft variants",
          "[study]") {
  // Graft diameter 26 / 28 / 30 mm x straight / neo-sinus, with known trends: the effective height falls
  // 0.25 mm per mm (Marom: falls: agree), the coaptation height rises 0.5 mm per mm (Marom: falls:
  // disagree), the straight graft closes 10 ms sooner (Katayama: agree) and carries 20 kPa less stress
  // (Katayama: more: disagree). The worst variant (largest diastolic cusp stress: 30 mm neo-sinus) has a VTK
  // frame: its stress map is drawn from it.
  const fs::path dir = scratch("study_report_graft") / "study";
  const nlohmann::json params = {{{"paths", {"aortic_root.graft_diameter", "open_boundaries.1.radius"}},
                                  {"labels", {"graft_diameter_m", "outlet_radius_m"}},
                                  {"values", {{0.026, 0.013}, {0.028, 0.014}, {0.030, 0.015}}},
                                  {"base", nullptr}},
                                 {{"paths", {"aortic_root.graft_shape", "aortic_root.neo_sinus_bulge"}},
                                  {"labels", {"graft_shape", "neo_sinus_bulge_m"}},
                                  {"values", {{"straight", 0}, {"neo_sinus", 0.003}}},
                                  {"base", nullptr}}};
  std::vector<FakeVariant> vs;
  for (double d : {26.0, 28.0, 30.0})
    for (int neo = 0; neo < 2; ++neo) {
      FakeVariant f;
      f.values = {nlohmann::json::array({d / 1000, d / 2000}),
                  neo ? nlohmann::json::array({"neo_sinus", 0.003}) : nlohmann::json::array({"straight", 0})};
      const double coapt = 2.0 + 0.5 * (d - 26);
      f.last = {{"effective_height_mm", 12.0 + 0.5 * neo - 0.25 * (d - 26)},
                {"coaptation_height_0_1_mm", coapt - 0.2},
                {"coaptation_height_0_2_mm", coapt},
                {"coaptation_height_1_2_mm", coapt + 0.2},
                {"closing_time_ms", 30.0 + 10.0 * neo},
                {"stress_diastole_peak_kPa", 100.0 + 20.0 * neo + d},
                {"stress_diastole_peak_c0_kPa", 100.0 + 20.0 * neo + d},
                {"stress_diastole_peak_c1_kPa", 90.0},
                {"stress_diastole_peak_c2_kPa", 80.0}};
      vs.push_back(f);
    }
  write_fake_study(dir, params, vs);
  const fs::path vtk = dir / "variants" / "v005" / "vtk";
  fs::create_directories(vtk);
  std::ofstream(vtk / "particles.pvd")
      << "<VTKFile><Collection>\n<DataSet timestep=\"0.1\" file=\"particles_00001.vtp\"/>\n"
         "<DataSet timestep=\"0.2\" file=\"particles_00002.vtp\"/>\n</Collection></VTKFile>\n";
  std::ofstream(vtk / "particles_00002.vtp")
      << "<VTKFile><PolyData><Piece><Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n0 0 0\n0.001 0.002 0.003\n0.002 0.001 0\n</DataArray>\n</Points><PointData>\n"
         "<DataArray type=\"Int32\" Name=\"body\" format=\"ascii\">\n0\n1\n1\n</DataArray>\n"
         "<DataArray type=\"Float64\" Name=\"von_mises\" format=\"ascii\">\n0\n1500\n3000\n</DataArray>\n"
         "</PointData></Piece></PolyData></VTKFile>\n";
  std::string output;
  REQUIRE(run_report(dir, output) == 0);
  INFO(output);
  const std::string html = slurp(dir / "report.html");
  CHECK(html.find("src='plots/nomogram.png'") != std::string::npos);
  CHECK(fs::file_size(dir / "plots" / "nomogram.png") > 1000);
  CHECK(html.find("Straight and neo-sinus grafts side by side") != std::string::npos);
  CHECK(html.find("Worst variant: v005") != std::string::npos);
  CHECK(html.find("src='plots/stress_map_v005.png'") != std::string::npos);
  CHECK(fs::file_size(dir / "plots" / "stress_map_v005.png") > 1000);
  CHECK(html.find("<h3>v000 (baseline)</h3><p>no VTK frame") != std::string::npos);
  CHECK(html.find("http") == std::string::npos);

  const auto val = validation_of(dir);
  for (const std::string shape : {"straight", "neo_sinus"}) {
    const std::string sweep = "graft diameter (" + shape + ")";
    INFO(sweep);
    REQUIRE(val.count({sweep, "effective height [mm per mm]"}));
    const auto& eff = val.at({sweep, "effective height [mm per mm]"});
    CHECK(eff.at("simulated_slope") == "-0.25");
    CHECK(eff.at("simulated") == "falls");
    CHECK(eff.at("published_slope") == "-0.29");
    CHECK(eff.at("verdict") == "agree");
    const auto& co = val.at({sweep, "coaptation height [mm per mm]"});
    CHECK(co.at("simulated_slope") == "0.5");
    CHECK(co.at("published_slope") == "-0.3");
    CHECK(co.at("verdict") == "disagree");
  }
  const auto& closing = val.at({"graft shape", "closing time [ms]"});
  CHECK(closing.at("simulated") == "straight - neo-sinus = -10 (mean of 3 pairs)");
  CHECK(closing.at("verdict") == "agree");
  CHECK(val.at({"graft shape", "diastolic peak stress [kPa]"}).at("verdict") == "disagree");
}

TEST_CASE(
    "study report: the commissure-rotation panel and the commissure-height rows from synthetic variants",
    "[study]") {
  // Commissure height x0.8 / x1.0 of 16.8 mm crossed with commissure 1 at 120 / 130 degrees: the coaptation
  // height grows 4 mm per unit factor (agree), the x0.8 valve regurgitates 8 % more (agree), the effective
  // height falls 0.1 mm per degree of rotation and the stress rises 1 kPa per degree (no published value).
  // No stress in any VTK frame: the stress maps fall back to the figure sheets, here none.
  const fs::path dir = scratch("study_report_rotation") / "study";
  const nlohmann::json params = {{{"paths", {"aortic_root.commissure_height"}},
                                  {"labels", {"commissure_height_m"}},
                                  {"values", {0.01344, 0.0168}},
                                  {"base", 0.0168}},
                                 {{"paths", {"aortic_root.commissure_angles.1"}},
                                  {"labels", {"commissure_1_angle_deg"}},
                                  {"values", {120, 130}},
                                  {"base", 120}}};
  std::vector<FakeVariant> vs;
  for (double factor : {0.8, 1.0})
    for (double angle : {120.0, 130.0}) {
      const double delta = angle - 120.0;
      FakeVariant f;
      f.values = {factor * 0.0168, angle};
      f.last = {{"coaptation_height_0_1_mm", 4.0 * factor},
                {"regurgitant_fraction_pct", factor < 0.9 ? 10.0 : 2.0},
                {"central_gap_area_mm2", factor < 0.9 ? 3.0 : 0.0},
                {"commissural_gap_area_c0_mm2", 0.1 * delta},
                {"effective_height_mm", 10.0 - 0.1 * delta},
                {"effective_height_c0_mm", 10.0 - 0.1 * delta},
                {"effective_height_c1_mm", 10.0 - 0.2 * delta},
                {"stress_diastole_peak_kPa", 50.0 + delta},
                {"stress_diastole_peak_c1_kPa", 50.0 + delta},
                {"stress_diastole_p95_c1_kPa", 40.0 + delta}};
      vs.push_back(f);
    }
  write_fake_study(dir, params, vs);
  std::string output;
  REQUIRE(run_report(dir, output) == 0);
  INFO(output);
  const std::string html = slurp(dir / "report.html");
  CHECK(html.find("src='plots/commissure_rotation.png'") != std::string::npos);
  CHECK(fs::file_size(dir / "plots" / "commissure_rotation.png") > 1000);
  CHECK(html.find("not applicable: the study does not sweep the graft") != std::string::npos);
  // The largest cusp stress, 60 kPa at 130 degrees, first reached by v001 (x0.8): the first of equals.
  CHECK(html.find("Worst variant: v001") != std::string::npos);
  const auto val = validation_of(dir);
  const std::string sweep = "commissure height (factor of the base)";
  REQUIRE(val.count({sweep, "coaptation height [mm per unit factor]"}));
  CHECK(val.at({sweep, "coaptation height [mm per unit factor]"}).at("simulated_slope") == "4");
  CHECK(val.at({sweep, "coaptation height [mm per unit factor]"}).at("verdict") == "agree");
  const auto& leak = val.at({sweep, "leakage at x0.8"});
  CHECK(leak.at("verdict") == "agree");
  CHECK(leak.at("simulated") == "regurgitant_fraction_pct x0.8 - x1.0 = 8; central gap at x0.8 3 mm2");
  const auto& rot = val.at({"commissure rotation delta", "effective height [mm per deg]"});
  CHECK(rot.at("simulated_slope") == "-0.1");
  CHECK(rot.at("verdict") == "no published value");
  CHECK(val.at({"commissure rotation delta", "diastolic peak stress [kPa per deg]"}).at("simulated_slope") ==
        "1");
}
