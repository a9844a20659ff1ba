// aortasph: the command line (SPEC.md section 1). Dispatches to the subcommands and maps errors to exit
// codes: 2 bad input, 3 unstable simulation, 1 images differ (compare), 130 interrupted.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "commands.hpp"
#include "core/sim_errors.hpp"
#include "cycle_report.hpp"
#include "errors.hpp"
#include "render_commands.hpp"

namespace {

const char* kUsage =
    "aortasph " AORTASPH_VERSION
    " - fluid, elastic and rigid bodies in one SPH framework, rendered offscreen\n"
    "\n"
    "usage:\n"
    "  aortasph run SCENE.json [--out DIR] [--threads N] [--end-time T] [--set KEY=VALUE]...\n"
    "                          [--no-render] [--vtk] [--vtk-every N] [--quiet] [--checkpoint-every T]\n"
    "  aortasph resume DIR [--threads N] [--quiet] [--end-time T]\n"
    "                                                   continue an interrupted run from DIR/checkpoint.bin\n"
    "                                                   (--end-time: on to a new end, e.g. more cycles)\n"
    "  aortasph check SCENE.json [--set KEY=VALUE]...   validate and print bodies, counts, h, dt, cost\n"
    "  aortasph compare A B [--diff DIFF.png] [--tolerance T]\n"
    "  aortasph movie DIR [--fps N]\n"
    "  aortasph plot DIR [--remeasure]                  Wiggers plot (DIR/figures/wiggers.png) of a run\n"
    "                                                   with a cycle block (needs python3-matplotlib);\n"
    "                                                   --remeasure: cycles.csv measured again first\n"
    "  aortasph study STUDY.json [--out DIR] [-j N] [--dry-run] [--cluster-hint]\n"
    "                                                   a parameter sweep on Snakemake (docs/studies.md)\n"
    "  aortasph bench [--threads N] [--quick] [--render] [--json FILE] [--steps N]\n"
    "                [--case dam_break|aortic_root | --scene SCENE.json | --from RUN_DIR]\n"
    "                [--set KEY=VALUE]...               --from: a run folder's checkpoint.bin as the start\n"
    "  aortasph --help | --version\n"
    "\n"
    "exit codes: 0 ok, 1 compare: images differ, 2 bad input, 3 unstable simulation, 130 interrupted\n"
    "(SIGINT/SIGTERM: the step in hand is finished, a checkpoint written, every file flushed)\n";

int dispatch(const std::vector<std::string>& args) {
  using namespace aortasph;
  if (args.empty()) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  const std::string& cmd = args[0];
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (cmd == "--help" || cmd == "-h" || cmd == "help") {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (cmd == "--version") {
    std::printf("aortasph %s\n", AORTASPH_VERSION);
    return 0;
  }
  if (cmd == "run") return cmd_run(parse_run_options(rest));
  if (cmd == "resume") return cmd_resume(parse_resume_options(rest));
  if (cmd == "check") {
    std::string scene;
    std::vector<std::string> sets;
    for (std::size_t k = 0; k < rest.size(); ++k) {
      if (rest[k] == "--set") {
        if (k + 1 >= rest.size()) throw InputError("--set: missing value");
        sets.push_back(rest[++k]);
      } else if (!rest[k].empty() && rest[k][0] == '-') {
        throw InputError(rest[k] + ": unknown option for check");
      } else if (scene.empty()) {
        scene = rest[k];
      } else {
        throw InputError(rest[k] + ": unexpected argument");
      }
    }
    if (scene.empty()) throw InputError("check: missing the scene file");
    return cmd_check(scene, sets);
  }
  if (cmd == "bench") {
    BenchOptions o;
    bool case_given = false;
    auto positive = [&](std::size_t k) {
      int v = 0;
      try {
        v = std::stoi(rest[k]);
      } catch (const std::exception&) {
        v = 0;
      }
      if (v < 1) throw InputError(rest[k - 1] + ": expected a positive integer, got " + rest[k]);
      return v;
    };
    for (std::size_t k = 0; k < rest.size(); ++k) {
      const bool has_value = k + 1 < rest.size();
      if (rest[k] == "--quick") {
        o.quick = true;
      } else if (rest[k] == "--render") {
        o.render = true;
      } else if (rest[k] == "--threads" && has_value) {
        o.threads = positive(++k);
      } else if (rest[k] == "--steps" && has_value) {
        o.steps = positive(++k);
      } else if (rest[k] == "--json" && has_value) {
        o.json = rest[++k];
      } else if (rest[k] == "--case" && has_value) {
        o.case_name = rest[++k];
        case_given = true;
      } else if (rest[k] == "--scene" && has_value) {
        o.scene = rest[++k];
      } else if (rest[k] == "--from" && has_value) {
        o.from = rest[++k];
      } else if (rest[k] == "--set" && has_value) {
        o.sets.push_back(rest[++k]);
      } else {
        throw InputError(rest[k] + ": unknown option for bench");
      }
    }
    if (o.scene && case_given) throw InputError("bench: --scene and --case exclude each other");
    if (o.from && (o.scene || case_given || o.quick))
      throw InputError("bench: --from excludes --scene, --case and --quick");
    return cmd_bench(o);
  }
  if (cmd == "compare") return cmd_compare(rest);
  if (cmd == "movie") return cmd_movie(rest);
  if (cmd == "plot") return cmd_plot(rest);
  if (cmd == "study") return cmd_study(rest);
  throw InputError(cmd + ": unknown command (see aortasph --help)");
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  try {
    return dispatch(args);
  } catch (const aortasph::InputError& e) {
    std::fprintf(stderr, "aortasph: error: %s\n", e.what());
    return 2;
  } catch (const aortasph::SetupError& e) {
    std::fprintf(stderr, "aortasph: error: %s\n", e.what());
    return 2;
  } catch (const aortasph::InstabilityError& e) {
    std::fprintf(stderr, "aortasph: %s\n", e.what());
    return 3;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "aortasph: error: out of memory (reduce the resolution or the domain)\n");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "aortasph: internal error: %s\n", e.what());
    return 1;
  }
}
