#include "geometry/shapes.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "geometry/aortic_root.hpp"

namespace aortasph {

namespace {

// Lattice points min + (i + 1/2) dx covering [lo, hi] along each axis, those for which keep(p) holds.
template <class Keep>
void lattice(const Vec3& lo, const Vec3& hi, double dx, Keep&& keep, std::vector<Vec3>& out) {
  const Eigen::Vector3i n = ((hi - lo) / dx).array().round().cast<int>().max(0);
  for (int k = 0; k < n.z(); ++k)
    for (int j = 0; j < n.y(); ++j)
      for (int i = 0; i < n.x(); ++i) {
        const Vec3 p = lo + dx * Vec3(i + 0.5, j + 0.5, k + 0.5);
        if (keep(p)) out.push_back(p);
      }
}

void add_quad(SurfaceMesh& m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const auto base = static_cast<uint32_t>(m.vertices.size());
  for (const Vec3* v : {&a, &b, &c, &d})
    m.vertices.push_back(
        {static_cast<float>(v->x()), static_cast<float>(v->y()), static_cast<float>(v->z())});
  m.triangles.push_back({base, base + 1, base + 2});
  m.triangles.push_back({base, base + 2, base + 3});
}

// Faces of a box; skip[f] leaves face f out (order -x, +x, -y, +y, -z, +z). inward flips the winding.
void box_mesh(const Box& b, const bool skip[6], bool inward, SurfaceMesh& m) {
  const Vec3 lo = b.min, hi = b.max;
  auto corner = [&](int x, int y, int z) {
    return Vec3(x ? hi.x() : lo.x(), y ? hi.y() : lo.y(), z ? hi.z() : lo.z());
  };
  // Each face listed counter-clockwise seen from outside.
  const int faces[6][4][3] = {
      {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}}, {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}},
      {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}, {{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}},
      {{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}, {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};
  for (int f = 0; f < 6; ++f) {
    if (skip[f]) continue;
    Vec3 v[4];
    for (int k = 0; k < 4; ++k) v[k] = corner(faces[f][k][0], faces[f][k][1], faces[f][k][2]);
    if (inward)
      add_quad(m, v[0], v[3], v[2], v[1]);
    else
      add_quad(m, v[0], v[1], v[2], v[3]);
  }
}

// Orthonormal frame (u, v) perpendicular to the unit axis a.
void frame(const Vec3& a, Vec3& u, Vec3& v) {
  u = (std::abs(a.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(a).normalized();
  v = a.cross(u);
}

// Side of a cylinder of radius r from base along axis a (length L); inward flips the winding.
void cylinder_mesh(const Vec3& base, const Vec3& a, double r, double L, bool inward, bool caps,
                   SurfaceMesh& m) {
  Vec3 u, v;
  frame(a, u, v);
  const int seg = 48;
  for (int s = 0; s < seg; ++s) {
    const double t0 = 2 * std::numbers::pi * s / seg, t1 = 2 * std::numbers::pi * (s + 1) / seg;
    const Vec3 r0 = r * (std::cos(t0) * u + std::sin(t0) * v), r1 = r * (std::cos(t1) * u + std::sin(t1) * v);
    const Vec3 a0 = base + r0, a1 = base + r1, b0 = a0 + L * a, b1 = a1 + L * a;
    if (inward)
      add_quad(m, a0, b0, b1, a1);
    else
      add_quad(m, a0, a1, b1, b0);
    if (caps) {
      add_quad(m, base, base + r1, base + r0, base);
      add_quad(m, base + L * a, base + L * a + r0, base + L * a + r1, base + L * a);
    }
  }
}

// In-plane axes (u, v) of a rectangle: u along u_axis projected into the plane (or the perpendicular_frame's
// first axis), v = n x u.
void rectangle_axes(const Shape& s, Vec3& u, Vec3& v) {
  const Vec3 n = s.normal.normalized();
  if (s.u_axis) {
    u = (*s.u_axis - s.u_axis->dot(n) * n).normalized();
  } else {
    Vec3 w;
    frame(n, u, w);
  }
  v = n.cross(u);
}

// One layer of particles on a shell's mid-surface at spacing dx, with normals and areas.
//   rectangle: (i + 1/2) dx from one corner along u and v, round(size / dx) per side, area dx^2;
//   disc: the centre and rings at radius k dr (dr = radius / round(radius / dx)) of round(2 pi k) particles,
//     each the area of its ring's annulus (half an annulus for the rim at exactly `radius`), so the rim lies
//     on the circle (where a clamped plate's boundary is);
//   cylindrical_panel: (i + 1/2) steps along the axis and along the arc (round(length / dx),
//     round(radius angle / dx)), area (length / n_axis) (radius angle / n_arc).
void sample_shell(const Shape& s, double dx, ShapeSample& out) {
  const Vec3 n = s.normal.normalized();
  auto add = [&](const Vec3& p, const Vec3& nrm, double area) {
    out.points.push_back(p);
    out.normals.push_back(nrm);
    out.areas.push_back(area);
  };
  if (s.kind == ShapeKind::Rectangle) {
    Vec3 u, v;
    rectangle_axes(s, u, v);
    const int na = static_cast<int>(std::lround(s.size[0] / dx)),
              nb = static_cast<int>(std::lround(s.size[1] / dx));
    for (int j = 0; j < nb; ++j)
      for (int i = 0; i < na; ++i)
        add(s.center + ((i + 0.5) * dx - 0.5 * na * dx) * u + ((j + 0.5) * dx - 0.5 * nb * dx) * v, n,
            dx * dx);
    const Vec3 a = 0.5 * na * dx * u, b = 0.5 * nb * dx * v;
    add_quad(out.mesh, s.center - a - b, s.center + a - b, s.center + a + b, s.center - a + b);
  } else if (s.kind == ShapeKind::Disc) {
    Vec3 u, v;
    frame(n, u, v);
    const int rings = static_cast<int>(std::lround(s.radius / dx));
    if (rings < 1) return;
    const double dr = s.radius / rings;
    add(s.center, n, std::numbers::pi * 0.25 * dr * dr);
    for (int k = 1; k <= rings; ++k) {
      const double r = k * dr;
      const int m = static_cast<int>(std::lround(2.0 * std::numbers::pi * k));
      const double outer = k == rings ? r : r + 0.5 * dr, inner = r - 0.5 * dr;
      const double area = std::numbers::pi * (outer * outer - inner * inner) / m;
      const double phase = (k % 2) * std::numbers::pi / m;  // stagger neighbouring rings
      for (int q = 0; q < m; ++q) {
        const double th = phase + 2.0 * std::numbers::pi * q / m;
        add(s.center + r * (std::cos(th) * u + std::sin(th) * v), n, area);
        if (k == rings) {
          out.clamped.resize(out.points.size(), 0);
          out.pinned.resize(out.points.size(), 0);
          out.clamped.back() = s.rim == 1;
          out.pinned.back() = s.rim == 2;
        }
      }
    }
    out.clamped.resize(out.points.size(), 0);
    out.pinned.resize(out.points.size(), 0);
    const int seg = 48;
    for (int q = 0; q < seg; ++q) {
      const double t0 = 2 * std::numbers::pi * q / seg, t1 = 2 * std::numbers::pi * (q + 1) / seg;
      add_quad(out.mesh, s.center, s.center + s.radius * (std::cos(t0) * u + std::sin(t0) * v),
               s.center + s.radius * (std::cos(t1) * u + std::sin(t1) * v), s.center);
    }
  } else {
    const Vec3 a = s.axis.normalized();
    const Vec3 crown = (n - n.dot(a) * a).normalized();
    const Vec3 side = a.cross(crown);
    const double half = 0.5 * s.angle * std::numbers::pi / 180.0;
    const int nl = static_cast<int>(std::lround(s.length / dx));
    const int nt = static_cast<int>(std::lround(s.radius * 2.0 * half / dx));
    if (nl < 1 || nt < 1) return;
    const double dl = s.length / nl, dth = 2.0 * half / nt;
    auto radial = [&](double th) { return Vec3(std::cos(th) * crown + std::sin(th) * side); };
    for (int j = 0; j < nt; ++j)
      for (int i = 0; i < nl; ++i) {
        const double th = -half + (j + 0.5) * dth;
        add(s.center + (-0.5 * s.length + (i + 0.5) * dl) * a + s.radius * radial(th), radial(th),
            dl * s.radius * dth);
      }
    const int seg = std::max(4, nt);
    for (int j = 0; j < seg; ++j) {
      const double t0 = -half + 2.0 * half * j / seg, t1 = -half + 2.0 * half * (j + 1) / seg;
      const Vec3 p0 = s.center + s.radius * radial(t0), p1 = s.center + s.radius * radial(t1);
      const Vec3 e = 0.5 * s.length * a;
      add_quad(out.mesh, p0 - e, p1 - e, p1 + e, p0 + e);
    }
  }
}

}  // namespace

void perpendicular_frame(const Vec3& axis, Vec3& u, Vec3& v) {
  frame(axis.normalized(), u, v);
}

Vec3 shape_center(const Shape& s) {
  switch (s.kind) {
    case ShapeKind::Box:
    case ShapeKind::Container:
      return 0.5 * (s.box.min + s.box.max);
    case ShapeKind::Sphere:
      return s.center;
    case ShapeKind::Cylinder:
    case ShapeKind::Tube:
      return s.base + 0.5 * s.length * s.axis.normalized();
    case ShapeKind::AorticRoot:
      return s.aortic.base;  // the same for every part of one root, so they rotate together
    case ShapeKind::Rectangle:
    case ShapeKind::Disc:
    case ShapeKind::CylindricalPanel:
      return s.center;
    default:
      return Vec3::Zero();
  }
}

ShapeSample sample_body(const Body& body, double dx) {
  ShapeSample out;
  const Shape& s = body.shape;
  switch (s.kind) {
    case ShapeKind::Box: {
      lattice(
          s.box.min, s.box.max, dx, [](const Vec3&) { return true; }, out.points);
      const bool none[6] = {};
      box_mesh(s.box, none, false, out.mesh);
      break;
    }
    case ShapeKind::Sphere: {
      const Vec3 r = Vec3::Constant(s.radius);
      lattice(
          s.center - r, s.center + r, dx, [&](const Vec3& p) { return (p - s.center).norm() <= s.radius; },
          out.points);
      // A UV sphere for the surface.
      const int nu = 32, nv = 16;
      for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
          auto at = [&](int ii, int jj) {
            const double th = std::numbers::pi * jj / nv, ph = 2 * std::numbers::pi * ii / nu;
            return Vec3(s.center + s.radius * Vec3(std::sin(th) * std::cos(ph), std::cos(th),
                                                   std::sin(th) * std::sin(ph)));
          };
          add_quad(out.mesh, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
        }
      break;
    }
    case ShapeKind::Cylinder: {
      const Vec3 a = s.axis.normalized();
      const Vec3 top = s.base + s.length * a;
      const Vec3 lo = s.base.cwiseMin(top) - Vec3::Constant(s.radius),
                 hi = s.base.cwiseMax(top) + Vec3::Constant(s.radius);
      lattice(
          lo, hi, dx,
          [&](const Vec3& p) {
            const double t = (p - s.base).dot(a);
            return t >= 0 && t <= s.length && (p - s.base - t * a).norm() <= s.radius;
          },
          out.points);
      cylinder_mesh(s.base, a, s.radius, s.length, false, true, out.mesh);
      break;
    }
    case ShapeKind::Container: {
      // Lattice continued outward from the inner box, `layers` deep on every closed face.
      auto open = [&](const char* f) { return std::find(s.open.begin(), s.open.end(), f) != s.open.end(); };
      const char* neg[3] = {"-x", "-y", "-z"};
      const char* pos[3] = {"+x", "+y", "+z"};
      Vec3 lo = s.box.min, hi = s.box.max;
      const double t = s.layers * dx;
      for (int d = 0; d < 3; ++d) {
        if (!open(neg[d])) lo[d] -= t;
        if (!open(pos[d])) hi[d] += t;
      }
      // Align the outer lattice with the inner box so the wall continues the fluid's lattice.
      lattice(
          lo, hi, dx, [&](const Vec3& p) { return !s.box.contains(p); }, out.points);
      bool skip[6];
      for (int d = 0; d < 3; ++d) {
        skip[2 * d] = open(neg[d]);
        skip[2 * d + 1] = open(pos[d]);
      }
      box_mesh(s.box, skip, true, out.mesh);
      break;
    }
    case ShapeKind::Tube: {
      // Wall between radius and radius + layers dx around the axis; lattice in the tube's own frame so the
      // wall is equally thick all round.
      const Vec3 a = s.axis.normalized();
      Vec3 u, v;
      frame(a, u, v);
      const double outer = s.radius + s.layers * dx;
      const int nr = static_cast<int>(std::ceil(outer / dx));
      const int nl = static_cast<int>(std::round(s.length / dx));
      for (int k = 0; k < nl; ++k)
        for (int j = -nr; j < nr; ++j)
          for (int i = -nr; i < nr; ++i) {
            const double x = (i + 0.5) * dx, y = (j + 0.5) * dx;
            const double rr = std::hypot(x, y);
            if (rr >= s.radius && rr < outer)
              out.points.push_back(s.base + (k + 0.5) * dx * a + x * u + y * v);
          }
      cylinder_mesh(s.base, a, s.radius, s.length, true, false, out.mesh);
      break;
    }
    case ShapeKind::AorticRoot:
      out = sample_aortic_root(s.aortic, s.aortic_part, s.aortic_index, dx);
      break;
    case ShapeKind::Mesh:
      break;  // refused by the scene loader until implemented
    case ShapeKind::Rectangle:
    case ShapeKind::Disc:
    case ShapeKind::CylindricalPanel:
      sample_shell(s, dx, out);
      break;
  }

  // Rotation about the shape's centre, then translation.
  if (body.rotate_degrees != 0.0 || body.translate != Vec3::Zero()) {
    const Vec3 c = shape_center(s);
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(body.rotate_degrees * std::numbers::pi / 180.0, body.rotate_axis.normalized())
            .toRotationMatrix();
    for (Vec3& p : out.points) p = c + R * (p - c) + body.translate;
    for (Vec3& nrm : out.normals) nrm = R * nrm;
    for (auto& vtx : out.mesh.vertices) {
      const Vec3 p = c + R * (Vec3(vtx[0], vtx[1], vtx[2]) - c) + body.translate;
      vtx = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
    }
  }
  return out;
}

}  // namespace aortasph
