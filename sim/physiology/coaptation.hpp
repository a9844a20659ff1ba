// Coaptation of a closed valve's leaflets (SPEC.md section 3, probe `coaptation`; docs/valve-metrics.md).
#pragma once

#include <vector>

#include "scene.hpp"

namespace aortasph {

struct CoaptationStats {
  // Per leaflet pair (a < b in list order): the coaptation height [m], the median over the coaptation line's
  // radial bins of the axial extent of the pair's contact particles in the bin, and the line's length, the
  // radial extent of all its contact particles.
  std::vector<double> height, length;
  double central_height = 0.0, effective_height = 0.0;
  std::vector<double> effective_per_leaflet;  // per leaflet: its highest particle near the axis (NaN: none)
};

// points[i] belongs to leaflet leaf[i] (0 .. leaflets - 1). Two points of different leaflets closer than
// `distance` are in contact. Axial coordinate z along the unit `axis` from `point` (the annulus plane), r the
// distance from the axis. A coaptation line runs from the centre up to its commissure, so its contact
// particles span the free edge's drop in z as well as the band the two leaflets share: the height is taken
// per radial bin `bin` wide (the extent in z of the pair's contact particles whose r falls in the bin), and
// the median over the bins that hold contact particles is the line's height. central_height: the z extent of
// contact particles (any pair) within central_radius of the axis; effective_height: the largest z of any
// leaflet point within central_radius (NaN when none: an open valve). Independent of the points' order.
CoaptationStats coaptation_stats(const std::vector<Vec3>& points, const std::vector<int>& leaf, int leaflets,
                                 const Vec3& point, const Vec3& axis, double distance, double central_radius,
                                 double bin);

}  // namespace aortasph
