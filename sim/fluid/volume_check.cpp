#include "fluid/volume_check.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include "core/neighbors.hpp"
#include "core/parallel.hpp"

namespace aortasph {

VolumeCheck fluid_volume_check(const Particles& P, const CubicSpline& kernel, const Periodic& periodic) {
  NeighborSearch nb;
  nb.set_periodic(periodic);
  nb.build(P.x, kernel.support);
  // Per particle (ratio, 1) if counted, else (0, 0); summed in parallel_reduce's fixed blocks.
  const auto [sum, count] = parallel_reduce(
      P.size(), std::pair<double, double>{0.0, 0.0},
      [&](std::size_t i) -> std::pair<double, double> {
        if (P.kind[i] != Kind::Fluid) return {0.0, 0.0};
        double rho = P.m[i] * kernel.W(0.0);
        for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
          const uint32_t j = nb.index()[k];
          if (!fluid_like(P.kind[j])) return {0.0, 0.0};
          rho += P.m[j] * kernel.W(periodic.image(P.x[i] - P.x[j]).norm());
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
