#include "cycle_report.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>

#include "embedded_scripts.hpp"
#include "errors.hpp"
#include "io/probes.hpp"
#include "output.hpp"
#include "scene_loader.hpp"

extern char** environ;

namespace aortasph {

namespace fs = std::filesystem;

int CsvTable::column(const std::string& name) const {
  const auto it = std::find(header.begin(), header.end(), name);
  return it == header.end() ? -1 : static_cast<int>(it - header.begin());
}

CsvTable read_csv(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot read");
  CsvTable t;
  std::string line;
  if (!std::getline(in, line) || line.empty()) throw InputError(file.string() + ":1: no header");
  {
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) t.header.push_back(cell);
  }
  long number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    std::vector<double> row;
    std::size_t from = 0;
    while (true) {
      const std::size_t to = line.find(',', from);
      const std::string cell = line.substr(from, to == std::string::npos ? std::string::npos : to - from);
      if (cell.empty()) {
        row.push_back(std::nan(""));
      } else {
        char* end = nullptr;
        const double v = std::strtod(cell.c_str(), &end);
        if (end == cell.c_str() || *end != '\0')
          throw InputError(file.string() + ":" + std::to_string(number) + ": not a number: '" + cell + "'");
        row.push_back(v);
      }
      if (to == std::string::npos) break;
      from = to + 1;
    }
    if (row.size() != t.header.size())
      throw InputError(file.string() + ":" + std::to_string(number) + ": " + std::to_string(row.size()) +
                       " cells, the header has " + std::to_string(t.header.size()));
    t.rows.push_back(std::move(row));
  }
  return t;
}

namespace {

const Probe* probe_named(const Scene& s, const std::string& name) {
  for (const Probe& p : s.probes)
    if (p.name == name) return &p;
  return nullptr;
}

// The columns of the stress and coaptation probes the block names ("cycle.stress" and so on as the path).
std::vector<std::pair<std::string, std::string>> probe_columns_of_block(const Scene& s) {
  std::vector<std::pair<std::string, std::string>> out;
  const CycleSpec& c = *s.cycle;
  if (!c.stress.empty())
    for (const char* f : {"max", "mean", "p95", "strain_max"})
      out.emplace_back("cycle.stress", c.stress + "." + f);
  if (!c.stress.empty())
    if (const Probe* p = probe_named(s, c.stress); p && p->per_body)
      for (std::size_t b = 0; b < p->bodies.size(); ++b)
        for (const std::string& f : stress_body_columns(b))
          out.emplace_back("cycle.stress", c.stress + "." + f);
  if (!c.coaptation.empty())
    if (const Probe* p = probe_named(s, c.coaptation))
      for (const std::string& f : coaptation_columns(p->bodies.size(), p->per_body))
        out.emplace_back("cycle.coaptation", c.coaptation + "." + f);
  if (!c.gap_area.empty())
    if (const Probe* p = probe_named(s, c.gap_area)) {
      out.emplace_back("cycle.gap_area", c.gap_area + ".central");
      for (std::size_t k = 0; k < p->commissures.size(); ++k)
        out.emplace_back("cycle.gap_area", c.gap_area + ".commissural_" + std::to_string(k));
    }
  if (!c.wall_distance.empty())
    if (const Probe* p = probe_named(s, c.wall_distance)) {
      out.emplace_back("cycle.wall_distance", c.wall_distance + ".min");
      for (std::size_t k = 0; k < p->bodies.size(); ++k)
        out.emplace_back("cycle.wall_distance", c.wall_distance + ".min_" + std::to_string(k));
    }
  return out;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> cycle_columns(const Scene& s) {
  std::vector<std::pair<std::string, std::string>> out;
  if (!s.cycle) return out;
  const CycleSpec& c = *s.cycle;
  const std::pair<const char*, const std::string*> named[] = {{"cycle.valve_flow", &c.valve_flow},
                                                              {"cycle.lv_pressure", &c.lv_pressure},
                                                              {"cycle.aortic_pressure", &c.aortic_pressure},
                                                              {"cycle.orifice_area", &c.orifice_area},
                                                              {"cycle.jet_speed", &c.jet_speed},
                                                              {"cycle.lvot_flow", &c.lvot_flow}};
  for (const auto& [path, col] : named)
    if (!col->empty()) out.emplace_back(path, *col);
  return out;
}

void check_cycle_columns(const Scene& s, const std::vector<std::string>& columns) {
  if (!s.cycle) return;
  auto all = cycle_columns(s);
  const auto more = probe_columns_of_block(s);
  all.insert(all.end(), more.begin(), more.end());
  for (const auto& [path, col] : all) {
    if (std::find(columns.begin(), columns.end(), col) != columns.end()) continue;
    // Name the columns of the probe the name starts with, to show what was meant.
    std::string near;
    for (const std::string& c : columns)
      if (c.compare(0, col.find('.'), col.substr(0, col.find('.'))) == 0)
        near += (near.empty() ? "" : ", ") + c;
    throw InputError(path + ": no probe writes a column '" + col + "'" +
                     (near.empty() ? std::string() : " (similar columns: " + near + ")"));
  }
}

std::vector<CycleMetrics> cycle_metrics_of(const Scene& s, const CsvTable& table,
                                           const CsvTable* diagnostics) {
  if (!s.cycle) return {};
  const CycleSpec& c = *s.cycle;
  const int tcol = table.column("time");
  if (tcol < 0) throw InputError("probes.csv: no time column");
  CycleSignals sig;
  auto col = [&](const std::string& name) {
    std::vector<double> v;
    const int k = name.empty() ? -1 : table.column(name);
    if (k < 0) return v;
    for (const auto& r : table.rows) v.push_back(r[k]);
    return v;
  };
  // Strictly increasing times only (a resumed run's file is; this guards a hand-edited one).
  sig.t = col("time");
  for (std::size_t i = 1; i < sig.t.size(); ++i)
    if (!(sig.t[i] > sig.t[i - 1]))
      throw InputError("probes.csv: times are not increasing at row " + std::to_string(i + 1));
  sig.valve_flow = col(c.valve_flow);
  sig.lv_pressure = col(c.lv_pressure);
  sig.aortic_pressure = col(c.aortic_pressure);
  sig.orifice_area = col(c.orifice_area);
  sig.jet_speed = col(c.jet_speed);
  sig.lvot_flow = col(c.lvot_flow);
  if (!c.stress.empty()) {
    sig.stress_max = col(c.stress + ".max");
    sig.stress_mean = col(c.stress + ".mean");
    sig.stress_p95 = col(c.stress + ".p95");
    sig.strain_max = col(c.stress + ".strain_max");
  }
  if (!c.coaptation.empty())
    if (const Probe* p = probe_named(s, c.coaptation)) {
      const std::size_t n = p->bodies.size();
      for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = a + 1; b < n; ++b) {
          const std::string pair = std::to_string(a) + "_" + std::to_string(b);
          sig.pair_names.push_back(pair);
          sig.coaptation_height.push_back(col(c.coaptation + ".height_" + pair));
          sig.coaptation_length.push_back(col(c.coaptation + ".length_" + pair));
        }
      sig.central_height = col(c.coaptation + ".central_height");
      sig.effective_height = col(c.coaptation + ".effective_height");
      if (p->per_body)
        for (std::size_t k = 0; k < n; ++k)
          sig.effective_height_cusp.push_back(col(c.coaptation + ".effective_height_" + std::to_string(k)));
    }
  if (!c.stress.empty())
    if (const Probe* p = probe_named(s, c.stress); p && p->per_body)
      for (std::size_t b = 0; b < p->bodies.size(); ++b) {
        const std::string k = c.stress + "." + std::to_string(b);
        sig.cusp_stress_max.push_back(col(k + ".max"));
        sig.cusp_stress_p95.push_back(col(k + ".p95"));
        sig.cusp_peak_height.push_back(col(k + ".max_height"));
        sig.cusp_peak_s.push_back(col(k + ".max_s"));
      }
  if (!c.gap_area.empty())
    if (const Probe* p = probe_named(s, c.gap_area)) {
      sig.gap_central = col(c.gap_area + ".central");
      for (std::size_t k = 0; k < p->commissures.size(); ++k)
        sig.gap_commissural.push_back(col(c.gap_area + ".commissural_" + std::to_string(k)));
    }
  if (!c.wall_distance.empty())
    if (const Probe* p = probe_named(s, c.wall_distance)) {
      sig.wall_min = col(c.wall_distance + ".min");
      for (std::size_t k = 0; k < p->bodies.size(); ++k)
        sig.wall_min_cusp.push_back(col(c.wall_distance + ".min_" + std::to_string(k)));
    }
  if (diagnostics) {
    const int dt = diagnostics->column("time"), de = diagnostics->column("max_density_error"),
              dv = diagnostics->column("volume_ratio");  // absent from runs before stop 51
    if (dt >= 0 && de >= 0 && !diagnostics->rows.empty()) {
      std::vector<double> t, e, v;
      for (const auto& r : diagnostics->rows)
        if (t.empty() || r[dt] > t.back()) {
          t.push_back(r[dt]), e.push_back(r[de]);
          if (dv >= 0) v.push_back(r[dv]);
        }
      for (const double x : sig.t) sig.density_error.push_back(sample(t, e, x));
      if (dv >= 0)
        for (const double x : sig.t) sig.volume_ratio.push_back(sample(t, v, x));
    }
  }
  CycleOptions o;
  o.period = c.period;
  o.start = c.start;
  o.lvot_area = c.lvot_area;
  o.density = c.density;
  o.hold_level = c.hold_level;
  o.pressure_zero = c.pressure_zero;
  std::vector<CycleMetrics> out = all_cycle_metrics(sig, o);
  if (c.cycles > 0 && static_cast<int>(out.size()) > c.cycles) out.resize(c.cycles);
  return out;
}

std::vector<std::string> cycle_metric_names(const Scene& s) {
  // The metrics of no cycle, shaped as the scene's would be: metric_table names them.
  CycleMetrics m;
  if (s.cycle) {
    const CycleSpec& c = *s.cycle;
    if (const Probe* p = c.coaptation.empty() ? nullptr : probe_named(s, c.coaptation))
      for (std::size_t a = 0; a < p->bodies.size(); ++a)
        for (std::size_t b = a + 1; b < p->bodies.size(); ++b) {
          m.pair_names.push_back(std::to_string(a) + "_" + std::to_string(b));
          m.coaptation_height_mm.push_back(0.0);
          m.coaptation_length_mm.push_back(0.0);
        }
    if (const Probe* p = c.coaptation.empty() ? nullptr : probe_named(s, c.coaptation); p && p->per_body)
      m.effective_height_mm_per.assign(p->bodies.size(), 0.0);
    if (const Probe* p = c.gap_area.empty() ? nullptr : probe_named(s, c.gap_area))
      m.commissural_gap_area_mm2_per.assign(p->commissures.size(), 0.0);
    if (const Probe* p = c.stress.empty() ? nullptr : probe_named(s, c.stress); p && p->per_body) {
      m.cusp_systole.assign(p->bodies.size(), {});
      m.cusp_diastole.assign(p->bodies.size(), {});
    }
    if (const Probe* p = c.wall_distance.empty() ? nullptr : probe_named(s, c.wall_distance))
      m.leaflet_wall_min_systole_mm_per.assign(p->bodies.size(), 0.0);
  }
  std::vector<std::string> names;
  for (const auto& [name, value] : metric_table(m)) names.push_back(name);
  return names;
}

void write_cycles_csv(const fs::path& file, const std::vector<CycleMetrics>& cycles, const Scene& scene) {
  std::ofstream f(file, std::ios::trunc);
  if (!f) throw InputError(file.string() + ": cannot open for writing");
  // Before the first cycle completes the header is already the scene's (its per-pair and per-cusp columns
  // too), so that a reader of an unfinished run sees the columns it will get.
  std::vector<std::string> header;
  if (cycles.empty())
    header = cycle_metric_names(scene);
  else
    for (const auto& [name, value] : metric_table(cycles.front())) header.push_back(name);
  for (std::size_t k = 0; k < header.size(); ++k) f << (k ? "," : "") << header[k];
  f << '\n';
  for (const CycleMetrics& m : cycles) {
    const auto row = metric_table(m);
    for (std::size_t k = 0; k < row.size(); ++k)
      f << (k ? "," : "") << (std::isnan(row[k].second) ? std::string() : format_number(row[k].second));
    f << '\n';
  }
  f.close();
  if (!f) throw InputError(file.string() + ": write failed (disk full?)");
}

nlohmann::json cycles_json(const Scene& s, const std::vector<CycleMetrics>& cycles) {
  nlohmann::json j;
  j["period_s"] = s.cycle->period;
  j["start_s"] = s.cycle->start;
  j["complete"] = cycles.size();
  if (s.cycle->cycles > 0) j["requested"] = s.cycle->cycles;
  j["file"] = "cycles.csv";
  j["per_cycle"] = nlohmann::json::array();
  for (const CycleMetrics& m : cycles) {
    nlohmann::json row;
    for (const auto& [name, v] : metric_table(m))
      row[name] = std::isnan(v) ? nlohmann::json() : nlohmann::json(v);
    row["periodic"] = m.cycle == 0 ? nlohmann::json() : nlohmann::json(m.periodic);
    j["per_cycle"].push_back(row);
  }
  if (!cycles.empty()) {
    j["metrics_from_cycle"] = cycles.back().cycle;
    j["metrics"] = j["per_cycle"].back();
    j["periodic_state"] = cycles.size() > 1 ? nlohmann::json(cycles.back().periodic) : nlohmann::json();
  }
  j["periodic_tolerance_pct"] = 2.0;
  // The pressure that reads 0 mmHg in the LV and aortic metrics (cycle.pressure_zero).
  j["pressure_zero_Pa"] = s.cycle->pressure_zero;
  return j;
}

std::string cycle_line(const CycleMetrics& m) {
  char buf[512];
  auto f = [](double v) {
    if (std::isnan(v)) return std::string("--");
    char b[32];
    std::snprintf(b, sizeof b, "%.4g", v);
    return std::string(b);
  };
  std::snprintf(buf, sizeof buf,
                "cycle %d [%g, %g] s: SV %s ml, peak flow %s ml/s, mean gradient %s mmHg, peak GOA %s cm2, "
                "end-diastolic aortic %s mmHg; ",
                m.cycle, m.t_start, m.t_end, f(m.stroke_volume_ml).c_str(),
                f(m.peak_forward_flow_ml_s).c_str(), f(m.mean_gradient_mmHg).c_str(),
                f(m.peak_goa_cm2).c_str(), f(m.aortic_end_diastolic_mmHg).c_str());
  std::string s = buf;
  if (m.cycle == 0) {
    s += "periodic state: -- (first cycle)";
  } else {
    std::snprintf(buf, sizeof buf, "SV change %s %%, EDP change %s %%: %s", f(m.sv_change_pct).c_str(),
                  f(m.edp_change_pct).c_str(), m.periodic ? "periodic (both < 2 %)" : "not periodic yet");
    s += buf;
  }
  return s;
}

namespace {

// Runs a program without a shell; quiet: its stdout and stderr go to /dev/null. Returns its exit status.
int spawn(const std::vector<std::string>& argv, bool quiet) {
  std::vector<char*> cargs;
  for (const auto& a : argv) cargs.push_back(const_cast<char*>(a.c_str()));
  cargs.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  if (quiet) {
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  }
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, cargs[0], &fa, nullptr, cargs.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return 127;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

// A python3 that imports matplotlib: $AORTASPH_PYTHON, /usr/bin/python3 (Debian's, where python3-matplotlib
// installs), then python3 on PATH; empty when none does.
std::string find_python() {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("AORTASPH_PYTHON"); env && *env) {
    candidates.push_back(env);
  } else {
    candidates.push_back("/usr/bin/python3");
    const char* path = std::getenv("PATH");
    std::istringstream dirs(path ? path : "");
    for (std::string dir; std::getline(dirs, dir, ':');)
      candidates.push_back((fs::path(dir.empty() ? "." : dir) / "python3").string());
  }
  for (const std::string& c : candidates)
    if (access(c.c_str(), X_OK) == 0 && spawn({c, "-c", "import matplotlib"}, true) == 0) return c;
  return "";
}

}  // namespace

int make_wiggers_plot(const fs::path& dir, std::string& error, bool remeasure) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    error = dir.string() + ": no such folder";
    return 2;
  }
  const fs::path run_json = dir / "run.json", probes = dir / "probes.csv", cycles = dir / "cycles.csv";
  auto missing = [&](const fs::path& f) {
    error = f.string() + ": missing (not the folder of a finished run?)";
    return 2;
  };
  if (!fs::is_regular_file(run_json, ec)) return missing(run_json);
  Scene scene;
  nlohmann::json j;
  try {
    std::ifstream in(run_json);
    j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("scene") || !j["scene"].is_object()) {
      error = run_json.string() + ": not a run.json (no scene)";
      return 2;
    }
    // The render block is not needed here (and a run with --end-time may hold figure times past its end).
    nlohmann::json recorded = j["scene"];
    recorded.erase("render");
    // A run stopped before its cycles' end (--end-time, exit 3, an interrupted run) is plotted as far as it
    // got: its recorded time.end may be short of the cycles the block asks for, which the loader refuses.
    // (NaN where a key is missing or not a number: then nothing changes and the loader names the problem.)
    const auto number = [](const nlohmann::json& o, const char* key) {
      return o.is_object() && o.contains(key) && o[key].is_number() ? o[key].get<double>() : std::nan("");
    };
    if (recorded.contains("cycle") && recorded.contains("time")) {
      const nlohmann::json& c = recorded["cycle"];
      const double need = number(c, "start") + number(c, "cycles") * number(c, "period");
      if (number(recorded["time"], "end") < need) recorded["time"]["end"] = need;
    }
    // Files the scene names (a waveform CSV) are relative to the scene file, as when it ran (and as `resume`
    // reads them).
    const fs::path base = j.contains("scene_file") && j["scene_file"].is_string()
                              ? fs::path(j["scene_file"].get<std::string>()).parent_path()
                              : fs::path();
    scene = load_scene_json(recorded, {}, base).scene;
  } catch (const InputError& e) {
    error = run_json.string() + ": its scene: " + e.what();
    return 2;
  }
  if (!scene.cycle) {
    error = run_json.string() + ": the run's scene has no cycle block (docs/scenes.md \"cycle\")";
    return 2;
  }
  if (!fs::is_regular_file(probes, ec)) return missing(probes);
  if (!fs::is_regular_file(cycles, ec)) return missing(cycles);
  try {
    const CsvTable table = read_csv(probes);
    const std::vector<std::string> columns(table.header.begin() + 1, table.header.end());
    check_cycle_columns(scene, columns);
    if (table.rows.size() < 2) {
      error = probes.string() + ": fewer than two rows";
      return 2;
    }
    if (remeasure) {
      // The cycles measured again with this program's definitions (docs/valve-metrics.md), as a run
      // measures them: from probes.csv and diagnostics.csv; cycles.csv and run.json's "cycles" rewritten.
      const fs::path diag = dir / "diagnostics.csv";
      std::optional<CsvTable> diagnostics;
      if (fs::is_regular_file(diag, ec)) diagnostics = read_csv(diag);
      const std::vector<CycleMetrics> measured =
          cycle_metrics_of(scene, table, diagnostics ? &*diagnostics : nullptr);
      write_cycles_csv(cycles, measured, scene);
      j["cycles"] = cycles_json(scene, measured);
      replace_file(run_json, j.dump(2) + "\n");
      for (const CycleMetrics& m : measured) std::printf("aortasph: %s\n", cycle_line(m).c_str());
      std::fflush(stdout);
    }
    read_csv(cycles);
  } catch (const InputError& e) {
    const std::string what = e.what();
    error = what.rfind("cycle.", 0) == 0 ? probes.string() + ": " + what : what;
    return 2;
  }
  const std::string python = find_python();
  if (python.empty()) {
    error =
        "no python3 with matplotlib found (install it: apt-get install python3-matplotlib; or set "
        "AORTASPH_PYTHON)";
    return 2;
  }
  fs::create_directories(dir / "figures", ec);
  const fs::path png = dir / "figures" / "wiggers.png";
  // The pressures are drawn as the metrics read them: 0 mmHg at cycle.pressure_zero.
  const int rc = spawn({python, "-c", std::string(scripts::plot_wiggers_py), dir.string(), png.string(),
                        nlohmann::json(scene.cycle->pressure_zero).dump()},
                       false);
  if (rc != 0 || !fs::is_regular_file(png, ec)) {
    error = "scripts/plot_wiggers.py failed (exit " + std::to_string(rc) + ")";
    return 2;
  }
  return 0;
}

int cmd_plot(const std::vector<std::string>& args) {
  std::vector<std::string> dirs;
  bool remeasure = false;
  for (const std::string& a : args) {
    if (a == "--remeasure") {
      remeasure = true;
    } else if (a.empty() || a[0] == '-') {
      std::fprintf(stderr,
                   "aortasph plot: error: unknown option '%s'\nusage: aortasph plot OUT_DIR [--remeasure]\n",
                   a.c_str());
      return 2;
    } else {
      dirs.push_back(a);
    }
  }
  if (dirs.size() != 1) {
    std::fprintf(
        stderr,
        "aortasph plot: error: expected one output folder\nusage: aortasph plot OUT_DIR [--remeasure]\n");
    return 2;
  }
  std::string error;
  const int rc = make_wiggers_plot(dirs[0], error, remeasure);
  if (rc != 0) {
    std::fprintf(stderr, "aortasph plot: error: %s\n", error.c_str());
    return rc;
  }
  std::printf("%s\n", (fs::path(dirs[0]) / "figures" / "wiggers.png").string().c_str());
  return 0;
}

}  // namespace aortasph
