#include "geometry/aortic_root.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <numbers>
#include <sstream>
#include <unordered_map>

namespace aortasph {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

constexpr double kDropExponent = 1.5;  // see leaflet_surface

double deg(double d) {
  return d * kPi / 180.0;
}

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// Angle in [0, 2 pi).
double wrap(double a) {
  a = std::fmod(a, kTwoPi);
  return a < 0.0 ? a + kTwoPi : a;
}

// Leaflet sheet: rows this far (in dx) from the attachment line, and the margins that keep bodies apart.
constexpr double kFirstRow = 0.5;       // first row's arc length from the attachment line
constexpr double kSectorMargin = 0.45;  // leaflet particles at least this far from a neighbour's sector
constexpr double kWallMargin = 0.4;     // ... and this far inside the lumen surface
constexpr double kClampDepth = 1.0;     // clamped: within this distance of the lumen surface (the first row)
constexpr double kLayerMin = 0.6;       // leaflet particles of one leaflet at least this far apart
constexpr double kBloodGap = 0.9;       // blood lattice points at least this far from leaflet particles
constexpr double kShellWallMargin = 0.1;  // shell leaflets: the sheet this far inside the lumen surface
constexpr double kShellClampDepth = 0.6;  // ... clamped: its first row, and within this of the lumen surface
constexpr double kShellBloodGap = 0.5;    // ... from a shell leaflet's sheet (along its normal)
constexpr double kShellPatch = 0.75;      // ... over a shell particle's patch (tangential offset, in dx)
constexpr int kMeridianSamples = 100;     // arc-length table along a leaflet meridian
constexpr int kAttachmentSamples = 512;   // mirror leaflets: attachment heights tabulated across a sector
constexpr double kMaxTilt = 30.0;         // mirror_tilt within +-30 degrees
constexpr int kCurveSamples = 400;        // free edge and mid-line lengths: chords along the curve

// Projected distance of a point at polar angle offset a inside a sector of width w, radius r, to the
// sector's two bounding half-planes (rays in projection).
double sector_distance(double r, double a, double w) {
  auto to_ray = [&](double t) { return t <= kPi / 2 ? r * std::sin(t) : r; };
  return std::min(to_ray(a), to_ray(w - a));
}

}  // namespace

AorticRootParams surgical_root(const AorticRootParams& p) {
  AorticRootParams q = p;
  if (q.graft_diameter > 0.0) {
    // The graft (David & Feindel 1992): commissures and STJ on its wall; the annulus (and the LVOT below)
    // keep annulus_radius. The neo-sinus bulge is A itself: sinus_radius is the cone's radius at half the
    // STJ height (where the bulge peaks mid-sinus) plus the bulge.
    const double r = 0.5 * q.graft_diameter;
    q.commissure_radius = r;
    q.stj_diameter = 0.0;
    q.sinuses = q.graft_shape == AorticGraftShape::NeoSinus;
    const double y = 0.5 * q.stj();
    const double cone =
        y < q.commissure_height ? q.annulus_radius + (r - q.annulus_radius) * y / q.commissure_height : r;
    if (q.sinuses) q.sinus_radius = cone + q.neo_sinus_bulge;
  }
  if (q.fixed_cusps && q.mirror_leaflets) {
    // The tilt that makes the mirror leaflets' free edge leaflet_free_edge long: bisection on the sign of
    // the difference over [0, kMaxTilt], outward into the sinus, where the free edge grows with the tilt
    // (measured: 27.4 to 37.7 mm in the default root; it grows again for tilts below 0, towards leaflets
    // that fold against the ventricle). An end when the length is out of reach: check_aortic_root refuses it.
    q.fixed_cusps = false;
    auto excess = [&](double tilt) {
      AorticRootParams t = q;
      t.mirror_tilt = tilt;
      return AorticRoot(t).free_edge_length() - q.leaflet_free_edge;
    };
    double lo = 0.0, hi = kMaxTilt;
    const double f_lo = excess(lo), f_hi = excess(hi);
    if ((f_lo < 0.0) == (f_hi < 0.0)) {
      q.mirror_tilt = std::abs(f_lo) < std::abs(f_hi) ? lo : hi;
    } else {
      const bool rising = f_lo < 0.0;
      for (int it = 0; it < 40; ++it) {
        const double mid = 0.5 * (lo + hi);
        ((excess(mid) < 0.0) == rising ? lo : hi) = mid;
      }
      q.mirror_tilt = 0.5 * (lo + hi);
    }
    // The result is a root with this tilt (cusps "root"): built again from it, nothing is solved again.
  }
  return q;
}

AorticRoot::AorticRoot(const AorticRootParams& p) : p_(surgical_root(p)) {
  for (int k = 0; k < 3; ++k) phi_[k] = deg(p_.commissure_angles[k]);
  dphi_[0] = phi_[1] - phi_[0];
  dphi_[1] = phi_[2] - phi_[1];
  dphi_[2] = phi_[0] + kTwoPi - phi_[2];
  const double half_edge = 0.5 * p_.leaflet_free_edge;
  y_c_ = p_.commissure_height -
         std::sqrt(std::max(0.0, half_edge * half_edge - p_.commissure_radius * p_.commissure_radius));
  bulge_ = p_.sinuses ? p_.sinus_radius - cone_radius(0.5 * p_.stj()) : 0.0;
  if (p_.mirror_leaflets) {
    // Leaflet k's attachment plane: through its two commissures and its nadir (the annulus mid-sector).
    auto at = [](double r, double th, double y) { return Vec3(r * std::cos(th), y, -r * std::sin(th)); };
    for (int k = 0; k < 3; ++k) {
      const Vec3 ca = at(p_.commissure_radius, phi_[k], p_.commissure_height);
      const Vec3 cb = at(p_.commissure_radius, phi_[k] + dphi_[k], p_.commissure_height);
      const Vec3 nadir = at(p_.annulus_radius, phi_[k] + 0.5 * dphi_[k], 0.0);
      Vec3 n = (cb - ca).cross(nadir - ca).normalized();
      if (n.y() < 0) n = -n;
      plane_n_[k] = n;
      plane_p_[k] = nadir;
    }
    const double slope = (p_.commissure_radius - p_.annulus_radius) / p_.commissure_height;
    lean_ = std::tan(std::atan(slope) + deg(p_.mirror_tilt));
    for (int k = 0; k < 3; ++k) {
      attachment_[k].resize(kAttachmentSamples + 1);
      for (int i = 0; i <= kAttachmentSamples; ++i)
        attachment_[k][i] = attachment_height(k, static_cast<double>(i) / kAttachmentSamples);
    }
    y_c_ = mirror_height(0, 0.0, 0.0);
    sag_ = 0.0;
    return;
  }
  // Belly sag S: the mid-line's length grows monotonically with S; bisection to leaflet_height.
  double lo = 0.0, hi = 4.0 * p_.annulus_radius;
  if (midline_length(0.0) >= p_.leaflet_height) {
    hi = 0.0;
  } else if (midline_length(hi) > p_.leaflet_height) {
    for (int it = 0; it < 80; ++it) {
      const double mid = 0.5 * (lo + hi);
      (midline_length(mid) < p_.leaflet_height ? lo : hi) = mid;
    }
  }
  sag_ = hi;
}

double AorticRoot::cone_radius(double y) const {
  const double ra = p_.annulus_radius, rc = p_.commissure_radius;
  if (y <= 0.0) return ra;
  if (y < p_.commissure_height) return ra + (rc - ra) * y / p_.commissure_height;
  if (y <= p_.stj()) {
    // stj_diameter: linear from the commissure radius to the STJ radius (check_aortic_root asks for an STJ
    // above the commissures when the two differ).
    if (p_.stj_diameter <= 0.0 || p_.stj() <= p_.commissure_height) return rc;
    return rc + (p_.stj_radius() - rc) * (y - p_.commissure_height) / (p_.stj() - p_.commissure_height);
  }
  const double rs = p_.stj_radius();
  return rs + (p_.aorta() - rs) * smoothstep((y - p_.stj()) / rc);
}

int AorticRoot::sector_of(double theta, double& s) const {
  for (int k = 0; k < 3; ++k) {
    const double d = wrap(theta - phi_[k]);
    if (d < dphi_[k]) {
      s = d / dphi_[k];
      return k;
    }
  }
  s = 0.0;  // only reached through rounding at a sector's end
  return 0;
}

double AorticRoot::attachment_height(int k, double s) const {
  if (!p_.mirror_leaflets) {
    const double c = std::cos(kPi * s);
    return p_.commissure_height * c * c;
  }
  // The plain cone's point at this angle on the attachment plane: bisection in y over [0, commissure height].
  const double th = phi_[k] + s * dphi_[k], c = std::cos(th), sn = std::sin(th);
  auto side = [&](double y) {
    const double r = cone_radius(y);
    return plane_side(k, Vec3(r * c, y, -r * sn));
  };
  double lo = 0.0, hi = p_.commissure_height;
  const double side_lo = side(lo), side_hi = side(hi);
  if (side_lo >= 0.0) return lo;
  if (side_hi <= 0.0) return hi;
  // The cone is straight below the commissures, so side() is linear in y there: its root y0 is known up to
  // rounding, and side()'s sign is certain at a midpoint farther than `sure` from it. The bisection then
  // takes the same steps as one that evaluates side() at every midpoint (the same result, bit for bit) and
  // evaluates it only near the root.
  const double y0 = -side_lo * (hi - lo) / (side_hi - side_lo), sure = 1e-9 * p_.commissure_height;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    const bool below = mid < y0 - sure ? true : mid > y0 + sure ? false : side(mid) < 0.0;
    (below ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double AorticRoot::plane_side(int k, const Vec3& x) const {
  return (x - plane_p_[k]).dot(plane_n_[k]);
}

Vec3 AorticRoot::reflect(int k, const Vec3& x) const {
  return x - 2.0 * plane_side(k, x) * plane_n_[k];
}

double AorticRoot::mirror_height(int k, double x, double z) const {
  // On the plane the point is its own mirror image, inside the cone; going down, the mirror image rises along
  // the aortic side and leaves the cone: bisection for where it crosses the cone's surface.
  const Vec3& n = plane_n_[k];
  const double y_plane =
      plane_p_[k].y() - ((x - plane_p_[k].x()) * n.x() + (z - plane_p_[k].z()) * n.z()) / n.y();
  auto outside = [&](double y) {
    const Vec3 q = reflect(k, Vec3(x, y, z));
    if (p_.mirror_tilt == 0.0) return std::hypot(q.x(), q.z()) - cone_radius(q.y());
    const double s = wrap(std::atan2(-q.z(), q.x()) - phi_[k]) / dphi_[k];
    return std::hypot(q.x(), q.z()) - open_radius(k, q.y(), s > 0.5 * (1.0 + kTwoPi / dphi_[k]) ? 0.0 : s);
  };
  double lo = y_plane - 4.0 * p_.commissure_height, hi = y_plane;
  if (outside(lo) < 0.0) return lo;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (outside(mid) > 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double AorticRoot::open_radius(int k, double y, double s) const {
  // A ruled surface through the attachment: at each s the line from the attachment point leaning
  // mirror_tilt outward from the cone's line (the cone below the commissures is straight in y).
  s = std::clamp(s, 0.0, 1.0);
  const std::vector<double>& t = attachment_[k];
  const double f = s * (t.size() - 1);
  const auto i = std::min(static_cast<std::size_t>(f), t.size() - 2);
  const double ya = t[i] + (f - i) * (t[i + 1] - t[i]);
  return cone_radius(ya) + (y - ya) * lean_;
}

double AorticRoot::bump(int k, double s, double y) const {
  if (bulge_ <= 0.0) return 0.0;
  const double ya = attachment_height(k, s), top = p_.stj();
  if (y <= ya || y >= top) return 0.0;
  const double w = std::sin(kPi * s);
  return bulge_ * w * w * std::sin(kPi * (y - ya) / (top - ya));
}

double AorticRoot::lumen_radius(double y, double theta) const {
  double s = 0.0;
  const int k = sector_of(theta, s);
  return cone_radius(y) + bump(k, s, y);
}

double AorticRoot::normal_scale(double y, double theta) const {
  const double h = 1e-7, ht = 1e-6, R = lumen_radius(y, theta);
  const double r_y = (lumen_radius(y + h, theta) - lumen_radius(y - h, theta)) / (2 * h);
  const double r_t = (lumen_radius(y, theta + ht) - lumen_radius(y, theta - ht)) / (2 * ht) / R;
  return std::sqrt(1.0 + r_y * r_y + r_t * r_t);
}

Vec3 AorticRoot::leaflet_surface(int k, double rho, double s, double inset) const {
  // In projection: from the apex (on the bisector, `inset` from both coaptation planes) to the attachment
  // point, whose angle runs over the sector less `inset` at the commissure radius at either end, so the
  // free edges (s = 0, 1) run parallel to the coaptation planes at distance `inset`.
  const double half = std::min(0.5 * dphi_[k], kPi / 2);
  const double r_apex = inset / std::sin(half), t_mid = phi_[k] + 0.5 * dphi_[k];
  const double delta = std::asin(std::min(1.0, inset / p_.commissure_radius));
  const double theta = phi_[k] + delta + s * (dphi_[k] - 2 * delta);
  const double ya = attachment_height(k, s);
  const double ra = cone_radius(ya);
  const double x = (1 - rho) * r_apex * std::cos(t_mid) + rho * ra * std::cos(theta);
  const double z = -(1 - rho) * r_apex * std::sin(t_mid) - rho * ra * std::sin(theta);
  if (p_.mirror_leaflets) return Vec3(x, mirror_height(k, x, z), z);
  // Free-edge line plus the attachment's drop below the commissures, fading towards the centre as rho^1.5,
  // less the belly's sag. The sag's profile across the leaflet, 1 - cos^4(pi s), is level at the free edges
  // and flat mid-leaflet, so the belly is a rounded trough rather than a fold along the bisector.
  const double c2 = std::cos(kPi * s) * std::cos(kPi * s);
  const double edge = y_c_ + (p_.commissure_height - y_c_) * rho;
  const double y = edge + (ya - p_.commissure_height) * std::pow(rho, kDropExponent) -
                   sag_ * std::sin(kPi * rho) * (1.0 - c2 * c2);
  return Vec3(x, y, z);
}

double AorticRoot::midline_length(double sag) const {
  // Mid-line s = 1/2 (without the dx/2 inset): r = rho annulus_radius, y as in leaflet_surface.
  const int n = 2000;
  double len = 0.0, r0 = 0.0, y0 = y_c_;
  for (int i = 1; i <= n; ++i) {
    const double rho = static_cast<double>(i) / n;
    const double r = rho * p_.annulus_radius;
    const double y = y_c_ + (p_.commissure_height - y_c_) * rho -
                     p_.commissure_height * std::pow(rho, kDropExponent) - sag * std::sin(kPi * rho);
    len += std::hypot(r - r0, y - y0);
    r0 = r;
    y0 = y;
  }
  return len;
}

double AorticRoot::free_edge_length() const {
  double len = 0.0;
  for (int k = 0; k < 3; ++k)
    for (double s : {0.0, 1.0}) {
      Vec3 prev = leaflet_surface(k, 0.0, s);
      for (int i = 1; i <= kCurveSamples; ++i) {
        const Vec3 q = leaflet_surface(k, static_cast<double>(i) / kCurveSamples, s);
        len += (q - prev).norm();
        prev = q;
      }
    }
  return len / 3.0;
}

double AorticRoot::geometric_height() const {
  // As many chords as midline_length() takes (Labrosse's mid-line has rho^1.5 at the centre).
  const int n = 2000;
  double len = 0.0;
  for (int k = 0; k < 3; ++k) {
    Vec3 prev = leaflet_surface(k, 0.0, 0.5);
    for (int i = 1; i <= n; ++i) {
      const Vec3 q = leaflet_surface(k, static_cast<double>(i) / n, 0.5);
      len += (q - prev).norm();
      prev = q;
    }
  }
  return len / 3.0;
}

double AorticRoot::leaflet_lowest() const {
  double low = y_c_;
  for (int i = 0; i <= 200; ++i)
    for (int j = 0; j <= 100; ++j) low = std::min(low, leaflet_surface(0, i / 200.0, j / 100.0).y());
  return low;
}

double AorticRoot::orifice_radius() const {
  return std::min(p_.annulus_radius, p_.commissure_radius);
}

double AorticRoot::annulus_area() const {
  return kPi * p_.annulus_radius * p_.annulus_radius;
}

Vec3 AorticRoot::to_world(double r, double theta, double y) const {
  return p_.base + Vec3(r * std::cos(theta), y, -r * std::sin(theta));
}

// ---------------------------------------------------------------------------------------------------------
// Wall

std::vector<Vec3> AorticRoot::wall_points(double dx, SurfaceMesh* mesh) const {
  const double y_bot = -p_.lvot_length, y_top = p_.stj() + p_.aorta_length;
  const double hy = 1e-4 * dx;
  auto r_y = [&](double y, double th) {
    return (lumen_radius(y + hy, th) - lumen_radius(y - hy, th)) / (2 * hy);
  };
  const int nt = 720;

  // Ring levels: dx apart along the wall where it is steepest at that height.
  std::vector<double> levels;
  for (double y = y_bot + 0.5 * dx; y <= y_top - 0.5 * dx + 1e-9 * dx;) {
    levels.push_back(y);
    double slope = 0.0;
    for (int m = 0; m < nt; m += 4) slope = std::max(slope, std::abs(r_y(y, phi_[0] + kTwoPi * m / nt)));
    y += dx / std::sqrt(1.0 + slope * slope);
  }

  std::vector<Vec3> out;
  std::vector<double> xs(nt + 1), zs(nt + 1), len(nt + 1);
  for (std::size_t q = 0; q < levels.size(); ++q) {
    const double y = levels[q];
    for (int j = 0; j < p_.wall_layers; ++j) {
      // Layer j's closed curve r(theta), offset so that layers are dx apart along the wall's normal.
      for (int m = 0; m <= nt; ++m) {
        const double th = phi_[0] + kTwoPi * m / nt;
        const double r = lumen_radius(y, th) + (j + 0.5) * dx * normal_scale(y, th);
        xs[m] = r * std::cos(th);
        zs[m] = -r * std::sin(th);
        len[m] = m == 0 ? 0.0 : len[m - 1] + std::hypot(xs[m] - xs[m - 1], zs[m] - zs[m - 1]);
      }
      const double perimeter = len[nt];
      const int n = std::max(8, static_cast<int>(std::lround(perimeter / dx)));
      // Neighbouring rings and layers staggered by half a spacing.
      const double shift = 0.5 * static_cast<double>((q + j) % 2);
      int m = 0;
      for (int i = 0; i < n; ++i) {
        const double a = (i + shift) * perimeter / n;
        while (m < nt - 1 && len[m + 1] < a) ++m;
        const double t = (a - len[m]) / std::max(len[m + 1] - len[m], 1e-300);
        out.push_back(p_.base + Vec3(xs[m] + t * (xs[m + 1] - xs[m]), y, zs[m] + t * (zs[m + 1] - zs[m])));
      }
    }
  }

  // Shell leaflets: the embedded rows (leaflet_shell) take the place of the wall particles within 0.55 dx
  // of them (the leaflet's tissue inserts into the wall there).
  if (p_.shell_leaflets) {
    std::vector<Vec3> sheet;
    for (int k = 0; k < 3; ++k) {
      const ShapeSample l = leaflet_shell(k, dx);
      for (std::size_t m = 0; m < l.points.size(); ++m)
        if (l.clamped[m] == 2) sheet.push_back(l.points[m]);
    }
    const double r2 = 0.55 * 0.55 * dx * dx;
    std::erase_if(out, [&](const Vec3& w) {
      return std::any_of(sheet.begin(), sheet.end(),
                         [&](const Vec3& q) { return (q - w).squaredNorm() < r2; });
    });
  }

  // Commissure posts (shell leaflets): wall particles between the leaflets below each commissure.
  if (p_.commissure_post_length() > 0.0)
    for (const Vec3& q : post_points(dx)) out.push_back(q);

  if (mesh) {
    // Lumen surface: a grid over (y, theta), closed around the axis, open at both ends. Triangles are
    // counter-clockwise seen from the lumen (normals point to the axis, as for a tube's wall).
    std::vector<double> ys;
    ys.push_back(y_bot);
    for (double y : levels) ys.push_back(y);
    ys.push_back(y_top);
    const int per_sector = 48, nc = 3 * per_sector;
    std::vector<double> th;
    for (int k = 0; k < 3; ++k)
      for (int m = 0; m < per_sector; ++m) th.push_back(phi_[k] + dphi_[k] * m / per_sector);
    for (double y : ys)
      for (double t : th) {
        const Vec3 v = to_world(lumen_radius(y, t), t, y);
        mesh->vertices.push_back(
            {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())});
      }
    for (std::size_t a = 0; a + 1 < ys.size(); ++a)
      for (int c = 0; c < nc; ++c) {
        const auto a0 = static_cast<uint32_t>(a * nc + c), a1 = static_cast<uint32_t>(a * nc + (c + 1) % nc);
        const auto b0 = a0 + nc, b1 = a1 + nc;
        mesh->triangles.push_back({a0, b0, b1});
        mesh->triangles.push_back({a0, b1, a1});
      }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------------
// Leaflets

void AorticRoot::leaflet_mid_surface(int k, double dx, std::vector<Vec3>& mids, std::vector<Vec3>& normals,
                                     std::vector<double>* areas, std::vector<int>* row_of,
                                     bool embedded) const {
  // The sheet is built on the surface inset by half a spacing from both coaptation planes, so its free edges
  // lie dx/2 from them and the neighbouring leaflet's particles are dx away across each plane.
  const double inset = 0.5 * dx;
  auto surface_at = [&](double rho, double s) { return leaflet_surface(k, rho, s, inset); };

  // Meridian s (s = const, from the apex at rho = 0 to the attachment at rho = 1): cumulative arc length.
  auto meridian = [&](double s) {
    std::vector<double> c(kMeridianSamples + 1, 0.0);
    Vec3 prev = surface_at(0.0, s);
    for (int m = 1; m <= kMeridianSamples; ++m) {
      const Vec3 q = surface_at(static_cast<double>(m) / kMeridianSamples, s);
      c[m] = c[m - 1] + (q - prev).norm();
      prev = q;
    }
    return c;
  };
  // Memoised by s: the rows below sample the same s values (the arc samples), and leaflet_surface is costly
  // for mirror leaflets (two bisections).
  std::unordered_map<double, std::vector<double>> meridians;
  auto meridian_at = [&](double s) -> const std::vector<double>& {
    auto it = meridians.find(s);
    if (it == meridians.end()) it = meridians.emplace(s, meridian(s)).first;
    return it->second;
  };
  // rho at arc length c from the apex along a meridian.
  auto rho_at = [&](const std::vector<double>& mc, double c) {
    const auto it = std::lower_bound(mc.begin(), mc.end(), c);
    if (it == mc.begin()) return 0.0;
    if (it == mc.end()) return 1.0;
    const auto m = static_cast<int>(it - mc.begin());
    const double t = (c - mc[m - 1]) / std::max(mc[m] - mc[m - 1], 1e-300);
    return (m - 1 + t) / kMeridianSamples;
  };

  // Number of rows: the mean meridian length over all three leaflets, in dx (the same for all three, so
  // their rows meet pairwise along the coaptation lines, where the meridians are alike).
  double mean_len = 0.0;
  const int ns = 32;
  for (int l = 0; l < 3; ++l)
    for (int i = 0; i < ns; ++i) {
      const double s = (i + 0.5) / ns;
      Vec3 prev = leaflet_surface(l, 0.0, s, inset);
      for (int m = 1; m <= kMeridianSamples; ++m) {
        const Vec3 q = leaflet_surface(l, static_cast<double>(m) / kMeridianSamples, s, inset);
        mean_len += (q - prev).norm() / (3 * ns);
        prev = q;
      }
    }
  const int rows = std::max(2, static_cast<int>(std::lround((mean_len - kFirstRow * dx) / dx)) + 1);

  // Row i on meridian s: arc length kFirstRow dx + i (L - kFirstRow dx) / (rows - 1) from the attachment;
  // the last row is the apex.
  auto row_rho = [&](int i, double s) {
    const std::vector<double>& mc = meridian_at(s);
    const double L = mc.back();
    const double from_att = kFirstRow * dx + i * (L - kFirstRow * dx) / (rows - 1);
    return rho_at(mc, L - from_att);
  };
  // The point at arc length c from the attachment along meridian s; c < 0: beyond the attachment, on the
  // meridian's tangent there (into the wall).
  auto merid_point = [&](double s, double c) -> Vec3 {
    const std::vector<double>& mc = meridian_at(s);
    if (c >= 0.0) return surface_at(rho_at(mc, mc.back() - c), s);
    const Vec3 a = surface_at(1.0, s), b = surface_at(1.0 - 1e-3, s);
    return a - c * (a - b).normalized();
  };
  // Row i's point on meridian s (row -1: the embedded row, (1 - kFirstRow) dx beyond the attachment).
  auto row_point = [&](int i, double s) {
    return i >= 0 ? surface_at(row_rho(i, s), s) : merid_point(s, -(1.0 - kFirstRow) * dx);
  };

  // Mid-surface points with their normals, row by row, equally spaced by arc length along each row.
  mids.clear();
  normals.clear();
  if (areas) areas->clear();
  if (row_of) row_of->clear();
  const int arc_samples = 128;
  for (int i = embedded ? -1 : 0; i < rows; ++i) {
    std::vector<double> ss(arc_samples + 1), cl(arc_samples + 1);
    Vec3 prev = Vec3::Zero();
    for (int a = 0; a <= arc_samples; ++a) {
      ss[a] = static_cast<double>(a) / arc_samples;
      const Vec3 q = row_point(i, ss[a]);
      cl[a] = a == 0 ? 0.0 : cl[a - 1] + (q - prev).norm();
      prev = q;
    }
    const double total = cl.back();
    const int n = std::max(1, static_cast<int>(std::lround(total / dx)) + 1);
    std::vector<double> row_s(n);
    for (int m = 0; m < n; ++m) {
      const double target = n == 1 ? 0.5 * total : total * m / (n - 1);
      const auto it = std::lower_bound(cl.begin(), cl.end(), target);
      double s = 1.0;
      if (it == cl.begin()) {
        s = 0.0;
      } else if (it != cl.end()) {
        const auto a = static_cast<int>(it - cl.begin());
        const double t = (target - cl[a - 1]) / std::max(cl[a] - cl[a - 1], 1e-300);
        s = ss[a - 1] + t * (ss[a] - ss[a - 1]);
      }
      row_s[m] = s;
    }
    for (int m = 0; m < n; ++m) {
      const double s = row_s[m];
      // Normal from the surface's tangents (at the apex, from just beside it; the embedded row: at the
      // attachment).
      const double e = 1e-6, rho = i >= 0 ? row_rho(i, s) : 1.0 - e;
      const double rn = std::max(rho, 1e-3);
      const Vec3 d_rho = surface_at(rn + e, s) - surface_at(rn, s);
      const Vec3 d_s = surface_at(rn, s + e) - surface_at(rn, s - e);
      mids.push_back(row_point(i, s));
      normals.push_back(d_rho.cross(d_s).normalized());
      if (row_of) row_of->push_back(i);
      if (!areas) continue;
      // The surface element this point stands for (shell leaflets): the cell between the meridians half way
      // to the row's neighbouring points (s = 0 and 1 at the row's ends) and the lines half way to the
      // neighbouring rows (by arc length along each meridian; the first row's cell reaches back to the
      // attachment line, the apex row's to the apex). The cells tile the mid-surface; each is summed as a
      // 2 x 2 grid of flat quads on the surface.
      const double s_lo = m == 0 ? 0.0 : 0.5 * (row_s[m - 1] + s),
                   s_hi = m == n - 1 ? 1.0 : 0.5 * (s + row_s[m + 1]);
      // The embedded row's cell: the spacing beyond the attachment line.
      auto cell_point = [&](double sc, double v) {
        const std::vector<double>& mc = meridian_at(sc);
        const double L = mc.back(), h = (L - kFirstRow * dx) / (rows - 1);
        const double c = kFirstRow * dx + i * h;
        const double lo = i < 0    ? -dx
                          : i == 0 ? 0.0
                                   : c - 0.5 * h,
                     hi = i < 0           ? 0.0
                          : i == rows - 1 ? L
                                          : c + 0.5 * h;
        return merid_point(sc, lo + v * (hi - lo));
      };
      Vec3 g[3][3];
      const double su[3] = {s_lo, s, s_hi};
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) g[a][b] = cell_point(su[a], 0.5 * b);
      double area = 0.0;
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
          area += 0.5 * ((g[a + 1][b] - g[a][b]).cross(g[a + 1][b + 1] - g[a][b]).norm() +
                         (g[a + 1][b + 1] - g[a][b]).cross(g[a][b + 1] - g[a][b]).norm());
      areas->push_back(area);
    }
  }
}

std::vector<Vec3> AorticRoot::leaflet_points(int k, double dx, std::vector<uint8_t>* clamped) const {
  std::vector<Vec3> mids, normals;
  leaflet_mid_surface(k, dx, mids, normals, nullptr, nullptr);
  for (Vec3& nrm : normals)
    if (nrm.y() < 0) nrm = -nrm;

  // Layers through the thickness, centred on the surface, the mid-surface first, then outwards in pairs
  // (ventricular side first). Where the sheet is folded tighter than its thickness, the concave side's
  // offsets crowd: a point closer than kLayerMin dx to one already placed is left out.
  std::vector<int> order;
  for (int j = 0; j < p_.leaflet_layers; ++j) order.push_back(j);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return std::abs(2 * a - (p_.leaflet_layers - 1)) < std::abs(2 * b - (p_.leaflet_layers - 1));
  });
  std::unordered_map<int64_t, std::vector<Vec3>> placed;
  auto key = [&](const Vec3& q, int a, int b, int c) {
    const int64_t i = static_cast<int64_t>(std::floor(q.x() / dx)) + a + (1 << 20);
    const int64_t j = static_cast<int64_t>(std::floor(q.y() / dx)) + b + (1 << 20);
    const int64_t l = static_cast<int64_t>(std::floor(q.z() / dx)) + c + (1 << 20);
    return (i << 42) | (j << 21) | l;
  };
  auto crowded = [&](const Vec3& q) {
    for (int a = -1; a <= 1; ++a)
      for (int b = -1; b <= 1; ++b)
        for (int c = -1; c <= 1; ++c) {
          const auto it = placed.find(key(q, a, b, c));
          if (it == placed.end()) continue;
          for (const Vec3& o : it->second)
            if ((o - q).squaredNorm() < kLayerMin * kLayerMin * dx * dx) return true;
        }
    return false;
  };
  std::vector<Vec3> out;
  if (clamped) clamped->clear();
  for (int j : order) {
    const double off = (j - 0.5 * (p_.leaflet_layers - 1)) * dx;
    for (std::size_t m = 0; m < mids.size(); ++m) {
      const Vec3 q = mids[m] + off * normals[m];
      const double r = std::hypot(q.x(), q.z()), th = std::atan2(-q.z(), q.x());
      double s = 0.0;
      if (sector_of(th, s) != k) continue;
      if (sector_distance(r, s * dphi_[k], dphi_[k]) < kSectorMargin * dx) continue;
      const double depth = (lumen_radius(q.y(), th) - r) / normal_scale(q.y(), th);
      if (depth < kWallMargin * dx || q.y() < -p_.lvot_length + 0.5 * dx) continue;
      if (crowded(q)) continue;
      placed[key(q, 0, 0, 0)].push_back(q);
      out.push_back(p_.base + q);
      if (clamped) clamped->push_back(depth < kClampDepth * dx ? 1 : 0);
    }
  }
  return out;
}

ShapeSample AorticRoot::leaflet_shell(int k, double dx) const {
  {
    const std::lock_guard<std::mutex> lock(shell_cache_->m);
    const auto it = shell_cache_->sheets.find({k, dx});
    if (it != shell_cache_->sheets.end()) return it->second;
  }
  ShapeSample out = leaflet_shell_uncached(k, dx);
  const std::lock_guard<std::mutex> lock(shell_cache_->m);
  shell_cache_->sheets.emplace(std::make_pair(k, dx), out);
  return out;
}

ShapeSample AorticRoot::leaflet_shell_uncached(int k, double dx) const {
  ShapeSample out;
  std::vector<Vec3> mids, normals;
  std::vector<double> areas;
  std::vector<int> row_of;
  leaflet_mid_surface(k, dx, mids, normals, &areas, &row_of, true);
  // One orientation over the whole sheet: d_rho x d_s keeps its side on the regular (rho, s) patch; its sign
  // is chosen so that the normal mid-belly points up the root (from the ventricle to the aorta).
  const double e = 1e-6, inset = 0.5 * dx;
  const Vec3 belly_n =
      (leaflet_surface(k, 0.5 + e, 0.5, inset) - leaflet_surface(k, 0.5, 0.5, inset))
          .cross(leaflet_surface(k, 0.5, 0.5 + e, inset) - leaflet_surface(k, 0.5, 0.5 - e, inset));
  const double sign = belly_n.y() < 0 ? -1.0 : 1.0;
  std::vector<std::size_t> kept, dropped;
  const double post_len = p_.mirror_leaflets ? p_.commissure_post_length() : 0.0;
  for (std::size_t m = 0; m < mids.size(); ++m) {
    const Vec3& q = mids[m];
    const double r = std::hypot(q.x(), q.z()), th = std::atan2(-q.z(), q.x());
    double s = 0.0;
    const double depth = (lumen_radius(q.y(), th) - r) / normal_scale(q.y(), th);
    // Commissure posts: the leaflets are attached to each other and to the wall within the post's distance
    // of a commissure (the tissue is continuous there in a real root).
    const bool post = near_commissure(q, post_len);
    // The embedded row (row -1) is the leaflet's tissue inside the wall: it closes the gap between the
    // first row and the wall's first layer, through which blood sliding along the wall passed round the
    // attachment (docs/scenes.md, "Embedded row"). None within a post (the post's wall particles are there).
    const bool embedded = row_of[m] < 0;
    if (sector_of(th, s) != k || sector_distance(r, s * dphi_[k], dphi_[k]) < kSectorMargin * dx ||
        (!embedded && depth < kShellWallMargin * dx) || (embedded && post) ||
        q.y() < -p_.lvot_length + 0.5 * dx) {
      if (!embedded) dropped.push_back(m);
      continue;
    }
    kept.push_back(m);
    out.points.push_back(p_.base + q);
    out.normals.push_back(sign * normals[m]);
    out.areas.push_back(areas[m]);
    // Circumferential about the root's axis (+y): the cusps' collagen runs from commissure to commissure.
    out.fibres.push_back(Vec3(-q.z(), 0.0, q.x()) / std::max(r, 1e-12));
    out.clamped.push_back(embedded ? 2 : row_of[m] == 0 || depth < kShellClampDepth * dx || post ? 1 : 0);
  }
  // A point left out hands its area to the nearest kept point, so the areas still tile the mid-surface.
  for (std::size_t m : dropped) {
    std::size_t best = 0;
    double d2 = 1e300;
    for (std::size_t j = 0; j < kept.size(); ++j) {
      const double e2 = (mids[kept[j]] - mids[m]).squaredNorm();
      if (e2 < d2) d2 = e2, best = j;
    }
    if (!kept.empty()) out.areas[best] += areas[m];
  }
  if (p_.lunula_height > 0.0) add_lunula(k, dx, row_of, kept, out);
  return out;
}

void AorticRoot::add_lunula(int k, double dx, const std::vector<int>& row_of,
                            const std::vector<std::size_t>& kept, ShapeSample& out) const {
  // The free-edge particles: the first (s = 0, on commissure k's plane) and the last (s = 1, on the next
  // commissure's plane) kept point of each row; a row of one point is the apex, on both planes. Each edge
  // runs in its plane's parallel dx/2 inside the sector (leaflet_surface), so a column straight up from an
  // edge particle stays in that plane.
  std::vector<std::size_t> first, last;  // indices into out, by row from the attachment to the apex
  std::size_t apex = out.points.size();
  for (std::size_t j = 0; j < kept.size(); ++j) {
    const int row = row_of[kept[j]];
    if (row < 0) continue;
    const bool starts = j == 0 || row_of[kept[j - 1]] != row;
    const bool ends = j + 1 == kept.size() || row_of[kept[j + 1]] != row;
    if (starts && ends) {
      apex = j;
    } else {
      if (starts) first.push_back(j);
      if (ends) last.push_back(j);
    }
  }
  const double post_len = p_.mirror_leaflets ? p_.commissure_post_length() : 0.0;
  out.lunula.assign(out.points.size(), 0);
  const double th0 = phi_[k], th1 = phi_[k] + dphi_[k];
  // Into the sector from each plane: the band's normal on the aortic side, as the sheet's normal turns there
  // (the sheet's normal points up the root, and at the free edge away from the plane).
  const Vec3 n0(-std::sin(th0), 0.0, -std::cos(th0)), n1(std::sin(th1), 0.0, std::cos(th1));
  auto horizontal = [&](std::size_t a, std::size_t b) {
    const Vec3 d = out.points[a] - out.points[b];
    return std::hypot(d.x(), d.z());
  };
  auto column = [&](std::size_t j, const Vec3& normal, const Vec3& fibre, double width) {
    const Vec3 q = out.points[j] - p_.base;
    const double rl = p_.lunula_radius > 0.0 ? p_.lunula_radius : p_.commissure_radius;
    const double f = std::min(1.0, std::hypot(q.x(), q.z()) / rl);
    const double w = p_.lunula_height * (1.0 - f * f);
    for (int i = 1; i * dx <= w * (1.0 + 1e-9); ++i) {
      const Vec3 x = q + Vec3(0.0, i * dx, 0.0);
      const double r = std::hypot(x.x(), x.z()), th = std::atan2(-x.z(), x.x());
      if ((lumen_radius(x.y(), th) - r) / normal_scale(x.y(), th) < kShellWallMargin * dx) break;
      const bool post = near_commissure(x, post_len);
      out.points.push_back(p_.base + x);
      out.normals.push_back(normal);
      out.areas.push_back(width * dx);
      out.fibres.push_back(fibre);
      out.clamped.push_back(post ? 1 : 0);
      out.lunula.push_back(1);
    }
  };
  for (int side = 0; side < 2; ++side) {
    std::vector<std::size_t> edge = side == 0 ? first : last;
    if (apex < out.points.size()) edge.push_back(apex);
    const Vec3& n = side == 0 ? n0 : n1;
    // A row whose end point was left out (at the wall, beside a neighbour's sector) ends inside the sheet.
    std::erase_if(edge, [&](std::size_t j) {
      return j != apex && std::abs((out.points[j] - p_.base).dot(n) - 0.5 * dx) > 0.25 * dx;
    });
    for (std::size_t e = 0; e < edge.size(); ++e) {
      if (edge[e] == apex) continue;  // the apex's column below, once
      // The horizontal width a column stands for: half the way to each neighbour along the edge.
      const double width = 0.5 *
                           ((e > 0 ? horizontal(edge[e], edge[e - 1]) : 0.0) +
                            (e + 1 < edge.size() ? horizontal(edge[e], edge[e + 1]) : 0.0)) *
                           (e > 0 && e + 1 < edge.size() ? 1.0 : 2.0);
      const Vec3 q = out.points[edge[e]] - p_.base;
      const Vec3 radial = Vec3(q.x(), 0.0, q.z()).normalized();  // along the edge, horizontally
      column(edge[e], n, radial, width);
    }
  }
  if (apex < out.points.size()) {
    // The apex's column, on both planes: half the way to the nearest edge particle of each.
    double width = 0.0;
    for (const auto* edge : {&first, &last})
      if (!edge->empty()) width += 0.5 * horizontal(apex, edge->back());
    const Vec3 bisector = (n0 + n1).normalized();  // outward along the sector's bisector
    column(apex, bisector, Vec3(0.0, 1.0, 0.0).cross(bisector).normalized(), width);
  }
}

// ---------------------------------------------------------------------------------------------------------
// Blood

std::vector<Vec3> AorticRoot::blood_points(double dx) const {
  return blood_lattice(dx);
}

std::vector<Vec3> AorticRoot::post_points(double dx) const {
  // A grid aligned with each commissure's radial plane: columns dx apart inward from dx/2 inside the
  // commissure radius, in each column rows dx apart downward from the free edge's height on the plane
  // (where the two sheets' edge rows lie dx/2 either side of it), and points on the plane and dx, 2 dx either
  // side of it. Kept: within the post's distance of the commissure point, dx/2 inside the lumen (normal
  // distance), on the plane or dx/2 below the sheet of its sector, and 0.55 dx from every leaflet particle
  // (the other bodies keep half a spacing).
  std::vector<Vec3> post;
  const double h = p_.commissure_post_length();
  if (h <= 0.0 || !p_.mirror_leaflets) return post;
  std::vector<Vec3> sheet;
  for (int k = 0; k < 3; ++k)
    for (const Vec3& q : leaflet_shell(k, dx).points) sheet.push_back(q - p_.base);
  const int n = static_cast<int>(std::ceil(h / dx)) + 1;
  for (int c = 0; c < 3; ++c) {
    const Vec3 C = commissure_point(c);
    const Vec3 er(std::cos(phi_[c]), 0.0, -std::sin(phi_[c])), ew(std::sin(phi_[c]), 0.0, std::cos(phi_[c]));
    const int left = (c + 2) % 3;  // the leaflet ending at commissure c; leaflet c starts there
    for (int a = 0; a < n; ++a) {
      const double r = p_.commissure_radius - (a + 0.5) * dx;
      const Vec3 on_plane = r * er;
      const double y_edge = std::min(mirror_height(left, on_plane.x(), on_plane.z()),
                                     mirror_height(c, on_plane.x(), on_plane.z()));
      for (int j = 0; j < 2 * n; ++j)
        for (int m = -2; m <= 2; ++m) {
          const Vec3 q = on_plane + Vec3(0.0, y_edge - j * dx, 0.0) + (m * dx) * ew;
          if ((q - C).squaredNorm() >= h * h) continue;
          const double rq = std::hypot(q.x(), q.z()), th = std::atan2(-q.z(), q.x());
          if ((lumen_radius(q.y(), th) - rq) / normal_scale(q.y(), th) < 0.5 * dx) continue;
          double s = 0.0;
          const int k = sector_of(th, s);
          if (m != 0 && q.y() > mirror_height(k, q.x(), q.z()) - 0.5 * dx) continue;
          bool clear = true;
          for (const Vec3& o : sheet) clear = clear && (o - q).squaredNorm() >= 0.55 * 0.55 * dx * dx;
          if (clear) post.push_back(p_.base + q);
        }
    }
  }
  return post;
}

bool AorticRoot::near_commissure(const Vec3& x, double reach) const {
  for (int c = 0; c < 3 && reach > 0.0; ++c)
    if ((x - commissure_point(c)).norm() < reach) return true;
  return false;
}

Vec3 AorticRoot::commissure_point(int c) const {
  const double th = phi_[c];
  return Vec3(p_.commissure_radius * std::cos(th), p_.commissure_height,
              -p_.commissure_radius * std::sin(th));
}

bool AorticRoot::in_post(const Vec3& x) const {
  const double h = p_.commissure_post_length();
  if (h <= 0.0 || !p_.mirror_leaflets) return false;
  for (int c = 0; c < 3; ++c) {
    if ((x - commissure_point(c)).squaredNorm() >= h * h) continue;
    // Inside the lumen, below the closed sheet of the sector x lies in (the mirror surface of its leaflet,
    // which the two leaflets' sheets follow up to dx/2 from the coaptation plane): the space between the two
    // leaflets, on their ventricular side, and the corner they make with the wall.
    const double th = std::atan2(-x.z(), x.x());
    if (std::hypot(x.x(), x.z()) >= lumen_radius(x.y(), th)) return false;
    double s = 0.0;
    const int k = sector_of(th, s);
    return x.y() < mirror_height(k, x.x(), x.z());
  }
  return false;
}

std::vector<Vec3> AorticRoot::blood_lattice(double dx) const {
  const bool posts = p_.commissure_post_length() > 0.0 && p_.mirror_leaflets;
  std::vector<Vec3> post_pts;
  if (posts) post_pts = post_points(dx);
  // Leaflet particles in a hash grid of cell dx, to keep the blood kBloodGap dx away from them.
  std::unordered_map<int64_t, std::vector<Vec3>> grid;
  auto cell = [&](const Vec3& q) {
    const Vec3 c = ((q - p_.base) / dx).array().floor();
    return (static_cast<int64_t>(c.x()) + (1 << 20)) * (int64_t(1) << 42) +
           (static_cast<int64_t>(c.y()) + (1 << 20)) * (int64_t(1) << 21) +
           (static_cast<int64_t>(c.z()) + (1 << 20));
  };
  double leaf_lo = 1e300, leaf_hi = -1e300;  // heights (relative to base) the leaflets span, +- dx
  // Shell leaflets: the normals too (indexed like the grid's points).
  std::unordered_map<int64_t, std::vector<Vec3>> grid_n;
  for (int k = 0; k < 3; ++k) {
    ShapeSample shell;
    if (p_.shell_leaflets) shell = leaflet_shell(k, dx);
    const std::vector<Vec3> pts = p_.shell_leaflets ? shell.points : leaflet_points(k, dx, nullptr);
    for (std::size_t m = 0; m < pts.size(); ++m) {
      const Vec3& q = pts[m];
      grid[cell(q)].push_back(q);
      if (p_.shell_leaflets) grid_n[cell(q)].push_back(shell.normals[m]);
      leaf_lo = std::min(leaf_lo, q.y() - p_.base.y() - dx);
      leaf_hi = std::max(leaf_hi, q.y() - p_.base.y() + dx);
    }
  }
  auto near_leaflet = [&](const Vec3& q) {
    for (int a = -1; a <= 1; ++a)
      for (int b = -1; b <= 1; ++b)
        for (int c = -1; c <= 1; ++c) {
          const int64_t key = cell(q + dx * Vec3(a, b, c));
          const auto it = grid.find(key);
          if (it == grid.end()) continue;
          for (std::size_t m = 0; m < it->second.size(); ++m) {
            const Vec3 d = q - it->second[m];
            if (!p_.shell_leaflets) {
              if (d.squaredNorm() < kBloodGap * kBloodGap * dx * dx) return true;
              continue;
            }
            // A shell is a sheet, not a row of balls: a point over a shell particle's patch (tangential
            // offset < kShellPatch dx) must be kShellBloodGap dx off the sheet along its normal, and every
            // point that far from the particle itself (round the free edges).
            const double dn = std::abs(d.dot(grid_n[key][m]));
            const double dt = (d - d.dot(grid_n[key][m]) * grid_n[key][m]).norm();
            if (d.norm() < kShellBloodGap * dx || (dn < kShellBloodGap * dx && dt < kShellPatch * dx))
              return true;
          }
        }
    return false;
  };

  const double y_bot = -p_.lvot_length, y_top = p_.stj() + p_.aorta_length;
  const double r_max = std::max({p_.annulus_radius, p_.commissure_radius, p_.stj_radius(), p_.aorta(),
                                 p_.sinuses ? p_.sinus_radius : 0.0}) +
                       dx;
  const int nr = static_cast<int>(std::ceil(r_max / dx));
  const int ny = static_cast<int>(std::lround((y_top - y_bot) / dx));
  std::vector<Vec3> out;
  for (int kz = -nr; kz < nr; ++kz)
    for (int jy = 0; jy < ny; ++jy)
      for (int ix = -nr; ix < nr; ++ix) {
        const double x = (ix + 0.5) * dx, y = y_bot + (jy + 0.5) * dx, z = (kz + 0.5) * dx;
        const double r = std::hypot(x, z);
        if (r > r_max) continue;
        const double th = std::atan2(-z, x);
        // Normal depth <= radial depth; the slope factor only where the radial depth leaves a doubt.
        const double radial = lumen_radius(y, th) - r;
        if (radial < 0.5 * dx || (radial < 4 * dx && radial / normal_scale(y, th) < 0.5 * dx)) continue;
        const Vec3 q = p_.base + Vec3(x, y, z);
        if (y >= leaf_lo && y <= leaf_hi && near_leaflet(q)) continue;
        if (posts && in_post(q - p_.base)) continue;
        if (posts) {  // and 0.75 dx from the post's particles
          bool clear = true;
          for (const Vec3& o : post_pts) clear = clear && (o - q).squaredNorm() >= 0.75 * 0.75 * dx * dx;
          if (!clear) continue;
        }
        out.push_back(q);
      }
  return out;
}

// ---------------------------------------------------------------------------------------------------------

namespace {

// The checks on the parameters as built (surgical keys applied).
std::optional<AorticRootError> check_resolved(const AorticRootParams& p, double dx) {
  auto err = [](std::string param, std::string msg) {
    return AorticRootError{std::move(param), std::move(msg)};
  };
  const double lengths[] = {p.annulus_radius, p.commissure_radius, p.commissure_height, p.sinus_radius,
                            p.lvot_length,    p.aorta_length,      p.leaflet_free_edge, p.leaflet_height};
  const char* names[] = {"annulus_radius", "commissure_radius", "commissure_height", "sinus_radius",
                         "lvot_length",    "aorta_length",      "leaflet_free_edge", "leaflet_height"};
  for (int i = 0; i < 8; ++i)
    if (!(lengths[i] > 0) || !std::isfinite(lengths[i])) return err(names[i], "must be positive");
  if (p.stj_height < 0 || p.aorta_radius < 0)
    return err(p.stj_height < 0 ? "stj_height" : "aorta_radius", "must be positive");
  if (p.leaflet_layers < 1) return err("leaflet_layers", "must be at least 1");
  if (p.wall_layers < 1) return err("wall_layers", "must be at least 1");

  const auto& a = p.commissure_angles;
  for (int k = 0; k < 2; ++k)
    if (!(a[k + 1] > a[k]))
      return err("commissure_angles",
                 "must increase (got " + num(a[0]) + ", " + num(a[1]) + ", " + num(a[2]) + ")");
  const double gaps[3] = {a[1] - a[0], a[2] - a[1], a[0] + 360.0 - a[2]};
  for (int k = 0; k < 3; ++k)
    if (gaps[k] < 30.0)
      return err("commissure_angles", "commissures " + std::to_string(k) + " and " +
                                          std::to_string((k + 1) % 3) + " are " + num(gaps[k]) +
                                          " degrees apart (at least 30)");

  if (p.stj_height > 0 && p.stj_height < p.commissure_height)
    return err("stj_height", "must not lie below commissure_height (" + num(p.commissure_height) + ")");
  if (p.sinuses && !(p.graft_diameter > 0.0)) {  // a neo-sinus graft's bulge is checked as such
    if (p.commissure_radius >= p.sinus_radius)
      return err("commissure_radius", "must be smaller than sinus_radius (" + num(p.sinus_radius) + ")");
    if (p.annulus_radius >= p.sinus_radius)
      return err("sinus_radius", "must be larger than annulus_radius (" + num(p.annulus_radius) + ")");
  }
  if (p.commissure_post > 0.0 && !p.mirror_leaflets)
    return err("commissure_post", "needs mirror leaflets (leaflet_shape \"mirror\")");
  if (!(p.commissure_post < 0.5 * p.commissure_radius) && p.commissure_post > 0.0)
    return err("commissure_post",
               num(p.commissure_post) +
                   " is too long (less than commissure_radius / 2 = " + num(0.5 * p.commissure_radius) + ")");
  if (std::abs(p.mirror_tilt) > 30.0)
    return err("mirror_tilt", num(p.mirror_tilt) + " is outside [-30, 30] degrees");
  if (p.lunula_height < 0.0) return err("lunula_height", "must not be negative");
  if (p.lunula_height > 0.0 && !(p.lunula_height < 0.5 * p.commissure_height))
    return err("lunula_height", num(p.lunula_height) + " is too high (less than commissure_height / 2 = " +
                                    num(0.5 * p.commissure_height) + ")");
  if (p.lunula_radius > 0.0 && !(p.lunula_height > 0.0)) return err("lunula_radius", "needs lunula_height");
  if (p.lunula_radius > p.commissure_radius)
    return err("lunula_radius", num(p.lunula_radius) +
                                    " is beyond the commissures (at most commissure_radius = " +
                                    num(p.commissure_radius) + ")");
  // Labrosse leaflets follow free_edge and leaflet_height; mirror leaflets follow the root alone.
  if (!p.mirror_leaflets) {
    if (p.leaflet_free_edge < 2.0 * p.commissure_radius)
      return err("leaflet_free_edge",
                 num(p.leaflet_free_edge) +
                     " is too short to close the valve: at least 2 x commissure_radius = " +
                     num(2.0 * p.commissure_radius));
    const double longest = 2.0 * std::hypot(p.commissure_radius, p.commissure_height);
    if (p.leaflet_free_edge > longest)
      return err("leaflet_free_edge",
                 num(p.leaflet_free_edge) +
                     " is too long: the free edges would meet below the annulus plane (at most " +
                     num(longest) + ")");

    const AorticRoot root(p);
    const double chord = std::hypot(p.annulus_radius, root.coaptation_height());
    if (p.leaflet_height < chord)
      return err("leaflet_height",
                 num(p.leaflet_height) +
                     " is too short to reach from the annulus to the coaptation point (at least " +
                     num(chord) + ")");
    if (root.leaflet_lowest() < -0.5 * p.annulus_radius)
      return err("leaflet_height",
                 num(p.leaflet_height) + " is too long: the closed leaflet's belly would sag to " +
                     num(root.leaflet_lowest()) + " below the annulus plane (at most annulus_radius / 2)");
  }

  if (dx > p.commissure_radius / 6.0)
    return err("spacing", "spacing " + num(dx) +
                              " is too coarse for the aortic root (at most commissure_radius / 6 = " +
                              num(p.commissure_radius / 6.0) + ")");
  if (p.leaflet_layers * dx > p.commissure_radius / 4.0)
    return err("leaflet_layers", std::to_string(p.leaflet_layers) + " layers at spacing " + num(dx) +
                                     " make the leaflets too thick (at most commissure_radius / 4)");
  const double low = AorticRoot(p).leaflet_lowest();
  if (low - 0.5 * p.leaflet_layers * dx < -p.lvot_length + dx)
    return err("lvot_length", num(p.lvot_length) + " is too short: the leaflets reach down to " +
                                  num(low - 0.5 * p.leaflet_layers * dx) + " below the annulus plane");
  if (p.lvot_length < dx || p.aorta_length < dx)
    return err(p.lvot_length < dx ? "lvot_length" : "aorta_length", "must be at least one particle spacing");
  return std::nullopt;
}

// The surgical keys themselves (on the parameters as given).
std::optional<AorticRootError> check_surgical(const AorticRootParams& p) {
  auto err = [](std::string param, std::string msg) {
    return AorticRootError{std::move(param), std::move(msg)};
  };
  const bool graft = p.graft_diameter > 0.0;
  if (!(p.graft_diameter >= 0.0) || !std::isfinite(p.graft_diameter))
    return err("graft_diameter", "must be positive");
  if (!(p.neo_sinus_bulge >= 0.0) || !std::isfinite(p.neo_sinus_bulge))
    return err("neo_sinus_bulge", "must be positive");
  if (!(p.stj_diameter >= 0.0) || !std::isfinite(p.stj_diameter))
    return err("stj_diameter", "must be positive");
  if (!graft && p.graft_shape != AorticGraftShape::Unset)
    return err("graft_shape", "needs graft_diameter (a native root's sinuses are sinuses and sinus_radius)");
  const bool neo = p.graft_shape == AorticGraftShape::NeoSinus;
  if (p.neo_sinus_bulge > 0.0 && !neo)
    return err("neo_sinus_bulge", "only a graft with graft_shape \"neo_sinus\" has a bulge");
  if (neo && !(p.neo_sinus_bulge > 0.0))
    return err("neo_sinus_bulge",
               "missing or 0: a neo_sinus graft needs its bulge out of the graft (metres, > 0)");
  if (neo && p.neo_sinus_bulge > 0.5 * p.graft_diameter)
    return err("neo_sinus_bulge", num(p.neo_sinus_bulge) + " is larger than the graft radius (" +
                                      num(0.5 * p.graft_diameter) + ")");
  if (graft && p.stj_diameter > 0.0)
    return err("stj_diameter", "the sinotubular junction follows the graft (graft_diameter): leave it out");
  if (p.stj_diameter > 0.0 && p.stj_diameter != 2.0 * p.commissure_radius && p.stj() <= p.commissure_height)
    return err("stj_diameter", num(p.stj_diameter) + " differs from 2 x commissure_radius (" +
                                   num(2.0 * p.commissure_radius) +
                                   "): needs stj_height above commissure_height, for the wall to widen or "
                                   "narrow from the commissures to the junction");
  return std::nullopt;
}

}  // namespace

std::optional<AorticRootError> check_aortic_root(const AorticRootParams& p, double dx) {
  if (auto e = check_surgical(p)) return e;
  const AorticRootParams q = surgical_root(p);
  auto e = check_resolved(q, dx);
  if (e && p.graft_diameter > 0.0) {
    // In a graft the radii are the graft's: name the key that set them.
    if (e->param == "commissure_radius") e->param = "graft_diameter";
    e->message += " (graft_diameter " + num(p.graft_diameter) + ": commissure_radius = graft_diameter / 2)";
  }
  if (!e && p.fixed_cusps && p.mirror_leaflets) {
    const AorticRoot root(q);
    const double fe = root.free_edge_length();
    if (std::abs(fe - p.leaflet_free_edge) > 1e-6 * p.leaflet_free_edge)
      return AorticRootError{"leaflet_free_edge",
                             num(p.leaflet_free_edge) +
                                 " cannot be kept by mirror leaflets in this root (cusps \"fixed\"): "
                                 "the nearest, at mirror_tilt " +
                                 num(root.params().mirror_tilt) + ", is " + num(fe)};
  }
  return e;
}

namespace {
// One root for the bodies of a scene: the wall, the blood and the three leaflets are sampled body by body
// with the same parameters, and the wall (its posts and embedded rows) and the blood (its gaps) each need the
// three leaflet sheets, whose mirror surface costs a bisection per point: built once per root they were built
// nine times, about 70 % of `aortasph check` of the physio scene (stop 62). The last few roots are kept.
std::shared_ptr<const AorticRoot> shared_root(const AorticRootParams& p) {
  static std::mutex m;
  static std::deque<std::pair<AorticRootParams, std::shared_ptr<const AorticRoot>>> roots;
  {
    const std::lock_guard<std::mutex> lock(m);
    for (const auto& [q, root] : roots)
      if (q == p) return root;
  }
  auto root =
      std::make_shared<const AorticRoot>(p);  // outside the lock (deterministic: built twice, the same)
  const std::lock_guard<std::mutex> lock(m);
  roots.emplace_back(p, root);
  if (roots.size() > 4) roots.pop_front();
  return root;
}
}  // namespace

ShapeSample sample_aortic_root(const AorticRootParams& p, AorticPart part, int leaflet, double dx) {
  ShapeSample out;
  const std::shared_ptr<const AorticRoot> shared = shared_root(p);
  const AorticRoot& root = *shared;
  switch (part) {
    case AorticPart::Wall:
      out.points = root.wall_points(dx, &out.mesh);
      break;
    case AorticPart::Blood:
      out.points = root.blood_points(dx);
      break;
    case AorticPart::Leaflet:
      if (p.shell_leaflets)
        out = root.leaflet_shell(std::clamp(leaflet, 0, 2), dx);
      else
        out.points = root.leaflet_points(std::clamp(leaflet, 0, 2), dx, &out.clamped);
      break;
  }
  return out;
}

double bending_equivalent_modulus(double real_youngs_modulus, double real_thickness, double model_thickness) {
  const double ratio = real_thickness / model_thickness;
  return real_youngs_modulus * ratio * ratio * ratio;
}

}  // namespace aortasph
