// aortasph bench: a standard case (the dam break: about 100k fluid particles, or 12k with --quick; or the
// aortic root main job, scenes/aortic_root.json), any scene file (--scene FILE) or a run folder's checkpoint
// (--from DIR: the state mid-run, e.g. a valve in systole) stepped a fixed number of times; prints fluid and
// all moving particle-steps per second, neighbours per particle, bytes per particle (the World's own
// accounting and the process's peak resident set), the per-phase profile, and writes bench.json. Speed is
// measured here, never in unit tests.
#include <algorithm>
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
#include "scene_loader.hpp"
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

// Peak resident set size of this process (VmHWM of /proc/self/status) in bytes; 0 where it cannot be read.
double peak_rss_bytes() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind("VmHWM:", 0) == 0) {
      try {
        return std::stod(line.substr(6)) * 1024.0;  // "VmHWM:   123456 kB"
      } catch (const std::exception&) {
        return 0.0;
      }
    }
  }
  return 0.0;
}

// Moving particles: every particle but the fixed walls (fluid, open-boundary buffers, elastic, rigid).
double moving_particles(const World& world) {
  return static_cast<double>(world.particles().size() - world.count(Kind::Wall));
}

}  // namespace

int cmd_bench(const BenchOptions& o) {
  if (o.threads > 0) set_threads(o.threads);
  const int used_threads = max_threads();
  Scene scene;
  std::optional<StateReader> state;  // --from: the checkpoint's state
  if (o.from) {
    CheckpointScene c = load_checkpoint(*o.from, o.sets);
    scene = std::move(c.loaded.scene);
    state.emplace(std::move(c.state));
  } else if (o.scene) {
    scene = load_scene(*o.scene, o.sets).scene;
  } else if (o.case_name == "aortic_root") {
    scene =
        load_scene(std::filesystem::path(AORTASPH_SOURCE_DIR) / "scenes" / "aortic_root.json", o.sets).scene;
  } else if (o.case_name == "dam_break") {
    if (!o.sets.empty())
      throw InputError("--set applies to --scene or --case aortic_root, not the dam break");
    scene = bench_scene(o.quick);
  } else {
    throw InputError("--case: unknown case " + o.case_name + " (dam_break, aortic_root)");
  }
  const int warmup = 5;
  const int steps = o.steps > 0 ? o.steps : (o.quick ? 40 : 60);

  World world(scene);
  if (state) {
    try {
      world.load_state(*state);
    } catch (const SetupError& e) {
      throw InputError(o.from->string() + ": " + e.what());
    }
  }
  const double t_from = world.time();
  const double dt = world.stable_dt();
  for (int k = 0; k < warmup; ++k) world.step(dt);
  const Profile before = world.profile();
  const long builds_before = world.list_builds();
  // Particle counts change with open boundaries: particle-steps are summed step by step.
  double fluid_steps = 0.0, moving_steps = 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < steps; ++k) {
    fluid_steps += static_cast<double>(world.count(Kind::Fluid));
    moving_steps += moving_particles(world);
    world.step(world.stable_dt());
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Profile p = world.profile() - before;

  const double fluid = static_cast<double>(world.count(Kind::Fluid));
  const double moving = moving_particles(world);
  const double total = static_cast<double>(world.particles().size());
  const double rate = fluid_steps / wall;
  const double moving_rate = moving_steps / wall;
  const double neighbours = static_cast<double>(world.neighbors().pairs()) / total;
  const double bytes = static_cast<double>(world.memory_bytes()) / std::max(fluid, 1.0);
  const double rss = peak_rss_bytes();
  const double rss_per_fluid = rss / std::max(fluid, 1.0);
  std::printf("aortasph bench: %s, %d thread(s)\n", scene.name.c_str(), used_threads);
  std::printf("  particles          %10.0f fluid, %.0f moving in all, %.0f boundary\n", fluid, moving,
              total - moving);
  std::printf("  steps              %10d (after %d warm-up), %.3f s wall", steps, warmup, wall);
  if (o.from) std::printf(", from t = %.6g s (checkpoint)", t_from);
  std::printf("\n");
  std::printf("  fluid particle-steps/s %10.3g\n", rate);
  std::printf("  particle-steps/s   %10.3g (all moving particles)\n", moving_rate);
  std::printf("  neighbours/particle %9.1f (lists include a skin of %.0f %% of the support)\n", neighbours,
              100.0 * scene.skin);
  std::printf("  list rebuilds      %10ld in %d steps\n", world.list_builds() - builds_before, steps);
  std::printf("  bytes/fluid particle %8.0f (World accounting), %.0f (peak RSS %.1f MiB)\n", bytes,
              rss_per_fluid, rss / (1024.0 * 1024.0));
  std::printf("  phase           seconds   share\n");
  for (const auto& [name, sec] : p.phases())
    std::printf("  %-13s %9.3f  %5.1f %%\n", name.c_str(), sec, 100.0 * sec / std::max(p.total(), 1e-12));

  nlohmann::json j;
  j["scene"] = scene.name;
  j["threads"] = used_threads;
  j["fluid_particles"] = fluid;
  j["moving_particles"] = moving;
  j["boundary_particles"] = total - fluid;
  j["steps"] = steps;
  if (o.from) j["from_time_s"] = t_from;
  j["skin"] = scene.skin;
  j["wall_s"] = wall;
  j["fluid_particle_steps_per_s"] = rate;
  j["particle_steps_per_s"] = moving_rate;
  j["neighbours_per_particle"] = neighbours;
  j["list_rebuilds"] = world.list_builds() - builds_before;
  j["bytes_per_fluid_particle"] = bytes;
  j["peak_rss_bytes"] = rss;
  j["peak_rss_bytes_per_fluid_particle"] = rss_per_fluid;
  for (const auto& [name, sec] : p.phases()) j["phases_s"][name] = sec;
  if (o.render) {
    // Render speed at 1920x1080: drawing and PNG encoding timed separately (render/render_bench).
    for (const int particles : o.quick ? std::vector<int>{100000} : std::vector<int>{100000, 1000000}) {
      const RenderBenchResult r = bench_render(std::cout, particles);
      j["render"][std::to_string(particles)] = {{"draw_ms", r.draw_ms}, {"png_ms", r.png_ms}};
    }
  }
  std::ofstream f(o.json, std::ios::trunc);
  if (!f) throw InputError(o.json.string() + ": cannot write");
  f << std::setw(2) << j << '\n';
  return 0;
}

}  // namespace aortasph
