// Figure sheets: frames in a grid with panel labels (a), (b), ... and, when colouring by a field, a colour
// bar with the field's name, unit and numeric range. White sheet, black text; width and height even.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "image.hpp"

namespace aortasph {

struct ColorBar {
  std::string colormap;  // a Colormap name
  double lo = 0.0, hi = 1.0;
  std::string name;  // e.g. "speed"
  std::string unit;  // e.g. "m/s" (may be empty)
};

struct FigurePanel {
  Image image;          // all panels of a sheet have the same size
  std::string caption;  // after the label, e.g. "t = 0.01 s" (may be empty)
};

// Throws RenderError for no panels, columns < 1 or panels of different sizes.
Image compose_figure(const std::vector<FigurePanel>& panels, int columns, const std::optional<ColorBar>& bar);

// "(a)", "(b)", ..., "(z)", "(aa)", ...
std::string panel_label(int index);

}  // namespace aortasph
