// Scene loading (SPEC.md section 2) and shape sampling.
#include <catch2/catch.hpp>

#include "errors.hpp"
#include "geometry/shapes.hpp"
#include "scene_loader.hpp"

using namespace aortasph;
using json = nlohmann::json;

namespace {

json good() {
  return json::parse(R"({
    "name": "t",
    "domain": { "min": [-1, -1, -1], "max": [1, 1, 1] },
    "resolution": { "spacing": 0.01 },
    "time": { "end": 0.1, "output_interval": 0.01 },
    "materials": { "water": { "type": "fluid", "density": 1000, "viscosity": 1e-6, "sound_speed": 20 },
                   "rubber": { "type": "elastic", "density": 1100, "youngs_modulus": 2e6, "poisson_ratio": 0.45 },
                   "wall": { "type": "wall" } },
    "bodies": [ { "name": "a", "material": "water", "shape": { "box": { "min": [0, 0, 0], "max": [0.1, 0.1, 0.1] } } },
                { "name": "b", "material": "wall", "shape": { "container": { "min": [0, 0, 0], "max": [0.2, 0.2, 0.1], "open": ["+y"] } } } ],
    "probes": [ { "name": "f", "type": "extent", "bodies": ["a"], "axis": "x", "stat": "max" } ]
  })");
}

std::string error_of(const json& j, const std::vector<std::string>& sets = {}) {
  try {
    load_scene_json(j, sets);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("a valid scene loads with its values and defaults", "[scene]") {
  const LoadedScene l = load_scene_json(good(), {});
  const Scene& s = l.scene;
  CHECK(s.name == "t");
  CHECK(s.spacing == 0.01);
  CHECK(s.smoothing_ratio == 1.3);  // default
  CHECK(s.skin == 0.1);             // default
  CHECK(s.gravity == Vec3(0, -9.81, 0));
  REQUIRE(s.materials.size() == 3);
  CHECK(s.materials[s.bodies[1].material].name == "wall");
  CHECK(s.materials[s.bodies[0].material].type == MaterialType::Fluid);
  CHECK(s.bodies[1].shape.kind == ShapeKind::Container);
  CHECK(s.bodies[1].shape.layers == 3);
  CHECK(s.probes[0].bodies == std::vector<int>{0});
  // Defaults are written into the resolved JSON (run.json).
  CHECK(l.resolved["resolution"]["smoothing_ratio"] == 1.3);
  CHECK(l.resolved["resolution"]["skin"] == 0.1);
  CHECK(l.resolved["materials"]["water"]["eos_exponent"] == 7.0);
}

TEST_CASE("set overrides reach nested keys, list entries and optional keys", "[scene]") {
  const LoadedScene l =
      load_scene_json(good(), {"resolution.spacing=0.004", "bodies.0.velocity=[0,0,-1]",
                               "materials.water.viscosity=2e-6", "bodies.0.color=[1,0,0]", "time.end=0.5"});
  CHECK(l.scene.spacing == 0.004);
  CHECK(l.scene.bodies[0].velocity == Vec3(0, 0, -1));
  CHECK(l.scene.materials[l.scene.bodies[0].material].viscosity == 2e-6);
  REQUIRE(l.scene.bodies[0].color);
  CHECK(*l.scene.bodies[0].color == Vec3(1, 0, 0));
  CHECK(l.resolved["time"]["end"] == 0.5);
}

TEST_CASE("malformed scenes are refused with the JSON path", "[scene][bad-input]") {
  struct Case {
    std::string what;
    std::function<void(json&)> edit;
    std::vector<std::string> sets;
    std::string expect;
  };
  const std::vector<Case> cases = {
      {"missing key", [](json& j) { j["resolution"].erase("spacing"); }, {}, "resolution.spacing: missing"},
      {"wrong type",
       [](json& j) { j["resolution"]["spacing"] = "fine"; },
       {},
       "resolution.spacing: expected a number"},
      {"negative spacing",
       [](json& j) { j["resolution"]["spacing"] = -0.01; },
       {},
       "resolution.spacing: must be positive"},
      {"vector of 2",
       [](json& j) {
         j["bodies"][0]["shape"]["box"]["max"] = {1, 2};
       },
       {},
       "bodies[0].shape.box.max: expected 3 numbers, got 2"},
      {"box inverted",
       [](json& j) {
         j["bodies"][0]["shape"]["box"]["max"] = {-1, 1, 1};
       },
       {},
       "bodies[0].shape.box.max"},
      {"unknown key", [](json& j) { j["resolution"]["spasing"] = 1; }, {}, "resolution.spasing: unknown key"},
      {"unknown material",
       [](json& j) { j["bodies"][0]["material"] = "blood"; },
       {},
       "unknown material 'blood'"},
      {"poisson 0.5",
       [](json& j) { j["materials"]["rubber"]["poisson_ratio"] = 0.5; },
       {},
       "materials.rubber.poisson_ratio"},
      {"poisson -1",
       [](json& j) { j["materials"]["rubber"]["poisson_ratio"] = -1.0; },
       {},
       "materials.rubber.poisson_ratio"},
      {"young 0",
       [](json& j) { j["materials"]["rubber"]["youngs_modulus"] = 0; },
       {},
       "materials.rubber.youngs_modulus"},
      {"density 0", [](json& j) { j["materials"]["water"]["density"] = 0; }, {}, "materials.water.density"},
      {"material type",
       [](json& j) { j["materials"]["water"]["type"] = "gas"; },
       {},
       "materials.water.type: unknown value"},
      {"two shapes",
       [](json& j) {
         j["bodies"][0]["shape"]["sphere"] = {{"center", {0, 0, 0}}, {"radius", 1}};
       },
       {},
       "bodies[0].shape: expected exactly one shape"},
      {"duplicate body", [](json& j) { j["bodies"][1]["name"] = "a"; }, {}, "duplicate body name"},
      {"probe body",
       [](json& j) { j["probes"][0]["bodies"] = {"zz"}; },
       {},
       "probes[0].bodies[0]: unknown body 'zz'"},
      {"probe axis", [](json& j) { j["probes"][0]["axis"] = "w"; }, {}, "probes[0].axis"},
      {"open face",
       [](json& j) { j["bodies"][1]["shape"]["container"]["open"] = {"up"}; },
       {},
       "open[0]: unknown face"},
      {"negative contact",
       [](json& j) {
         j["contact"] = {{"stiffness", -1}};
       },
       {},
       "contact.stiffness"},
      {"negative fluid barrier",
       [](json& j) {
         j["contact"] = {{"shell_fluid_barrier", -0.5}};
       },
       {},
       "contact.shell_fluid_barrier"},
      {"cfl", [](json& j) { j["time"]["cfl"] = 2; }, {}, "time.cfl"},
      {"odd width",
       [](json& j) {
         j["render"] = {{"width", 101}};
       },
       {},
       "render.width: must be even"},
      {"camera along up",
       [](json& j) {
         j["render"] = {{"cameras", {{{"name", "c"}, {"eye", {0, 1, 0}}, {"target", {0, 0, 0}}}}}};
       },
       {},
       "render.cameras[0].up"},
      {"figure camera",
       [](json& j) {
         j["render"] = {{"figures", {{{"name", "f"}, {"camera", "x"}, {"times", {0}}}}}};
       },
       {},
       "unknown camera"},
      {"huge", [](json& j) { j["resolution"]["spacing"] = 1e-5; }, {}, "too many particles"},
      {"set unknown", [](json&) {}, {"resolution.spacin=0.004"}, "unknown path 'resolution.spacin'"},
      {"set index", [](json&) {}, {"bodies.7.velocity=[1,0,0]"}, "index 7 out of range"},
      {"set not key=value", [](json&) {}, {"resolution.spacing"}, "expected KEY=VALUE"},
      {"set bad value", [](json&) {}, {"resolution.spacing=abc"}, "resolution.spacing: expected a number"},
  };
  for (const Case& c : cases) {
    json j = good();
    c.edit(j);
    const std::string err = error_of(j, c.sets);
    INFO(c.what << ": '" << err << "'");
    CHECK(err.find(c.expect) != std::string::npos);
  }
}

TEST_CASE("shapes sample the lattice: box, sphere, container, tube", "[scene][shapes]") {
  const double dx = 0.01;
  Body b;
  b.shape.kind = ShapeKind::Box;
  b.shape.box = {Vec3(0, 0, 0), Vec3(0.1, 0.05, 0.03)};
  CHECK(sample_body(b, dx).points.size() == 10 * 5 * 3);

  b.shape.kind = ShapeKind::Sphere;
  b.shape.center = Vec3(0, 0, 0);
  b.shape.radius = 0.1;
  const double n_sphere = static_cast<double>(sample_body(b, dx).points.size());
  CHECK(n_sphere * dx * dx * dx == Approx(4.0 / 3.0 * std::numbers::pi * 1e-3).epsilon(0.03));

  b.shape.kind = ShapeKind::Container;
  b.shape.box = {Vec3(0, 0, 0), Vec3(0.1, 0.1, 0.1)};
  b.shape.layers = 3;
  b.shape.open = {"+y"};
  const auto c = sample_body(b, dx).points;
  // (16 x 13 x 16) outer lattice minus the 10^3 inside: no top layers.
  CHECK(c.size() == 16 * 13 * 16 - 10 * 10 * 10);
  for (const Vec3& p : c) {
    REQUIRE(!b.shape.box.contains(p));
    REQUIRE(p.y() < 0.1);  // open top
    REQUIRE(p.minCoeff() > -0.03);
  }

  b.shape.kind = ShapeKind::Tube;
  b.shape.base = Vec3(0, 0, 0);
  b.shape.axis = Vec3(0, 1, 0);
  b.shape.radius = 0.05;
  b.shape.length = 0.1;
  const auto t = sample_body(b, dx);
  REQUIRE(t.points.size() > 100);
  for (const Vec3& p : t.points) {
    const double r = std::hypot(p.x(), p.z());
    REQUIRE(r >= 0.05);
    REQUIRE(r < 0.05 + 3 * dx);
  }
  CHECK(!t.mesh.empty());

  // Rotation about the shape's centre, then translation.
  Body r;
  r.shape.kind = ShapeKind::Box;
  r.shape.box = {Vec3(0, 0, 0), Vec3(0.04, 0.02, 0.02)};
  r.rotate_axis = Vec3(0, 0, 1);
  r.rotate_degrees = 90;
  r.translate = Vec3(1, 0, 0);
  Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
  for (const Vec3& p : sample_body(r, dx).points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  CHECK(hi.x() - lo.x() == Approx(0.01).margin(1e-9));  // the long side now points along y
  CHECK(hi.y() - lo.y() == Approx(0.03).margin(1e-9));
  CHECK(0.5 * (hi.x() + lo.x()) == Approx(1.02).margin(1e-9));
}
