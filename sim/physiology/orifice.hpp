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

// The open area of orifice_area split into regions (probe `gap_area`, docs/valve-metrics.md): the open cells
// (the same raster as orifice_area) within central_radius of the disc's centre are `central`; every other
// open cell belongs to the commissure whose direction in the disc's plane (from the centre, projected) is
// nearest its own by angle: commissural[k]. total = central + sum commissural = orifice_area. Without
// commissures every open cell is central.
struct OrificeRegions {
  double total = 0.0, central = 0.0;
  std::vector<double> commissural;  // per commissure [m^2]
};
OrificeRegions orifice_regions(const std::vector<Vec3>& points, double spacing, const Vec3& center,
                               const Vec3& normal, double radius, double central_radius,
                               const std::vector<Vec3>& commissures);

// Cover radius of one particle, in particle spacings (see orifice_area).
constexpr double kOrificeCoverRadius = 0.75;

}  // namespace aortasph
