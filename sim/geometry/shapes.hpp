// Particle sampling of the scene's shapes on a cubic lattice of the particle spacing (SPEC.md section 2), and
// the surface meshes that the renderer draws for walls.
#pragma once

#include <cstdint>
#include <vector>

#include "io/snapshot.hpp"
#include "scene.hpp"

namespace aortasph {

struct ShapeSample {
  std::vector<Vec3> points;  // particle centres, world coordinates, lexicographic lattice order
  SurfaceMesh mesh;          // surface for rendering, world coordinates
  // Empty, or one flag per point: 1 = clamped by the shape itself (the aortic leaflets' rows along their
  // attachment to the wall; 2 = clamped and embedded in the wall: a shell leaflet's row beyond its attachment
  // line, where the wall's particles make room for it). Elastic solvers treat these like the body's `fixed`
  // region.
  std::vector<uint8_t> clamped;
  // Shell shapes (rectangle, disc, cylindrical_panel): per point the unit normal of the mid-surface and the
  // area the particle stands for; pinned like clamped, position only (a disc's pinned rim).
  std::vector<Vec3> normals;
  std::vector<double> areas;
  std::vector<uint8_t> pinned;
  // Empty, or per point a fibre direction for shells with fibres (the aortic leaflets: circumferential).
  std::vector<Vec3> fibres;
  // Empty, or per point 1 where the point is an aortic shell leaflet's lunula
  // (AorticRootParams::lunula_height), which may have its own material.
  std::vector<uint8_t> lunula;
};

// Whether a shape is a shell's mid-surface (one layer of particles).
inline bool is_shell_shape(ShapeKind k) {
  return k == ShapeKind::Rectangle || k == ShapeKind::Disc || k == ShapeKind::CylindricalPanel;
}

// Lattice convention: a box [min, max] holds the centres min + (i + 1/2) dx, so the particles' cubes tile it
// exactly. Curved shapes keep the lattice points inside them. Container and tube walls lie outside their
// inner surface, `layers` particles thick. The body's rotation (about the shape's centre) and translation are
// applied last.
ShapeSample sample_body(const Body& body, double spacing);

// Unit vectors u, v with (u, v, axis) orthonormal: the frame in which tubes (and open boundaries,
// sim/boundary/open_boundary.hpp) lay out their lattice across the axis, so that the two line up.
void perpendicular_frame(const Vec3& axis, Vec3& u, Vec3& v);

// Centre about which a shape rotates: the centre of its bounding box before rotation.
Vec3 shape_center(const Shape& shape);

}  // namespace aortasph
