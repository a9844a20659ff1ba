// A prescribed pressure (or any scalar) history for an open boundary: a constant, or a table of (t, value)
// pairs with strictly increasing times, interpolated linearly, optionally repeated with a period (a cardiac
// cycle), plus a constant offset. Plain values: the scene loader (app/) fills it from the scene's number,
// table or CSV file (app/waveform_csv.hpp) in SI units; sim/ only evaluates it.
#pragma once

#include <vector>

namespace aortasph {

struct Waveform {
  std::vector<double> t;      // empty for a constant [s]
  std::vector<double> value;  // one entry for a constant [Pa]
  // > 0: the table is one cycle, repeated with this period [s]; the table must span at most one period
  // (t.back() - t.front() <= period); between its last point and its first point one period later the value
  // is interpolated linearly (a table that does not close on itself is closed so). 0: not repeated, the
  // first / last value is held outside the table.
  double period = 0.0;
  double offset = 0.0;  // added to every value [Pa] (e.g. the fluid's background pressure)

  // The value at `time`.
  double at(double time) const;
  bool constant() const { return t.empty(); }
};

}  // namespace aortasph
