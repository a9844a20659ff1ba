// Render benchmark: ms per 1920x1080 frame, drawing (incl. read-back) and PNG encoding measured separately.
#pragma once

#include <ostream>

namespace aortasph {

struct RenderBenchResult {
  int particles = 0;
  double draw_ms = 0.0;  // splats + resolve + glReadPixels, mean over the timed frames
  double png_ms = 0.0;   // libpng encoding of the same frame (level 1, SUB filter), in memory
  double png_kb = 0.0;
};

// Renders a synthetic block of `particles` fluid particles coloured by a speed field (a dam-break-like slab
// seen by a 3/4 view camera), `frames` timed frames after one warm-up, and prints one line to `out`.
RenderBenchResult bench_render(std::ostream& out, int particles, int frames = 3);

}  // namespace aortasph
