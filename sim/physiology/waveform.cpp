#include "physiology/waveform.hpp"

#include <cmath>

namespace aortasph {

double Waveform::at(double time) const {
  if (t.empty()) return (value.empty() ? 0.0 : value[0]) + offset;
  double s = time;
  if (period > 0.0) {
    // The phase in [t.front(), t.front() + period).
    s = t.front() + (time - t.front()) - period * std::floor((time - t.front()) / period);
    if (s > t.back()) {
      // Between the last point and the first point of the next cycle.
      const double span = t.front() + period - t.back();
      const double w = span > 0.0 ? (s - t.back()) / span : 0.0;
      return value.back() + w * (value.front() - value.back()) + offset;
    }
  }
  if (s <= t.front()) return value.front() + offset;
  if (s >= t.back()) return value.back() + offset;
  std::size_t k = 1;
  while (t[k] < s) ++k;
  const double w = (s - t[k - 1]) / (t[k] - t[k - 1]);
  return value[k - 1] + w * (value[k] - value[k - 1]) + offset;
}

}  // namespace aortasph
