#include "resources.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "errors.hpp"

namespace aortasph {

namespace {

std::string gigabytes(double bytes) {
  std::ostringstream s;
  s.precision(bytes < 1e9 ? 2 : 3);
  s << bytes / 1e9 << " GB";
  return s.str();
}

}  // namespace

double estimate_particles(const Scene& scene) {
  const double dx = scene.spacing;
  const double pi = std::numbers::pi;
  double total = 0.0;
  for (const Body& body : scene.bodies) {
    const Shape& s = body.shape;
    double n = 0.0;
    switch (s.kind) {
      case ShapeKind::Box: {
        const Vec3 e = (s.box.max - s.box.min) / dx;
        n = (e.array() + 1.0).prod();
        break;
      }
      case ShapeKind::Container: {
        const Vec3 inner = (s.box.max - s.box.min) / dx;
        const Vec3 outer = inner.array() + 2.0 * s.layers;
        n = outer.prod() - inner.prod();
        break;
      }
      case ShapeKind::Sphere:
        n = 4.0 / 3.0 * pi * std::pow(s.radius / dx, 3);
        break;
      case ShapeKind::Cylinder:
        n = pi * std::pow(s.radius / dx, 2) * (s.length / dx + 1.0);
        break;
      case ShapeKind::Tube: {
        const double r = s.radius / dx, R = r + s.layers;
        n = pi * (R * R - r * r) * (s.length / dx + 1.0) + 2.0 * pi * R * R * s.layers;
        break;
      }
      default:
        n = 0.0;  // shapes sampled from files are counted when they are loaded
    }
    total += n;
  }
  return total;
}

double bytes_per_particle(const Scene& scene) {
  // Neighbours within 1 + skin supports (support = 2 h = 2 smoothing_ratio dx) on the cubic lattice.
  const double radius = (1.0 + scene.skin) * 2.0 * scene.smoothing_ratio;
  const double neighbours = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  return 160.0 + 4.0 * neighbours * 1.5 + 100.0;
}

double estimate_output_bytes(const Scene& scene, double particles, long outputs, bool render, int vtk_every) {
  const double n = static_cast<double>(std::max(outputs, 0L));
  double bytes = 0.0;
  if (render)
    bytes += n * static_cast<double>(scene.render.cameras.size()) * scene.render.width * scene.render.height *
             3.0 / 4.0;
  // --vtk-every N writes every N-th output's frame and the last one.
  if (vtk_every > 0) bytes += 170.0 * particles * std::min(n, std::ceil(n / vtk_every) + 1.0);
  return bytes;
}

std::optional<double> available_memory() {
  std::ifstream f("/proc/meminfo");
  std::string key;
  double kb = 0;
  std::string unit;
  while (f >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024.0;
  return std::nullopt;
}

void check_resources(const Scene& scene, const std::filesystem::path& dir, long outputs, bool render,
                     int vtk_every) {
  const double particles = estimate_particles(scene);
  const double need = particles * bytes_per_particle(scene);
  if (const auto have = available_memory(); have && need > *have) {
    std::ostringstream msg;
    msg.precision(3);
    msg << "the scene needs about " << gigabytes(need) << " of memory (" << particles << " particles at "
        << "resolution.spacing = " << scene.spacing << " m, about " << std::lround(bytes_per_particle(scene))
        << " bytes each), but only " << gigabytes(*have)
        << " are available (MemAvailable); use a coarser resolution.spacing or smaller bodies";
    throw InputError(msg.str());
  }
  const double write = estimate_output_bytes(scene, particles, outputs, render, vtk_every);
  std::error_code ec;
  const auto space = std::filesystem::space(dir, ec);
  if (!ec && write > static_cast<double>(space.available)) {
    std::ostringstream msg;
    msg << "the run will write about " << gigabytes(write) << " (" << outputs << " outputs";
    if (render)
      msg << " x " << scene.render.cameras.size() << " camera(s) x " << scene.render.width << "x"
          << scene.render.height << " frames";
    msg << "), but only " << gigabytes(static_cast<double>(space.available)) << " are free on "
        << dir.string()
        << "; raise time.output_interval, lower render.width/height, or write elsewhere with --out";
    throw InputError(msg.str());
  }
}

}  // namespace aortasph
