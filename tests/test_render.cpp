// Renderer tests: golden images with known answers, determinism, the frame pipeline, compare/movie commands
// and bad input. Small images (64..160 px) keep the whole file to a few seconds, also in unoptimised builds.
//
// Golden images live in tests/golden/. They are compared through the same code as `aortasph compare`
// (render/image_compare) with kGoldenTolerance: the largest allowed difference of one colour channel.
// llvmpipe is deterministic, so on one machine the difference is 0; the small allowance absorbs rounding
// differences between Mesa/LLVM versions, while any real change (camera, colour, lighting, size) exceeds it
// by far (proved by the "deliberate change" test). To regenerate the goldens after an intended change, run
//   AORTASPH_UPDATE_GOLDEN=1 ./aortasph_tests "[render]"
// look at the new tests/golden/*.png, and commit them.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "colormap.hpp"
#include "figure.hpp"
#include "gl_context.hpp"
#include "image_compare.hpp"
#include "pipeline.hpp"
#include "render_commands.hpp"
#include "renderer.hpp"

using namespace aortasph;
namespace fs = std::filesystem;

namespace {

constexpr int kGoldenTolerance = 2;

fs::path golden_dir() {
  return fs::path(AORTASPH_TEST_DIR) / "golden";
}

bool updating_goldens() {
  const char* env = std::getenv("AORTASPH_UPDATE_GOLDEN");
  return env && std::string(env) == "1";
}

// Compares with tests/golden/<name> (or rewrites it when updating); returns the difference.
ImageDiff check_golden(const std::string& name, const Image& image) {
  const fs::path path = golden_dir() / name;
  if (updating_goldens()) write_png(path, image);
  const ImageDiff d = compare_images(read_png(path), image);
  INFO(describe(name, d));
  CHECK(d.within(kGoldenTolerance));
  return d;
}

// A fresh folder under the system temp folder, removed again at the end of the test case. The process id
// keeps concurrent test runs (e.g. two build trees) apart.
struct ScratchDir {
  fs::path path;
  explicit ScratchDir(const std::string& name)
      : path(fs::temp_directory_path() / ("aortasph_test_render_" + std::to_string(getpid()) + "_" + name)) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

RenderSettings small_settings(int w, int h) {
  RenderSettings s;
  s.width = w;
  s.height = h;
  s.background = Vec3(0, 0, 0);
  return s;
}

Camera front_camera(double distance = 2.0) {
  Camera c;
  c.name = "front";
  c.eye = Vec3(0, 0, distance);
  c.target = Vec3(0, 0, 0);
  c.fov_deg = 35;
  return c;
}

BodyView body(const std::string& name, std::array<float, 3> color, RenderMode mode = RenderMode::Particles) {
  BodyView b;
  b.name = name;
  b.color = color;
  b.render = mode;
  return b;
}

Snapshot one_splat(std::array<float, 3> color = {0.9f, 0.3f, 0.1f}) {
  Snapshot s;
  s.spacing = 0.5;
  s.position = {0, 0, 0};
  s.body = {0};
  s.bodies.push_back(body("ball", color));
  return s;
}

// A square of side 2 in the plane z = z0, facing +z, as two triangles.
SurfaceMesh square(float z0, float half = 1.0f) {
  SurfaceMesh m;
  m.vertices = {{-half, -half, z0}, {half, -half, z0}, {half, half, z0}, {-half, half, z0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

// Particles along x coloured by a field from 0 to 1 (a colormap strip).
Snapshot strip(int n) {
  Snapshot s;
  s.spacing = 2.0 / n;
  s.fields.push_back({"speed", "m/s", {}});
  s.bodies.push_back(body("strip", {1, 1, 1}));
  for (int i = 0; i < n; ++i) {
    s.position.insert(s.position.end(), {static_cast<float>(-1.0 + (i + 0.5) * s.spacing), 0.0f, 0.0f});
    s.body.push_back(0);
    s.fields[0].values.push_back(static_cast<float>(i) / (n - 1));
  }
  return s;
}

// A small composite scene: a block of "water" particles in a translucent box, a red rigid ball, the box cut
// by a clip plane, and a hidden body that must not appear.
Snapshot composite_scene() {
  Snapshot s;
  s.spacing = 0.1;
  s.bodies = {body("water", {0.2f, 0.45f, 0.9f}), body("ball", {0.85f, 0.2f, 0.15f}),
              body("tank", {0.6f, 0.6f, 0.6f}, RenderMode::Surface),
              body("ghost", {0, 1, 0}, RenderMode::Hidden)};
  for (int x = 0; x < 8; ++x)
    for (int y = 0; y < 4; ++y)
      for (int z = 0; z < 5; ++z) {
        s.position.insert(s.position.end(), {-0.75f + 0.1f * x, -0.45f + 0.1f * y, -0.25f + 0.1f * z});
        s.body.push_back(0);
      }
  s.position.insert(s.position.end(), {0.4f, 0.2f, 0.0f, 0.5f, 0.2f, 0.0f, 0.0f, 0.5f, 0.0f});
  s.body.insert(s.body.end(), {1, 1, 3});
  // Open-top box 1.8 x 1.0 x 0.8 from quads.
  SurfaceMesh& m = s.bodies[2].mesh;
  const float X = 0.9f, Y0 = -0.5f, Y1 = 0.5f, Z = 0.4f;
  auto quad = [&](std::array<float, 3> a, std::array<float, 3> b, std::array<float, 3> c,
                  std::array<float, 3> d) {
    const auto k = static_cast<uint32_t>(m.vertices.size());
    m.vertices.insert(m.vertices.end(), {a, b, c, d});
    m.triangles.push_back({k, k + 1, k + 2});
    m.triangles.push_back({k, k + 2, k + 3});
  };
  quad({-X, Y0, -Z}, {X, Y0, -Z}, {X, Y0, Z}, {-X, Y0, Z});    // floor
  quad({-X, Y0, -Z}, {X, Y0, -Z}, {X, Y1, -Z}, {-X, Y1, -Z});  // back
  quad({-X, Y0, Z}, {X, Y0, Z}, {X, Y1, Z}, {-X, Y1, Z});      // front
  quad({-X, Y0, -Z}, {-X, Y0, Z}, {-X, Y1, Z}, {-X, Y1, -Z});  // left
  quad({X, Y0, -Z}, {X, Y0, Z}, {X, Y1, Z}, {X, Y1, -Z});      // right
  return s;
}

RenderSettings composite_settings() {
  RenderSettings s = small_settings(160, 96);
  s.background = Vec3(1, 1, 1);
  s.clip = Clip{Vec3(0, 0, 0.1), Vec3(0, 0, 1), {2}};
  return s;
}

Camera composite_camera() {
  Camera c;
  c.name = "three_quarter";
  c.eye = Vec3(1.6, 1.3, 2.4);
  c.target = Vec3(0, -0.1, 0);
  c.fov_deg = 40;
  return c;
}

int lum(const uint8_t* p) {
  return p[0] + p[1] + p[2];
}

}  // namespace

TEST_CASE("render: one splat centred in view has the lit colour and a centred, symmetric disc", "[render]") {
  Renderer renderer(small_settings(64, 64));
  const std::array<float, 3> color = {0.9f, 0.3f, 0.1f};
  const Image image = renderer.render(one_splat(color), front_camera());
  check_golden("render_splat.png", image);

  // Near the centre, shade = colour * (ambient + diffuse * n.L) + specular * (n.h)^shininess with the
  // sphere's normal n at each pixel centre (the image centre is a pixel corner, so the four pixels around it
  // are checked).
  const float* L = Lighting::kLightDir;
  const double f = 1.0 / std::tan(17.5 * std::numbers::pi / 180.0);  // proj[1][1]
  const double half_px = 0.25 * f * 64 / 2.0 / 2.0;                  // r * proj11 * height / distance / 2
  const double hn = std::sqrt(L[0] * L[0] + L[1] * L[1] + (L[2] + 1.0) * (L[2] + 1.0));
  for (int y : {31, 32})
    for (int x : {31, 32}) {
      const double px = (x + 0.5 - 32) / half_px, py = (32 - (y + 0.5)) / half_px;
      const double nz = std::sqrt(1 - px * px - py * py);
      const double diffuse = px * L[0] + py * L[1] + nz * L[2];
      const double spec = Lighting::kSpecular *
                          std::pow((px * L[0] + py * L[1] + nz * (L[2] + 1.0)) / hn, Lighting::kShininess);
      for (int c = 0; c < 3; ++c) {
        const double expected =
            255.0 * (color[c] * (Lighting::kAmbient + Lighting::kDiffuse * diffuse) + spec);
        CHECK(std::abs(image.at(x, y)[c] - std::min(255.0, expected)) <= 2.0);
      }
    }
  // The disc: its bounding box is centred and its diameter is the projected one,
  // d = 2 r f / (distance) with f = (h/2) / tan(fov/2) for a sphere of radius r = spacing / 2.
  int x0 = 64, x1 = -1, y0 = 64, y1 = -1;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      if (lum(image.at(x, y)) > 0) {
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
  CHECK(x0 + x1 == 63);
  CHECK(y0 + y1 == 63);
  const double diameter = 2 * half_px;
  CHECK(std::abs((x1 - x0 + 1) - diameter) <= 2.0);
  // Coverage symmetric left/right and top/bottom (silhouette, not shading: the light comes from one side).
  int asym = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 32; ++x) {
      asym += (lum(image.at(x, y)) > 0) != (lum(image.at(63 - x, y)) > 0);
      asym += (lum(image.at(y, x)) > 0) != (lum(image.at(y, 63 - x)) > 0);
    }
  CHECK(asym <= 8);
}

TEST_CASE("render: a translucent lit plane facing the camera has the computed mean colour", "[render]") {
  RenderSettings settings = small_settings(64, 48);
  settings.background = Vec3(0.2, 0.4, 0.6);
  Renderer renderer(settings);
  Snapshot snap;
  snap.bodies.push_back(body("wall", {0.8f, 0.6f, 0.2f}, RenderMode::Surface));
  snap.bodies[0].mesh = square(0.0f, 5.0f);  // fills the view
  const Image image = renderer.render(snap, front_camera());
  check_golden("render_plane.png", image);
  const double a = Lighting::kMeshAlpha;
  const double shade = Lighting::kAmbient + Lighting::kDiffuse * Lighting::kLightDir[2];
  for (int c = 0; c < 3; ++c) {
    double mean = 0;
    for (int i = 0; i < 64 * 48; ++i) mean += image.rgb[3 * i + c];
    mean /= 64 * 48;
    const double expected = 255.0 * (a * snap.bodies[0].color[c] * shade + (1 - a) * settings.background[c]);
    CHECK(std::abs(mean - expected) <= 1.0);
  }
}

TEST_CASE("render: colormap strips through the field path", "[render]") {
  for (const std::string map : {"viridis", "coolwarm"}) {
    RenderSettings settings = small_settings(128, 32);
    settings.color_by = "speed";
    settings.colormap = map;
    settings.range = std::make_pair(0.0, 1.0);
    Renderer renderer(settings);
    Camera cam = front_camera(0.9);  // the strip spans the width
    const Image image = renderer.render(strip(16), cam);
    check_golden("render_strip_" + map + ".png", image);
  }
  // Anchor values of the maps themselves.
  const Colormap viridis("viridis"), coolwarm("coolwarm");
  CHECK(viridis(0.0) == std::array<uint8_t, 3>{68, 1, 84});
  CHECK(viridis(1.0) == std::array<uint8_t, 3>{253, 231, 37});
  CHECK(viridis(0.5) == std::array<uint8_t, 3>{33, 145, 140});
  CHECK(coolwarm(0.5) == std::array<uint8_t, 3>{221, 221, 221});
  CHECK(viridis(-3.0) == viridis(0.0));
  CHECK(viridis(std::nan("")) == viridis(0.0));
}

TEST_CASE("render: composite scene (splats, translucent clipped box, hidden body)", "[render]") {
  Renderer renderer(composite_settings());
  const Snapshot snap = composite_scene();
  const Image image = renderer.render(snap, composite_camera());
  check_golden("render_scene.png", image);
  // The hidden body's bright green never shows.
  int green = 0;
  for (int i = 0; i < image.w * image.h; ++i)
    green += image.rgb[3 * i + 1] > 200 && image.rgb[3 * i] < 80 && image.rgb[3 * i + 2] < 80;
  CHECK(green == 0);
}

TEST_CASE("render: a deliberate change fails the golden comparison", "[render]") {
  const Image golden = read_png(golden_dir() / "render_scene.png");
  {
    Renderer renderer(composite_settings());
    Camera moved = composite_camera();
    moved.eye += Vec3(0.05, 0, 0);  // a few centimetres
    const ImageDiff d = compare_images(golden, renderer.render(composite_scene(), moved));
    INFO(describe("moved camera", d));
    CHECK_FALSE(d.within(kGoldenTolerance));
  }
  {
    Renderer renderer(composite_settings());
    Snapshot recoloured = composite_scene();
    recoloured.bodies[1].color = {0.8f, 0.25f, 0.15f};  // the ball, slightly less red
    const ImageDiff d = compare_images(golden, renderer.render(recoloured, composite_camera()));
    INFO(describe("recoloured ball", d));
    CHECK_FALSE(d.within(kGoldenTolerance));
  }
}

TEST_CASE("render: frames are bitwise identical across renders and renderers", "[render]") {
  const Snapshot snap = composite_scene();
  Renderer first(composite_settings());
  const Image a = first.render(snap, composite_camera());
  const Image b = first.render(snap, composite_camera());
  Renderer second(composite_settings());
  const Image c = second.render(snap, composite_camera());
  CHECK(a == b);
  CHECK(a == c);
  // And the PNG bytes too.
  CHECK(encode_png(a) == encode_png(c));
}

TEST_CASE("render: the field range is chosen once, from the first non-constant field", "[render]") {
  RenderSettings settings = small_settings(32, 32);
  settings.color_by = "speed";
  Renderer renderer(settings);
  Snapshot snap = strip(4);
  snap.fields[0].values = {0, 0, 0, 0};
  renderer.render(snap, front_camera());
  CHECK_FALSE(renderer.field_range().has_value());
  snap.fields[0].values = {0.5f, 1, 2, 3};
  renderer.render(snap, front_camera());
  REQUIRE(renderer.field_range().has_value());
  CHECK(renderer.field_range()->first == 0.0);  // speeds start at 0
  CHECK(renderer.field_range()->second == 3.0);
  snap.fields[0].values = {0, 10, 20, 30};
  renderer.render(snap, front_camera());
  CHECK(renderer.field_range()->second == 3.0);  // kept for the whole run
}

TEST_CASE("render: bad input raises RenderError with a clear message", "[render]") {
  auto message_of = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const RenderError& e) {
      return e.what();
    }
    return "(no error)";
  };
  RenderSettings s = small_settings(32, 32);
  s.colormap = "rainbow";
  CHECK_THAT(message_of([&] { Renderer r(s); }), Catch::Contains("unknown colormap \"rainbow\""));
  s = small_settings(0, 32);
  CHECK_THAT(message_of([&] { Renderer r(s); }), Catch::Contains("render.width"));
  s = small_settings(32, 31);
  CHECK_THAT(message_of([&] { Renderer r(s); }), Catch::Contains("render.height"));
  Camera along_up = front_camera();
  along_up.eye = Vec3(0, 3, 0);
  CHECK_THAT(message_of([&] { validate_camera(along_up); }), Catch::Contains("parallel to up"));
  s = small_settings(32, 32);
  Renderer renderer(s);
  CHECK_THAT(message_of([&] { renderer.render(one_splat(), along_up); }), Catch::Contains("parallel to up"));
  s.cameras.push_back(along_up);
  CHECK_THAT(message_of([&] {
               ScratchDir dir("bad");
               FramePipeline p(s, dir.path, 0.1);
             }),
             Catch::Contains("parallel to up"));
  Snapshot broken = one_splat();
  broken.body = {5};
  CHECK_THAT(message_of([&] { renderer.render(broken, front_camera()); }), Catch::Contains("body 5"));

  RenderSettings by_speed = small_settings(32, 32);
  by_speed.color_by = "speed";
  Renderer speed_renderer(by_speed);
  Snapshot short_field = strip(4);
  short_field.fields[0].values.pop_back();
  CHECK_THAT(message_of([&] { speed_renderer.render(short_field, front_camera()); }),
             Catch::Contains("3 values for 4 particles"));

  // A shader that fails to compile names its file and line.
  GlContext context;
  const std::string vert = "#version 330 core\nvoid main() { gl_Position = vec4(0.0); }\n";
  const std::string frag = "#version 330 core\nout vec4 c;\nvoid main() {\n  c = vec4(undefined_thing);\n}\n";
  const std::string msg =
      message_of([&] { build_program("shaders/ok.vert.glsl", vert, "shaders/bad.frag.glsl", frag); });
  CHECK_THAT(msg, Catch::Contains("shaders/bad.frag.glsl:4:"));
  CHECK_THAT(msg, Catch::Contains("undefined_thing"));
}

TEST_CASE("render: PNG write/read round trip, a failed write leaves no file", "[render]") {
  const ScratchDir scratch("png");
  const fs::path& dir = scratch.path;
  Image image(6, 4, 10, 20, 30);
  image.at(5, 3)[0] = 255;
  write_png(dir / "a.png", image);
  CHECK(read_png(dir / "a.png") == image);
  CHECK_THROWS_AS(write_png(dir / "missing_folder" / "b.png", image), RenderError);
  CHECK_FALSE(fs::exists(dir / "missing_folder"));
  CHECK_THROWS_AS(read_png(dir / "nothing.png"), RenderError);
  std::ofstream(dir / "fake.png") << "not a png";
  CHECK_THROWS_AS(read_png(dir / "fake.png"), RenderError);
}

TEST_CASE("render: frame pipeline writes numbered frames and an even-sized figure", "[render]") {
  const ScratchDir scratch("pipeline");
  const fs::path& out = scratch.path;
  RenderSettings settings = small_settings(96, 64);
  settings.color_by = "speed";
  settings.cameras = {front_camera(3.35), composite_camera()};
  settings.cameras[1].name = "side";
  settings.figures = {Figure{"sheet", "front", {0.0, 0.1, 0.2}, 2}};
  {
    FramePipeline pipeline(settings, out, 0.1);
    for (int k = 0; k < 4; ++k) {
      Snapshot s = strip(12);
      s.frame = k;
      s.time = 0.1 * k;
      for (float& v : s.fields[0].values) v *= static_cast<float>(k + 1);
      pipeline.push(std::move(s));
    }
    pipeline.finish();
    CHECK_FALSE(pipeline.failed());
  }
  for (const std::string cam : {"front", "side"})
    for (int k = 0; k < 4; ++k) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05d.png", k);
      const Image frame = read_png(out / "frames" / cam / name);
      CHECK(frame.w == 96);
      CHECK(frame.h == 64);
    }
  CHECK_FALSE(fs::exists(out / "frames" / "front" / "frame_00004.png"));
  const Image sheet = read_png(out / "figures" / "sheet.png");
  CHECK(sheet.w % 2 == 0);
  CHECK(sheet.h % 2 == 0);
  CHECK(sheet.w > 2 * 96);
  CHECK(sheet.h > 2 * 64);
}

TEST_CASE("render: a render-thread error stops the pipeline with a message", "[render]") {
  RenderSettings settings = small_settings(32, 32);
  settings.cameras = {front_camera()};
  const ScratchDir scratch("pipeline_error");
  FramePipeline pipeline(settings, scratch.path, 0.1);
  Snapshot bad = one_splat();
  bad.body = {7};  // a body that does not exist
  bool threw = false;
  try {
    pipeline.push(bad);
    for (int k = 0; k < 10; ++k) pipeline.push(one_splat());  // soon refused
    pipeline.finish();
  } catch (const RenderError& e) {
    threw = true;
    CHECK_THAT(std::string(e.what()), Catch::Contains("body 7"));
  }
  CHECK(threw);
  CHECK(pipeline.failed());
}

TEST_CASE("render: figure sheet composition labels panels and adds a colour bar", "[render]") {
  CHECK(panel_label(0) == "(a)");
  CHECK(panel_label(5) == "(f)");
  CHECK(panel_label(26) == "(aa)");
  std::vector<FigurePanel> panels;
  for (int k = 0; k < 3; ++k)
    panels.push_back({Image(40, 30, 50 * k, 100, 150), "t = 0." + std::to_string(k) + " s"});
  const Image plain = compose_figure(panels, 2, std::nullopt);
  const Image with_bar = compose_figure(panels, 2, ColorBar{"viridis", 0.0, 1.5, "speed", "m/s"});
  CHECK(plain.w % 2 == 0);
  CHECK(plain.h % 2 == 0);
  CHECK(with_bar.h > plain.h);
  CHECK(with_bar.w == plain.w);
  check_golden("render_figure.png", with_bar);
  CHECK_THROWS_AS(compose_figure({}, 2, std::nullopt), RenderError);
}

TEST_CASE("render: compare command exit codes and messages", "[render]") {
  const ScratchDir scratch("compare");
  const fs::path& dir = scratch.path;
  Image a(8, 8, 100, 100, 100), b = a, c(8, 6, 0, 0, 0);
  b.at(3, 3)[1] = 104;
  write_png(dir / "a.png", a);
  write_png(dir / "b.png", b);
  write_png(dir / "c.png", c);
  const std::string A = (dir / "a.png").string(), B = (dir / "b.png").string();
  CHECK(cmd_compare({A, A}) == 0);
  CHECK(cmd_compare({A, B}) == 1);
  CHECK(cmd_compare({A, B, "--tolerance", "4"}) == 0);
  CHECK(cmd_compare({A, B, "--tolerance", "3", "--diff", (dir / "diff.png").string()}) == 1);
  CHECK(read_png(dir / "diff.png").at(3, 3)[0] > 128);
  CHECK(cmd_compare({A, (dir / "c.png").string()}) == 2);     // size mismatch
  CHECK(cmd_compare({A, (dir / "none.png").string()}) == 2);  // missing
  CHECK(cmd_compare({A, B, "--tolerance", "x"}) == 2);
  CHECK(cmd_compare({A}) == 2);
  // Folders: same names compare pairwise; different sets are bad input.
  fs::create_directories(dir / "x");
  fs::create_directories(dir / "y");
  write_png(dir / "x" / "f.png", a);
  write_png(dir / "y" / "f.png", b);
  CHECK(cmd_compare({(dir / "x").string(), (dir / "y").string()}) == 1);
  CHECK(cmd_compare({(dir / "x").string(), (dir / "y").string(), "--tolerance", "4"}) == 0);
  write_png(dir / "y" / "g.png", b);
  CHECK(cmd_compare({(dir / "x").string(), (dir / "y").string()}) == 2);
}

TEST_CASE("render: movie command", "[render]") {
  const ScratchDir scratch("movie");
  const fs::path& dir = scratch.path;
  CHECK(cmd_movie({dir.string()}) == 2);                // no frames
  CHECK(cmd_movie({(dir / "missing").string()}) == 2);  // no folder
  CHECK(cmd_movie({dir.string(), "--fps", "0"}) == 2);  // bad fps
  fs::create_directories(dir / "frames" / "front");
  for (int k = 0; k < 3; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", k);
    write_png(dir / "frames" / "front" / name, Image(32, 16, 40 * k, 80, 120));
  }
  setenv("AORTASPH_FFMPEG", "/nonexistent/ffmpeg", 1);
  CHECK(cmd_movie({dir.string()}) == 2);  // ffmpeg missing
  unsetenv("AORTASPH_FFMPEG");
  if (std::system("command -v ffmpeg > /dev/null 2>&1") == 0) {
    CHECK(cmd_movie({dir.string(), "--fps", "10"}) == 0);
    CHECK(fs::file_size(dir / "frames" / "front.mp4") > 0);
  }
}

TEST_CASE("render: a short scene run gives identical frames for 1 and 2 threads, matching the golden",
          "[render]") {
  const ScratchDir scratch("run");
  const fs::path scene = scratch.path / "tiny_cubes.json";
  // Two small water cubes flying at each other (the fluid_cubes scene, scaled down to 2 x 216 particles).
  std::ofstream(scene) << R"({
  "name": "tiny_cubes",
  "domain": { "min": [-1, -1, -1], "max": [1, 1, 1] },
  "resolution": { "spacing": 0.01, "smoothing_ratio": 1.3 },
  "time": { "end": 0.01, "output_interval": 0.005, "cfl": 0.25, "max_dt": 1e-3 },
  "gravity": [0, 0, 0],
  "materials": { "water": { "type": "fluid", "density": 1000, "viscosity": 1e-6, "sound_speed": 20 } },
  "bodies": [
    { "name": "left", "material": "water", "shape": { "box": { "min": [-0.07, -0.03, -0.03], "max": [-0.01, 0.03, 0.03] } },
      "velocity": [1, 0, 0], "color": [0.2, 0.45, 0.9] },
    { "name": "right", "material": "water", "shape": { "box": { "min": [0.01, -0.01, -0.03], "max": [0.07, 0.05, 0.03] } },
      "velocity": [-1, 0, 0], "color": [0.9, 0.35, 0.25] }
  ],
  "render": {
    "width": 96, "height": 64, "background": [1, 1, 1], "color_by": "material",
    "cameras": [ { "name": "oblique", "eye": [0.07, 0.08, 0.17], "target": [0, 0.01, 0], "up": [0, 1, 0], "fov_deg": 40 } ]
  }
})";
  for (const std::string threads : {"1", "2"}) {
    const std::string cmd = std::string(AORTASPH_BINARY) + " run " + scene.string() + " --quiet --threads " +
                            threads + " --out " + (scratch.path / ("t" + threads)).string() +
                            " > /dev/null 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
  }
  const fs::path frames1 = scratch.path / "t1" / "frames" / "oblique",
                 frames2 = scratch.path / "t2" / "frames" / "oblique";
  CHECK(png_names(frames1) ==
        std::vector<std::string>{"frame_00000.png", "frame_00001.png", "frame_00002.png"});
  CHECK(cmd_compare({frames1.string(), frames2.string()}) == 0);  // bitwise identical (tolerance 0)
  check_golden("render_run.png", read_png(frames1 / "frame_00002.png"));
}

namespace {

// Two blocks of particles side by side, "left" (blue, x < 0) and "right" (red, x > 0), in front of a
// translucent "glass" square, with speed and pressure fields: left moves at 0..1 m/s (growing with y) under
// pressure 1 Pa, right at 5 m/s under -1 Pa. Particle centres: x = -0.55 .. -0.25 and 0.25 .. 0.55,
// y = -0.25 .. 0.25, step 0.1.
Snapshot two_blocks() {
  Snapshot s;
  s.spacing = 0.1;
  s.bodies = {body("left", {0.2f, 0.45f, 0.9f}), body("right", {0.9f, 0.35f, 0.25f}),
              body("glass", {0.9f, 0.9f, 0.2f}, RenderMode::Surface)};
  s.bodies[2].mesh = square(-0.5f, 5.0f);
  s.fields = {{"speed", "m/s", {}}, {"pressure", "Pa", {}}};
  for (int b = 0; b < 2; ++b)
    for (int x = 0; x < 4; ++x)
      for (int y = 0; y < 6; ++y) {
        s.position.insert(s.position.end(), {(b ? 0.25f : -0.55f) + 0.1f * x, -0.25f + 0.1f * y, 0.0f});
        s.body.push_back(static_cast<uint16_t>(b));
        s.fields[0].values.push_back(b ? 5.0f : static_cast<float>(y) / 5.0f);
        s.fields[1].values.push_back(b ? -1.0f : 1.0f);
      }
  return s;
}

// Centre pixel of the particle block at (x, y) world coordinates for front_camera() (fov 35, distance 2).
std::pair<int, int> pixel_of(double x, double y, int w, int h) {
  const double f = 1.0 / std::tan(17.5 * std::numbers::pi / 180.0) / 2.0;  // per unit at distance 2
  return {static_cast<int>(w / 2.0 + x * f * h / 2.0), static_cast<int>(h / 2.0 - y * f * h / 2.0)};
}

}  // namespace

TEST_CASE("render: per-camera overrides (hide, color_by, colormap, range, clip) change only that camera",
          "[render]") {
  RenderSettings settings = small_settings(96, 64);  // black background, color_by material
  // The run-wide clip removes the upper half (y > 0.05) of "left".
  settings.clip = Clip{Vec3(0, 0.05, 0), Vec3(0, 1, 0), {0}};
  const Camera plain = front_camera();
  Camera overridden = front_camera();
  overridden.name = "overridden";
  overridden.hide = {1, 2};  // right, glass
  overridden.color_by = "pressure";
  overridden.colormap = "coolwarm";
  overridden.range = std::make_pair(-1.0, 1.0);
  Camera unclipped = front_camera();
  unclipped.name = "unclipped";
  unclipped.clip = false;
  // Overrides equal to the run-wide values change nothing.
  Camera same = front_camera();
  same.name = "same";
  same.color_by = "material";
  same.colormap = "viridis";
  same.clip = true;
  settings.cameras = {plain, overridden, unclipped, same};
  Renderer renderer(settings);
  const Snapshot snap = two_blocks();
  const Image a = renderer.render(snap, plain);
  const Image b = renderer.render(snap, overridden);
  const Image c = renderer.render(snap, unclipped);
  CHECK(renderer.render(snap, same) == a);
  CHECK(renderer.render(snap, plain) == a);  // the overridden camera left no state behind

  // Pixels at particle centres (not between two splats).
  const auto [rx, ry] = pixel_of(0.35, -0.05, 96, 64);   // right block
  const auto [lx, ly] = pixel_of(-0.45, -0.15, 96, 64);  // lower (kept) half of left
  const auto [ux, uy] = pixel_of(-0.45, 0.15, 96, 64);   // upper (clipped) half of left
  const auto [gx, gy] = pixel_of(0.0, -0.2, 96, 64);     // only the glass, between the blocks
  auto is_background = [](const Image& im, int x, int y) {
    return im.at(x, y)[0] == 0 && im.at(x, y)[1] == 0 && im.at(x, y)[2] == 0;
  };
  INFO("right " << rx << "," << ry << " left " << lx << "," << ly << " upper " << ux << "," << uy);
  // Hidden bodies: the right block and the glass are drawn by `plain` but not by `overridden`.
  CHECK(a.at(rx, ry)[0] > 2 * a.at(rx, ry)[2]);  // red block
  CHECK(is_background(b, rx, ry));
  CHECK_FALSE(is_background(a, gx, gy));  // the translucent glass over the black background
  CHECK(is_background(b, gx, gy));
  // Colour: body colour (blue) in `plain`; pressure 1 Pa at the top of [-1, 1] in coolwarm (red) in
  // `overridden`.
  CHECK(a.at(lx, ly)[2] > a.at(lx, ly)[0] + 60);
  CHECK(b.at(lx, ly)[0] > b.at(lx, ly)[2] + 60);
  // Clip: the upper half of "left" is cut away except for the camera with clip false.
  CHECK_FALSE(is_background(c, ux, uy));
  CHECK(c.at(ux, uy)[2] > c.at(ux, uy)[0] + 60);  // left's own blue
  CHECK(a.at(ux, uy)[2] < c.at(ux, uy)[2]);       // cut away there
  CHECK(is_background(b, ux, uy));                // clipped, glass hidden
  CHECK(c.at(rx, ry)[0] == a.at(rx, ry)[0]);      // elsewhere the same

  // Ranges: fixed for `overridden`; none for material; chosen at run time otherwise, from the particles the
  // camera draws (hiding the fast right block leaves 0..1 m/s), shared by cameras that colour alike.
  CHECK(renderer.field_range(overridden) == std::make_pair(-1.0, 1.0));
  CHECK_FALSE(renderer.field_range(plain).has_value());
  CHECK_FALSE(renderer.field_range().has_value());
  Camera speed_all = front_camera(), speed_left = front_camera();
  speed_all.color_by = speed_left.color_by = "speed";
  speed_left.hide = {1};
  Camera speed_left_too = speed_left;
  speed_left_too.hide = {1, 1};
  renderer.render(snap, speed_all);
  renderer.render(snap, speed_left);
  CHECK(renderer.field_range(speed_all) == std::make_pair(0.0, 5.0));
  CHECK(renderer.field_range(speed_left) == std::make_pair(0.0, 1.0));
  CHECK(renderer.field_range(speed_left_too) == std::make_pair(0.0, 1.0));
  CHECK_FALSE(renderer.field_range().has_value());  // the run-wide colouring is still "material"

  // A camera whose field the snapshot lacks falls back to body colours, as an empty field always did.
  Snapshot no_pressure = two_blocks();
  no_pressure.fields.pop_back();
  Camera recoloured = front_camera();
  recoloured.color_by = "pressure";
  recoloured.colormap = "coolwarm";
  CHECK(renderer.render(no_pressure, recoloured) == a);
}

TEST_CASE("render: a camera's own colour bar in its figure, other cameras keep the run-wide one",
          "[render]") {
  const ScratchDir scratch("camera_bars");
  const fs::path& out = scratch.path;
  RenderSettings settings = small_settings(96, 64);
  settings.color_by = "speed";
  Camera valve = front_camera();
  valve.name = "valve";
  valve.color_by = "pressure";
  valve.colormap = "coolwarm";
  valve.range = std::make_pair(-2.0, 2.0);
  valve.hide = {1};
  settings.cameras = {front_camera(), valve};
  settings.figures = {Figure{"speed_sheet", "front", {0.0, 0.1}, 2},
                      Figure{"valve_sheet", "valve", {0.0, 0.1}, 2}};
  std::vector<std::optional<std::pair<double, double>>> ranges;
  {
    FramePipeline pipeline(settings, out, 0.1);
    for (int k = 0; k < 2; ++k) {
      Snapshot s = two_blocks();
      s.frame = k;
      s.time = 0.1 * k;
      pipeline.push(std::move(s));
    }
    pipeline.flush();
    ranges = pipeline.camera_ranges();
    pipeline.finish();
    REQUIRE_FALSE(pipeline.failed());
    CHECK(pipeline.field_range() == std::make_pair(0.0, 5.0));
  }
  REQUIRE(ranges.size() == 2);
  CHECK(ranges[0] == std::make_pair(0.0, 5.0));
  CHECK(ranges[1] == std::make_pair(-2.0, 2.0));
  // Each sheet is exactly its camera's frames with its camera's colour bar: field name, unit, colormap and
  // range.
  auto sheet_of = [&](const std::string& camera, const std::optional<ColorBar>& bar) {
    std::vector<FigurePanel> panels;
    panels.push_back({read_png(out / "frames" / camera / "frame_00000.png"), "t = 0 s"});
    panels.push_back({read_png(out / "frames" / camera / "frame_00001.png"), "t = 0.1 s"});
    return compose_figure(panels, 2, bar);
  };
  const ColorBar speed_bar{"viridis", 0.0, 5.0, "speed", "m/s"},
      valve_bar{"coolwarm", -2.0, 2.0, "pressure", "Pa"};
  const Image speed_sheet = read_png(out / "figures" / "speed_sheet.png");
  const Image valve_sheet = read_png(out / "figures" / "valve_sheet.png");
  CHECK(speed_sheet == sheet_of("front", speed_bar));
  CHECK(valve_sheet == sheet_of("valve", valve_bar));
  CHECK_FALSE(valve_sheet == sheet_of("valve", speed_bar));  // the bar is not the run-wide one
}

TEST_CASE("render: a run with per-camera overrides, the camera without them renders as before", "[render]") {
  const ScratchDir scratch("camera_overrides");
  // The scene of the 1-vs-2-threads test above (its "oblique" camera has the golden render_run.png), plus a
  // front camera and the same view hiding "right" and colouring by speed.
  const std::string bodies = R"(
  "name": "tiny_cubes",
  "domain": { "min": [-1, -1, -1], "max": [1, 1, 1] },
  "resolution": { "spacing": 0.01, "smoothing_ratio": 1.3 },
  "time": { "end": 0.01, "output_interval": 0.005, "cfl": 0.25, "max_dt": 1e-3 },
  "gravity": [0, 0, 0],
  "materials": { "water": { "type": "fluid", "density": 1000, "viscosity": 1e-6, "sound_speed": 20 } },
  "bodies": [
    { "name": "left", "material": "water", "shape": { "box": { "min": [-0.07, -0.03, -0.03], "max": [-0.01, 0.03, 0.03] } },
      "velocity": [1, 0, 0], "color": [0.2, 0.45, 0.9] },
    { "name": "right", "material": "water", "shape": { "box": { "min": [0.01, -0.01, -0.03], "max": [0.07, 0.05, 0.03] } },
      "velocity": [-1, 0, 0], "color": [0.9, 0.35, 0.25] }
  ],)";
  const std::string oblique =
      R"({ "name": "oblique", "eye": [0.07, 0.08, 0.17], "target": [0, 0.01, 0], "up": [0, 1, 0], "fov_deg": 40 })";
  const std::string with = "{" + bodies + R"(
  "render": {
    "width": 96, "height": 64, "background": [1, 1, 1], "color_by": "material",
    "cameras": [ )" + oblique +
                           R"(,
      { "name": "front", "eye": [0, 0.01, 0.3], "target": [0, 0.01, 0], "fov_deg": 40 },
      { "name": "front_hide", "eye": [0, 0.01, 0.3], "target": [0, 0.01, 0], "fov_deg": 40,
        "hide": ["right"], "color_by": "speed", "colormap": "coolwarm", "range": [0, 1] } ],
    "figures": [ { "name": "fig_front", "camera": "front", "times": [0, 0.01] },
                 { "name": "fig_hide", "camera": "front_hide", "times": [0, 0.01] } ]
  }
})";
  const std::string without = "{" + bodies + R"(
  "render": { "width": 96, "height": 64, "background": [1, 1, 1], "color_by": "material", "cameras": [ )" +
                              oblique + R"( ] }
})";
  for (const auto& [name, text] : {std::pair{"with", with}, std::pair{"without", without}}) {
    const fs::path scene = scratch.path / (std::string(name) + ".json");
    std::ofstream(scene) << text;
    const std::string cmd = std::string(AORTASPH_BINARY) + " run " + scene.string() + " --quiet --out " +
                            (scratch.path / name).string() + " > /dev/null 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
  }
  const fs::path out = scratch.path / "with";

  // The camera without overrides: bitwise the frames of the run without the other cameras, and the golden.
  CHECK(cmd_compare({(out / "frames" / "oblique").string(),
                     (scratch.path / "without" / "frames" / "oblique").string()}) == 0);
  check_golden("render_run.png", read_png(out / "frames" / "oblique" / "frame_00002.png"));

  // Hide: where `front` shows the red right cube, `front_hide` shows the white background; color_by: where
  // `front` shows the blue left cube, `front_hide` shows speed 1 m/s at the top of coolwarm [0, 1] (red).
  const Image front = read_png(out / "frames" / "front" / "frame_00000.png");
  const Image hide = read_png(out / "frames" / "front_hide" / "frame_00000.png");
  int red = 0, blue = 0, red_not_background = 0, blue_not_recoloured = 0;
  for (int y = 0; y < front.h; ++y)
    for (int x = 0; x < front.w; ++x) {
      const uint8_t *f = front.at(x, y), *h = hide.at(x, y);
      if (f[0] > f[1] + 60 && f[0] > f[2] + 60) {
        ++red;
        red_not_background += !(h[0] == 255 && h[1] == 255 && h[2] == 255);
      }
      if (f[2] > f[0] + 60) {
        ++blue;
        blue_not_recoloured += !(h[0] > h[2] + 20);
      }
    }
  INFO(red << " red pixels, " << blue << " blue pixels");
  CHECK(red > 200);
  CHECK(blue > 200);
  CHECK(red_not_background == 0);
  CHECK(blue_not_recoloured == 0);

  // Figures: `fig_front` (material) has no colour bar; `fig_hide` has the camera's own: speed [m/s],
  // coolwarm, 0..1.
  const Image fig_front = read_png(out / "figures" / "fig_front.png");
  const Image fig_hide = read_png(out / "figures" / "fig_hide.png");
  auto sheet_of = [&](const std::string& camera, const std::optional<ColorBar>& bar) {
    return compose_figure({{read_png(out / "frames" / camera / "frame_00000.png"), "t = 0 s"},
                           {read_png(out / "frames" / camera / "frame_00002.png"), "t = 0.01 s"}},
                          3, bar);
  };
  CHECK(fig_front == sheet_of("front", std::nullopt));
  CHECK(fig_hide == sheet_of("front_hide", ColorBar{"coolwarm", 0.0, 1.0, "speed", "m/s"}));
  CHECK(fig_hide.h > fig_front.h);

  // The resolved scene keeps the cameras as written: absent overrides are not filled in.
  std::ifstream run_json(out / "run.json");
  const auto cameras = nlohmann::json::parse(run_json)["scene"]["render"]["cameras"];
  REQUIRE(cameras.size() == 3);
  for (const char* key : {"color_by", "colormap", "range", "hide", "clip"})
    CHECK_FALSE(cameras[0].contains(key));
  CHECK(cameras[2]["hide"] == nlohmann::json::array({"right"}));
}

TEST_CASE("render: libOSMesa (llvmpipe, libLLVM) is loaded only by a run that draws frames", "[render]") {
  // The renderer opens libOSMesa at its first GL context (render/gl_api.hpp), so that a run without frames
  // does not carry llvmpipe's memory. The dynamic loader's own log (LD_DEBUG=files, glibc) names every
  // library it maps; the rendering run guards that the log is seen at all.
  const ScratchDir scratch("lazy_osmesa");
  const fs::path scene = scratch.path / "tiny.json";
  std::ofstream(scene) << R"({
  "name": "tiny",
  "domain": { "min": [-1, -1, -1], "max": [1, 1, 1] },
  "resolution": { "spacing": 0.01, "smoothing_ratio": 1.3 },
  "time": { "end": 0.002, "output_interval": 0.001, "cfl": 0.25, "max_dt": 1e-3 },
  "gravity": [0, 0, 0],
  "materials": { "water": { "type": "fluid", "density": 1000, "viscosity": 1e-6, "sound_speed": 20 } },
  "bodies": [ { "name": "cube", "material": "water", "shape": { "box": { "min": [0, 0, 0], "max": [0.03, 0.03, 0.03] } } } ],
  "render": { "width": 32, "height": 32,
              "cameras": [ { "name": "c", "eye": [0.1, 0.1, 0.2], "target": [0.015, 0.015, 0.015], "up": [0, 1, 0] } ] }
})";
  const auto loader_log = [&](const std::string& name, const std::string& extra) {
    const fs::path log = scratch.path / (name + ".log");
    const std::string cmd = "LD_DEBUG=files " + std::string(AORTASPH_BINARY) + " run " + scene.string() +
                            " --quiet --out " + (scratch.path / name).string() + extra + " > " +
                            log.string() + " 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
    std::ifstream f(log);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  };
  const std::string drawn = loader_log("drawn", "");
  CHECK(fs::exists(scratch.path / "drawn" / "frames" / "c" / "frame_00002.png"));
  CHECK(drawn.find("libOSMesa") != std::string::npos);
  const std::string plain = loader_log("plain", " --no-render");
  CHECK(plain.find("file=") != std::string::npos);  // the loader's log is there
  CHECK(plain.find("libOSMesa") == std::string::npos);
}
