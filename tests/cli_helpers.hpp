// Helpers of the tests that run the aortasph binary: scratch folders, whole-file reads, a command's exit code
// and standard error.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace aortasph::test {

// An empty folder <tmp>/aortasph_test_<pid>/<name> (emptied when it exists).
inline std::filesystem::path scratch(const std::string& name) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("aortasph_test_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// The whole file, bytes as they are ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// Runs `aortasph ARGS`: its exit code (-1 when it did not exit), its stderr in err and, when out is given,
// its stdout there (else discarded).
inline int run_cli(const std::string& args, std::string& err, std::string* out = nullptr) {
  const auto tmp = std::filesystem::temp_directory_path();
  const auto e = tmp / ("aortasph_test_err_" + std::to_string(::getpid()));
  const auto o = tmp / ("aortasph_test_out_" + std::to_string(::getpid()));
  const std::string cmd = std::string(AORTASPH_BINARY) + " " + args + " > " +
                          (out ? o.string() : std::string("/dev/null")) + " 2> " + e.string();
  const int status = std::system(cmd.c_str());
  err = slurp(e);
  std::filesystem::remove(e);
  if (out) {
    *out = slurp(o);
    std::filesystem::remove(o);
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace aortasph::test
