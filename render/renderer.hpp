// Offscreen renderer: draws a Snapshot for a Camera into an RGB8 image with OSMesa (llvmpipe).
//
// Particles are lit sphere impostors (GL_POINTS, radius = spacing / 2, true depth); bodies with
// render == Surface are drawn as their translucent, two-sided lit mesh instead of their particles; shell
// bodies with a sheet (BodyView::sheet) as that opaque, smooth, two-sided lit sheet through their particles,
// coloured per vertex; Hidden bodies, and the bodies a camera hides, are not drawn. Colour is the body colour
// (color_by == "material") or the snapshot's field through the colormap, with one range for the whole run.
// The clip plane removes the +normal half of the listed bodies. Each camera may override color_by, colormap,
// range, hide and clip (scene.hpp Camera; RenderSettings::*_of say what applies). Anti-aliasing: a 4x
// multisampled framebuffer with alpha-to-coverage on the splat rims (smooth silhouettes without shading every
// sample; llvmpipe offers at most 4 samples).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "image.hpp"
#include "io/snapshot.hpp"
#include "render_error.hpp"
#include "scene.hpp"

namespace aortasph {

// Lighting shared by both shaders (and by the golden tests, which compute expected shades from it).
// The light is fixed to the camera (a "headlight" from the upper left), so every view is lit alike.
struct Lighting {
  static constexpr float kAmbient = 0.35f;
  static constexpr float kDiffuse = 0.65f;
  static constexpr float kSpecular = 0.2f;
  static constexpr float kShininess = 24.0f;
  static constexpr float kLightDir[3] = {-0.3f, 0.4f, 0.866025f};  // view space, unit length
  static constexpr float kMeshAlpha = 0.3f;                        // translucency of wall surfaces
};

// Samples per pixel of the multisampled framebuffer; $AORTASPH_MSAA (1, 2, 4 or 8) overrides it, for
// measuring the anti-aliasing cost (render_bench) and for quick previews.
inline constexpr int kMsaaSamples = 4;
int msaa_samples();

// Throws RenderError naming the problem: a camera at its target, a view direction parallel to up, a zero up
// vector, a field of view outside (0, 180).
void validate_camera(const Camera& camera);

// Throws RenderError for: width/height not positive and even (or above 16384), an unknown colormap, a
// background outside [0, 1], an inverted or empty range, a zero clip normal, an invalid camera (also its
// own colormap, color_by or range).
void validate_render_settings(const RenderSettings& settings);

class Renderer {
 public:
  // Validates the settings and creates the GL context on the calling thread; render() must be called on the
  // same thread.
  explicit Renderer(const RenderSettings& settings);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Draws one frame of settings().width x settings().height. Throws RenderError on GL errors or an
  // inconsistent snapshot (field or body index sizes).
  Image render(const Snapshot& snapshot, const Camera& camera);

  // The colour range in use for cameras without overrides: settings().range, or the one chosen from the
  // first snapshot whose field is not constant (then kept for the rest of the run). Empty while none has
  // been chosen or for color_by "material".
  std::optional<std::pair<double, double>> field_range() const;
  // The same for one camera: its own range, settings().range when it colours by the run's field, or the one
  // chosen from the particles it draws. Cameras with the same field, colormap and hidden bodies share the
  // chosen range.
  std::optional<std::pair<double, double>> field_range(const Camera& camera) const;

  const RenderSettings& settings() const;
  std::string gl_renderer() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace aortasph
