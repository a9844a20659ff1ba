#include "waveform_csv.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include "errors.hpp"

namespace aortasph {

namespace {

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  const auto b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

// The cell as a finite number, or false.
bool number(const std::string& cell, double& out) {
  const std::string c = trim(cell);
  if (c.empty()) return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtod(c.c_str(), &end);
  return end == c.c_str() + c.size() && errno == 0 && std::isfinite(out);
}

}  // namespace

Waveform read_waveform_csv(const std::filesystem::path& file, const std::string& shown, double scale) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(shown + ": no such waveform file");
  std::ifstream f(file);
  if (!f) throw InputError(shown + ": cannot read");
  Waveform w;
  std::string line;
  int lineno = 0;
  bool header_allowed = true;
  while (std::getline(f, line)) {
    ++lineno;
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    const std::string at = shown + ":" + std::to_string(lineno) + ": ";
    std::vector<std::string> cells;
    std::stringstream ss(t);
    for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
    if (!t.empty() && t.back() == ',') cells.push_back("");
    double time = 0.0, value = 0.0;
    const bool ok = cells.size() == 2 && number(cells[0], time) && number(cells[1], value);
    if (!ok) {
      // A header line (no cell a number) before the first sample.
      bool any_number = false;
      for (const std::string& c : cells) {
        double x = 0.0;
        any_number = any_number || number(c, x);
      }
      if (header_allowed && !any_number && cells.size() == 2) {
        header_allowed = false;
        continue;
      }
      if (cells.size() != 2)
        throw InputError(at + "expected 2 cells (time, value), got " + std::to_string(cells.size()));
      throw InputError(at + "expected two finite numbers (time, value), got '" + t + "'");
    }
    header_allowed = false;
    if (!w.t.empty() && !(time > w.t.back())) {
      std::ostringstream msg;
      msg << at << "times must increase strictly (" << time << " after " << w.t.back() << ")";
      throw InputError(msg.str());
    }
    w.t.push_back(time);
    w.value.push_back(value * scale);
  }
  if (f.bad()) throw InputError(shown + ": cannot read");
  if (w.t.empty()) throw InputError(shown + ": no samples (expected lines 'time, value')");
  return w;
}

}  // namespace aortasph
