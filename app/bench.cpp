// aortasph bench: a standard dam break (about 100k fluid particles, or 12k with --quick) stepped a fixed
// number of times; prints fluid particle-steps per second, neighbours per particle, bytes per particle and
// the per-phase profile, and writes bench.json. Speed is measured here, never in unit tests.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "core/parallel.hpp"
#include "errors.hpp"
#include "render_bench.hpp"
#include "world.hpp"

namespace aortasph {

namespace {

// Dam break in a tank: a water column of 0.2 x 0.4 x depth next to the -x wall of a 0.8 m long tank.
Scene bench_scene(bool quick) {
  Scene s;
  s.name = quick ? "bench_dam_break_quick" : "bench_dam_break";
  s.spacing = quick ? 0.0088 : 0.004;  // 12k / 100k fluid particles
  const double depth = quick ? 0.0704 : 0.08;
  s.domain = {Vec3(-0.1, -0.1, -0.1), Vec3(0.9, 0.6, depth + 0.1)};
  s.t_end = 1.0;
  s.max_dt = 1e-3;
  Material water;
  water.name = "water";
  water.type = MaterialType::Fluid;
  water.density = 1000;
  water.viscosity = 1e-6;
  water.sound_speed = 30;
  Material wall;
  wall.name = "wall";
  wall.type = MaterialType::Wall;
  s.materials = {water, wall};
  Body column;
  column.name = "column";
  column.material = 0;
  column.shape.kind = ShapeKind::Box;
  column.shape.box = {Vec3(0, 0, 0), Vec3(0.2, 0.4, depth)};
  // The column starts at the speed of a developed surge front (1.5 m/s), so the neighbour lists are rebuilt
  // as often as in the flowing dam break; from rest they would hardly be rebuilt during the measured steps.
  column.velocity = Vec3(1.5, 0, 0);
  Body tank;
  tank.name = "tank";
  tank.material = 1;
  tank.shape.kind = ShapeKind::Container;
  tank.shape.box = {Vec3(0, 0, 0), Vec3(0.8, 0.5, depth)};
  tank.shape.layers = 3;
  tank.shape.open = {"+y"};
  s.bodies = {column, tank};
  return s;
}

}  // namespace

int cmd_bench(int threads, bool quick, bool render, const std::filesystem::path& json_out) {
  if (threads > 0) set_threads(threads);
  const int used_threads = max_threads();
  const Scene scene = bench_scene(quick);
  const int warmup = 5;
  const int steps = quick ? 40 : 60;

  World world(scene);
  const double fluid = static_cast<double>(world.count(Kind::Fluid));
  const double total = static_cast<double>(world.particles().size());
  const double dt = world.stable_dt();
  for (int k = 0; k < warmup; ++k) world.step(dt);
  const Profile before = world.profile();
  const long builds_before = world.list_builds();
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < steps; ++k) world.step(world.stable_dt());
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Profile p = world.profile() - before;

  const double rate = fluid * steps / wall;
  const double neighbours = static_cast<double>(world.neighbors().pairs()) / total;
  const double bytes = static_cast<double>(world.memory_bytes()) / fluid;
  std::printf("aortasph bench: %s, %d thread(s)\n", scene.name.c_str(), used_threads);
  std::printf("  particles          %10.0f fluid, %.0f boundary\n", fluid, total - fluid);
  std::printf("  steps              %10d (after %d warm-up), %.3f s wall\n", steps, warmup, wall);
  std::printf("  fluid particle-steps/s %10.3g\n", rate);
  std::printf("  neighbours/particle %9.1f (lists include a skin of 10 %% of the support)\n", neighbours);
  std::printf("  list rebuilds      %10ld in %d steps\n", world.list_builds() - builds_before, steps);
  std::printf("  bytes/fluid particle %8.0f\n", bytes);
  std::printf("  phase        seconds   share\n");
  for (const auto& [name, sec] : p.phases())
    std::printf("  %-10s %9.3f  %5.1f %%\n", name.c_str(), sec, 100.0 * sec / std::max(p.total(), 1e-12));

  nlohmann::json j;
  j["scene"] = scene.name;
  j["threads"] = used_threads;
  j["fluid_particles"] = fluid;
  j["boundary_particles"] = total - fluid;
  j["steps"] = steps;
  j["wall_s"] = wall;
  j["fluid_particle_steps_per_s"] = rate;
  j["neighbours_per_particle"] = neighbours;
  j["list_rebuilds"] = world.list_builds() - builds_before;
  j["bytes_per_fluid_particle"] = bytes;
  for (const auto& [name, sec] : p.phases()) j["phases_s"][name] = sec;
  if (render) {
    // Render speed at 1920x1080: drawing and PNG encoding timed separately (render/render_bench).
    for (const int particles : quick ? std::vector<int>{100000} : std::vector<int>{100000, 1000000}) {
      const RenderBenchResult r = bench_render(std::cout, particles);
      j["render"][std::to_string(particles)] = {{"draw_ms", r.draw_ms}, {"png_ms", r.png_ms}};
    }
  }
  std::ofstream f(json_out, std::ios::trunc);
  if (!f) throw InputError(json_out.string() + ": cannot write");
  f << std::setw(2) << j << '\n';
  return 0;
}

}  // namespace aortasph
