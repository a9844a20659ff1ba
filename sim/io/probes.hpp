// Probes: measured values written as one row of probes.csv per output time (SPEC.md section 3).
#pragma once

#include <string>
#include <vector>

#include "world.hpp"

namespace aortasph {

// The nearest-rank q-th percentile of v (the ceil(q/100 n)-th smallest value; 0 for no value).
double percentile_nearest_rank(std::vector<double> v, double q);

// The columns of a coaptation probe over `leaflets` bodies, without the probe's name: height_A_B and
// length_A_B per pair A < B of list positions, then central_height and effective_height; per_leaflet: then
// effective_height_K per leaflet K (its own highest particle within central_radius of the axis).
std::vector<std::string> coaptation_columns(std::size_t leaflets, bool per_leaflet = false);

// The per-body columns of a per_body stress probe for list position b, without the probe's name: b.max,
// b.p95 [Pa], b.max_height [m] (the peak particle's height above the annulus plane at t = 0), b.max_s (its
// fraction of the cusp's angular span, 0 and 1 at the commissures).
std::vector<std::string> stress_body_columns(std::size_t b);

class ProbeSet {
 public:
  // Resolves what needs the initial state (the particle a `point` probe follows). Throws SetupError for a
  // probe the world cannot measure.
  ProbeSet(const Scene& scene, const World& world);

  // Column names, without the leading `time`.
  const std::vector<std::string>& columns() const { return columns_; }
  // One value per column; NaN where a probe has nothing to measure (an extent over no particle).
  std::vector<double> measure(const World& world) const;

 private:
  std::vector<Probe> probes_;
  std::vector<uint32_t> tracked_id_;  // per probe: particle id followed by a `point` probe
  // Per probe: a per_body stress probe's cusp frames (per listed body: the reference angle of its centroid
  // about the axis and the angular span of its particles about it, at t = 0).
  struct CuspFrame {
    double theta_c = 0.0, phi_min = 0.0, phi_max = 0.0;
  };
  std::vector<std::vector<CuspFrame>> cusp_frames_;
  // Per probe: a wall_distance probe's leaflet particles (ids, sorted) farther than `exclude` from the walls
  // at t = 0.
  std::vector<std::vector<uint32_t>> eligible_;
  std::vector<std::string> columns_;
};

}  // namespace aortasph
