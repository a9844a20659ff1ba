// The long Taylor-Green runs of scripts/validate_taylor_green.sh (hidden: not in CTest). The 2-D vortex at
// Re = U lambda / nu = 100 (U = 1 m/s, lambda = 1 m, nu = 0.01 m^2/s) in a periodic box lambda x lambda x
// 8 dx; prints KE / exp(-4 nu k^2 t) at every tenth of the decay time T, the closest pair over dx, the
// largest speed, and the cost. Parameters from the environment: N (lambda/dx, 20), C0 (10), PB (the
// transport velocity's background pressure, 2e5 = 2 rho0 c0^2; 0: off), JITTER (bodies[].jitter, 0.2 of
// dx; 0: the exact lattice), GAMMA (1), SUMM (density summation, 1), DELTA (delta-SPH, 0.1, with SUMM=0
// only), SHIFT (shifting A, 0), SR (h / dx, 1.3), KMAX (tenths of T, 10), NU (kinematic viscosity, 0.01:
// Re = 100; the decay time T = 1 / (4 nu k^2) follows it). The defaults are the set-up that meets issue
// 20's target at lambda/20 (docs/validation.md).
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "builders.hpp"
#include "core/parallel.hpp"

using namespace aortasph;
using namespace aortasph::test;

static double envd(const char* k, double d) {
  const char* v = std::getenv(k);
  return v ? std::atof(v) : d;
}

TEST_CASE("Taylor-Green vortex at Re = 100, long run (scripts/validate_taylor_green.sh)",
          "[.][taylor-green-validate]") {
  const int across = static_cast<int>(envd("N", 20));
  const double c0 = envd("C0", 10), pb = envd("PB", 2e5), gamma = envd("GAMMA", 1), nu = envd("NU", 0.01),
               U = 1, lambda = 1, delta = envd("DELTA", 0.1), shifting = envd("SHIFT", 0), sr = envd("SR", 0);
  const bool summ = envd("SUMM", 1) > 0;
  const double dx = lambda / across;
  TaylorGreen c;
  c.lambda = lambda;
  c.U = U;
  c.nu = nu;
  Scene s = c.scene(across, c0, 0.0, delta, shifting);
  if (sr > 0) s.smoothing_ratio = sr;
  Material& m = s.materials[0];
  m.eos_exponent = gamma;
  m.density_summation = summ;
  m.transport_velocity_pb = pb;
  s.bodies[0].jitter = envd("JITTER", 0.2);
  World w(s);
  auto ke = [&] { return kinetic_energy(w); };
  const double rate = 4 * nu * std::pow(2 * M_PI / lambda, 2), T = 1 / rate;
  const double e0 = ke();
  double worst = 0;
  auto t0 = std::chrono::steady_clock::now();
  const int kmax = static_cast<int>(envd("KMAX", 10));
  for (int k = 1; k <= kmax; ++k) {
    const double t = 0.1 * k * T;
    w.advance_to(t, [] { return true; });
    const double r = ke() / e0 / std::exp(-rate * t);
    worst = std::max(worst, std::abs(r - 1));
    const Particles& P = w.particles();
    const Periodic per(s.domain, s.periodic);
    double dmin = 1e9, vmax = 0;
    for (std::size_t i = 0; i < P.size(); ++i) {
      vmax = std::max(vmax, P.v[i].norm());
      for (std::size_t j = i + 1; j < P.size(); ++j) dmin = std::min(dmin, per.image(P.x[i] - P.x[j]).norm());
    }
    std::printf("t=%.3f KE/exact=%.4f dmin/dx=%.3f vmax=%.3f n=%zu\n", t, r, dmin / dx, vmax, P.size());
  }
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("N=%d worst=%.4f steps=%ld wall=%.2fs particle-steps/s=%.3g\n", across, worst, (long)w.steps(),
              sec, double(w.particles().size()) * w.steps() / sec);
}
