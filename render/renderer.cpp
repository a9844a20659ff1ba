#include "renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <limits>
#include <map>
#include <tuple>

#include "colormap.hpp"
#include "embedded_shaders.hpp"
#include "gl_api.hpp"  // GL and OSMesa, loaded at the first GlContext (not linked)
#include "gl_context.hpp"

namespace aortasph {

// The vertex records Renderer::Impl holds (a named namespace: in a unity group, GCC reports a class member of
// a type from an anonymous namespace, -Wsubobject-linkage).
namespace renderer_detail {

// One particle as the GPU sees it: 16 bytes.
struct SplatVertex {
  float position[3];
  uint8_t color[4];
};

// One vertex of a shell sheet: 28 bytes.
struct SheetVertex {
  float position[3];
  float normal[3];
  uint8_t color[4];
};

}  // namespace renderer_detail

using renderer_detail::SheetVertex;
using renderer_detail::SplatVertex;

namespace {

constexpr int kMaxImageSize = 16384;  // llvmpipe's renderbuffer limit

glm::dvec3 to_glm(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

std::string vec_str(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%g, %g, %g]", v.x(), v.y(), v.z());
  return buf;
}

// Shell bodies with a sheet are drawn as that sheet, not as particles, unless hidden.
bool drawn_as_sheet(const BodyView& body) {
  return !body.sheet.empty() && body.render != RenderMode::Hidden;
}

bool diverging(const std::string& colormap) {
  return colormap == "coolwarm";
}

bool valid_range(const std::pair<double, double>& r) {
  return r.first < r.second && std::isfinite(r.first) && std::isfinite(r.second);
}

// What one camera draws with (RenderSettings::*_of): its field, colormap, fixed range, hidden bodies, clip.
struct Look {
  const std::string& color_by;
  const std::string& colormap;
  std::optional<std::pair<double, double>> range;
  std::vector<int> hide;  // sorted, unique
  const Clip* clip;
  Look(const RenderSettings& s, const Camera& c)
      : color_by(s.color_by_of(c)),
        colormap(s.colormap_of(c)),
        range(s.range_of(c)),
        hide(c.hide),
        clip(s.clip_of(c)) {
    std::sort(hide.begin(), hide.end());
    hide.erase(std::unique(hide.begin(), hide.end()), hide.end());
  }
  bool hides(std::size_t b) const {
    return std::binary_search(hide.begin(), hide.end(), static_cast<int>(b));
  }
};

// Cameras that colour alike share a range chosen at run time: same field, colormap and hidden bodies.
using RangeKey = std::tuple<std::string, std::string, std::vector<int>>;

}  // namespace

int msaa_samples() {
  if (const char* env = std::getenv("AORTASPH_MSAA"); env && *env) {
    const int n = std::atoi(env);
    if (n == 1 || n == 2 || n == 4 || n == 8) return n;
  }
  return kMsaaSamples;
}

void validate_camera(const Camera& camera) {
  const std::string who = "render.cameras \"" + camera.name + "\": ";
  const Vec3 dir = camera.target - camera.eye;
  if (!(dir.norm() > 0.0))
    throw RenderError(who + "eye and target are the same point " + vec_str(camera.eye));
  if (!(camera.up.norm() > 0.0)) throw RenderError(who + "up is the zero vector");
  if (dir.normalized().cross(camera.up.normalized()).norm() < 1e-6)
    throw RenderError(who + "the view direction " + vec_str(dir) + " is parallel to up " +
                      vec_str(camera.up) + " (choose another up vector)");
  if (!(camera.fov_deg > 0.0 && camera.fov_deg < 180.0))
    throw RenderError(who + "fov_deg must be in (0, 180), got " + std::to_string(camera.fov_deg));
}

void validate_render_settings(const RenderSettings& s) {
  for (const auto& [value, key] : {std::pair{s.width, "width"}, std::pair{s.height, "height"}}) {
    if (value <= 0 || value % 2 != 0 || value > kMaxImageSize)
      throw RenderError(std::string("render.") + key + ": must be a positive even number up to " +
                        std::to_string(kMaxImageSize) + " (video encoders need even sizes), got " +
                        std::to_string(value));
  }
  for (int c = 0; c < 3; ++c)
    if (!(s.background[c] >= 0.0 && s.background[c] <= 1.0))
      throw RenderError("render.background: components must be in [0, 1], got " + vec_str(s.background));
  Colormap check(s.colormap);  // throws for an unknown name
  if (s.color_by.empty()) throw RenderError("render.color_by: empty");
  if (s.range && !valid_range(*s.range))
    throw RenderError("render.range: expected [min, max] with min < max");
  if (s.clip && !(s.clip->normal.norm() > 0.0)) throw RenderError("render.clip.normal: zero vector");
  for (std::size_t c = 0; c < s.cameras.size(); ++c) {
    const Camera& camera = s.cameras[c];
    validate_camera(camera);
    const std::string at = "render.cameras[" + std::to_string(c) + "].";
    if (camera.colormap) {
      const auto names = Colormap::names();
      if (std::find(names.begin(), names.end(), *camera.colormap) == names.end())
        throw RenderError(at + "colormap: unknown colormap \"" + *camera.colormap +
                          "\" (known: viridis, coolwarm)");
    }
    if (camera.color_by && camera.color_by->empty()) throw RenderError(at + "color_by: empty");
    if (camera.range && !valid_range(*camera.range))
      throw RenderError(at + "range: expected [min, max] with min < max");
  }
}

struct Renderer::Impl {
  RenderSettings settings;
  std::map<RangeKey, std::pair<double, double>> ranges;  // chosen at run time, kept for the run
  GlContext context;
  GLuint splat_program = 0, mesh_program = 0, sheet_program = 0;
  GLuint splat_vao = 0, mesh_vao = 0, splat_vbo = 0, mesh_vbo = 0, mesh_ebo = 0;
  GLuint sheet_vao = 0, sheet_vbo = 0, sheet_ebo = 0;
  GLuint ms_fbo = 0, ms_color = 0, ms_depth = 0, resolve_fbo = 0, resolve_color = 0;
  float max_point_size = 64.0f;
  std::vector<SplatVertex> splats;          // reused between frames
  std::vector<SheetVertex> sheet_vertices;  // all sheets of a frame, reused
  std::vector<std::array<uint32_t, 3>> sheet_triangles;
  std::vector<std::pair<std::size_t, std::size_t>> sheet_ranges;  // per drawn sheet: first triangle, count
  std::vector<uint8_t> sheet_clipped;                             // per drawn sheet
  std::vector<uint8_t> rows;                                      // read-back buffer, reused

  explicit Impl(const RenderSettings& s) : settings(s) {
    splat_program = build_program("shaders/splat.vert.glsl", shaders::splat_vert_glsl,
                                  "shaders/splat.frag.glsl", shaders::splat_frag_glsl);
    mesh_program = build_program("shaders/mesh.vert.glsl", shaders::mesh_vert_glsl, "shaders/mesh.frag.glsl",
                                 shaders::mesh_frag_glsl);
    sheet_program = build_program("shaders/sheet.vert.glsl", shaders::sheet_vert_glsl,
                                  "shaders/sheet.frag.glsl", shaders::sheet_frag_glsl);
    GLfloat range_px[2] = {1, 64};
    glGetFloatv(GL_POINT_SIZE_RANGE, range_px);
    max_point_size = range_px[1];

    glGenVertexArrays(1, &splat_vao);
    glGenBuffers(1, &splat_vbo);
    glBindVertexArray(splat_vao);
    glBindBuffer(GL_ARRAY_BUFFER, splat_vbo);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(SplatVertex), nullptr);
    glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(SplatVertex),
                          reinterpret_cast<void*>(offsetof(SplatVertex, color)));
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);

    glGenVertexArrays(1, &mesh_vao);
    glGenBuffers(1, &mesh_vbo);
    glGenBuffers(1, &mesh_ebo);
    glBindVertexArray(mesh_vao);
    glBindBuffer(GL_ARRAY_BUFFER, mesh_vbo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh_ebo);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
    glEnableVertexAttribArray(0);

    glGenVertexArrays(1, &sheet_vao);
    glGenBuffers(1, &sheet_vbo);
    glGenBuffers(1, &sheet_ebo);
    glBindVertexArray(sheet_vao);
    glBindBuffer(GL_ARRAY_BUFFER, sheet_vbo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, sheet_ebo);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(SheetVertex), nullptr);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(SheetVertex),
                          reinterpret_cast<void*>(offsetof(SheetVertex, normal)));
    glVertexAttribPointer(2, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(SheetVertex),
                          reinterpret_cast<void*>(offsetof(SheetVertex, color)));
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glEnableVertexAttribArray(2);

    const int w = settings.width, h = settings.height;
    GLint max_samples = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    const int samples = std::min(msaa_samples(), static_cast<int>(max_samples));
    glGenFramebuffers(1, &ms_fbo);
    glGenRenderbuffers(1, &ms_color);
    glGenRenderbuffers(1, &ms_depth);
    glBindRenderbuffer(GL_RENDERBUFFER, ms_color);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, ms_depth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, ms_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, ms_color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, ms_depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw RenderError("OpenGL: multisampled framebuffer of " + std::to_string(w) + "x" + std::to_string(h) +
                        " is incomplete");
    glGenFramebuffers(1, &resolve_fbo);
    glGenRenderbuffers(1, &resolve_color);
    glBindRenderbuffer(GL_RENDERBUFFER, resolve_color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_color);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw RenderError("OpenGL: resolve framebuffer is incomplete");
    glEnable(GL_PROGRAM_POINT_SIZE);
    check_gl("renderer setup");
  }

  ~Impl() {
    // The context may not be current on this thread any more (another Renderer drew since): make it so,
    // then free; errors here are ignored, the context is going away anyway.
    try {
      context.make_current();
    } catch (...) {
      return;
    }
    glDeleteProgram(splat_program);
    glDeleteProgram(mesh_program);
    glDeleteProgram(sheet_program);
    const GLuint buffers[] = {splat_vbo, mesh_vbo, mesh_ebo, sheet_vbo, sheet_ebo};
    glDeleteBuffers(5, buffers);
    const GLuint vaos[] = {splat_vao, mesh_vao, sheet_vao};
    glDeleteVertexArrays(3, vaos);
    const GLuint fbos[] = {ms_fbo, resolve_fbo};
    glDeleteFramebuffers(2, fbos);
    const GLuint rbs[] = {ms_color, ms_depth, resolve_color};
    glDeleteRenderbuffers(3, rbs);
  }

  // The field a camera colours by, or nullptr for body colours (color_by "material", or a snapshot without
  // that field's values).
  static const SnapshotField* field_of(const Snapshot& snap, const Look& look) {
    if (look.color_by == "material") return nullptr;
    const SnapshotField* f = snap.field(look.color_by);
    return f && !f->values.empty() ? f : nullptr;
  }

  static RangeKey key_of(const Look& look) { return {look.color_by, look.colormap, look.hide}; }

  // The camera's range: its fixed one, or the one chosen for its kind of look; empty for body colours.
  std::optional<std::pair<double, double>> range_of(const Look& look) const {
    if (look.color_by == "material") return std::nullopt;
    if (look.range) return look.range;
    const auto it = ranges.find(key_of(look));
    if (it == ranges.end()) return std::nullopt;
    return it->second;
  }

  // Without a fixed range, the range is chosen at the first snapshot whose field, over the particles the
  // camera draws (clip aside), is not constant, and kept for the run. Fields that never go negative (speed,
  // stress, displacement) start at 0; diverging maps get a range symmetric about 0 so that the neutral
  // colour means zero.
  void choose_range(const Snapshot& snap, const Look& look, const SnapshotField* field) {
    if (!field || look.range || ranges.count(key_of(look))) return;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (size_t i = 0; i < snap.size(); ++i) {
      const int b = snap.body[i];
      if (b >= static_cast<int>(snap.bodies.size()) ||
          (snap.bodies[b].render != RenderMode::Particles && !drawn_as_sheet(snap.bodies[b])) ||
          look.hides(b))
        continue;
      const double v = field->values[i];
      if (!std::isfinite(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    if (!(hi > lo)) return;
    if (diverging(look.colormap)) {
      const double m = std::max(std::abs(lo), std::abs(hi));
      ranges[key_of(look)] = {-m, m};
    } else {
      ranges[key_of(look)] = {std::min(lo, 0.0), hi};
    }
  }

  // Array sizes first: everything after indexes by particle.
  static void check_sizes(const Snapshot& snap, const SnapshotField* field) {
    const size_t n = snap.size();
    if (snap.position.size() != 3 * n)
      throw RenderError("snapshot: " + std::to_string(snap.position.size()) + " coordinates for " +
                        std::to_string(n) + " particles");
    if (field && field->values.size() != n)
      throw RenderError("snapshot: field \"" + field->name + "\" has " +
                        std::to_string(field->values.size()) + " values for " + std::to_string(n) +
                        " particles");
  }

  void build_splats(const Snapshot& snap, const Look& look, const SnapshotField* field) {
    const size_t n = snap.size();
    const size_t nb = snap.bodies.size();
    std::vector<uint8_t> draw(nb, 0), clipped(nb, 0);
    std::vector<std::array<uint8_t, 4>> body_color(nb);
    for (size_t b = 0; b < nb; ++b) {
      draw[b] =
          snap.bodies[b].render == RenderMode::Particles && snap.bodies[b].sheet.empty() && !look.hides(b);
      for (int c = 0; c < 3; ++c)
        body_color[b][c] =
            static_cast<uint8_t>(std::lround(std::clamp(snap.bodies[b].color[c], 0.0f, 1.0f) * 255.0f));
      body_color[b][3] = 255;
    }
    glm::dvec3 clip_n(0.0), clip_p(0.0);
    if (look.clip) {
      clip_n = glm::normalize(to_glm(look.clip->normal));
      clip_p = to_glm(look.clip->point);
      for (int b : look.clip->bodies)
        if (b >= 0 && static_cast<size_t>(b) < nb) clipped[b] = 1;
    }
    const auto range = range_of(look);
    std::optional<Colormap> colormap;
    if (field) colormap.emplace(look.colormap);
    const double lo = range ? range->first : 0.0;
    const double inv = range ? 1.0 / (range->second - range->first) : 0.0;
    splats.clear();
    splats.reserve(n);
    for (size_t i = 0; i < n; ++i) {
      const size_t b = snap.body[i];
      if (b >= nb)
        throw RenderError("snapshot: particle " + std::to_string(i) + " belongs to body " +
                          std::to_string(b) + " but there are " + std::to_string(nb) + " bodies");
      if (!draw[b]) continue;
      const float* p = &snap.position[3 * i];
      if (clipped[b] &&
          clip_n.x * (p[0] - clip_p.x) + clip_n.y * (p[1] - clip_p.y) + clip_n.z * (p[2] - clip_p.z) > 0.0)
        continue;
      SplatVertex v;
      std::memcpy(v.position, p, sizeof v.position);
      if (field) {
        // Before a range exists (constant field so far) every value maps to the bottom of the map.
        const auto c = (*colormap)((field->values[i] - lo) * inv);
        v.color[0] = c[0];
        v.color[1] = c[1];
        v.color[2] = c[2];
        v.color[3] = 255;
      } else {
        std::memcpy(v.color, body_color[b].data(), 4);
      }
      splats.push_back(v);
    }
  }

  // The sheets of the shell bodies the camera draws: each sheet's particles as vertices, with normals summed
  // from the triangles at the current positions (area weighted) and the colour of their particle.
  void build_sheets(const Snapshot& snap, const Look& look, const SnapshotField* field) {
    sheet_vertices.clear();
    sheet_triangles.clear();
    sheet_ranges.clear();
    sheet_clipped.clear();
    const size_t n = snap.size();
    const auto range = range_of(look);
    std::optional<Colormap> colormap;
    if (field) colormap.emplace(look.colormap);
    const double lo = range ? range->first : 0.0;
    const double inv = range ? 1.0 / (range->second - range->first) : 0.0;
    std::vector<uint32_t> local(n, std::numeric_limits<uint32_t>::max());
    std::vector<glm::vec3> normal;
    for (size_t b = 0; b < snap.bodies.size(); ++b) {
      const BodyView& body = snap.bodies[b];
      if (!drawn_as_sheet(body) || look.hides(b)) continue;
      const size_t first_vertex = sheet_vertices.size(), first_triangle = sheet_triangles.size();
      std::array<uint8_t, 4> body_color;
      for (int c = 0; c < 3; ++c)
        body_color[c] = static_cast<uint8_t>(std::lround(std::clamp(body.color[c], 0.0f, 1.0f) * 255.0f));
      body_color[3] = 255;
      for (const auto& t : body.sheet) {
        std::array<uint32_t, 3> lt;
        for (int c = 0; c < 3; ++c) {
          const uint32_t i = t[c];
          if (i >= n || snap.body[i] != b)
            throw RenderError("snapshot: sheet of body \"" + body.name + "\" indexes particle " +
                              std::to_string(i) + ", not one of its own");
          if (local[i] == std::numeric_limits<uint32_t>::max()) {
            local[i] = static_cast<uint32_t>(sheet_vertices.size() - first_vertex);
            SheetVertex v{};
            std::memcpy(v.position, &snap.position[3 * i], sizeof v.position);
            if (field) {
              const auto col = (*colormap)((field->values[i] - lo) * inv);
              v.color[0] = col[0];
              v.color[1] = col[1];
              v.color[2] = col[2];
              v.color[3] = 255;
            } else {
              std::memcpy(v.color, body_color.data(), 4);
            }
            sheet_vertices.push_back(v);
          }
          lt[c] = local[i];
        }
        sheet_triangles.push_back(lt);
      }
      // Area-weighted vertex normals (the cross product's length is twice the area).
      normal.assign(sheet_vertices.size() - first_vertex, glm::vec3(0.0f));
      for (size_t k = first_triangle; k < sheet_triangles.size(); ++k) {
        const auto& t = sheet_triangles[k];
        const glm::vec3 a = glm::make_vec3(sheet_vertices[first_vertex + t[0]].position);
        const glm::vec3 bb = glm::make_vec3(sheet_vertices[first_vertex + t[1]].position);
        const glm::vec3 c = glm::make_vec3(sheet_vertices[first_vertex + t[2]].position);
        const glm::vec3 fn = glm::cross(bb - a, c - a);
        for (uint32_t v : t) normal[v] += fn;
      }
      for (size_t v = 0; v < normal.size(); ++v) {
        const float len = glm::length(normal[v]);
        const glm::vec3 nv = len > 0.0f ? normal[v] / len : glm::vec3(0.0f, 0.0f, 1.0f);
        std::memcpy(sheet_vertices[first_vertex + v].normal, glm::value_ptr(nv), sizeof(float) * 3);
      }
      // Vertex indices of this sheet into the shared vertex array; reset the map for the next body.
      for (size_t k = first_triangle; k < sheet_triangles.size(); ++k)
        for (uint32_t& v : sheet_triangles[k]) v += static_cast<uint32_t>(first_vertex);
      for (const auto& t : body.sheet)
        for (uint32_t i : t) local[i] = std::numeric_limits<uint32_t>::max();
      sheet_ranges.emplace_back(first_triangle, sheet_triangles.size() - first_triangle);
      sheet_clipped.push_back(look.clip && std::count(look.clip->bodies.begin(), look.clip->bodies.end(),
                                                      static_cast<int>(b)) > 0);
    }
  }

  // Near and far planes enclosing everything drawn, so depth precision follows the scene's scale.
  std::pair<double, double> depth_bounds(const Snapshot& snap, const Look& look, const glm::dvec3& eye,
                                         const glm::dvec3& dir) {
    double dmin = std::numeric_limits<double>::infinity(), dmax = -dmin;
    auto add = [&](const float* p) {
      const double d = (p[0] - eye.x) * dir.x + (p[1] - eye.y) * dir.y + (p[2] - eye.z) * dir.z;
      dmin = std::min(dmin, d);
      dmax = std::max(dmax, d);
    };
    for (const SplatVertex& v : splats) add(v.position);
    for (const SheetVertex& v : sheet_vertices) add(v.position);
    for (size_t b = 0; b < snap.bodies.size(); ++b)
      if (snap.bodies[b].render == RenderMode::Surface && !look.hides(b))
        for (const auto& p : snap.bodies[b].mesh.vertices) add(p.data());
    const double margin = snap.spacing + 1e-6;
    if (!(dmax > 0.0)) return {0.01, 1.0};  // nothing in front of the camera
    const double far = dmax + margin;
    const double near = std::max(dmin - margin, far * 1e-4);
    return {near, far};
  }

  Image render(const Snapshot& snap, const Camera& camera) {
    validate_camera(camera);
    context.make_current();
    const Look look(settings, camera);
    const SnapshotField* field = field_of(snap, look);
    check_sizes(snap, field);
    choose_range(snap, look, field);
    build_splats(snap, look, field);
    build_sheets(snap, look, field);

    const int w = settings.width, h = settings.height;
    const glm::dvec3 eye = to_glm(camera.eye), target = to_glm(camera.target);
    const glm::dvec3 dir = glm::normalize(target - eye);
    const auto [near, far] = depth_bounds(snap, look, eye, dir);
    const glm::mat4 view = glm::mat4(glm::lookAt(eye, target, to_glm(camera.up)));
    const glm::mat4 proj =
        glm::mat4(glm::perspective(glm::radians(camera.fov_deg), static_cast<double>(w) / h, near, far));
    const float* light = Lighting::kLightDir;

    glBindFramebuffer(GL_FRAMEBUFFER, ms_fbo);
    glViewport(0, 0, w, h);
    glClearColor(static_cast<float>(settings.background.x()), static_cast<float>(settings.background.y()),
                 static_cast<float>(settings.background.z()), 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glEnable(GL_MULTISAMPLE);

    if (!splats.empty()) {
      glUseProgram(splat_program);
      glUniformMatrix4fv(glGetUniformLocation(splat_program, "u_view"), 1, GL_FALSE, glm::value_ptr(view));
      glUniformMatrix4fv(glGetUniformLocation(splat_program, "u_proj"), 1, GL_FALSE, glm::value_ptr(proj));
      glUniform1f(glGetUniformLocation(splat_program, "u_radius"), static_cast<float>(snap.spacing * 0.5));
      glUniform2f(glGetUniformLocation(splat_program, "u_viewport"), static_cast<float>(w),
                  static_cast<float>(h));
      glUniform1f(glGetUniformLocation(splat_program, "u_max_point_size"), max_point_size);
      glUniform3fv(glGetUniformLocation(splat_program, "u_light_dir"), 1, light);
      glUniform1f(glGetUniformLocation(splat_program, "u_ambient"), Lighting::kAmbient);
      glUniform1f(glGetUniformLocation(splat_program, "u_diffuse"), Lighting::kDiffuse);
      glUniform1f(glGetUniformLocation(splat_program, "u_specular"), Lighting::kSpecular);
      // splat.frag.glsl raises the specular term to the 24th power by squaring (no pow() per fragment).
      static_assert(Lighting::kShininess == 24.0f, "splat.frag.glsl hard-codes the shininess 24");
      const glm::vec3 half_vec = glm::normalize(glm::vec3(light[0], light[1], light[2] + 1.0f));
      glUniform3fv(glGetUniformLocation(splat_program, "u_half_vec"), 1, glm::value_ptr(half_vec));
      glBindVertexArray(splat_vao);
      glBindBuffer(GL_ARRAY_BUFFER, splat_vbo);
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(splats.size() * sizeof(SplatVertex)),
                   splats.data(), GL_STREAM_DRAW);
      glDepthMask(GL_TRUE);
      glDisable(GL_BLEND);
      glEnable(GL_SAMPLE_ALPHA_TO_COVERAGE);
      glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(splats.size()));
      glDisable(GL_SAMPLE_ALPHA_TO_COVERAGE);
    }

    // Opaque shell sheets, two-sided lit, with depth writes like the splats.
    if (!sheet_triangles.empty()) {
      glUseProgram(sheet_program);
      glUniformMatrix4fv(glGetUniformLocation(sheet_program, "u_view"), 1, GL_FALSE, glm::value_ptr(view));
      glUniformMatrix4fv(glGetUniformLocation(sheet_program, "u_proj"), 1, GL_FALSE, glm::value_ptr(proj));
      glUniform3fv(glGetUniformLocation(sheet_program, "u_light_dir"), 1, light);
      glUniform1f(glGetUniformLocation(sheet_program, "u_ambient"), Lighting::kAmbient);
      glUniform1f(glGetUniformLocation(sheet_program, "u_diffuse"), Lighting::kDiffuse);
      glUniform1f(glGetUniformLocation(sheet_program, "u_specular"), Lighting::kSpecular);
      glUniform1f(glGetUniformLocation(sheet_program, "u_shininess"), Lighting::kShininess);
      glm::vec4 plane(0.0f);
      if (look.clip) {
        const glm::dvec3 cn = glm::normalize(to_glm(look.clip->normal));
        plane = glm::vec4(glm::vec3(cn), static_cast<float>(-glm::dot(cn, to_glm(look.clip->point))));
      }
      glUniform4fv(glGetUniformLocation(sheet_program, "u_clip_plane"), 1, glm::value_ptr(plane));
      glBindVertexArray(sheet_vao);
      glBindBuffer(GL_ARRAY_BUFFER, sheet_vbo);
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(sheet_vertices.size() * sizeof(SheetVertex)),
                   sheet_vertices.data(), GL_STREAM_DRAW);
      glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                   static_cast<GLsizeiptr>(sheet_triangles.size() * sizeof(sheet_triangles[0])),
                   sheet_triangles.data(), GL_STREAM_DRAW);
      glDepthMask(GL_TRUE);
      glDisable(GL_BLEND);
      glDisable(GL_CULL_FACE);
      for (size_t k = 0; k < sheet_ranges.size(); ++k) {
        if (sheet_clipped[k])
          glEnable(GL_CLIP_DISTANCE0);
        else
          glDisable(GL_CLIP_DISTANCE0);
        glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * sheet_ranges[k].second), GL_UNSIGNED_INT,
                       reinterpret_cast<void*>(3 * sizeof(uint32_t) * sheet_ranges[k].first));
      }
      glDisable(GL_CLIP_DISTANCE0);
    }

    // Translucent surfaces after the opaque splats, without depth writes, so particles behind a wall show
    // through it and overlapping wall layers all contribute.
    bool any_mesh = false;
    for (size_t b = 0; b < snap.bodies.size(); ++b)
      any_mesh |=
          snap.bodies[b].render == RenderMode::Surface && !snap.bodies[b].mesh.empty() && !look.hides(b);
    if (any_mesh) {
      glUseProgram(mesh_program);
      glUniformMatrix4fv(glGetUniformLocation(mesh_program, "u_view"), 1, GL_FALSE, glm::value_ptr(view));
      glUniformMatrix4fv(glGetUniformLocation(mesh_program, "u_proj"), 1, GL_FALSE, glm::value_ptr(proj));
      glUniform3fv(glGetUniformLocation(mesh_program, "u_light_dir"), 1, light);
      glUniform1f(glGetUniformLocation(mesh_program, "u_ambient"), Lighting::kAmbient);
      glUniform1f(glGetUniformLocation(mesh_program, "u_diffuse"), Lighting::kDiffuse);
      glUniform1f(glGetUniformLocation(mesh_program, "u_alpha"), Lighting::kMeshAlpha);
      glm::vec4 plane(0.0f);
      if (look.clip) {
        const glm::dvec3 n = glm::normalize(to_glm(look.clip->normal));
        plane = glm::vec4(glm::vec3(n), static_cast<float>(-glm::dot(n, to_glm(look.clip->point))));
      }
      glUniform4fv(glGetUniformLocation(mesh_program, "u_clip_plane"), 1, glm::value_ptr(plane));
      glBindVertexArray(mesh_vao);
      // GL_ARRAY_BUFFER is global state, not part of the VAO: the splat buffer may still be bound.
      glBindBuffer(GL_ARRAY_BUFFER, mesh_vbo);
      glDepthMask(GL_FALSE);
      glEnable(GL_BLEND);
      glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
      glDisable(GL_CULL_FACE);
      for (size_t b = 0; b < snap.bodies.size(); ++b) {
        const BodyView& body = snap.bodies[b];
        if (body.render != RenderMode::Surface || body.mesh.empty() || look.hides(b)) continue;
        const size_t nv = body.mesh.vertices.size();
        for (const auto& t : body.mesh.triangles)
          if (t[0] >= nv || t[1] >= nv || t[2] >= nv)
            throw RenderError("snapshot: mesh of body \"" + body.name + "\" indexes a missing vertex");
        const bool clip = look.clip && std::count(look.clip->bodies.begin(), look.clip->bodies.end(),
                                                  static_cast<int>(b)) > 0;
        if (clip)
          glEnable(GL_CLIP_DISTANCE0);
        else
          glDisable(GL_CLIP_DISTANCE0);
        glUniform3f(glGetUniformLocation(mesh_program, "u_color"), body.color[0], body.color[1],
                    body.color[2]);
        glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(nv * sizeof(body.mesh.vertices[0])),
                     body.mesh.vertices.data(), GL_STREAM_DRAW);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                     static_cast<GLsizeiptr>(body.mesh.triangles.size() * sizeof(body.mesh.triangles[0])),
                     body.mesh.triangles.data(), GL_STREAM_DRAW);
        glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * body.mesh.triangles.size()), GL_UNSIGNED_INT,
                       nullptr);
      }
      glDisable(GL_CLIP_DISTANCE0);
      glDisable(GL_BLEND);
      glDepthMask(GL_TRUE);
    }

    // Resolve the samples, then read back; GL rows run bottom-up, images top-down.
    glBindFramebuffer(GL_READ_FRAMEBUFFER, ms_fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo);
    glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo);
    // RGBA is the framebuffer's own layout, so llvmpipe copies it directly (GL_RGB takes a per-pixel
    // conversion path, measured slower); dropping alpha and flipping rows happen in one pass here.
    rows.resize(static_cast<size_t>(w) * h * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rows.data());
    check_gl("drawing a frame");
    Image image(w, h);
    for (int y = 0; y < h; ++y) {
      const uint8_t* src = rows.data() + static_cast<size_t>(h - 1 - y) * w * 4;
      uint8_t* dst = image.at(0, y);
      for (int x = 0; x < w; ++x, src += 4, dst += 3) {
        dst[0] = src[0];
        dst[1] = src[1];
        dst[2] = src[2];
      }
    }
    return image;
  }
};

namespace {
const RenderSettings& validated(const RenderSettings& s) {
  validate_render_settings(s);
  return s;
}
}  // namespace

Renderer::Renderer(const RenderSettings& settings) : impl_(std::make_unique<Impl>(validated(settings))) {}
Renderer::~Renderer() = default;

Image Renderer::render(const Snapshot& snapshot, const Camera& camera) {
  return impl_->render(snapshot, camera);
}

std::optional<std::pair<double, double>> Renderer::field_range() const {
  return field_range(Camera{});
}

std::optional<std::pair<double, double>> Renderer::field_range(const Camera& camera) const {
  return impl_->range_of(Look(impl_->settings, camera));
}

const RenderSettings& Renderer::settings() const {
  return impl_->settings;
}
std::string Renderer::gl_renderer() const {
  return impl_->context.renderer_name();
}

}  // namespace aortasph
