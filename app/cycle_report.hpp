// The per-cycle valve metrics of a run (scene block `cycle`; docs/valve-metrics.md): read from probes.csv,
// written to cycles.csv and run.json, one line per cycle on standard output; the Wiggers plot.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "physiology/valve_metrics.hpp"
#include "scene.hpp"

namespace aortasph {

// A CSV table of numbers (probes.csv): its header and rows; an empty cell or "nan" reads as NaN. Throws
// InputError naming the file and line.
struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  int column(const std::string& name) const;  // -1 when absent
};
CsvTable read_csv(const std::filesystem::path& file);

// The probe columns the cycle block names (JSON path, column), in the block's order.
std::vector<std::pair<std::string, std::string>> cycle_columns(const Scene& scene);

// Throws InputError naming the cycle block's key when a column it names is not among the probes' columns.
void check_cycle_columns(const Scene& scene, const std::vector<std::string>& probe_columns);

// The metrics of every complete cycle in the table (probes.csv with a `time` column); the density error comes
// from diagnostics (diagnostics.csv, its `max_density_error` read at the probes' times) when given.
std::vector<CycleMetrics> cycle_metrics_of(const Scene& scene, const CsvTable& probes,
                                           const CsvTable* diagnostics = nullptr);

// The cycles.csv column names of the scene's cycle block (the per-pair, per-commissure and per-cusp columns
// follow its probes), in cycles.csv order.
std::vector<std::string> cycle_metric_names(const Scene& scene);

// Writes cycles.csv (one row per cycle, empty cells where a metric is not measurable).
void write_cycles_csv(const std::filesystem::path& file, const std::vector<CycleMetrics>& cycles,
                      const Scene& scene);

// The run.json entry: the period, the cycles and the periodic-state test; the last cycle is the one the
// metrics are taken from.
nlohmann::json cycles_json(const Scene& scene, const std::vector<CycleMetrics>& cycles);

// One line for standard output: the cycle's main numbers and the periodic-state test.
std::string cycle_line(const CycleMetrics& m);

// Draws OUT_DIR/figures/wiggers.png with scripts/plot_wiggers.py (embedded); returns 0, or 2 with a message
// in `error` (a missing folder or column, no python3 with matplotlib, the script failing). With remeasure,
// first the cycles measured again from probes.csv (and diagnostics.csv) with this program's metric
// definitions and the scene run.json records, cycles.csv and run.json's "cycles" rewritten, each cycle's line
// printed (`aortasph plot OUT_DIR --remeasure`: a finished run brought up to date after a definition changed,
// without running it again).
int make_wiggers_plot(const std::filesystem::path& dir, std::string& error, bool remeasure = false);

// aortasph plot OUT_DIR
int cmd_plot(const std::vector<std::string>& args);

}  // namespace aortasph
