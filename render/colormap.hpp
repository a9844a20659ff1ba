// Colormaps for field colouring: "viridis" (perceptually uniform, sequential) and "coolwarm" (Moreland's
// diverging map, for signed fields such as pressure). Piecewise linear between published anchor colours.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace aortasph {

class Colormap {
 public:
  // Throws RenderError for an unknown name, listing the known ones.
  explicit Colormap(const std::string& name);
  static std::vector<std::string> names();

  // t in [0, 1] (clamped; NaN maps to 0).
  std::array<uint8_t, 3> operator()(double t) const;
  const std::string& name() const { return name_; }

 private:
  std::string name_;
  std::vector<std::array<uint8_t, 3>> anchors_;  // evenly spaced over [0, 1]
};

}  // namespace aortasph
