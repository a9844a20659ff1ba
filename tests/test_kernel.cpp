// Kernel properties (paper eqs. 5-8) and the neighbour search against brute force.
#include <catch2/catch.hpp>
#include <random>

#include "core/kernel.hpp"
#include "core/neighbors.hpp"
#include "core/parallel.hpp"

using namespace aortasph;

namespace {

// Lattice of spacing dx around the origin, wide enough to cover the support.
std::vector<Vec3> lattice(double dx, int half, Vec3 shift = Vec3::Zero()) {
  std::vector<Vec3> pts;
  for (int i = -half; i <= half; ++i)
    for (int j = -half; j <= half; ++j)
      for (int k = -half; k <= half; ++k) pts.push_back(shift + dx * Vec3(i, j, k));
  return pts;
}

}  // namespace

// The lattice sum of eq. (5) at h = 1.3 dx is 0.997262 (computed independently with a 5-line Python sum): the
// issue's target |sum - 1| < 1e-3 is missed by the kernel itself, not by this code (the sum oscillates with
// h/dx: 1.2 -> 1.00081, 1.4 -> 0.99897, 2.0 -> 1.00008). So the test pins the exact value and checks < 1e-3
// where the kernel reaches it.
TEST_CASE("cubic spline sums to one on a lattice", "[kernel]") {
  const double dx = 0.01;
  auto lattice_sum = [&](double ratio, const Vec3& shift, Vec3* grad_out) {
    const CubicSpline K(ratio * dx);
    double sum = 0.0;
    Vec3 grad = Vec3::Zero();
    for (const Vec3& p : lattice(dx, 5)) {
      const Vec3 r = shift - p;
      sum += K.W(r.norm()) * dx * dx * dx;
      grad += K.gradW(r, r.norm()) * dx * dx * dx;
    }
    if (grad_out) *grad_out = grad * K.h;
    return sum;
  };
  Vec3 grad;
  CHECK(lattice_sum(1.3, Vec3::Zero(), &grad) == Approx(0.9972618283).epsilon(1e-9));
  CHECK(grad.norm() < 1e-12);  // symmetric lattice: the gradient sum vanishes
  CHECK(std::abs(lattice_sum(1.2, Vec3::Zero(), nullptr) - 1.0) < 1e-3);
  CHECK(std::abs(lattice_sum(2.0, Vec3::Zero(), nullptr) - 1.0) < 1e-4);
  // Off-lattice evaluation point at h = 1.3 dx: sum within 3e-3, gradient sum small against 1/h.
  const double shifted = lattice_sum(1.3, Vec3(0.3 * dx, 0.1 * dx, 0.45 * dx), &grad);
  CHECK(std::abs(shifted - 1.0) < 3e-3);
  CHECK(grad.norm() < 2e-2);
}

TEST_CASE("cubic spline is symmetric, positive, compact and its gradient antisymmetric", "[kernel]") {
  const CubicSpline K(0.013);
  const double alpha = 3.0 / (2.0 * std::numbers::pi * std::pow(0.013, 3));
  CHECK(K.W(0.0) == Approx(alpha * 2.0 / 3.0));                   // eq. (5) at q = 0
  CHECK(K.W(2.0 * K.h) == Approx(0.0).margin(1e-12 * K.W(0.0)));  // 2h * (1/h) may round just below 2
  CHECK(K.W(2.0001 * K.h) == 0.0);
  CHECK(K.W(2.5 * K.h) == 0.0);
  CHECK(K.dWdr(2.0001 * K.h) == 0.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  for (int t = 0; t < 1000; ++t) {
    const Vec3 xij(u(rng), u(rng), u(rng));
    const double r = xij.norm();
    CHECK(K.W(r) >= 0.0);  // eq. (8)
    const Vec3 g1 = K.gradW(xij, r), g2 = K.gradW(Vec3(-xij), r);
    CHECK((g1 + g2).norm() == 0.0);               // exactly antisymmetric: pair forces cancel bit for bit
    if (r >= 2.0 * K.h) CHECK(g1.norm() == 0.0);  // compact support
  }
  // dW/dr matches a central difference of W, both branches.
  for (double q : {0.3, 0.9, 1.2, 1.8}) {
    const double r = q * K.h, e = 1e-7 * K.h;
    CHECK(K.dWdr(r) == Approx((K.W(r + e) - K.W(r - e)) / (2 * e)).epsilon(1e-5));
  }
  // Continuity at q = 1.
  CHECK(K.W(K.h * (1 - 1e-12)) == Approx(K.W(K.h * (1 + 1e-12))));
}

TEST_CASE("cubic spline integrates to one (eq. 6) by quadrature", "[kernel]") {
  const CubicSpline K(1.0);
  // 4 pi int_0^2 W(r) r^2 dr, midpoint rule.
  const int n = 20000;
  double integral = 0.0;
  for (int k = 0; k < n; ++k) {
    const double r = (k + 0.5) * 2.0 / n;
    integral += 4.0 * std::numbers::pi * K.W(r) * r * r * (2.0 / n);
  }
  CHECK(integral == Approx(1.0).epsilon(1e-6));
}

TEST_CASE("neighbour search agrees with brute force on random particles", "[neighbors]") {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> x(3000);
  for (auto& p : x) p = Vec3(u(rng), 0.5 * u(rng), 0.2 * u(rng));
  const double radius = 0.06;
  NeighborSearch nb;
  nb.build(x, radius);
  REQUIRE(nb.size() == x.size());
  std::size_t total = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    std::vector<uint32_t> brute, found(nb.index().begin() + nb.begin(i), nb.index().begin() + nb.end(i));
    for (std::size_t j = 0; j < x.size(); ++j)
      if (j != i && (x[i] - x[j]).squaredNorm() < radius * radius) brute.push_back(static_cast<uint32_t>(j));
    std::sort(found.begin(), found.end());
    REQUIRE(found == brute);
    total += brute.size();
  }
  CHECK(total == nb.pairs());
  CHECK(total > 10 * x.size());  // the test is not vacuous

  // The spatial order is a permutation.
  auto order = nb.spatial_order();
  std::sort(order.begin(), order.end());
  for (std::size_t k = 0; k < order.size(); ++k) REQUIRE(order[k] == k);
}

TEST_CASE("neighbour lists are identical for 1 and 2 threads", "[neighbors][determinism]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> x(5000);
  for (auto& p : x) p = Vec3(u(rng), u(rng), u(rng));
  set_threads(1);
  NeighborSearch a;
  a.build(x, 0.08);
  set_threads(2);
  NeighborSearch b;
  b.build(x, 0.08);
  CHECK(a.index() == b.index());
  CHECK(a.spatial_order() == b.spatial_order());
}
