// The subcommands of the aortasph program (SPEC.md section 1). Each returns the process exit code.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/checkpoint.hpp"
#include "scene_loader.hpp"

namespace aortasph {

struct RunOptions {
  std::filesystem::path scene;
  std::optional<std::filesystem::path> out;  // default out/<scene name>/
  int threads = 0;                           // 0: OpenMP's default
  std::optional<double> end_time;
  std::vector<std::string> sets;  // --set KEY=VALUE
  bool no_render = false;
  bool vtk = false;
  int vtk_every = 1;  // --vtk-every N: a VTK frame every N-th output (and the last); implies --vtk
  bool quiet = false;
  std::optional<double> checkpoint_every;  // --checkpoint-every T: simulated seconds between checkpoints
};

// aortasph resume DIR [--threads N] [--quiet]
struct ResumeOptions {
  std::filesystem::path dir;
  int threads = 0;
  bool quiet = false;
  std::optional<double> end_time;  // --end-time: run on to a new end (extends a finished run)
};

int cmd_run(const RunOptions& options);
int cmd_resume(const ResumeOptions& options);
// resume: the scene as this program resolves it (now), less the keys the recorded resolution lacks (keys
// added since, at defaults that keep the older behaviour), for comparing with what the checkpoint recorded.
nlohmann::json pruned_to(const nlohmann::json& now, const nlohmann::json& recorded);
// A run folder's checkpoint (DIR/checkpoint.bin, as `resume` reads it): the scene it was written with,
// resolved again and refused where it no longer resolves to the recorded values, then `sets` (--set
// KEY=VALUE) applied on top; and its state, for World::load_state. Throws InputError naming a missing or
// damaged file.
struct CheckpointScene {
  LoadedScene loaded;
  StateReader state;
};
CheckpointScene load_checkpoint(const std::filesystem::path& dir, const std::vector<std::string>& sets);
int cmd_check(const std::filesystem::path& scene, const std::vector<std::string>& sets);
// aortasph bench [--threads N] [--quick] [--render] [--json FILE] [--case NAME | --scene FILE | --from DIR]
//                [--set KEY=VALUE]... [--steps N]
struct BenchOptions {
  int threads = 0;
  bool quick = false;
  bool render = false;
  std::filesystem::path json = "bench.json";
  std::string case_name = "dam_break";         // standard cases: dam_break, aortic_root
  std::optional<std::filesystem::path> scene;  // --scene FILE: any scene instead of a standard case
  std::optional<std::filesystem::path> from;   // --from DIR: a run folder's checkpoint (mid-run state)
  std::vector<std::string> sets;               // --set KEY=VALUE on --scene, --from or --case aortic_root
  int steps = 0;                               // 0: 60 (40 with --quick)
};

int cmd_bench(const BenchOptions& options);

// aortasph study STUDY.json [--out DIR] [-j N] [--dry-run] [--cluster-hint] (docs/studies.md)
int cmd_study(const std::vector<std::string>& args);

// Parses the arguments after the subcommand word (throws InputError on bad arguments).
RunOptions parse_run_options(const std::vector<std::string>& args);
ResumeOptions parse_resume_options(const std::vector<std::string>& args);

}  // namespace aortasph
