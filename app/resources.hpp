// Resource checks before a run (issue 7): refuse, with a message naming the numbers, a run that would run out
// of memory or disk halfway instead of dying there.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>

#include "scene.hpp"

namespace aortasph {

// Particles the scene's shapes will hold, from their volumes on the lattice (an estimate within a few per
// cent for boxes, spheres and cylinders; containers and tubes counted as closed shells, an upper bound).
double estimate_particles(const Scene& scene);

// Bytes a run holds per particle: the particle arrays (about 160 B), the Verlet neighbour lists (4 B per
// neighbour within 1.1 kernel supports, about 100 at smoothing_ratio 1.3, counted 1.5 times for the growth of
// the lists' storage) and scratch arrays (about 100 B). About 850 B at smoothing_ratio 1.3.
double bytes_per_particle(const Scene& scene);

// Bytes the frames of the remaining outputs will take: a PNG of these renders compresses to about a quarter
// of its raw RGB size (width * height * 3 / 4; measured 0.05..0.3 on the project's scenes, so this is
// generous), per camera and output; with VTK frames (vtk_every >= 1: every vtk_every-th output and the last;
// 0: none) also about 170 B per particle and frame (ASCII .vtp).
double estimate_output_bytes(const Scene& scene, double particles, long outputs, bool render, int vtk_every);

// MemAvailable of /proc/meminfo in bytes, or nothing when it cannot be read.
std::optional<double> available_memory();

// Throws InputError when the estimated memory exceeds what is available, or the estimated output exceeds the
// free space under dir. outputs: the outputs still to be written; vtk_every as for estimate_output_bytes.
void check_resources(const Scene& scene, const std::filesystem::path& dir, long outputs, bool render,
                     int vtk_every);

}  // namespace aortasph
