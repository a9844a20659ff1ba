// Sheets of the shell bodies: a triangulated surface through the shell particles, built once in the reference
// configuration and drawn (render/) and written (VTK polygons) at the current positions.
//
// The triangles are the restricted Delaunay triangles of the reference mid-surface positions: a triangle
// (i, j, k) of one body is kept when
//   - every edge is at most max_edge (1.5 dx: free edges, holes and slits stay open),
//   - its circumradius R is at most max_edge (no slivers),
//   - the ball centred at its circumcentre with radius R holds no other particle of the body strictly inside
//     (on a plane this is exactly the empty-circumcircle test of a Delaunay triangulation).
// Points on one circle (the four corners of a lattice cell) are a tie: every triangle of that circle sees the
// same set of cocircular points, and only the fan from the lowest index of that set, in their order round
// the circle, is kept, so ties are broken the same way from every triangle (one diagonal per lattice cell).
// The result depends only on the reference positions and their order (deterministic); each triangle is
// ordered (i < j < k up to orientation) and oriented counter-clockwise about the reference normals N.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/particles.hpp"

namespace aortasph {

class Shells;

using Triangle = std::array<uint32_t, 3>;

// Triangles through the points X (indices into X), oriented along the normals N (one per point).
std::vector<Triangle> triangulate_sheet(const std::vector<Vec3>& X, const std::vector<Vec3>& N,
                                        double max_edge);

// The sheet of every shell body: triangles by shell slot (Shells' slots never change, the particle index of
// a slot does: Shells::at).
class ShellSheets {
 public:
  ShellSheets() = default;
  // body: the body index of each shell slot; max_edge: 1.75 dx (the World's choice).
  ShellSheets(const Shells& shells, const std::vector<uint16_t>& body, double max_edge);
  bool empty() const { return triangles_.empty(); }
  // Triangles of all bodies, by shell slot, and the body of each.
  const std::vector<Triangle>& triangles() const { return triangles_; }
  const std::vector<uint16_t>& body() const { return body_; }

 private:
  std::vector<Triangle> triangles_;
  std::vector<uint16_t> body_;
};

}  // namespace aortasph
