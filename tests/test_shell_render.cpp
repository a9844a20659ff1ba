// Shell sheets (sim/solid/shell_mesh.hpp, render/renderer.cpp, app/output.cpp): the reference triangulation
// of a lattice and of a sampled disc, the sheet drawn without holes, thin edge-on, lit alike from both sides
// and coloured by the field, and the VTK file carrying normals, thickness and the polygons.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>

#include "colormap.hpp"
#include "output.hpp"
#include "renderer.hpp"
#include "scene_loader.hpp"
#include "solid/shell_mesh.hpp"
#include "world.hpp"

using namespace aortasph;
namespace fs = std::filesystem;

namespace {

// An nx x ny lattice at spacing dx in the xy-plane centred on the origin, normals +z.
void lattice(int nx, int ny, double dx, std::vector<Vec3>& X, std::vector<Vec3>& N) {
  X.clear();
  N.clear();
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      X.emplace_back(dx * (i - 0.5 * (nx - 1)), dx * (j - 0.5 * (ny - 1)), 0.0);
      N.push_back(Vec3::UnitZ());
    }
}

double longest_edge(const std::vector<Vec3>& X, const std::vector<Triangle>& T) {
  double L = 0.0;
  for (const auto& t : T)
    for (int c = 0; c < 3; ++c) L = std::max(L, (X[t[c]] - X[t[(c + 1) % 3]]).norm());
  return L;
}

double total_area(const std::vector<Vec3>& X, const std::vector<Triangle>& T) {
  double A = 0.0;
  for (const auto& t : T) A += 0.5 * (X[t[1]] - X[t[0]]).cross(X[t[2]] - X[t[0]]).norm();
  return A;
}

// A snapshot of one sheet through X (bent into a cylinder of radius Rb about the y axis when Rb > 0),
// with field "u" = x and body colour grey.
Snapshot sheet_snapshot(const std::vector<Vec3>& X0, const std::vector<Triangle>& T, double dx, double Rb) {
  Snapshot s;
  s.spacing = dx;
  for (const Vec3& p : X0) {
    Vec3 q = p;
    if (Rb > 0.0) q = Vec3(Rb * std::sin(p.x() / Rb), p.y(), Rb * (1.0 - std::cos(p.x() / Rb)));
    for (int d = 0; d < 3; ++d) s.position.push_back(static_cast<float>(q[d]));
    s.body.push_back(0);
  }
  BodyView b;
  b.name = "sheet";
  b.type = MaterialType::Shell;
  b.color = {0.8f, 0.8f, 0.8f};
  b.sheet = T;
  s.bodies.push_back(b);
  SnapshotField f;
  f.name = "u";
  for (const Vec3& p : X0) f.values.push_back(static_cast<float>(p.x()));
  s.fields.push_back(f);
  return s;
}

Camera camera_at(const Vec3& eye, const Vec3& up = Vec3::UnitY()) {
  Camera c;
  c.name = "c";
  c.eye = eye;
  c.target = Vec3::Zero();
  c.up = up;
  c.fov_deg = 40;
  return c;
}

bool lit(const Image& im, int x, int y) {
  const uint8_t* p = im.at(x, y);
  return p[0] || p[1] || p[2];
}

double coverage(const Image& im) {
  long n = 0;
  for (int y = 0; y < im.h; ++y)
    for (int x = 0; x < im.w; ++x) n += lit(im, x, y);
  return static_cast<double>(n) / (im.w * im.h);
}

// Mean of r+g+b over the covered pixels.
double mean_brightness(const Image& im) {
  double sum = 0.0;
  long n = 0;
  for (int y = 0; y < im.h; ++y)
    for (int x = 0; x < im.w; ++x)
      if (lit(im, x, y)) {
        const uint8_t* p = im.at(x, y);
        sum += p[0] + p[1] + p[2];
        ++n;
      }
  return n ? sum / n : 0.0;
}

}  // namespace

TEST_CASE("shell sheets: a lattice gives 2 (n-1)(m-1) triangles, no edge above 1.5 dx, oriented along N",
          "[shell_render]") {
  const double dx = 0.01;
  std::vector<Vec3> X, N;
  for (const auto& [nx, ny] : {std::pair{2, 2}, std::pair{7, 4}, std::pair{13, 9}}) {
    lattice(nx, ny, dx, X, N);
    const auto T = triangulate_sheet(X, N, 1.5 * dx);
    CHECK(T.size() == static_cast<std::size_t>(2 * (nx - 1) * (ny - 1)));
    CHECK(longest_edge(X, T) <= 1.5 * dx);
    CHECK(total_area(X, T) == Approx((nx - 1) * (ny - 1) * dx * dx).epsilon(1e-9));  // no overlap, no hole
    for (const auto& t : T) CHECK((X[t[1]] - X[t[0]]).cross(X[t[2]] - X[t[0]]).z() > 0.0);
    // Deterministic: the same triangles again.
    CHECK(triangulate_sheet(X, N, 1.5 * dx) == T);
    // Flipped normals flip the orientation.
    std::vector<Vec3> down(N.size(), -Vec3::UnitZ());
    for (const auto& t : triangulate_sheet(X, down, 1.5 * dx))
      CHECK((X[t[1]] - X[t[0]]).cross(X[t[2]] - X[t[0]]).z() < 0.0);
  }
  // A slit two spacings wide (a missing column) stays open: two separate lattices' worth of triangles.
  lattice(11, 6, dx, X, N);
  std::vector<Vec3> Xs, Ns;
  for (std::size_t i = 0; i < X.size(); ++i)
    if (std::abs(X[i].x()) > 0.5 * dx) {
      Xs.push_back(X[i]);
      Ns.push_back(N[i]);
    }
  const auto T = triangulate_sheet(Xs, Ns, 1.5 * dx);
  CHECK(T.size() == static_cast<std::size_t>(2 * 2 * (5 - 1) * (6 - 1)));
  CHECK(longest_edge(Xs, T) <= 1.5 * dx);
}

TEST_CASE("shell sheets: the sampled disc of scenes/shell_plate.json is covered, and VTK carries the sheet",
          "[shell_render]") {
  const LoadedScene loaded =
      load_scene(fs::path(AORTASPH_TEST_DIR) / ".." / "scenes" / "shell_plate.json", {});
  const World w(loaded.scene);
  const Shells& sh = w.shells();
  const ShellSheets& sheets = w.shell_sheets();
  REQUIRE(sh.size() > 1000);
  const double dx = loaded.scene.spacing, a = 1.016;
  std::vector<Vec3> X;
  for (std::size_t s = 0; s < sh.size(); ++s) X.push_back(sh.reference(s));
  const auto& T = sheets.triangles();
  // Euler: a disc triangulated without holes has F = 2 V - B - 2 triangles (B boundary vertices); the ring
  // sampling puts about 2 pi a / dx particles on the rim.
  INFO("particles " << sh.size() << ", triangles " << T.size());
  CHECK(longest_edge(X, T) <= 1.75 * dx);
  // The triangles cover the polygon of the outermost ring: within 1 % of the disc through it.
  double r_max = 0.0;
  for (const Vec3& p : X) r_max = std::max(r_max, p.norm());
  CHECK(r_max <= a + 1e-9);
  const double area = total_area(X, T);
  CHECK(area <= std::numbers::pi * r_max * r_max);
  CHECK(area > 0.99 * std::numbers::pi * r_max * r_max);
  CHECK(static_cast<double>(T.size()) > 2.0 * sh.size() - 2.0 * 2.0 * std::numbers::pi * a / dx);
  CHECK(static_cast<double>(T.size()) < 2.0 * sh.size());
  for (const auto& t : T) CHECK((X[t[1]] - X[t[0]]).cross(X[t[2]] - X[t[0]]).z() > 0.0);

  // The snapshot hands the sheet to the renderer by particle index.
  const Snapshot snap = w.snapshot("stress", 0);
  REQUIRE(snap.bodies.size() == 1);
  CHECK(snap.bodies[0].sheet.size() == T.size());

  // VTK: normal and thickness point data, the triangles as polygons.
  const fs::path dir = fs::temp_directory_path() / ("aortasph_test_shell_vtk_" + std::to_string(getpid()));
  fs::remove_all(dir);
  {
    VtkWriter vtk(dir);
    vtk.write(w, 0);
  }
  std::ifstream in(dir / "particles_00000.vtp");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  fs::remove_all(dir);
  CHECK(text.find("Name=\"normal\" NumberOfComponents=\"3\"") != std::string::npos);
  CHECK(text.find("Name=\"thickness\"") != std::string::npos);
  CHECK(text.find("NumberOfPolys=\"" + std::to_string(T.size()) + "\"") != std::string::npos);
  CHECK(text.find("<Polys>") != std::string::npos);
  // The normal of the flat plate at rest is +z; the thickness that of the material.
  const auto at = text.find("Name=\"normal\"");
  std::istringstream normals(text.substr(text.find('\n', at) + 1));
  double nx = 0, ny = 0, nz = 0;
  normals >> nx >> ny >> nz;
  CHECK(std::abs(nz) == Approx(1.0).margin(1e-9));
  const auto tt = text.find("Name=\"thickness\"");
  std::istringstream thick(text.substr(text.find('\n', tt) + 1));
  double t0 = 0;
  thick >> t0;
  CHECK(t0 == Approx(0.0254));
}

TEST_CASE("shell sheets: each aortic shell leaflet is one sheet without holes (Euler characteristic 1)",
          "[shell_render][shell_leaflet]") {
  // The three leaflets of scenes/shell_valve_closed.json (the main scene's mirror leaflets, dx = 1 mm). A
  // triangulated disc has V - E + F = 1; every hole lowers it by one. At edges up to 1.5 dx each leaflet had
  // two holes: cells of the curved sampling whose diagonals are both 1.52 dx.
  const LoadedScene loaded =
      load_scene(fs::path(AORTASPH_TEST_DIR) / ".." / "scenes" / "shell_valve_closed.json", {});
  const World w(loaded.scene);
  const ShellSheets& sheets = w.shell_sheets();
  const Particles& P = w.particles();
  for (int b = 0; b < 3; ++b) {
    std::set<std::pair<uint32_t, uint32_t>> edges;
    std::set<uint32_t> vertices;
    std::size_t faces = 0;
    for (std::size_t k = 0; k < sheets.triangles().size(); ++k) {
      if (sheets.body()[k] != b) continue;
      const auto& t = sheets.triangles()[k];
      ++faces;
      for (int e = 0; e < 3; ++e) {
        const uint32_t u = t[e], v = t[(e + 1) % 3];
        edges.insert({std::min(u, v), std::max(u, v)});
        vertices.insert(u);
      }
    }
    std::size_t particles = 0;  // shell slots of the body (the triangles' vertices are slots)
    for (std::size_t q = 0; q < w.shells().size(); ++q) particles += P.body[w.shells().at(q)] == b;
    const long chi =
        static_cast<long>(vertices.size()) - static_cast<long>(edges.size()) + static_cast<long>(faces);
    INFO("leaflet " << b << ": " << particles << " particles, V " << vertices.size() << ", E " << edges.size()
                    << ", F " << faces << ", V - E + F = " << chi);
    CHECK(vertices.size() == particles);  // every particle on the sheet
    CHECK(chi == 1);
  }
}

TEST_CASE("shell sheets: drawn without holes, thin edge-on, lit alike from both sides, coloured by the field",
          "[shell_render]") {
  const double dx = 0.02;
  std::vector<Vec3> X, N;
  lattice(41, 31, dx, X, N);  // 0.8 x 0.6
  const auto T = triangulate_sheet(X, N, 1.5 * dx);
  RenderSettings settings;
  settings.width = 160;
  settings.height = 120;
  settings.background = Vec3(0, 0, 0);
  settings.color_by = "material";
  Renderer r(settings);

  // Flat sheet face-on: the projected rectangle is covered with no hole, from both sides alike.
  const Snapshot flat = sheet_snapshot(X, T, dx, 0.0);
  const Image front = r.render(flat, camera_at(Vec3(0, 0, 2)));
  const Image back = r.render(flat, camera_at(Vec3(0, 0, -2)));
  const Image edge = r.render(flat, camera_at(Vec3(0, -2, 0), Vec3::UnitZ()));
  // Half-height of the view at distance 2 is 2 tan(20 deg) = 0.728: the sheet spans 0.3 / 0.728 of it.
  const double px = settings.height / (2.0 * 2.0 * std::tan(20.0 * std::numbers::pi / 180.0));
  const int hx = static_cast<int>(0.4 * px) - 2, hy = static_cast<int>(0.3 * px) - 2;
  long holes = 0;
  for (int y = settings.height / 2 - hy; y < settings.height / 2 + hy; ++y)
    for (int x = settings.width / 2 - hx; x < settings.width / 2 + hx; ++x) holes += !lit(front, x, y);
  CHECK(holes == 0);
  const double expected = (0.8 * px) * (0.6 * px) / (settings.width * settings.height);
  CHECK(coverage(front) == Approx(expected).epsilon(0.08));
  CHECK(coverage(back) == Approx(coverage(front)).epsilon(0.02));
  CHECK(coverage(edge) < 0.05 * coverage(front));
  INFO("front " << mean_brightness(front) << ", back " << mean_brightness(back));
  CHECK(mean_brightness(front) > 0.6 * 3 * 0.8 * 255);  // more than ambient: lit
  CHECK(mean_brightness(back) / mean_brightness(front) == Approx(1.0).epsilon(0.05));

  // Bent sheet (radius 0.4 about the y axis, 115 degrees of arc): seen from its concave and its convex side
  // it is covered and lit alike; edge-on along y it is the arc, still much thinner than face-on.
  const Snapshot bent = sheet_snapshot(X, T, dx, 0.4);
  const Image concave = r.render(bent, camera_at(Vec3(0, 0, 2.2)));
  const Image convex = r.render(bent, camera_at(Vec3(0, 0, -1.8)));
  const Image arc = r.render(bent, camera_at(Vec3(0, -2, 0.2), Vec3::UnitZ()));
  CHECK(coverage(concave) > 0.1);
  CHECK(coverage(convex) > 0.1);
  CHECK(mean_brightness(convex) / mean_brightness(concave) == Approx(1.0).epsilon(0.15));
  CHECK(coverage(arc) < 0.5 * coverage(concave));

  // Coloured by the field: the left and right ends of the sheet take the colormap's ends.
  RenderSettings by_field = settings;
  by_field.color_by = "u";
  by_field.colormap = "viridis";
  by_field.range = std::pair{-0.4, 0.4};
  Renderer rf(by_field);
  const Image coloured = rf.render(flat, camera_at(Vec3(0, 0, 2)));
  const Colormap viridis("viridis");
  const auto lo = viridis(0.0), hi = viridis(1.0);
  const uint8_t* left = coloured.at(settings.width / 2 - hx + 1, settings.height / 2);
  const uint8_t* right = coloured.at(settings.width / 2 + hx - 1, settings.height / 2);
  // Lit shades of the map's ends: the hue (channel order) is that of the map's colour.
  CHECK(left[2] > left[1]);    // viridis 0: dark purple, blue above green
  CHECK(right[1] > right[2]);  // viridis 1: yellow, green above blue
  CHECK((lo[2] > lo[1]) == true);
  CHECK((hi[1] > hi[2]) == true);
}
