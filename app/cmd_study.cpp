// aortasph study STUDY.json: a parameter sweep of `aortasph run` jobs on Snakemake (docs/studies.md, issue 19
// items 2-5). This file only reads and checks the study, writes the workflow (DIR/Snakefile,
// DIR/variants.csv, DIR/study.json, DIR/study_report.py) and hands it to snakemake: scheduling, skipping
// finished variants and the cluster back ends are Snakemake's.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "core/sim_errors.hpp"
#include "cycle_report.hpp"
#include "embedded_scripts.hpp"
#include "errors.hpp"
#include "io/probes.hpp"
#include "physiology/valve_metrics.hpp"
#include "scene_loader.hpp"
#include "world.hpp"

extern char** environ;

namespace aortasph {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const char* kStudyUsage =
    "usage: aortasph study STUDY.json [--out DIR] [-j N] [--dry-run] [--cluster-hint]\n";

struct Parameter {
  std::string path;   // a --set path (dots, list indices as numbers)
  std::string label;  // column name in variants.csv / metrics.csv (default: the path)
  std::vector<json> values;
  std::vector<std::string> where;  // each value's JSON path in the study file
  // Zipped parameters set several paths together: each value is a list, one entry per path. A plain parameter
  // has one path and its value is the value itself.
  std::vector<std::string> paths, labels;
  bool zipped = false;
  json base;  // the base scene's own value at the first path (null when it has none): the report's reference
};

// The --set items of one value of a parameter.
std::vector<std::string> sets_of(const Parameter& p, const json& value);
// The variants.csv cells of one value (one per path).
std::vector<json> cells_of(const Parameter& p, const json& value) {
  if (!p.zipped) return {value};
  return std::vector<json>(value.begin(), value.end());
}

struct Study {
  fs::path file;
  std::string name, title, description;
  fs::path scene;  // absolute
  std::vector<Parameter> parameters;
  std::vector<std::string> fixed;  // KEY=VALUE
  std::vector<std::string> metrics;
  int threads = 1;
  double checkpoint_every = 0.0;  // 0: a tenth of the run
  bool render = false;
  int vtk_every = 0;  // 0: no VTK frames; N: `aortasph run --vtk-every N` (the stress maps read the last)
  json report;
};

[[noreturn]] void fail(const Study& s, const std::string& path, const std::string& message) {
  throw InputError(s.file.string() + ": " + path + ": " + message);
}

void check_keys(const Study& s, const json& j, const std::string& path, const std::set<std::string>& keys) {
  if (!j.is_object()) fail(s, path.empty() ? "study" : path, "expected an object");
  for (const auto& [k, v] : j.items())
    if (!keys.count(k)) fail(s, path.empty() ? k : path + "." + k, "unknown key");
}

// The JSON value at a --set path of the resolved scene, or nullptr.
const json* at_path(const json& root, const std::string& key) {
  const json* node = &root;
  std::stringstream ss(key);
  for (std::string part; std::getline(ss, part, '.');) {
    if (node->is_array()) {
      char* end = nullptr;
      const unsigned long i = std::strtoul(part.c_str(), &end, 10);
      if (part.empty() || *end != '\0' || i >= node->size()) return nullptr;
      node = &(*node)[i];
    } else if (node->is_object() && node->contains(part)) {
      node = &(*node)[part];
    } else {
      return nullptr;
    }
  }
  return node;
}

double number_at(const Study& s, const json& j, const std::string& path) {
  if (!j.is_number()) fail(s, path, "expected a number");
  return j.get<double>();
}

// A value rounded to 12 significant digits (0.0168 * 1.1 is 0.01848, not 0.018480000000000003).
json rounded(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return std::stod(buf);
}

std::string join_sets(const std::vector<std::string>& sets) {
  std::string out;
  for (const auto& x : sets) out += (out.empty() ? "" : " ") + x;
  return out;
}

std::string set_item(const std::string& path, const json& value) {
  return path + "=" + value.dump();
}

// Loads the base scene with the given --sets; an InputError becomes one naming the study's JSON path.
LoadedScene load_variant(const Study& s, const std::vector<std::string>& sets, const std::string& path) {
  try {
    return load_scene(s.scene, sets);
  } catch (const InputError& e) {
    fail(s, path, e.what());
  }
}

std::vector<std::string> sets_of(const Parameter& p, const json& value) {
  std::vector<std::string> out;
  const std::vector<json> cells = cells_of(p, value);
  for (std::size_t k = 0; k < p.paths.size(); ++k) out.push_back(set_item(p.paths[k], cells[k]));
  return out;
}

// { "paths": [A, B], "labels": [...], "values": [[a0, b0], [a1, b1], ...] }: A and B change together.
Parameter zipped_parameter(const Study& s, const json& p, const std::string& where, const LoadedScene& base) {
  check_keys(s, p, where, {"paths", "labels", "values"});
  Parameter par;
  par.zipped = true;
  if (!p["paths"].is_array() || p["paths"].empty())
    fail(s, where + ".paths", "expected a list of --set paths");
  for (std::size_t k = 0; k < p["paths"].size(); ++k) {
    if (!p["paths"][k].is_string() || p["paths"][k].get<std::string>().empty())
      fail(s, where + ".paths[" + std::to_string(k) + "]", "expected a --set path");
    par.paths.push_back(p["paths"][k].get<std::string>());
  }
  par.labels = par.paths;
  if (p.contains("labels")) {
    if (!p["labels"].is_array() || p["labels"].size() != par.paths.size())
      fail(s, where + ".labels", "expected one label per path");
    for (std::size_t k = 0; k < par.paths.size(); ++k) {
      if (!p["labels"][k].is_string())
        fail(s, where + ".labels[" + std::to_string(k) + "]", "expected a string");
      par.labels[k] = p["labels"][k].get<std::string>();
    }
  }
  par.path = par.paths[0];
  par.label = par.labels[0];
  if (!p.contains("values") || !p["values"].is_array())
    fail(s, where + ".values", "expected a list of value lists, one entry per path");
  if (p["values"].empty()) fail(s, where + ".values", "empty sweep: no values");
  for (std::size_t k = 0; k < p["values"].size(); ++k) {
    const json& v = p["values"][k];
    const std::string at = where + ".values[" + std::to_string(k) + "]";
    if (!v.is_array() || v.size() != par.paths.size())
      fail(s, at, "expected a list of " + std::to_string(par.paths.size()) + " values, one per path");
    par.values.push_back(v);
    par.where.push_back(at);
  }
  if (const json* current = at_path(base.resolved, par.paths[0])) par.base = *current;
  for (std::size_t k = 0; k < par.paths.size(); ++k)
    if (!at_path(base.resolved, par.paths[k])) {
      std::vector<std::string> sets = s.fixed;
      sets.push_back(set_item(par.paths[k], par.values[0][k]));
      load_variant(s, sets, where + ".paths[" + std::to_string(k) + "]");
    }
  return par;
}

Study read_study(const fs::path& file) {
  Study s;
  s.file = file;
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot read the study file");
  const json j = json::parse(in, nullptr, false);
  if (j.is_discarded()) throw InputError(file.string() + ": not valid JSON");
  check_keys(s, j, "",
             {"name", "title", "description", "scene", "parameters", "fixed", "metrics", "run", "report"});
  s.name = j.value("name", file.stem().string());
  s.title = j.value("title", s.name);
  s.description = j.value("description", "");
  if (!j.contains("scene") || !j["scene"].is_string()) fail(s, "scene", "expected the base scene's path");
  fs::path scene = j["scene"].get<std::string>();
  if (scene.is_relative()) scene = file.parent_path() / scene;
  std::error_code ec;
  if (!fs::is_regular_file(scene, ec)) fail(s, "scene", "no such file '" + scene.string() + "'");
  s.scene = fs::absolute(scene).lexically_normal();

  if (j.contains("fixed")) {
    if (!j["fixed"].is_object()) fail(s, "fixed", "expected an object of --set paths and values");
    for (const auto& [k, v] : j["fixed"].items()) s.fixed.push_back(set_item(k, v));
  }
  if (j.contains("run")) {
    const json& r = j["run"];
    check_keys(s, r, "run", {"threads", "checkpoint_every", "render", "vtk"});
    if (r.contains("threads")) {
      if (!r["threads"].is_number_integer() || r["threads"].get<int>() < 1)
        fail(s, "run.threads", "expected an integer >= 1");
      s.threads = r["threads"].get<int>();
    }
    if (r.contains("checkpoint_every")) {
      s.checkpoint_every = number_at(s, r["checkpoint_every"], "run.checkpoint_every");
      if (!(s.checkpoint_every > 0)) fail(s, "run.checkpoint_every", "must be positive");
    }
    if (r.contains("render")) {
      if (!r["render"].is_boolean()) fail(s, "run.render", "expected true or false");
      s.render = r["render"].get<bool>();
    }
    if (r.contains("vtk")) {  // true: every output; N: every N-th output and the last
      const json& v = r["vtk"];
      if (v.is_boolean())
        s.vtk_every = v.get<bool>() ? 1 : 0;
      else if (v.is_number_integer() && v.get<long>() >= 1 && v.get<long>() <= 1000000)
        s.vtk_every = static_cast<int>(v.get<long>());
      else
        fail(s, "run.vtk", "expected true, false or a whole number of outputs >= 1, got " + v.dump());
    }
  }
  s.report = j.value("report", json::object());
  check_keys(s, s.report, "report", {"title", "wiggers", "figures", "plots"});

  // The base scene with the fixed --sets: every parameter path must exist in it (the loader names a bad one).
  const LoadedScene base = load_variant(s, s.fixed, "fixed");
  if (!base.scene.cycle)
    fail(s, "scene",
         "'" + s.scene.string() + "' has no cycle block: a study collects the cycles.csv metrics " +
             "(docs/scenes.md \"The cardiac cycle\")");

  if (!j.contains("parameters") || !j["parameters"].is_array() || j["parameters"].empty())
    fail(s, "parameters", "empty sweep: expected a list of at least one parameter");
  for (std::size_t i = 0; i < j["parameters"].size(); ++i) {
    const json& p = j["parameters"][i];
    const std::string where = "parameters[" + std::to_string(i) + "]";
    if (p.is_object() && p.contains("paths")) {  // several paths that change together (zipped)
      s.parameters.push_back(zipped_parameter(s, p, where, base));
      continue;
    }
    check_keys(s, p, where, {"path", "label", "values", "range", "scale"});
    Parameter par;
    if (!p.contains("path") || !p["path"].is_string() || p["path"].get<std::string>().empty())
      fail(s, where + ".path", "expected a --set path such as \"aortic_root.commissure_height\"");
    par.path = p["path"].get<std::string>();
    par.label = p.value("label", par.path);
    const json* current = at_path(base.resolved, par.path);
    if (current) par.base = *current;
    const int kinds = int(p.contains("values")) + int(p.contains("range")) + int(p.contains("scale"));
    if (kinds != 1) fail(s, where, "expected exactly one of values, range, scale");
    if (p.contains("values")) {
      if (!p["values"].is_array()) fail(s, where + ".values", "expected a list");
      for (const json& v : p["values"]) par.values.push_back(v);
    } else if (p.contains("range")) {
      const json& r = p["range"];
      check_keys(s, r, where + ".range", {"from", "to", "step"});
      for (const char* k : {"from", "to", "step"})
        if (!r.contains(k)) fail(s, where + ".range." + k, "missing");
      const double from = number_at(s, r["from"], where + ".range.from");
      const double to = number_at(s, r["to"], where + ".range.to");
      const double step = number_at(s, r["step"], where + ".range.step");
      if (!(step > 0)) fail(s, where + ".range.step", "must be positive");
      if (to < from) fail(s, where + ".range.to", "below range.from");
      const double n = std::floor((to - from) / step + 1e-9);
      if (n > 10000) fail(s, where + ".range", "more than 10000 values");
      const bool integers = r["from"].is_number_integer() && r["step"].is_number_integer();
      for (long k = 0; k <= static_cast<long>(n); ++k) {
        if (integers)
          par.values.push_back(r["from"].get<long>() + k * r["step"].get<long>());
        else
          par.values.push_back(rounded(from + k * step));
      }
    } else {
      if (!p["scale"].is_array()) fail(s, where + ".scale", "expected a list of factors");
      if (!current)
        fail(s, where + ".path", "the scene has no '" + par.path + "' (scale multiplies its value)");
      if (!current->is_number())
        fail(s, where + ".scale", "'" + par.path + "' is not a number in the scene (scale multiplies it)");
      for (std::size_t k = 0; k < p["scale"].size(); ++k)
        par.values.push_back(
            rounded(number_at(s, p["scale"][k], where + ".scale[" + std::to_string(k) + "]") *
                    current->get<double>()));
    }
    const std::string list = p.contains("values") ? ".values" : p.contains("range") ? ".range" : ".scale";
    if (par.values.empty()) fail(s, where + list, "empty sweep: no values");
    // A path the resolved scene lacks may still be an optional key the loader accepts: it decides.
    if (!current) {
      std::vector<std::string> sets = s.fixed;
      sets.push_back(set_item(par.path, par.values[0]));
      load_variant(s, sets, where + ".path");
    }
    // Where each value is written in the study file (for messages): values[k], scale[k], range (value v).
    for (std::size_t k = 0; k < par.values.size(); ++k)
      par.where.push_back(
          where + list +
          (p.contains("range") ? " (value " + par.values[k].dump() + ")" : "[" + std::to_string(k) + "]"));
    par.paths = {par.path};
    par.labels = {par.label};
    s.parameters.push_back(par);
  }

  // The metrics: cycles.csv columns (all of them by default).
  // The per-pair, per-commissure and per-cusp columns follow the scene's probes (app/cycle_report.cpp).
  const std::vector<std::string> columns = cycle_metric_names(base.scene);
  if (j.contains("metrics")) {
    if (!j["metrics"].is_array() || j["metrics"].empty())
      fail(s, "metrics", "expected a list of column names");
    for (std::size_t k = 0; k < j["metrics"].size(); ++k) {
      const json& m = j["metrics"][k];
      const std::string where = "metrics[" + std::to_string(k) + "]";
      if (!m.is_string()) fail(s, where, "expected a cycles.csv column name");
      if (std::find(columns.begin(), columns.end(), m.get<std::string>()) == columns.end())
        fail(s, where, "'" + m.get<std::string>() + "' is not a cycles.csv column (docs/valve-metrics.md)");
      s.metrics.push_back(m.get<std::string>());
    }
  } else {
    for (const auto& c : columns)
      if (c != "cycle") s.metrics.push_back(c);
  }
  return s;
}

struct Variant {
  std::string id;
  std::vector<json> values;        // the variants.csv cells: one per parameter path
  std::vector<std::size_t> index;  // the value's position in each parameter's list
  std::vector<std::string> sets;
};

std::vector<Variant> variants_of(const Study& s) {
  std::size_t total = 1;
  for (const auto& p : s.parameters) {
    total *= p.values.size();
    if (total > 10000) throw InputError(s.file.string() + ": parameters: more than 10000 variants");
  }
  std::vector<Variant> out;
  const int width = total > 1000 ? 4 : 3;
  for (std::size_t n = 0; n < total; ++n) {
    Variant v;
    char id[16];
    std::snprintf(id, sizeof id, "v%0*zu", width, n);
    v.id = id;
    v.sets = s.fixed;
    std::size_t rest = n, stride = total;
    for (const auto& p : s.parameters) {  // the first parameter varies slowest
      stride /= p.values.size();
      const json& value = p.values[rest / stride];
      v.index.push_back(rest / stride);
      rest %= stride;
      for (const json& cell : cells_of(p, value)) v.values.push_back(cell);
      for (const std::string& item : sets_of(p, value)) v.sets.push_back(item);
    }
    out.push_back(v);
  }
  return out;
}

std::string csv_cell(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string q = "\"";
  for (char c : text) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string py_str(const std::string& text) {
  return json(text).dump();
}  // a JSON string is a Python literal

// Writes a file only when its content changes (Snakemake's rerun triggers look at the Snakefile's code).
void write_if_changed(const fs::path& file, const std::string& text) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream old;
  old << in.rdbuf();
  if (in && old.str() == text) return;
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw InputError(file.string() + ": cannot write");
}

std::string self_executable() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("aortasph") : p.string();
}

// The python of the report rule: $AORTASPH_PYTHON, else Debian's /usr/bin/python3 (where python3-matplotlib
// installs; a python3 earlier on PATH may lack it), else python3 on PATH.
std::string report_python() {
  if (const char* env = std::getenv("AORTASPH_PYTHON"); env && *env) return env;
  return access("/usr/bin/python3", X_OK) == 0 ? "/usr/bin/python3" : "python3";
}

std::string snakefile(const Study& s, const std::vector<Variant>& variants, double checkpoint_every) {
  std::ostringstream f;
  f << "# Written by `aortasph study " << s.file.string() << "` (docs/studies.md); rewritten on each call.\n"
    << "# Run it from this folder's parent: snakemake -s DIR/Snakefile -d DIR -j N\n"
    << "import json\nimport os\nimport shlex\nimport subprocess\n\n"
    << "AORTASPH = " << py_str(self_executable()) << "\n"
    << "SCENE = " << py_str(s.scene.string()) << "\n"
    << "CHECKPOINT_EVERY = " << json(checkpoint_every).dump() << "\n"
    << "PYTHON = " << py_str(report_python()) << "\n"
    << "RENDER = " << (s.render ? "True" : "False") << "\n"
    << "VTK_EVERY = " << s.vtk_every << "  # 0: no VTK frames\n"
    << "# variant id -> its --set KEY=VALUE list (fixed sets first); variants.csv has the values\n"
    << "VARIANTS = {\n";
  for (const auto& v : variants) {
    f << "    " << py_str(v.id) << ": [";
    for (std::size_t k = 0; k < v.sets.size(); ++k) f << (k ? ", " : "") << py_str(v.sets[k]);
    f << "],\n";
  }
  f << "}\n"
    << R"SNK(
def read_json(path):
    try:
        with open(path) as fh:
            return json.load(fh)
    except (OSError, ValueError):
        return None

def variant_job(vid, threads, log):
    """Runs variant vid, or resumes it, or finds it done; raises unless it ends with status ok."""
    d = "variants/" + vid
    os.makedirs(d, exist_ok=True)
    want = VARIANTS[vid]
    had = read_json(d + "/sets.json")  # the --set list the folder's run was started with
    run = read_json(d + "/run.json") or {}
    status = run.get("status")
    if had == want and status == "ok" and os.path.isfile(d + "/cycles.csv"):
        return  # finished before (the marker was lost)
    if had == want and status in ("interrupted", "running") and os.path.isfile(d + "/checkpoint.bin"):
        cmd = [AORTASPH, "resume", d, "--threads", str(threads), "--quiet"]
    else:  # a fresh run (an earlier one with other settings is replaced, its checkpoint removed by run)
        for stale in ("run.json", "cycles.csv"):  # an earlier run's results must not pass for this one's
            if os.path.exists(d + "/" + stale):
                os.remove(d + "/" + stale)
        with open(d + "/sets.json", "w") as fh:
            json.dump(want, fh)
        cmd = [AORTASPH, "run", SCENE] + [a for x in want for a in ("--set", x)]
        cmd += ["--out", d, "--threads", str(threads), "--checkpoint-every", str(CHECKPOINT_EVERY), "--quiet"]
        if not RENDER:
            cmd.append("--no-render")
        if VTK_EVERY > 0:
            cmd += ["--vtk-every", str(VTK_EVERY)]
    with open(log, "w") as out:  # the run's output goes to the variant's log
        rc = subprocess.run(cmd, stdout=out, stderr=subprocess.STDOUT, check=False).returncode
    run = read_json(d + "/run.json") or {}
    if rc != 0 or run.get("status") != "ok" or not os.path.isfile(d + "/cycles.csv"):
        raise RuntimeError(vid + ": the run exited " + str(rc) + " with status " + str(run.get("status")) +
                           " (see " + log + ")")

rule all:
    input: "metrics.csv", "report.html"

rule variant:
    output: "variants/{id}/complete"
    log: "variants/{id}/log.txt"
    threads: )SNK"
    << s.threads << R"SNK(
    params: sets=lambda wildcards: VARIANTS[wildcards.id]
    run:
        variant_job(wildcards.id, threads, log[0])
        with open(output[0], "w") as fh:
            fh.write("ok\n")

rule report:
    input: expand("variants/{id}/complete", id=list(VARIANTS))
    output: "metrics.csv", "report.html"
    params: python=shlex.quote(PYTHON)
    shell: "{params.python} study_report.py ."
)SNK";
  return f.str();
}

std::string cluster_hint(const fs::path& snake, const fs::path& dir, const Study& s) {
  std::ostringstream o;
  o << "on a Slurm cluster (Snakemake 7.21's --slurm executor; the same files, skipping finished variants):\n"
    << "  snakemake -s " << snake.string() << " -d " << dir.string()
    << " --slurm --jobs 100 --rerun-incomplete --default-resources slurm_account=ACCOUNT "
       "slurm_partition=PARTITION runtime=240 mem_mb=4000 --set-threads variant="
    << s.threads << "\n"
    << "or through sbatch directly:\n"
    << "  snakemake -s " << snake.string() << " -d " << dir.string()
    << " --jobs 100 --rerun-incomplete --cluster \"sbatch --cpus-per-task={threads} --time=04:00:00\"\n";
  return o.str();
}

// While snakemake runs: Ctrl-C (SIGINT to the terminal's process group) reaches snakemake and the runs
// themselves, which stop cleanly (a checkpoint each); this process waits for that instead of dying first. A
// SIGTERM sent to this process alone is passed on to snakemake.
volatile sig_atomic_t g_child = 0;
volatile sig_atomic_t g_interrupted = 0;
void on_signal(int sig) {
  g_interrupted = 1;
  if (sig == SIGTERM && g_child > 0) ::kill(static_cast<pid_t>(g_child), SIGTERM);
}

int spawn_wait(const std::vector<std::string>& argv) {
  std::vector<char*> cargs;
  for (const auto& a : argv) cargs.push_back(const_cast<char*>(a.c_str()));
  cargs.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, cargs[0], nullptr, nullptr, cargs.data(), environ) != 0) return 127;
  g_child = pid;
  struct sigaction sa = {}, old_int = {}, old_term = {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
  }
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  g_child = 0;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

}  // namespace

int cmd_study(const std::vector<std::string>& args) {
  fs::path file;
  std::optional<fs::path> out;
  int jobs = 1;
  bool dry_run = false, hint_only = false;
  for (std::size_t k = 0; k < args.size(); ++k) {
    const std::string& a = args[k];
    const bool has_value = k + 1 < args.size();
    if (a == "--out" && has_value) {
      out = args[++k];
    } else if ((a == "-j" || a == "--jobs") && has_value) {
      char* end = nullptr;
      const long n = std::strtol(args[k + 1].c_str(), &end, 10);
      if (*end != '\0' || n < 1) throw InputError(a + ": expected a positive integer, got " + args[k + 1]);
      jobs = static_cast<int>(n);
      ++k;
    } else if (a == "--dry-run" || a == "-n") {
      dry_run = true;
    } else if (a == "--cluster-hint") {
      hint_only = true;
    } else if (!a.empty() && a[0] != '-' && file.empty()) {
      file = a;
    } else {
      throw InputError(a + ": unknown option for study\n" + kStudyUsage);
    }
  }
  if (file.empty()) throw InputError(std::string("study: missing the study file\n") + kStudyUsage);

  const Study s = read_study(file);
  const std::vector<Variant> variants = variants_of(s);
  // Each variant loaded with all its sets (the combination may be what the loader refuses).
  double checkpoint_every = s.checkpoint_every;
  for (const auto& v : variants) {
    try {
      const LoadedScene l = load_scene(s.scene, v.sets);
      if (checkpoint_every <= 0) checkpoint_every = std::max(l.scene.t_end / 10.0, 1e-6);
      // As `aortasph check` does: the World is built (geometry, open-boundary buffers inside the domain) and
      // the probes resolved, so that a variant the run would refuse is refused here, before any run starts.
      try {
        const World world(l.scene);
        check_cycle_columns(l.scene, ProbeSet(l.scene, world).columns());
      } catch (const SetupError& e) {
        fail(s, "parameters (variant " + v.id + ": " + join_sets(v.sets) + ")", e.what());
      }
    } catch (const InputError& e) {
      if (std::string(e.what()).rfind(s.file.string() + ": ", 0) == 0) throw;
      // Name the value at fault when one refuses alone (with the fixed sets), else the combination.
      for (std::size_t k = 0; k < s.parameters.size(); ++k) {
        std::vector<std::string> sets = s.fixed;
        const Parameter& p = s.parameters[k];
        for (const std::string& item : sets_of(p, p.values[v.index[k]])) sets.push_back(item);
        load_variant(s, sets, p.where[v.index[k]]);
      }
      fail(s, "parameters (variant " + v.id + ": " + join_sets(v.sets) + ")", e.what());
    }
  }

  const fs::path dir = out ? *out : fs::path("out") / "studies" / s.name;
  if (fs::absolute(dir).lexically_normal().string().find_first_of(" \t\n") != std::string::npos)
    throw InputError("--out " + dir.string() + ": the study folder's path (" +
                     fs::absolute(dir).lexically_normal().string() +
                     ") has a space: Snakemake 7 cannot run jobs there (it changes into it unquoted)");
  std::error_code ec;
  fs::create_directories(dir / "variants", ec);
  if (ec) throw InputError(dir.string() + ": cannot create the study folder: " + ec.message());

  std::ostringstream table;
  table << "id";
  for (const auto& p : s.parameters)
    for (const auto& label : p.labels) table << "," << csv_cell(label);
  table << "\n";
  for (const auto& v : variants) {
    table << v.id;
    for (const auto& value : v.values)
      table << "," << csv_cell(value.is_string() ? value.get<std::string>() : value.dump());
    table << "\n";
  }
  write_if_changed(dir / "variants.csv", table.str());

  json info;
  info["name"] = s.name;
  info["title"] = s.report.value("title", s.title);
  info["description"] = s.description;
  info["study_file"] = fs::absolute(s.file).lexically_normal().string();
  info["scene"] = s.scene.string();
  info["fixed"] = s.fixed;
  info["metrics"] = s.metrics;
  info["report"] = s.report;
  info["parameters"] = json::array();
  for (const auto& p : s.parameters)
    info["parameters"].push_back(
        {{"paths", p.paths}, {"labels", p.labels}, {"values", p.values}, {"base", p.base}});
  info["variants"] = json::array();
  for (const auto& v : variants) info["variants"].push_back({{"id", v.id}, {"sets", v.sets}});
  write_if_changed(dir / "study.json", info.dump(2) + "\n");
  write_if_changed(dir / "study_report.py", std::string(scripts::study_report_py));
  const fs::path snake = dir / "Snakefile";
  write_if_changed(snake, snakefile(s, variants, checkpoint_every));

  std::printf("aortasph study: %s: %zu variants (%s), workflow in %s\n", s.name.c_str(), variants.size(),
              (dir / "variants.csv").string().c_str(), snake.string().c_str());
  const std::string hint = cluster_hint(snake, dir, s);
  if (hint_only) {
    std::fputs(hint.c_str(), stdout);
    return 0;
  }
  std::fflush(stdout);
  std::vector<std::string> cmd{"snakemake",   "-s", snake.string(),       "-d",
                               dir.string(),  "-j", std::to_string(jobs), "--rerun-incomplete",
                               "--keep-going"};
  if (dry_run) cmd.push_back("-n");
  const int rc = spawn_wait(cmd);
  if (rc == 127) {
    std::fprintf(stderr,
                 "aortasph study: error: snakemake not found (Debian: apt-get install snakemake; "
                 "scripts/install-deps.sh)\n");
    return 2;
  }
  if (g_interrupted) {
    std::fprintf(stderr,
                 "aortasph study: interrupted; the same command finishes the missing variants (an unfinished "
                 "run resumes from its checkpoint)\n");
    return 130;
  }
  if (rc != 0) {
    std::fprintf(stderr,
                 "aortasph study: snakemake failed (exit %d); the logs are in %s/variants/*/log.txt\n", rc,
                 dir.string().c_str());
    return 1;
  }
  if (!dry_run)
    std::printf("aortasph study: %s and %s\n", (dir / "metrics.csv").string().c_str(),
                (dir / "report.html").string().c_str());
  std::fputs(hint.c_str(), stdout);
  return 0;
}

}  // namespace aortasph
