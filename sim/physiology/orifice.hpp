// Projected open area of a valve (SPEC.md section 3, probe `orifice_area`; issue 6).
#pragma once

#include <vector>

#include "scene.hpp"

namespace aortasph {

// Open area [m^2] of the disc (center, unit normal, radius) left uncovered by the projection of `points`
// (the valve's particles) along the normal. The disc is rasterised on a square grid of cells spacing / 8
// wide (coarser, at most 2000 x 2000 cells, for a disc of more than 250 spacings across); a cell (by its
// centre) is covered when it lies within 0.75 spacing of a projected particle. The cover radius 0.75 dx is
// the smallest round number above dx / sqrt(2), the radius at which discs on a square lattice of pitch dx
// cover the plane without holes, so a closed sheet of particles about dx apart reads as closed, while a gap
// of more than 1.5 dx between particles reads as open. Points off the disc's plane count as projected; pass
// only the valve's particles.
double orifice_area(const std::vector<Vec3>& points, double spacing, const Vec3& center, const Vec3& normal,
                    double radius);

// Cover radius of one particle, in particle spacings (see orifice_area).
constexpr double kOrificeCoverRadius = 0.75;

}  // namespace aortasph
