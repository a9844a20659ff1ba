// Probes: measured values written as one row of probes.csv per output time (SPEC.md section 3).
#pragma once

#include <string>
#include <vector>

#include "world.hpp"

namespace aortasph {

// The nearest-rank q-th percentile of v (the ceil(q/100 n)-th smallest value; 0 for no value).
double percentile_nearest_rank(std::vector<double> v, double q);

// The columns of a coaptation probe over `leaflets` bodies, without the probe's name: height_A_B and
// length_A_B per pair A < B of list positions, then central_height and effective_height.
std::vector<std::string> coaptation_columns(std::size_t leaflets);

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
  std::vector<std::string> columns_;
};

}  // namespace aortasph
