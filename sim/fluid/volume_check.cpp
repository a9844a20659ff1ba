#include "fluid/volume_check.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include "core/parallel.hpp"

namespace aortasph {

VolumeCheck fluid_volume_check(const Particles& P, const CubicSpline& kernel, const Periodic& periodic,
                               const NeighborSearch* lists) {
  NeighborSearch own;
  if (!lists) {
    own.set_periodic(periodic);
    own.build(P.x, kernel.support);
  }
  const NeighborSearch& nb = lists ? *lists : own;
  const double support2 = kernel.support * kernel.support;
  // Per particle (ratio, 1) if counted, else (0, 0); summed in parallel_reduce's fixed blocks.
  const auto [sum, count] = parallel_reduce(
      P.size(), std::pair<double, double>{0.0, 0.0},
      [&](std::size_t i) -> std::pair<double, double> {
        if (P.kind[i] != Kind::Fluid) return {0.0, 0.0};
        double rho = P.m[i] * kernel.W(0.0);
        for (uint32_t k = nb.begin(i); k < nb.full_end(i); ++k) {  // masked pairs too: all of the support
          const uint32_t j = nb.index()[k];
          const double r2 = periodic.image(P.x[i] - P.x[j]).squaredNorm();
          if (r2 >= support2) continue;
          if (!fluid_like(P.kind[j])) return {0.0, 0.0};
          rho += P.m[j] * kernel.W(std::sqrt(r2));
        }
        return {rho / P.rho[i], 1.0};
      },
      [](std::pair<double, double> a, std::pair<double, double> b) {
        return std::pair{a.first + b.first, a.second + b.second};
      });
  VolumeCheck c;
  c.particles = static_cast<std::size_t>(count);
  c.mean = count > 0 ? sum / count : std::numeric_limits<double>::quiet_NaN();
  return c;
}

}  // namespace aortasph
