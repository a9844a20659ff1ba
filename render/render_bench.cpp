#include "render_bench.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "image.hpp"
#include "renderer.hpp"

namespace aortasph {

RenderBenchResult bench_render(std::ostream& out, int particles, int frames) {
  using clock = std::chrono::steady_clock;
  RenderSettings settings;
  settings.width = 1920;
  settings.height = 1080;
  settings.color_by = "speed";
  settings.range = std::make_pair(0.0, 2.0);
  Camera camera;
  camera.name = "bench";
  camera.eye = Vec3(2.2, 1.4, 2.6);
  camera.target = Vec3(0.5, 0.25, 0.25);

  // A slab 2:1:1 filled on a lattice, so the spacing matches the count like a real scene's would.
  const double spacing = std::cbrt(0.5 / std::max(particles, 1));
  const int nx = static_cast<int>(std::ceil(1.0 / spacing)), ny = static_cast<int>(std::ceil(0.5 / spacing));
  Snapshot snap;
  snap.spacing = spacing;
  SnapshotField& speed = snap.fields.emplace_back();
  speed.name = "speed";
  speed.unit = "m/s";
  BodyView water;
  water.name = "water";
  snap.bodies.push_back(water);
  for (int i = 0; i < particles; ++i) {
    const int x = i % nx, y = (i / nx) % ny, z = i / (nx * ny);
    snap.position.insert(snap.position.end(),
                         {static_cast<float>((x + 0.5) * spacing), static_cast<float>((y + 0.5) * spacing),
                          static_cast<float>((z + 0.5) * spacing)});
    snap.body.push_back(0);
    speed.values.push_back(static_cast<float>(2.0 * y * spacing + std::sin(10.0 * x * spacing)));
  }

  Renderer renderer(settings);
  Image image = renderer.render(snap, camera);  // warm-up: shader JIT, buffer allocation
  RenderBenchResult r;
  r.particles = particles;
  const auto t0 = clock::now();
  for (int k = 0; k < frames; ++k) image = renderer.render(snap, camera);
  const auto t1 = clock::now();
  size_t bytes = 0;
  for (int k = 0; k < frames; ++k) bytes = encode_png(image).size();
  const auto t2 = clock::now();
  r.draw_ms = std::chrono::duration<double, std::milli>(t1 - t0).count() / frames;
  r.png_ms = std::chrono::duration<double, std::milli>(t2 - t1).count() / frames;
  r.png_kb = static_cast<double>(bytes) / 1024.0;
  char line[160];
  std::snprintf(line, sizeof line,
                "render 1920x1080, %d particles: draw %.1f ms/frame, PNG %.1f ms/frame (%.0f KB)", particles,
                r.draw_ms, r.png_ms, r.png_kb);
  out << line << '\n';
  return r;
}

}  // namespace aortasph
