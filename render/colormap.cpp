#include "colormap.hpp"

#include <algorithm>
#include <cmath>

#include "render_error.hpp"

namespace aortasph {

namespace {

// Viridis at t = 0, 0.1, ..., 1 (the matplotlib map's published 11-step values).
const std::vector<std::array<uint8_t, 3>> kViridis = {
    {68, 1, 84},    {72, 36, 117},  {65, 68, 135},  {53, 95, 141},  {42, 120, 142}, {33, 145, 140},
    {34, 168, 132}, {68, 191, 112}, {122, 209, 81}, {189, 223, 38}, {253, 231, 37}};

// Moreland's "cool to warm" at t = 0, 1/8, ..., 1: blue through light grey to red.
const std::vector<std::array<uint8_t, 3>> kCoolwarm = {{59, 76, 192},   {98, 130, 234},  {141, 176, 254},
                                                       {184, 208, 249}, {221, 221, 221}, {245, 196, 173},
                                                       {244, 154, 123}, {222, 96, 77},   {180, 4, 38}};

}  // namespace

std::vector<std::string> Colormap::names() {
  return {"viridis", "coolwarm"};
}

Colormap::Colormap(const std::string& name) : name_(name) {
  if (name == "viridis")
    anchors_ = kViridis;
  else if (name == "coolwarm")
    anchors_ = kCoolwarm;
  else
    throw RenderError("render.colormap: unknown colormap \"" + name + "\" (known: viridis, coolwarm)");
}

std::array<uint8_t, 3> Colormap::operator()(double t) const {
  if (!(t > 0.0)) t = 0.0;  // also catches NaN
  if (t > 1.0) t = 1.0;
  const double x = t * static_cast<double>(anchors_.size() - 1);
  const size_t k = std::min(static_cast<size_t>(x), anchors_.size() - 2);
  const double f = x - static_cast<double>(k);
  std::array<uint8_t, 3> out;
  for (int c = 0; c < 3; ++c)
    out[c] = static_cast<uint8_t>(std::lround((1.0 - f) * anchors_[k][c] + f * anchors_[k + 1][c]));
  return out;
}

}  // namespace aortasph
