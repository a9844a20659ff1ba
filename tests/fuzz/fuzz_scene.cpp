// libFuzzer target over scene loading and validation (issue 7). Input: a scene file's text, optionally
// followed by a NUL byte and --set overrides, one per line. Bad input must end in InputError or SetupError
// (exit 2 in the program); any other exception, a crash or a sanitizer report is a bug. Scenes small enough
// (at most kMaxParticles by the resource estimate) are also built into a World and stepped twice, so that
// shape sampling, the overlap check and the first steps see the fuzzed values too.
//
// Build and run: scripts/fuzz.sh [SECONDS] (clang, -fsanitize=fuzzer,address,undefined). A crash found is
// fixed and its input added to tests/fuzz/corpus/ (replayed by every fuzz run).
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "core/sim_errors.hpp"
#include "errors.hpp"
#include "resources.hpp"
#include "scene_loader.hpp"
#include "world.hpp"

namespace {
constexpr double kMaxParticles = 2000;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  using namespace aortasph;
  const std::string input(reinterpret_cast<const char*>(data), size);
  const auto nul = input.find('\0');
  const std::string text = input.substr(0, nul);
  std::vector<std::string> sets;
  if (nul != std::string::npos) {
    std::istringstream rest(input.substr(nul + 1));
    for (std::string line; std::getline(rest, line);)
      if (!line.empty()) sets.push_back(line);
  }
  try {
    const LoadedScene loaded = load_scene_text(text, sets, "fuzz");
    if (estimate_particles(loaded.scene) <= kMaxParticles) {
      World world(loaded.scene);
      for (int k = 0; k < 2; ++k) world.step(std::min(world.stable_dt(), 1e-3));
    }
  } catch (const InputError&) {
  } catch (const SetupError&) {
  } catch (const InstabilityError&) {
  }
  return 0;
}
