#include "scene_loader.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include "errors.hpp"
#include "geometry/aortic_root.hpp"
#include "geometry/shapes.hpp"
#include "waveform_csv.hpp"

namespace aortasph {

namespace {

using json = nlohmann::json;

std::string type_name(const json& j) {
  if (j.is_number()) return "a number";
  if (j.is_string()) return "a string";
  if (j.is_boolean()) return "a boolean";
  if (j.is_array()) return "a list";
  if (j.is_object()) return "an object";
  return "null";
}

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw InputError(path + ": " + what);
}

std::string join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}
std::string index(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

// Reads one JSON object: checks its type, that it has no unknown key (typos are errors), fills defaults into
// the JSON (so the resolved scene in run.json is complete) and records the keys an object may have, for
// --set.
class Obj {
 public:
  Obj(json& j, std::string path, std::vector<std::string> keys,
      std::map<std::string, std::set<std::string>>& allowed)
      : j_(j), path_(std::move(path)) {
    if (!j_.is_object()) fail(path_.empty() ? "scene" : path_, "expected an object, got " + type_name(j_));
    for (auto it = j_.begin(); it != j_.end(); ++it)
      if (std::find(keys.begin(), keys.end(), it.key()) == keys.end()) {
        std::string list;
        for (const auto& k : keys) list += (list.empty() ? "" : ", ") + k;
        fail(join(path_, it.key()), "unknown key (allowed here: " + list + ")");
      }
    allowed[path_].insert(keys.begin(), keys.end());
  }

  const std::string& path() const { return path_; }
  std::string path(const std::string& key) const { return join(path_, key); }
  bool has(const std::string& key) const { return j_.contains(key); }
  json& raw(const std::string& key) {
    if (!j_.contains(key)) fail(path(key), "missing");
    return j_[key];
  }

  double number(const std::string& key, std::optional<double> def = std::nullopt) {
    if (!j_.contains(key)) {
      if (!def) fail(path(key), "missing (expected a number)");
      j_[key] = *def;
    }
    const json& v = j_[key];
    if (!v.is_number()) fail(path(key), "expected a number, got " + type_name(v));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(path(key), "expected a finite number");
    return d;
  }
  double positive(const std::string& key, std::optional<double> def = std::nullopt) {
    const double d = number(key, def);
    if (!(d > 0)) fail(path(key), "must be positive, got " + json(d).dump());
    return d;
  }
  double non_negative(const std::string& key, std::optional<double> def = std::nullopt) {
    const double d = number(key, def);
    if (d < 0) fail(path(key), "must not be negative, got " + json(d).dump());
    return d;
  }
  int integer(const std::string& key, std::optional<int> def, int lo, int hi) {
    const double d = number(key, def ? std::optional<double>(*def) : std::nullopt);
    if (d != std::floor(d) || d < lo || d > hi)
      fail(path(key), "expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi) + ", got " +
                          json(d).dump());
    return static_cast<int>(d);
  }
  bool boolean(const std::string& key, bool def) {
    if (!j_.contains(key)) j_[key] = def;
    if (!j_[key].is_boolean()) fail(path(key), "expected true or false, got " + type_name(j_[key]));
    return j_[key].get<bool>();
  }
  std::string string(const std::string& key, std::optional<std::string> def = std::nullopt) {
    if (!j_.contains(key)) {
      if (!def) fail(path(key), "missing (expected a string)");
      j_[key] = *def;
    }
    if (!j_[key].is_string()) fail(path(key), "expected a string, got " + type_name(j_[key]));
    return j_[key].get<std::string>();
  }
  std::string choice(const std::string& key, std::vector<std::string> options,
                     std::optional<std::string> def = std::nullopt) {
    const std::string s = string(key, def);
    if (std::find(options.begin(), options.end(), s) == options.end()) {
      std::string list;
      for (const auto& o : options) list += (list.empty() ? "" : ", ") + o;
      fail(path(key), "unknown value '" + s + "' (expected one of: " + list + ")");
    }
    return s;
  }
  Vec3 vec3(const std::string& key, std::optional<Vec3> def = std::nullopt) {
    if (!j_.contains(key)) {
      if (!def) fail(path(key), "missing (expected 3 numbers)");
      j_[key] = {def->x(), def->y(), def->z()};
    }
    const json& v = j_[key];
    if (!v.is_array()) fail(path(key), "expected 3 numbers, got " + type_name(v));
    if (v.size() != 3) fail(path(key), "expected 3 numbers, got " + std::to_string(v.size()));
    Vec3 out;
    for (int d = 0; d < 3; ++d) {
      if (!v[d].is_number()) fail(index(path(key), d), "expected a number, got " + type_name(v[d]));
      out[d] = v[d].get<double>();
      if (!std::isfinite(out[d])) fail(index(path(key), d), "expected a finite number");
    }
    return out;
  }
  Vec3 unit(const std::string& key, std::optional<Vec3> def = std::nullopt) {
    const Vec3 v = vec3(key, def);
    if (v.norm() < 1e-12) fail(path(key), "must not be the zero vector");
    return v.normalized();
  }
  Vec3 color(const std::string& key) {
    const Vec3 c = vec3(key);
    for (int d = 0; d < 3; ++d)
      if (c[d] < 0 || c[d] > 1) fail(index(path(key), d), "colour components must lie in 0..1");
    return c;
  }
  Box box(const std::string& lo_key = "min", const std::string& hi_key = "max") {
    Box b{vec3(lo_key), vec3(hi_key)};
    for (int d = 0; d < 3; ++d)
      if (!(b.min[d] < b.max[d]))
        fail(path(hi_key),
             "must be greater than " + lo_key + " in every component (component " + std::to_string(d) + ")");
    return b;
  }
  std::vector<std::string> strings(const std::string& key,
                                   std::optional<std::vector<std::string>> def = std::nullopt) {
    if (!j_.contains(key)) {
      if (!def) fail(path(key), "missing (expected a list of strings)");
      j_[key] = *def;
    }
    const json& v = j_[key];
    if (!v.is_array()) fail(path(key), "expected a list of strings, got " + type_name(v));
    std::vector<std::string> out;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_string()) fail(index(path(key), i), "expected a string, got " + type_name(v[i]));
      out.push_back(v[i].get<std::string>());
    }
    return out;
  }

 private:
  json& j_;
  std::string path_;
};

class Loader {
 public:
  std::map<std::string, std::set<std::string>> allowed;
  std::filesystem::path base_dir;  // the scene file's folder: files the scene names are relative to it

  Scene load(json& root) {
    Scene s;
    Obj top(root, "",
            {"name", "description", "domain", "resolution", "time", "gravity", "materials", "contact",
             "aortic_root", "bodies", "open_boundaries", "probes", "cycle", "render", "pressure_gauge"},
            allowed);
    s.name = top.string("name");
    if (s.name.empty() || s.name.find('/') != std::string::npos || s.name == "." || s.name == "..")
      fail("name", "must be a non-empty name without '/'");
    if (top.has("description")) top.string("description");

    Obj dom(top.raw("domain"), "domain", {"min", "max", "max_leave_fraction", "periodic"}, allowed);
    s.domain = dom.box();
    const std::vector<std::string> periodic = dom.strings("periodic", std::vector<std::string>{});
    for (std::size_t k = 0; k < periodic.size(); ++k) {
      const std::string& a = periodic[k];
      if (a != "x" && a != "y" && a != "z")
        fail(index(dom.path("periodic"), k), "unknown axis '" + a + "' (x, y or z)");
      if (s.periodic[a[0] - 'x']) fail(index(dom.path("periodic"), k), "axis '" + a + "' listed twice");
      s.periodic[a[0] - 'x'] = true;
    }
    s.max_leave_fraction = dom.non_negative("max_leave_fraction", 0.0);
    if (s.max_leave_fraction > 1) fail(dom.path("max_leave_fraction"), "must lie in 0..1");

    Obj res(top.raw("resolution"), "resolution", {"spacing", "smoothing_ratio", "skin"}, allowed);
    s.spacing = res.positive("spacing");
    s.smoothing_ratio = res.number("smoothing_ratio", 1.3);
    if (s.smoothing_ratio < 1.0 || s.smoothing_ratio > 3.0)
      fail(res.path("smoothing_ratio"), "must lie in 1..3");
    s.skin = res.number("skin", 0.1);
    if (s.skin < 0.02 || s.skin > 0.5)
      fail(res.path("skin"), "must lie in 0.02..0.5 (of the kernel support)");

    Obj time(top.raw("time"), "time",
             {"end", "output_interval", "probe_interval", "cfl", "max_dt", "max_speed", "max_density_error",
              "fixed_dt"},
             allowed);
    // Without time.end, a cycle block with `cycles` sets the run's length (docs/scenes.md "cycle").
    if (!time.has("end") && top.has("cycle")) {
      if (const auto end = cycle_end(top.raw("cycle"))) root["time"]["end"] = *end;
    }
    if (!time.has("end")) fail(time.path("end"), "missing (expected a number; or give cycle.cycles)");
    s.t_end = time.positive("end");
    s.output_interval = time.positive("output_interval");
    s.cfl = time.positive("cfl", 0.25);
    if (s.cfl > 1) fail(time.path("cfl"), "must lie in (0, 1]");
    s.max_dt = time.positive("max_dt", 1e-3);
    s.max_speed = time.non_negative("max_speed", 0.0);
    s.max_density_error = time.non_negative("max_density_error", 0.5);
    s.fixed_dt = time.non_negative("fixed_dt", 0.0);
    if (s.t_end / s.output_interval > 1e6) fail(time.path("output_interval"), "more than a million outputs");
    // Probe rows between the frames (docs/scenes.md "time"): a whole number of them per output interval, so
    // that every frame has its row. Left out, it is output_interval, and stays out of the resolved scene
    // (a --set of output_interval on the resolved scene moves it too).
    s.probe_interval = time.has("probe_interval") ? time.positive("probe_interval") : s.output_interval;
    {
      const double per_output = s.output_interval / s.probe_interval;
      if (per_output < 1.0 - 1e-9 || std::abs(per_output - std::round(per_output)) > 1e-6 * per_output)
        fail(time.path("probe_interval"), json(s.probe_interval).dump() +
                                              " s must divide time.output_interval " +
                                              json(s.output_interval).dump() + " s a whole number of times");
      if (s.t_end / s.probe_interval > 1e6)
        fail(time.path("probe_interval"), "more than a million probe rows");
    }

    s.pressure_gauge_open =
        top.choice("pressure_gauge", {"open_boundaries", "none"}, "open_boundaries") == "open_boundaries";

    if (!top.has("gravity")) root["gravity"] = {0.0, -9.81, 0.0};
    s.gravity = top.vec3("gravity");

    materials(top.raw("materials"), s);
    if (!top.has("contact")) root["contact"] = json::object();
    Obj con(top.raw("contact"), "contact",
            {"stiffness", "damping", "shear", "friction", "shell_stiffness", "shell_margin", "shell_damping",
             "shell_fluid_barrier"},
            allowed);
    s.contact.stiffness = con.non_negative("stiffness", 0.0);
    s.contact.damping = con.non_negative("damping", 0.0);
    s.contact.shear = con.non_negative("shear", 0.0);
    s.contact.friction = con.non_negative("friction", 0.5);
    s.contact.shell_stiffness = con.non_negative("shell_stiffness", 0.0);
    if (con.has("shell_margin")) s.contact.shell_margin = con.non_negative("shell_margin", 0.0);
    s.contact.shell_damping = con.non_negative("shell_damping", 0.5);
    s.contact.shell_fluid_barrier = con.non_negative("shell_fluid_barrier", 1.0);

    // Geometry shared by the aortic_root shapes (each shape's own keys override it).
    if (top.has("aortic_root")) {
      Obj r(top.raw("aortic_root"), "aortic_root", root_keys(), allowed);
      AorticRootParams p;
      root_params(r, p, true);
      if (const auto e = check_aortic_root(p, s.spacing))
        fail(e->param == "spacing" ? "resolution.spacing" : r.path(e->param), e->message);
      shared_root_ = p;
      shared_root_keys_.clear();
      for (auto it = top.raw("aortic_root").begin(); it != top.raw("aortic_root").end(); ++it)
        shared_root_keys_.insert(it.key());
    }

    json& bodies = top.raw("bodies");
    if (!bodies.is_array() || bodies.empty()) fail("bodies", "expected a non-empty list of bodies");
    for (std::size_t b = 0; b < bodies.size(); ++b)
      s.bodies.push_back(body(bodies[b], index("bodies", b), s));
    for (std::size_t b = 0; b < s.bodies.size(); ++b)
      for (std::size_t c = 0; c < b; ++c)
        if (s.bodies[b].name == s.bodies[c].name)
          fail(index("bodies", b) + ".name", "duplicate body name '" + s.bodies[b].name + "'");
    if (s.bodies.size() > 60000) fail("bodies", "too many bodies");
    shell_leaflets(s);

    if (top.has("open_boundaries")) {
      json& obs = top.raw("open_boundaries");
      if (!obs.is_array()) fail("open_boundaries", "expected a list, got " + type_name(obs));
      for (std::size_t k = 0; k < obs.size(); ++k) {
        s.open_boundaries.push_back(open_boundary(obs[k], index("open_boundaries", k), s));
        for (std::size_t q = 0; q < k; ++q)
          if (s.open_boundaries[q].name == s.open_boundaries[k].name)
            fail(index("open_boundaries", k) + ".name",
                 "duplicate open boundary name '" + s.open_boundaries[k].name + "'");
      }
    }

    if (!top.has("probes")) root["probes"] = json::array();
    json& probes = top.raw("probes");
    if (!probes.is_array()) fail("probes", "expected a list, got " + type_name(probes));
    for (std::size_t p = 0; p < probes.size(); ++p) {
      s.probes.push_back(probe(probes[p], index("probes", p), s));
      for (std::size_t q = 0; q < p; ++q)
        if (s.probes[q].name == s.probes[p].name)
          fail(index("probes", p) + ".name", "duplicate probe name '" + s.probes[p].name + "'");
    }
    if (top.has("cycle")) s.cycle = cycle(top.raw("cycle"), s);
    if (top.has("render")) render(top.raw("render"), s);
    check_periodic(s);
    return s;
  }

  // A periodic scene (domain.periodic; sim/core/periodic.hpp) holds fluid and walls only, and each period
  // spans at least 2.5 neighbour-search radii (the cell stencil of the search must not wrap onto itself).
  static void check_periodic(const Scene& s) {
    if (std::none_of(s.periodic.begin(), s.periodic.end(), [](bool b) { return b; })) return;
    for (std::size_t b = 0; b < s.bodies.size(); ++b) {
      const MaterialType t = s.materials[s.bodies[b].material].type;
      if (t == MaterialType::Elastic || t == MaterialType::Rigid)
        fail(index("bodies", b) + ".material",
             "elastic and rigid bodies are not supported in a periodic domain (domain.periodic)");
    }
    if (!s.open_boundaries.empty())
      fail("open_boundaries", "open boundaries are not supported in a periodic domain (domain.periodic)");
    const double radius =
        (1.0 + s.skin) * 2.0 * s.smoothing_ratio * s.spacing;  // support plus the lists' skin
    for (int a = 0; a < 3; ++a) {
      const double len = s.domain.max[a] - s.domain.min[a];
      if (s.periodic[a] && len < 2.5 * radius * (1.0 + 1e-9)) {
        std::ostringstream m;
        m << "the domain is " << len << " m long along periodic axis " << char('x' + a) << ": at least "
          << 2.5 * radius << " m (2.5 neighbour-search radii at this spacing) is needed";
        fail("domain.periodic", m.str());
      }
    }
  }

 private:
  std::optional<AorticRootParams> shared_root_;
  std::set<std::string> shared_root_keys_;

  static std::vector<std::string> root_keys() {
    return {"base",           "annulus_radius", "commissure_radius", "commissure_height", "sinus_radius",
            "stj_height",     "aorta_radius",   "lvot_length",       "aorta_length",      "leaflet_free_edge",
            "leaflet_height", "leaflet_layers", "wall_layers",       "commissure_angles", "sinuses",
            "leaflet_shape",  "mirror_tilt",    "graft_diameter",    "graft_shape",       "neo_sinus_bulge",
            "stj_diameter",   "cusps",          "commissure_post",   "lunula_height",     "lunula_material",
            "lunula_radius"};
  }

  // Reads the aortic_root parameters that o holds over p; with fill, every parameter, defaults written into
  // the JSON (stj_height and aorta_radius excepted: they follow commissure_height and commissure_radius).
  static void root_params(Obj& o, AorticRootParams& p, bool fill) {
    auto length = [&](const char* key, double& v) {
      if (fill || o.has(key)) v = o.positive(key, v);
    };
    if (fill || o.has("base")) p.base = o.vec3("base", p.base);
    length("annulus_radius", p.annulus_radius);
    length("commissure_radius", p.commissure_radius);
    length("commissure_height", p.commissure_height);
    length("sinus_radius", p.sinus_radius);
    if (o.has("stj_height")) p.stj_height = o.positive("stj_height");
    if (o.has("aorta_radius")) p.aorta_radius = o.positive("aorta_radius");
    length("lvot_length", p.lvot_length);
    length("aorta_length", p.aorta_length);
    length("leaflet_free_edge", p.leaflet_free_edge);
    length("leaflet_height", p.leaflet_height);
    if (fill || o.has("leaflet_layers"))
      p.leaflet_layers = o.integer("leaflet_layers", p.leaflet_layers, 1, 10);
    if (fill || o.has("wall_layers")) p.wall_layers = o.integer("wall_layers", p.wall_layers, 1, 20);
    if (fill || o.has("commissure_angles")) {
      const auto& a = p.commissure_angles;
      const Vec3 v = o.vec3("commissure_angles", Vec3(a[0], a[1], a[2]));
      p.commissure_angles = {v.x(), v.y(), v.z()};
    }
    if (fill || o.has("sinuses")) p.sinuses = o.boolean("sinuses", p.sinuses);
    if (fill || o.has("leaflet_shape"))
      p.mirror_leaflets = o.choice("leaflet_shape", {"labrosse", "mirror"},
                                   p.mirror_leaflets ? "mirror" : "labrosse") == "mirror";
    if (o.has("mirror_tilt")) p.mirror_tilt = o.number("mirror_tilt");
    // Read only where given (no default written): the default follows the leaflets (shell or not).
    if (o.has("commissure_post")) p.commissure_post = o.non_negative("commissure_post");
    if (o.has("lunula_height")) p.lunula_height = o.non_negative("lunula_height");
    if (o.has("lunula_material")) p.lunula_material = o.string("lunula_material");
    if (o.has("lunula_radius")) p.lunula_radius = o.non_negative("lunula_radius");
    surgical_params(o, p);
  }

  // The surgical keys (issue 19 item 1; sim/geometry/aortic_root.hpp): read only where given, no defaults
  // written (a scene without them reads as before).
  static void surgical_params(Obj& o, AorticRootParams& p) {
    if (o.has("graft_diameter")) p.graft_diameter = o.positive("graft_diameter");
    if (o.has("graft_shape"))
      p.graft_shape = o.choice("graft_shape", {"straight", "neo_sinus"}) == "neo_sinus"
                          ? AorticGraftShape::NeoSinus
                          : AorticGraftShape::Straight;
    if (o.has("neo_sinus_bulge")) p.neo_sinus_bulge = o.non_negative("neo_sinus_bulge");
    if (o.has("stj_diameter")) p.stj_diameter = o.positive("stj_diameter");
    if (o.has("cusps")) p.fixed_cusps = o.choice("cusps", {"root", "fixed"}) == "fixed";
  }

  Shape aortic_root_shape(json& j, const std::string& path, double dx) {
    std::vector<std::string> keys = root_keys();
    keys.insert(keys.end(), {"part", "index"});
    Obj o(j, path, keys, allowed);
    Shape sh;
    sh.kind = ShapeKind::AorticRoot;
    const std::string part = o.choice("part", {"wall", "blood", "leaflet"});
    sh.aortic_part = part == "wall"    ? AorticPart::Wall
                     : part == "blood" ? AorticPart::Blood
                                       : AorticPart::Leaflet;
    if (sh.aortic_part == AorticPart::Leaflet)
      sh.aortic_index = o.integer("index", std::nullopt, 0, 2);
    else if (o.has("index"))
      fail(o.path("index"), "only leaflets have an index");
    // Shared geometry first, then this shape's own keys (all of them, defaults filled, when nothing is
    // shared).
    sh.aortic = shared_root_.value_or(AorticRootParams{});
    root_params(o, sh.aortic, !shared_root_);
    if (const auto e = check_aortic_root(sh.aortic, dx)) {
      const std::string at = e->param == "spacing" ? "resolution.spacing"
                             : o.has(e->param) || !shared_root_keys_.count(e->param)
                                 ? o.path(e->param)
                                 : "aortic_root." + e->param;
      fail(at, e->message);
    }
    return sh;
  }

  void materials(json& j, Scene& s) {
    if (!j.is_object() || j.empty()) fail("materials", "expected an object of named materials");
    for (auto it = j.begin(); it != j.end(); ++it) {
      const std::string path = "materials." + it.key();
      if (!it.value().is_object()) fail(path, "expected an object, got " + type_name(it.value()));
      const std::string type = it.value().contains("type") && it.value()["type"].is_string()
                                   ? it.value()["type"].get<std::string>()
                                   : "";
      if (!it.value().contains("type"))
        fail(path + ".type", "missing (expected fluid, elastic, rigid, wall or shell)");
      if (type != "fluid" && type != "elastic" && type != "rigid" && type != "wall" && type != "shell")
        fail(path + ".type", "unknown value " + it.value()["type"].dump() +
                                 " (expected one of: fluid, elastic, rigid, wall, shell)");
      Material m;
      m.name = it.key();
      std::vector<std::string> keys = {"type"};
      if (type == "fluid")
        keys = {"type",
                "density",
                "viscosity",
                "sound_speed",
                "eos_exponent",
                "delta_sph",
                "artificial_viscosity",
                "riemann_dissipation",
                "tensile_correction",
                "density_summation",
                "background_pressure",
                "shifting",
                "shifting_ale",
                "mask_density",
                "transport_velocity"};
      else if (type == "elastic")
        keys = {"type",  "density", "youngs_modulus", "poisson_ratio", "hourglass", "artificial_viscosity",
                "model", "gradient"};
      else if (type == "rigid")
        keys = {"type", "density"};
      else if (type == "shell")
        keys = {"type",
                "density",
                "youngs_modulus",
                "poisson_ratio",
                "thickness",
                "model",
                "damping",
                "dynamic_viscosity",
                "hourglass",
                "c1",
                "c2",
                "c3",
                "delta"};
      Obj o(it.value(), path, keys, allowed);
      o.choice("type", {"fluid", "elastic", "rigid", "wall", "shell"});
      if (type == "fluid") {
        m.type = MaterialType::Fluid;
        m.density = o.positive("density");
        m.viscosity = o.non_negative("viscosity");
        m.sound_speed = o.positive("sound_speed");
        m.eos_exponent = o.positive("eos_exponent", 7.0);
        m.delta_sph = o.non_negative("delta_sph", 0.1);
        m.artificial_viscosity = o.non_negative("artificial_viscosity", 0.0);
        m.riemann_dissipation = o.non_negative("riemann_dissipation", 0.0);
        if (m.riemann_dissipation > 100.0)
          fail(o.path("riemann_dissipation"), "must lie in 0..100 (Zhang, Hu & Adams 2017 use 3)");
        m.tensile_correction = o.non_negative("tensile_correction", 0.0);
        if (m.tensile_correction > 1.0)
          fail(o.path("tensile_correction"), "must lie in 0..1 (Monaghan 2000 uses 0.2)");
        m.density_summation = o.boolean("density_summation", false);
        m.background_pressure = o.number("background_pressure", 0.0);
        m.shifting = o.non_negative("shifting", 0.0);
        if (m.shifting > 10.0) fail(o.path("shifting"), "must lie in 0..10 (Skillen et al. 2013 use 1..6)");
        m.shifting_ale = o.boolean("shifting_ale", false);
        m.mask_density = o.boolean("mask_density", false);
        if (o.has("transport_velocity")) {  // Adami et al. 2013 (sim/fluid/transport_velocity.hpp)
          Obj tv(o.raw("transport_velocity"), o.path("transport_velocity"), {"background_pressure"}, allowed);
          m.transport_velocity_pb = tv.positive("background_pressure");
          if (!m.density_summation)
            fail(o.path("transport_velocity"),
                 "needs \"density_summation\": true (the density must follow the transported particles, "
                 "as in Adami et al. 2013)");
          if (m.transport_velocity_pb > 1e3 * m.density * m.sound_speed * m.sound_speed)
            fail(tv.path("background_pressure"),
                 "must not exceed 1000 rho0 c0^2 (Adami et al. use rho0 c0^2)");
        }
      } else if (type == "elastic") {
        m.type = MaterialType::Elastic;
        m.density = o.positive("density");
        m.youngs_modulus = o.positive("youngs_modulus");
        m.poisson_ratio = o.number("poisson_ratio");
        if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5))
          fail(o.path("poisson_ratio"), "must lie in (-1, 0.5), got " + json(m.poisson_ratio).dump());
        m.hourglass = o.non_negative("hourglass", 10.0);
        m.solid_art_viscosity = o.non_negative("artificial_viscosity", 1.0);
        if (!o.has("model")) it.value()["model"] = "saint_venant_kirchhoff";
        m.neo_hookean = o.choice("model", {"saint_venant_kirchhoff", "neo_hookean"}) == "neo_hookean";
        if (!o.has("gradient")) it.value()["gradient"] = "second_order";
        m.second_order_gradient = o.choice("gradient", {"first_order", "second_order"}) == "second_order";
      } else if (type == "shell") {
        shell_material(o, it.value(), m, s);
      } else if (type == "rigid") {
        m.type = MaterialType::Rigid;
        m.density = o.positive("density");
      } else {
        m.type = MaterialType::Wall;
      }
      s.materials.push_back(m);
    }
  }

  // Shell aortic leaflets (issue 16): all three leaflets of a root are shells or none is; the root's other
  // parts (wall, blood) learn it, so the blood keeps its gap from the one-layer sheets.
  void shell_leaflets(Scene& s) {
    int shells = 0, leaflets = 0;
    std::size_t volumetric = 0;
    for (std::size_t b = 0; b < s.bodies.size(); ++b) {
      const Shape& sh = s.bodies[b].shape;
      if (sh.kind != ShapeKind::AorticRoot || sh.aortic_part != AorticPart::Leaflet) continue;
      ++leaflets;
      if (sh.aortic.shell_leaflets)
        ++shells;
      else
        volumetric = b;
    }
    if (shells == 0) {
      // Commissure posts clamp shell leaflets to the wall and a lunula is a band of the shell's sheet: with
      // volumetric leaflets neither is.
      struct ShellOnly {
        const char* key;
        double AorticRootParams::*value;
        const char* message;
      };
      for (const ShellOnly& k :
           {ShellOnly{"commissure_post", &AorticRootParams::commissure_post,
                      "commissure posts need shell leaflets"},
            ShellOnly{"lunula_height", &AorticRootParams::lunula_height, "a lunula needs shell leaflets"}})
        for (std::size_t b = 0; b < s.bodies.size(); ++b) {
          const Shape& sh = s.bodies[b].shape;
          if (sh.kind != ShapeKind::AorticRoot || !(sh.aortic.*k.value > 0.0)) continue;
          const std::string key = std::string("aortic_root.") + k.key;
          fail(shared_root_keys_.count(k.key) ? key : index("bodies", b) + ".shape." + key,
               std::string(k.message) + " (a leaflet material of type shell)");
        }
      return;
    }
    // The lunula's material: a shell material, for a lunula.
    for (std::size_t b = 0; b < s.bodies.size(); ++b) {
      const AorticRootParams& a = s.bodies[b].shape.aortic;
      if (s.bodies[b].shape.kind != ShapeKind::AorticRoot || a.lunula_material.empty()) continue;
      const std::string key = shared_root_keys_.count("lunula_material")
                                  ? "aortic_root.lunula_material"
                                  : index("bodies", b) + ".shape.aortic_root.lunula_material";
      const int m = material_index(s, a.lunula_material, key);
      if (s.materials[m].type != MaterialType::Shell)
        fail(key, "'" + a.lunula_material + "' is not a shell material");
      if (!(a.lunula_height > 0.0)) fail(key, "there is no lunula (aortic_root.lunula_height is 0)");
    }
    if (shells != leaflets)
      fail(index("bodies", volumetric) + ".material",
           "the aortic leaflets are shells or none is: this leaflet's material is not a shell, another's is");
    for (Body& b : s.bodies)
      if (b.shape.kind == ShapeKind::AorticRoot) b.shape.aortic.shell_leaflets = true;
  }

  // A shell material (sim/solid/shell.hpp): plane-stress SVK or incompressible neo-Hookean, thickness a
  // parameter of at most kMaxShellThickness spacings (a thicker sheet is resolved by a volumetric solid).
  static constexpr double kMaxShellThickness = 4.0;
  void shell_material(Obj& o, json& j, Material& m, const Scene& s) {
    m.type = MaterialType::Shell;
    m.density = o.positive("density");
    m.youngs_modulus = o.positive("youngs_modulus");
    if (!o.has("model")) j["model"] = "saint_venant_kirchhoff";
    const std::string model = o.choice("model", {"saint_venant_kirchhoff", "neo_hookean", "lee_sacks"});
    m.neo_hookean = model != "saint_venant_kirchhoff";  // lee_sacks: neo-Hookean plus an exponential term
    if (model == "lee_sacks") {
      // delta: the isotropic share (1, the default: no fibre term; 0: fibres only, c2 not used).
      m.lee_sacks_delta = o.number("delta", 1.0);
      if (!(m.lee_sacks_delta >= 0.0 && m.lee_sacks_delta <= 1.0))
        fail(o.path("delta"), "must lie in [0, 1], got " + json(m.lee_sacks_delta).dump());
      m.lee_sacks_c1 = o.positive("c1");
      if (m.lee_sacks_delta > 0.0 || o.has("c2")) m.lee_sacks_c2 = o.positive("c2");
      if (m.lee_sacks_delta < 1.0 || o.has("c3")) m.lee_sacks_c3 = o.positive("c3");
    } else {
      for (const char* key : {"c1", "c2", "c3", "delta"})
        if (o.has(key))
          fail(o.path(key), "only the lee_sacks model takes c1, c2, c3 and delta (model is " + model + ")");
    }
    m.poisson_ratio = o.number("poisson_ratio");
    if (m.neo_hookean) {
      if (!(m.poisson_ratio >= 0.45 && m.poisson_ratio <= 0.5))
        fail(o.path("poisson_ratio"), "the " + model +
                                          " shell is incompressible: expected 0.45..0.5 (it uses 0.5), got " +
                                          json(m.poisson_ratio).dump());
    } else if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5)) {
      fail(o.path("poisson_ratio"), "must lie in (-1, 0.5), got " + json(m.poisson_ratio).dump());
    }
    m.thickness = o.positive("thickness");
    if (m.thickness > kMaxShellThickness * s.spacing)
      fail(o.path("thickness"), "is " + json(m.thickness / s.spacing).dump() +
                                    " spacings: a shell may be at most " + json(kMaxShellThickness).dump() +
                                    " spacings thick (resolve a thicker sheet with an elastic body)");
    m.shell_damping = o.non_negative("damping", 0.0);
    m.shell_viscosity = o.non_negative("dynamic_viscosity", 0.0);
    m.hourglass = o.non_negative("hourglass", 0.05);
  }

  int material_index(const Scene& s, const std::string& name, const std::string& path) {
    for (std::size_t m = 0; m < s.materials.size(); ++m)
      if (s.materials[m].name == name) return static_cast<int>(m);
    fail(path, "unknown material '" + name + "'");
  }

  static bool identity_transform(const Body& b) {
    return b.translate == Vec3::Zero() && b.rotate_degrees == 0.0;
  }

  int body_index(const Scene& s, const std::string& name, const std::string& path) {
    for (std::size_t b = 0; b < s.bodies.size(); ++b)
      if (s.bodies[b].name == name) return static_cast<int>(b);
    fail(path, "unknown body '" + name + "'");
  }

  Body body(json& j, const std::string& path, const Scene& s) {
    Obj o(j, path,
          {"name", "material", "shape", "translate", "rotate", "velocity", "angular_velocity", "color",
           "render", "fixed", "initial_flow", "pinned", "pressure_load", "slip", "jitter", "fibre_direction"},
          allowed);
    Body b;
    b.name = o.string("name");
    if (b.name.empty()) fail(o.path("name"), "must not be empty");
    b.material = material_index(s, o.string("material"), o.path("material"));
    b.shape = shape(o.raw("shape"), o.path("shape"), s.spacing);
    if (b.shape.kind == ShapeKind::AorticRoot) {
      const MaterialType t = s.materials[b.material].type;
      const AorticPart part = b.shape.aortic_part;
      if (part == AorticPart::Wall && t != MaterialType::Wall)
        fail(o.path("material"), "the aortic root's wall needs a wall material");
      if (part == AorticPart::Blood && t != MaterialType::Fluid)
        fail(o.path("material"), "the aortic root's blood needs a fluid material");
      if (part == AorticPart::Leaflet && t != MaterialType::Elastic && t != MaterialType::Wall &&
          t != MaterialType::Shell)
        fail(o.path("material"),
             "an aortic leaflet needs an elastic, a shell (or, held still, a wall) material");
      // A shell leaflet: one layer on the mid-surface (sim/geometry/aortic_root.hpp, leaflet_shell).
      if (part == AorticPart::Leaflet && t == MaterialType::Shell) b.shape.aortic.shell_leaflets = true;
    }
    b.translate = o.vec3("translate", Vec3::Zero());
    if (o.has("rotate")) {
      Obj r(o.raw("rotate"), o.path("rotate"), {"axis", "degrees"}, allowed);
      b.rotate_axis = r.unit("axis");
      b.rotate_degrees = r.number("degrees");
    }
    b.velocity = o.vec3("velocity", Vec3::Zero());
    b.angular_velocity = o.vec3("angular_velocity", Vec3::Zero());
    if (o.has("slip")) {  // the viscous wall condition (issue 20): no_slip (default) or free_slip
      const MaterialType t = s.materials[b.material].type;
      if (t != MaterialType::Wall && t != MaterialType::Rigid && t != MaterialType::Elastic)
        fail(o.path("slip"), "only a wall, rigid or elastic body takes a slip condition");
      b.free_slip = o.choice("slip", {"no_slip", "free_slip"}) == "free_slip";
    }
    if (o.has("initial_flow")) {
      if (s.materials[b.material].type != MaterialType::Fluid)
        fail(o.path("initial_flow"), "only a fluid body takes an initial flow field");
      Obj f(o.raw("initial_flow"), o.path("initial_flow"), {"taylor_green"}, allowed);
      Obj tg(f.raw("taylor_green"), f.path("taylor_green"), {"speed", "wavelength"}, allowed);
      b.taylor_green = InitialFlow{tg.number("speed"), tg.positive("wavelength")};
    }
    if (o.has("jitter")) {  // issue 20: a fluid body's particles off their lattice sites (docs/scenes.md)
      if (s.materials[b.material].type != MaterialType::Fluid)
        fail(o.path("jitter"), "only a fluid body takes a jitter");
      b.jitter = o.number("jitter");
      if (!(b.jitter >= 0.0 && b.jitter <= 0.25))
        fail(o.path("jitter"),
             "must lie in 0..0.25 (a fraction of the spacing), got " + json(b.jitter).dump());
    }
    if (o.has("color")) b.color = o.color("color");
    const std::string mode = o.choice("render", {"particles", "surface", "hidden"}, "particles");
    b.render = mode == "surface"  ? RenderMode::Surface
               : mode == "hidden" ? RenderMode::Hidden
                                  : RenderMode::Particles;
    const bool shell = s.materials[b.material].type == MaterialType::Shell;
    if (shell != (is_shell_shape(b.shape.kind) || b.shape.aortic.shell_leaflets)) {
      fail(o.path("material"),
           shell ? "a shell material needs a shell shape (rectangle, disc or cylindrical_panel)"
                 : "a shell shape (rectangle, disc, cylindrical_panel) needs a shell material");
    }
    if (shell) {
      if (o.has("fixed")) b.shell_fixed = boxes(o, "fixed");
      if (o.has("pinned")) b.shell_pinned = boxes(o, "pinned");
      if (o.has("pressure_load")) b.pressure_load = series(o, "pressure_load", std::nullopt, false);
      if (o.has("fibre_direction")) b.fibre_direction = o.unit("fibre_direction");
      return b;
    }
    if (o.has("fibre_direction")) fail(o.path("fibre_direction"), "only shell bodies have a fibre direction");
    if (o.has("pinned")) fail(o.path("pinned"), "only shell bodies can be pinned");
    if (o.has("pressure_load")) fail(o.path("pressure_load"), "only shell bodies carry a pressure_load");
    if (o.has("fixed")) {
      json& f = o.raw("fixed");
      if (f.is_object() && f.contains("box")) {
        Obj fo(f, o.path("fixed"), {"box"}, allowed);
        Obj bo(fo.raw("box"), fo.path("box"), {"min", "max"}, allowed);
        b.fixed = bo.box();
      } else {
        Obj fo(f, o.path("fixed"), {"min", "max"}, allowed);
        b.fixed = fo.box();
      }
      if (s.materials[b.material].type != MaterialType::Elastic)
        fail(o.path("fixed"), "only elastic bodies can have a fixed region");
    }
    return b;
  }

  // A support: one box ({"min", "max"} or {"box": {...}}) or a list of them.
  std::vector<Box> boxes(Obj& o, const std::string& key) {
    json& f = o.raw(key);
    std::vector<Box> out;
    auto one = [&](json& e, const std::string& path) {
      if (e.is_object() && e.contains("box")) {
        Obj fo(e, path, {"box"}, allowed);
        Obj bo(fo.raw("box"), fo.path("box"), {"min", "max"}, allowed);
        out.push_back(bo.box());
      } else {
        Obj fo(e, path, {"min", "max"}, allowed);
        out.push_back(fo.box());
      }
    };
    if (f.is_array()) {
      if (f.empty()) fail(o.path(key), "expected a box or a non-empty list of boxes");
      for (std::size_t k = 0; k < f.size(); ++k) one(f[k], index(o.path(key), k));
    } else {
      one(f, o.path(key));
    }
    return out;
  }

  // Shell shapes: one layer of particles on the mid-surface.
  void shell_shape(const std::string& kind, json& j, const std::string& p, Shape& sh, double dx) {
    if (kind == "rectangle") {
      Obj b(j, p, {"center", "size", "normal", "u_axis"}, allowed);
      sh.kind = ShapeKind::Rectangle;
      sh.center = b.vec3("center");
      const json& sz = b.raw("size");
      if (!sz.is_array() || sz.size() != 2 || !sz[0].is_number() || !sz[1].is_number())
        fail(b.path("size"), "expected two numbers [a, b]");
      sh.size = {sz[0].get<double>(), sz[1].get<double>()};
      for (int k = 0; k < 2; ++k)
        if (!(sh.size[k] > 0) || !std::isfinite(sh.size[k]))
          fail(index(b.path("size"), k), "must be positive");
      sh.normal = b.unit("normal");
      if (b.has("u_axis")) {
        const Vec3 u = b.unit("u_axis");
        if ((u - u.dot(sh.normal) * sh.normal).norm() < 1e-6) fail(b.path("u_axis"), "is parallel to normal");
        sh.u_axis = u;
      }
      for (int k = 0; k < 2; ++k)
        if (std::lround(sh.size[k] / dx) < 1)
          fail(index(b.path("size"), k), "samples no particle at spacing " + json(dx).dump());
    } else if (kind == "disc") {
      Obj b(j, p, {"center", "radius", "normal", "rim"}, allowed);
      sh.kind = ShapeKind::Disc;
      sh.center = b.vec3("center");
      sh.radius = b.positive("radius");
      sh.normal = b.unit("normal");
      const std::string rim = b.choice("rim", {"free", "fixed", "pinned"}, "free");
      sh.rim = rim == "fixed" ? 1 : rim == "pinned" ? 2 : 0;
      if (std::lround(sh.radius / dx) < 1)
        fail(b.path("radius"), "samples no ring of particles at spacing " + json(dx).dump() +
                                   " (the radius must be at least half a spacing)");
    } else {
      Obj b(j, p, {"center", "axis", "radius", "length", "angle", "normal"}, allowed);
      sh.kind = ShapeKind::CylindricalPanel;
      sh.center = b.vec3("center");
      sh.axis = b.unit("axis");
      sh.radius = b.positive("radius");
      sh.length = b.positive("length");
      sh.angle = b.positive("angle");
      if (sh.angle > 360) fail(b.path("angle"), "must lie in (0, 360] degrees");
      sh.normal = b.unit("normal");
      if (std::abs(sh.normal.dot(sh.axis)) > 1e-6)
        fail(b.path("normal"), "must be perpendicular to axis (the direction from the axis to the crown)");
      if (std::lround(sh.length / dx) < 1)
        fail(b.path("length"), "samples no particle at spacing " + json(dx).dump());
      if (std::lround(sh.radius * sh.angle * std::numbers::pi / 180.0 / dx) < 1)
        fail(b.path("angle"), "the arc samples no particle at spacing " + json(dx).dump());
    }
  }

  Shape shape(json& j, const std::string& path, double dx) {
    static const std::vector<std::string> kinds = {"box",  "sphere",           "cylinder", "container",
                                                   "tube", "aortic_root",      "mesh",     "rectangle",
                                                   "disc", "cylindrical_panel"};
    Obj o(j, path, kinds, allowed);
    if (j.size() != 1)
      fail(path,
           "expected exactly one shape (one of box, sphere, cylinder, container, tube, aortic_root), got " +
               std::to_string(j.size()));
    const std::string kind = j.begin().key();
    Shape sh;
    const std::string p = o.path(kind);
    if (kind == "box") {
      Obj b(o.raw(kind), p, {"min", "max"}, allowed);
      sh.kind = ShapeKind::Box;
      sh.box = b.box();
    } else if (kind == "sphere") {
      Obj b(o.raw(kind), p, {"center", "radius"}, allowed);
      sh.kind = ShapeKind::Sphere;
      sh.center = b.vec3("center");
      sh.radius = b.positive("radius");
    } else if (kind == "cylinder" || kind == "tube") {
      const bool tube = kind == "tube";
      Obj b(o.raw(kind), p,
            tube ? std::vector<std::string>{"base", "axis", "radius", "length", "layers"}
                 : std::vector<std::string>{"base", "axis", "radius", "length"},
            allowed);
      sh.kind = tube ? ShapeKind::Tube : ShapeKind::Cylinder;
      sh.base = b.vec3("base");
      sh.axis = b.unit("axis");
      sh.radius = b.positive("radius");
      sh.length = b.positive("length");
      if (tube) sh.layers = b.integer("layers", 3, 1, 20);
    } else if (kind == "container") {
      Obj b(o.raw(kind), p, {"min", "max", "layers", "open"}, allowed);
      sh.kind = ShapeKind::Container;
      sh.box = b.box();
      sh.layers = b.integer("layers", 3, 1, 20);
      sh.open = b.strings("open", std::vector<std::string>{});
      for (std::size_t k = 0; k < sh.open.size(); ++k) {
        static const std::set<std::string> faces = {"+x", "-x", "+y", "-y", "+z", "-z"};
        if (!faces.count(sh.open[k]))
          fail(index(b.path("open"), k),
               "unknown face '" + sh.open[k] + "' (expected +x, -x, +y, -y, +z or -z)");
      }
    } else if (kind == "aortic_root") {
      sh = aortic_root_shape(o.raw(kind), p, dx);
    } else if (kind == "rectangle" || kind == "disc" || kind == "cylindrical_panel") {
      shell_shape(kind, o.raw(kind), p, sh, dx);
      const double area = kind == "rectangle" ? sh.size[0] * sh.size[1]
                          : kind == "disc"    ? std::numbers::pi * sh.radius * sh.radius
                                              : sh.length * sh.radius * sh.angle * std::numbers::pi / 180.0;
      if (area / (dx * dx) > 2e8)
        fail(p, "holds about " + json(area / (dx * dx)).dump() + " particles at spacing " + json(dx).dump() +
                    ": too many particles");
      return sh;
    } else {
      fail(p, "shape '" + kind + "' is not supported yet");
    }
    // A lattice of more than about 200 million points would exhaust memory long before it ran.
    Vec3 extent = Vec3::Zero();
    if (sh.kind == ShapeKind::Box || sh.kind == ShapeKind::Container) {
      extent = sh.box.max - sh.box.min + Vec3::Constant(2 * sh.layers * dx);
    } else if (sh.kind == ShapeKind::AorticRoot) {
      const AorticRootParams a = surgical_root(sh.aortic);
      const double r =
          std::max({a.annulus_radius, a.sinus_radius, a.stj_radius(), a.aorta()}) + a.wall_layers * dx;
      extent = Vec3(2 * r, a.lvot_length + a.stj() + a.aorta_length, 2 * r);
    } else
      extent = Vec3::Constant(2 * (sh.radius + sh.layers * dx) + sh.length);
    const double cells = (extent / dx).array().ceil().prod();
    if (cells > 2e8)
      fail(p, "holds about " + json(cells).dump() + " lattice points at spacing " + json(dx).dump() +
                  ": too many particles");
    return sh;
  }

  // A constant or a table [[t, value], ...] with strictly increasing times (linear in between, held outside).
  TimeSeries series(Obj& o, const std::string& key, std::optional<double> def, bool non_negative) {
    if (!o.has(key) && def) return TimeSeries{{}, {o.number(key, def)}};
    json& v = o.raw(key);
    TimeSeries ts;
    auto check = [&](double x, const std::string& path) {
      if (non_negative && x < 0) fail(path, "must not be negative, got " + json(x).dump());
    };
    if (v.is_number()) {
      const double x = o.number(key);
      check(x, o.path(key));
      ts.value = {x};
      return ts;
    }
    if (!v.is_array() || v.empty())
      fail(o.path(key), "expected a number or a table [[t, value], ...], got " + type_name(v));
    for (std::size_t k = 0; k < v.size(); ++k) {
      const std::string p = index(o.path(key), k);
      const json& row = v[k];
      if (!row.is_array() || row.size() != 2 || !row[0].is_number() || !row[1].is_number())
        fail(p, "expected a pair [t, value] of numbers");
      const double t = row[0].get<double>(), x = row[1].get<double>();
      if (!std::isfinite(t) || !std::isfinite(x)) fail(p, "expected finite numbers");
      if (!ts.t.empty() && !(t > ts.t.back()))
        fail(p,
             "times must increase strictly (" + json(t).dump() + " after " + json(ts.t.back()).dump() + ")");
      check(x, p);
      ts.t.push_back(t);
      ts.value.push_back(x);
    }
    return ts;
  }

  OpenBoundarySpec open_boundary(json& j, const std::string& path, const Scene& s) {
    if (!j.is_object()) fail(path, "expected an object, got " + type_name(j));
    const std::string type = j.contains("type") && j["type"].is_string() ? j["type"].get<std::string>() : "";
    if (j.contains("type") && type != "inflow" && type != "outflow")
      fail(path + ".type", "unknown value " + j["type"].dump() + " (expected one of: inflow, outflow)");
    std::vector<std::string> keys = {"name", "type", "point", "normal", "radius", "layers", "non_reflecting"};
    if (type == "inflow") keys.insert(keys.end(), {"body", "velocity", "profile", "pressure"});
    if (type == "outflow") keys.insert(keys.end(), {"pressure", "windkessel"});
    // An inflow is driven by a velocity or by a pressure, an outflow holds a pressure or a Windkessel: one
    // of the two (issue 17).
    if (type == "inflow" && j.contains("velocity") && j.contains("pressure"))
      fail(path + ".pressure", "an inflow takes either 'velocity' or 'pressure', not both");
    if (type == "inflow" && !j.contains("velocity") && !j.contains("pressure"))
      fail(path + ".velocity", "missing (an inflow needs 'velocity' or 'pressure')");
    if (type == "outflow" && j.contains("pressure") && j.contains("windkessel"))
      fail(path + ".windkessel", "an outflow takes either 'pressure' or 'windkessel', not both");
    Obj o(j, path, keys, allowed);
    OpenBoundarySpec b;
    b.name = o.string("name");
    if (b.name.empty()) fail(o.path("name"), "must not be empty");
    if (b.name.find_first_of(",\"\n") != std::string::npos)
      fail(o.path("name"), "must not contain commas or quotes (it names probe columns)");
    b.type = o.choice("type", {"inflow", "outflow"}) == "inflow" ? OpenBoundaryType::Inflow
                                                                 : OpenBoundaryType::Outflow;
    b.point = o.vec3("point");
    b.normal = o.unit("normal");
    b.radius = o.positive("radius");
    b.layers = o.integer("layers", 4, 1, 50);
    // The buffer must cover the kernel support 2h of the fluid next to the disc.
    const int min_layers = static_cast<int>(std::ceil(2.0 * s.smoothing_ratio - 1e-9));
    if (b.layers < min_layers)
      fail(o.path("layers"),
           "must be at least " + std::to_string(min_layers) +
               " (the buffer must cover the kernel support 2h = " + json(2.0 * s.smoothing_ratio).dump() +
               " spacings), got " + std::to_string(b.layers));
    if (b.type == OpenBoundaryType::Inflow) {
      b.body = body_index(s, o.string("body"), o.path("body"));
      if (s.materials[s.bodies[b.body].material].type != MaterialType::Fluid)
        fail(o.path("body"),
             "body '" + s.bodies[b.body].name + "' is not a fluid (an inflow feeds a fluid body)");
      if (o.has("pressure")) {
        if (o.has("profile"))
          fail(o.path("profile"),
               "a pressure inlet has no prescribed profile (its velocity comes from the fluid)");
        b.pressure_inlet = true;
        b.inlet_pressure = waveform(o, "pressure");
      } else {
        b.velocity = series(o, "velocity", std::nullopt, true);
        b.parabolic = o.choice("profile", {"uniform", "parabolic"}, "uniform") == "parabolic";
      }
    } else if (o.has("windkessel")) {
      b.windkessel = windkessel(o.raw("windkessel"), o.path("windkessel"));
    } else {
      b.pressure = series(o, "pressure", 0.0, false);
    }
    // The characteristic treatment (issue 17 item 3; open_boundary.hpp): only its relaxation time.
    if (o.has("non_reflecting")) {
      Obj nr(o.raw("non_reflecting"), o.path("non_reflecting"), {"relaxation_time"}, allowed);
      b.non_reflecting_tau = nr.positive("relaxation_time");
    }
    return b;
  }

  // An inflow's pressure (issue 17): a number, a table [[t, p], ...] (as series()), or a waveform file
  // {"file", "units", "period", "offset"}.
  Waveform waveform(Obj& o, const std::string& key) {
    json& v = o.raw(key);
    if (!v.is_object()) {
      const TimeSeries ts = series(o, key, std::nullopt, false);
      Waveform w;
      w.t = ts.t;
      w.value = ts.value;
      return w;
    }
    Obj f(v, o.path(key), {"file", "units", "period", "offset"}, allowed);
    const std::string units = f.choice("units", {"Pa", "mmHg"});
    const double scale = units == "mmHg" ? 133.322387415 : 1.0;  // 1 mmHg = 133.322387415 Pa (ISO 80000-4)
    const std::string name = f.string("file");
    if (name.empty()) fail(f.path("file"), "must not be empty");
    const std::filesystem::path file =
        std::filesystem::path(name).is_absolute() ? std::filesystem::path(name) : base_dir / name;
    Waveform w;
    try {
      w = read_waveform_csv(file, file.string(), scale);
    } catch (const InputError& e) {
      fail(f.path("file"), e.what());
    }
    if (f.has("period")) {
      w.period = f.positive("period");
      if (w.t.back() - w.t.front() > w.period * (1.0 + 1e-12))
        fail(f.path("period"), "the waveform in " + file.string() + " spans " +
                                   json(w.t.back() - w.t.front()).dump() + " s, more than one period (" +
                                   json(w.period).dump() + " s)");
    }
    w.offset = f.number("offset", 0.0);
    return w;
  }

  // An outflow's RCR Windkessel (sim/physiology/windkessel.hpp), SI units.
  WindkesselParams windkessel(json& j, const std::string& path) {
    Obj o(j, path,
          {"proximal_resistance", "capacitance", "distal_resistance", "distal_pressure", "initial_pressure"},
          allowed);
    WindkesselParams w;
    w.proximal_resistance = o.positive("proximal_resistance");
    w.capacitance = o.positive("capacitance");
    w.distal_resistance = o.positive("distal_resistance");
    w.distal_pressure = o.number("distal_pressure");
    w.initial_pressure = o.number("initial_pressure");
    return w;
  }

  Probe probe(json& j, const std::string& path, const Scene& s) {
    if (!j.is_object()) fail(path, "expected an object, got " + type_name(j));
    const std::string type = j.contains("type") && j["type"].is_string() ? j["type"].get<std::string>() : "";
    std::vector<std::string> keys = {"name", "type"};
    if (type == "extent") keys.insert(keys.end(), {"bodies", "axis", "stat", "region", "link"});
    if (type == "pressure") keys.insert(keys.end(), {"point", "radius", "normal"});
    if (type == "body") keys.insert(keys.end(), {"body"});
    if (type == "point") keys.insert(keys.end(), {"body", "reference"});
    if (type == "flow_rate") keys.insert(keys.end(), {"point", "normal", "radius"});
    if (type == "orifice_area") keys.insert(keys.end(), {"body", "bodies", "point", "normal", "radius"});
    if (type == "stress") keys.insert(keys.end(), {"bodies", "per_body", "point", "normal"});
    if (type == "gap") keys.insert(keys.end(), {"bodies"});
    if (type == "gap_area")
      keys.insert(keys.end(), {"bodies", "point", "normal", "radius", "central_radius", "commissures"});
    if (type == "wall_distance") keys.insert(keys.end(), {"bodies", "walls", "exclude", "reach"});
    if (type == "max_speed") keys.insert(keys.end(), {"bodies", "region", "smoothed"});
    if (type == "coaptation")
      keys.insert(keys.end(), {"bodies", "point", "normal", "distance", "central_radius", "per_leaflet"});
    if (type == "displacement") keys.insert(keys.end(), {"body", "point"});
    Obj o(j, path, keys, allowed);
    Probe p;
    p.name = o.string("name");
    if (p.name.empty() || p.name.find_first_of(",\"\n") != std::string::npos)
      fail(o.path("name"), "must be a non-empty name without commas or quotes");
    o.choice("type", {"extent", "pressure", "body", "point", "energy", "momentum", "flow_rate",
                      "orifice_area", "open_boundary", "stress", "gap", "max_speed", "coaptation",
                      "displacement", "gap_area", "wall_distance"});
    if (type == "extent") {
      p.type = ProbeType::Extent;
      const auto names = o.strings("bodies");
      if (names.empty()) fail(o.path("bodies"), "expected at least one body");
      for (std::size_t k = 0; k < names.size(); ++k)
        p.bodies.push_back(body_index(s, names[k], index(o.path("bodies"), k)));
      const std::string axis = o.choice("axis", {"x", "y", "z"});
      p.axis = axis[0] - 'x';
      const std::string stat = o.choice("stat", {"max", "min", "extent"});
      p.stat_max = stat != "min";
      p.stat_extent = stat == "extent";
      if (o.has("link") && !p.stat_extent) fail(o.path("link"), "only for \"stat\": \"extent\"");
      if (o.has("link")) p.link = o.positive("link");
      if (o.has("region")) {
        Obj r(o.raw("region"), o.path("region"), {"min", "max"}, allowed);
        p.region = r.box();
      }
    } else if (type == "pressure") {
      p.type = ProbeType::Pressure;
      p.point = o.vec3("point");
      // Optional sensor face (issue 20, Lobovsky et al. 2014): the mean over a disc of this radius in the
      // plane normal to `normal`, like a pressure transducer's sensing area.
      if (o.has("radius")) {
        p.radius = o.positive("radius");
        p.normal = o.unit("normal");
      } else if (o.has("normal")) {
        fail(o.path("normal"), "only with \"radius\" (the sensor's face)");
      }
    } else if (type == "body") {
      p.type = ProbeType::BodyState;
      p.body = body_index(s, o.string("body"), o.path("body"));
    } else if (type == "point") {
      p.type = ProbeType::Point;
      p.body = body_index(s, o.string("body"), o.path("body"));
      p.reference = o.vec3("reference");
    } else if (type == "displacement") {
      // .ux .uy .uz of the body particle nearest `point` at t = 0.
      p.type = ProbeType::Displacement;
      p.body = body_index(s, o.string("body"), o.path("body"));
      p.point = o.vec3("point");
    } else if (type == "energy") {
      p.type = ProbeType::Energy;
    } else if (type == "momentum") {
      p.type = ProbeType::Momentum;
    } else if (type == "open_boundary") {
      p.type = ProbeType::OpenBoundary;
      if (s.open_boundaries.empty()) fail(o.path("type"), "the scene has no open_boundaries");
    } else if (type == "flow_rate") {
      p.type = ProbeType::FlowRate;
      p.point = o.vec3("point");
      p.normal = o.unit("normal");
      p.radius = o.positive("radius");
    } else if (type == "stress") {
      p.type = ProbeType::Stress;
      const auto names = o.strings("bodies");
      if (names.empty()) fail(o.path("bodies"), "expected at least one body");
      for (std::size_t k = 0; k < names.size(); ++k) {
        p.bodies.push_back(body_index(s, names[k], index(o.path("bodies"), k)));
        if (s.materials[s.bodies[p.bodies.back()].material].type != MaterialType::Elastic &&
            s.materials[s.bodies[p.bodies.back()].material].type != MaterialType::Shell)
          fail(index(o.path("bodies"), k), "body '" + names[k] + "' is not elastic: it carries no stress");
      }
      // Per body (docs/valve-metrics.md): the valve frame the peak's place is given in; for aortic_root
      // leaflets by default the root's annulus plane (its base, +y).
      p.per_body = o.boolean("per_body", false);
      if (!p.per_body && (o.has("point") || o.has("normal")))
        fail(o.path(o.has("point") ? "point" : "normal"), "only with \"per_body\": true");
      if (p.per_body) {
        const Body& b0 = s.bodies[p.bodies.front()];
        const bool root = b0.shape.kind == ShapeKind::AorticRoot && identity_transform(b0);
        if (!root && !(o.has("point") && o.has("normal")))
          fail(path,
               "per_body needs 'point' and 'normal' (the annulus plane) unless the bodies are "
               "untransformed aortic_root leaflets");
        p.point = root ? o.vec3("point", b0.shape.aortic.base) : o.vec3("point");
        p.normal = root ? o.unit("normal", Vec3::UnitY()) : o.unit("normal");
      }
    } else if (type == "max_speed") {
      p.type = ProbeType::MaxSpeed;
      const auto names = o.strings("bodies", std::vector<std::string>{});
      for (std::size_t k = 0; k < names.size(); ++k) {
        p.bodies.push_back(body_index(s, names[k], index(o.path("bodies"), k)));
        if (s.materials[s.bodies[p.bodies.back()].material].type != MaterialType::Fluid)
          fail(index(o.path("bodies"), k), "body '" + names[k] + "' is not a fluid");
      }
      if (o.has("region")) {
        Obj r(o.raw("region"), o.path("region"), {"min", "max"}, allowed);
        p.region = r.box();
      }
      p.smoothed = o.boolean("smoothed", false);
    } else if (type == "coaptation") {
      p.type = ProbeType::Coaptation;
      const auto names = o.strings("bodies");
      if (names.size() < 2) fail(o.path("bodies"), "expected at least two leaflets");
      if (names.size() > 16) fail(o.path("bodies"), "expected at most 16 leaflets");
      for (std::size_t k = 0; k < names.size(); ++k) {
        p.bodies.push_back(body_index(s, names[k], index(o.path("bodies"), k)));
        for (std::size_t l = 0; l < k; ++l)
          if (p.bodies[l] == p.bodies.back())
            fail(index(o.path("bodies"), k), "body '" + names[k] + "' listed twice");
      }
      p.point = o.vec3("point");
      p.normal = o.unit("normal");
      p.distance = o.positive("distance", 1.5 * s.spacing);
      p.central_radius = o.positive("central_radius", 2.0 * s.spacing);
      p.per_body = o.boolean("per_leaflet", false);
    } else if (type == "gap_area") {
      // The orifice's open area split into the central part and one part per commissure.
      p.type = ProbeType::GapArea;
      const auto names = o.strings("bodies");
      if (names.empty()) fail(o.path("bodies"), "expected at least one body");
      for (std::size_t k = 0; k < names.size(); ++k)
        p.bodies.push_back(body_index(s, names[k], index(o.path("bodies"), k)));
      const Body& b0 = s.bodies[p.bodies.front()];
      const bool root = b0.shape.kind == ShapeKind::AorticRoot && identity_transform(b0);
      const std::optional<AorticRoot> geo =
          root ? std::optional<AorticRoot>(AorticRoot(b0.shape.aortic)) : std::nullopt;
      p.point = root ? o.vec3("point", b0.shape.aortic.base) : o.vec3("point");
      p.normal = root ? o.unit("normal", Vec3::UnitY()) : o.unit("normal");
      if (o.has("radius") || !root)
        p.radius = o.positive("radius");
      else
        p.radius = geo->orifice_radius();
      p.central_radius = o.positive("central_radius", p.radius / 3.0);
      if (p.central_radius >= p.radius)
        fail(o.path("central_radius"), "must be smaller than the radius (" + json(p.radius).dump() + " m)");
      if (o.has("commissures")) {
        const json& c = o.raw("commissures");
        if (!c.is_array() || c.size() < 2 || c.size() > 16)
          fail(o.path("commissures"), "expected a list of 2 to 16 points [x, y, z]");
        for (std::size_t k = 0; k < c.size(); ++k) {
          const json& q = c[k];
          if (!q.is_array() || q.size() != 3 || !q[0].is_number() || !q[1].is_number() || !q[2].is_number())
            fail(index(o.path("commissures"), k), "expected a point [x, y, z]");
          const Vec3 x(q[0].get<double>(), q[1].get<double>(), q[2].get<double>());
          const Vec3 rel = x - p.point;
          if ((rel - rel.dot(p.normal) * p.normal).norm() < 1e-9)
            fail(index(o.path("commissures"), k), "on the axis: it has no direction about it");
          p.commissures.push_back(x);
        }
      } else if (root) {
        // The root's commissures (AorticRoot: sector k starts at commissure k).
        const AorticRootParams& g = geo->params();
        for (int k = 0; k < 3; ++k)
          p.commissures.push_back(
              geo->to_world(g.commissure_radius, geo->sector_start(k), g.commissure_height));
      } else {
        fail(o.path("commissures"), "required unless the bodies are untransformed aortic_root leaflets");
      }
    } else if (type == "wall_distance") {
      // The smallest distance from the leaflets to the wall (docs/valve-metrics.md).
      p.type = ProbeType::WallDistance;
      const auto names = o.strings("bodies");
      if (names.empty()) fail(o.path("bodies"), "expected at least one body");
      if (names.size() > 16) fail(o.path("bodies"), "expected at most 16 bodies");
      for (std::size_t k = 0; k < names.size(); ++k)
        p.bodies.push_back(body_index(s, names[k], index(o.path("bodies"), k)));
      const auto walls = o.strings("walls");
      if (walls.empty()) fail(o.path("walls"), "expected at least one body");
      for (std::size_t k = 0; k < walls.size(); ++k) {
        p.walls.push_back(body_index(s, walls[k], index(o.path("walls"), k)));
        if (std::find(p.bodies.begin(), p.bodies.end(), p.walls.back()) != p.bodies.end())
          fail(index(o.path("walls"), k), "body '" + walls[k] + "' is also in 'bodies'");
      }
      p.exclude = o.non_negative("exclude", 3.0 * s.spacing);
      p.reach = o.positive("reach", 8.0 * s.spacing);
      if (p.reach > 50.0 * s.spacing) fail(o.path("reach"), "at most 50 spacings");
    } else if (type == "gap") {
      p.type = ProbeType::Gap;
      const auto names = o.strings("bodies");
      if (names.size() < 2) fail(o.path("bodies"), "expected at least two bodies");
      for (std::size_t k = 0; k < names.size(); ++k) {
        p.bodies.push_back(body_index(s, names[k], index(o.path("bodies"), k)));
        for (std::size_t l = 0; l < k; ++l)
          if (p.bodies[l] == p.bodies.back())
            fail(index(o.path("bodies"), k), "body '" + names[k] + "' listed twice");
      }
    } else {
      // The valve: one body (SPEC) or several (`bodies`: the three leaflets of an aortic valve).
      p.type = ProbeType::OrificeArea;
      if (o.has("body") == o.has("bodies")) fail(path, "orifice_area needs either 'body' or 'bodies'");
      if (o.has("body")) {
        p.bodies.push_back(body_index(s, o.string("body"), o.path("body")));
      } else {
        const auto names = o.strings("bodies");
        if (names.empty()) fail(o.path("bodies"), "expected at least one body");
        for (std::size_t k = 0; k < names.size(); ++k)
          p.bodies.push_back(body_index(s, names[k], index(o.path("bodies"), k)));
      }
      p.point = o.vec3("point");
      p.normal = o.unit("normal");
      if (o.has("radius")) {
        p.radius = o.positive("radius");
      } else {
        // Default: the valve's own disc, when it is an aortic_root leaflet (AorticRoot::orifice_radius()).
        const Shape& sh = s.bodies[p.bodies.front()].shape;
        if (sh.kind != ShapeKind::AorticRoot)
          fail(o.path("radius"), "required unless the valve is an aortic_root leaflet");
        p.radius = AorticRoot(sh.aortic).orifice_radius();
      }
    }
    return p;
  }

  // time.end from a cycle block with `cycles` (start + cycles x period), or nothing.
  std::optional<double> cycle_end(json& j) {
    if (!j.is_object() || !j.contains("cycles")) return std::nullopt;
    Obj o(j, "cycle", cycle_keys(), allowed);
    const double period = o.positive("period");
    const int cycles = o.integer("cycles", std::nullopt, 1, 100000);
    return o.non_negative("start", 0.0) + cycles * period;
  }

  static std::vector<std::string> cycle_keys() {
    return {"period",       "cycles",    "start",         "lv_pressure",  "aortic_pressure", "valve_flow",
            "orifice_area", "jet_speed", "lvot_flow",     "lvot_area",    "stress",          "coaptation",
            "hold_level",   "gap_area",  "wall_distance", "pressure_zero"};
  }

  // The probe a column name belongs to: a probe `name` writes the column `name` (one-column probes) or
  // `name.field`. The exact field list is checked against the probes' columns before a run starts
  // (check_cycle_columns in app/run.cpp).
  static const Probe* column_probe(const Scene& s, const std::string& column) {
    const Probe* best = nullptr;
    for (const Probe& p : s.probes)
      if (column == p.name || (column.size() > p.name.size() + 1 &&
                               column.compare(0, p.name.size(), p.name) == 0 && column[p.name.size()] == '.'))
        if (!best || p.name.size() > best->name.size()) best = &p;
    return best;
  }

  // The cycle block (docs/scenes.md "cycle"): the period and the probe columns of the valve metrics.
  CycleSpec cycle(json& j, const Scene& s) {
    Obj o(j, "cycle", cycle_keys(), allowed);
    CycleSpec c;
    c.period = o.positive("period");
    if (o.has("cycles")) c.cycles = o.integer("cycles", std::nullopt, 1, 100000);
    c.start = o.non_negative("start", 0.0);
    if (c.cycles > 0 && c.start + c.cycles * c.period > s.t_end * (1 + 1e-9))
      fail(o.path("cycles"), std::to_string(c.cycles) +
                                 " cycles need time.end >= " + json(c.start + c.cycles * c.period).dump() +
                                 " s, got " + json(s.t_end).dump());
    if (c.period < 4.0 * s.probe_interval)
      fail(o.path("period"),
           "must hold at least 4 probe rows (time.probe_interval " + json(s.probe_interval).dump() + " s)");
    if (c.start + c.period > s.t_end + 1e-9 * c.period)
      fail(o.path("period"), "time.end " + json(s.t_end).dump() + " s holds no complete cycle (start " +
                                 json(c.start).dump() + " s + period)");
    auto column = [&](const char* key, bool required, std::string& out) {
      if (!required && !o.has(key)) return;
      out = o.string(key);
      const Probe* p = column_probe(s, out);
      if (!p) fail(o.path(key), "no probe writes a column '" + out + "'");
    };
    column("valve_flow", true, c.valve_flow);
    column("lv_pressure", true, c.lv_pressure);
    column("aortic_pressure", true, c.aortic_pressure);
    column("orifice_area", false, c.orifice_area);
    column("jet_speed", false, c.jet_speed);
    column("lvot_flow", false, c.lvot_flow);
    if (o.has("lvot_area")) {
      c.lvot_area = o.positive("lvot_area");
    } else {
      // The disc of the flow_rate probe the LVOT flow is read from: pi r^2.
      const Probe* p = column_probe(s, c.lvot_flow.empty() ? c.valve_flow : c.lvot_flow);
      if (p && p->type == ProbeType::FlowRate) c.lvot_area = std::numbers::pi * p->radius * p->radius;
    }
    auto named_probe = [&](const char* key, ProbeType type, const char* what, std::string& out) {
      if (!o.has(key)) return;
      out = o.string(key);
      const auto it =
          std::find_if(s.probes.begin(), s.probes.end(), [&](const Probe& p) { return p.name == out; });
      if (it == s.probes.end()) fail(o.path(key), "no probe named '" + out + "'");
      if (it->type != type) fail(o.path(key), "probe '" + out + "' is not a " + what + " probe");
    };
    named_probe("stress", ProbeType::Stress, "stress", c.stress);
    named_probe("coaptation", ProbeType::Coaptation, "coaptation", c.coaptation);
    named_probe("gap_area", ProbeType::GapArea, "gap_area", c.gap_area);
    named_probe("wall_distance", ProbeType::WallDistance, "wall_distance", c.wall_distance);
    c.hold_level = o.non_negative("hold_level", 9332.57);
    double background = 0.0;
    for (const Material& m : s.materials)
      if (m.type == MaterialType::Fluid) {
        c.density = m.density;
        background = m.background_pressure;
        break;
      }
    c.pressure_zero = o.number("pressure_zero", background);
    return c;
  }

  // [low, high] with low < high (a colour range).
  static std::pair<double, double> color_range(Obj& o, const std::string& key) {
    const json& v = o.raw(key);
    if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
      fail(o.path(key), "expected two numbers [low, high]");
    const std::pair<double, double> r{v[0].get<double>(), v[1].get<double>()};
    if (!(r.first < r.second)) fail(o.path(key), "low must be below high");
    return r;
  }

  void render(json& j, Scene& s) {
    Obj o(j, "render",
          {"width", "height", "background", "color_by", "colormap", "range", "cameras", "clip", "figures"},
          allowed);
    RenderSettings& r = s.render;
    r.width = o.integer("width", 1280, 2, 16384);
    r.height = o.integer("height", 720, 2, 16384);
    if (r.width % 2 || r.height % 2)
      fail(o.path(r.width % 2 ? "width" : "height"), "must be even (movies need even sizes)");
    if (!o.has("background")) j["background"] = {1.0, 1.0, 1.0};
    r.background = o.color("background");
    const std::vector<std::string> fields = {"material", "speed", "pressure", "displacement", "stress"};
    r.color_by = o.choice("color_by", fields, "material");
    r.colormap = o.string("colormap", "viridis");
    if (o.has("range")) r.range = color_range(o, "range");
    if (!o.has("cameras")) j["cameras"] = json::array();
    json& cams = o.raw("cameras");
    if (!cams.is_array()) fail(o.path("cameras"), "expected a list, got " + type_name(cams));
    for (std::size_t c = 0; c < cams.size(); ++c) {
      Obj co(cams[c], index("render.cameras", c),
             {"name", "eye", "target", "up", "fov_deg", "color_by", "colormap", "range", "hide", "clip"},
             allowed);
      Camera cam;
      cam.name = co.string("name");
      if (cam.name.empty() || cam.name.find('/') != std::string::npos)
        fail(co.path("name"), "must be a non-empty name without '/'");
      for (const Camera& other : r.cameras)
        if (other.name == cam.name) fail(co.path("name"), "duplicate camera name '" + cam.name + "'");
      cam.eye = co.vec3("eye");
      cam.target = co.vec3("target");
      cam.up = co.unit("up", Vec3::UnitY());
      cam.fov_deg = co.number("fov_deg", 35.0);
      if (cam.fov_deg <= 1 || cam.fov_deg >= 179) fail(co.path("fov_deg"), "must lie in (1, 179) degrees");
      if ((cam.eye - cam.target).norm() < 1e-12) fail(co.path("target"), "must differ from eye");
      if ((cam.eye - cam.target).normalized().cross(cam.up).norm() < 1e-6)
        fail(co.path("up"), "is parallel to the viewing direction");
      // Overrides of the run-wide settings; absent keys are not filled in (absent = the run-wide value, so
      // that --set render.color_by=... still reaches every camera that does not set its own).
      if (co.has("color_by")) cam.color_by = co.choice("color_by", fields);
      if (co.has("colormap")) cam.colormap = co.string("colormap");  // the renderer checks the name
      if (co.has("range")) cam.range = color_range(co, "range");
      if (co.has("hide")) {
        const auto names = co.strings("hide");
        for (std::size_t k = 0; k < names.size(); ++k)
          cam.hide.push_back(body_index(s, names[k], index(co.path("hide"), k)));
      }
      if (co.has("clip")) cam.clip = co.boolean("clip", true);
      r.cameras.push_back(cam);
    }
    if (o.has("clip")) {
      Obj co(o.raw("clip"), "render.clip", {"point", "normal", "bodies"}, allowed);
      Clip clip;
      clip.point = co.vec3("point");
      clip.normal = co.unit("normal");
      const auto names = co.strings("bodies", std::vector<std::string>{});
      for (std::size_t k = 0; k < names.size(); ++k)
        clip.bodies.push_back(body_index(s, names[k], index(co.path("bodies"), k)));
      r.clip = clip;
    }
    if (!o.has("figures")) j["figures"] = json::array();
    json& figs = o.raw("figures");
    if (!figs.is_array()) fail(o.path("figures"), "expected a list, got " + type_name(figs));
    for (std::size_t f = 0; f < figs.size(); ++f) {
      Obj fo(figs[f], index("render.figures", f), {"name", "camera", "times", "columns"}, allowed);
      Figure fig;
      fig.name = fo.string("name");
      if (fig.name.empty() || fig.name.find('/') != std::string::npos)
        fail(fo.path("name"), "must be a non-empty name without '/'");
      fig.camera = fo.string("camera");
      if (std::none_of(r.cameras.begin(), r.cameras.end(),
                       [&](const Camera& c) { return c.name == fig.camera; }))
        fail(fo.path("camera"), "unknown camera '" + fig.camera + "'");
      const json& t = fo.raw("times");
      if (!t.is_array() || t.empty()) fail(fo.path("times"), "expected a non-empty list of times");
      for (std::size_t k = 0; k < t.size(); ++k) {
        if (!t[k].is_number()) fail(index(fo.path("times"), k), "expected a number, got " + type_name(t[k]));
        const double v = t[k].get<double>();
        if (v < 0 || v > s.t_end + 1e-12) fail(index(fo.path("times"), k), "must lie in 0..time.end");
        fig.times.push_back(v);
      }
      fig.columns = fo.integer("columns", 3, 1, 64);
      r.figures.push_back(fig);
    }
  }
};

// Applies one --set KEY=VALUE to the JSON. A key may be new only where the loader allows it (an optional
// key).
void apply_override(json& root, const std::string& item,
                    const std::map<std::string, std::set<std::string>>& allowed) {
  const auto eq = item.find('=');
  if (eq == std::string::npos || eq == 0) throw InputError("--set " + item + ": expected KEY=VALUE");
  const std::string key = item.substr(0, eq), text = item.substr(eq + 1);
  json value = json::parse(text, nullptr, false);
  if (value.is_discarded()) value = text;  // not JSON: a plain string

  std::vector<std::string> parts;
  std::stringstream ss(key);
  for (std::string part; std::getline(ss, part, '.');) parts.push_back(part);
  json* node = &root;
  std::string path;  // in the loader's notation: a.b[2].c
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const std::string& part = parts[k];
    const bool last = k + 1 == parts.size();
    if (node->is_array()) {
      std::size_t i = 0;
      try {
        std::size_t used = 0;
        i = std::stoul(part, &used);
        if (used != part.size()) throw std::invalid_argument("");
      } catch (const std::exception&) {
        throw InputError("--set " + item + ": '" + part + "' is not a list index (at '" + path + "')");
      }
      if (i >= node->size())
        throw InputError("--set " + item + ": index " + part + " out of range ('" + path + "' has " +
                         std::to_string(node->size()) + " entries)");
      path = index(path, i);
      node = &(*node)[i];
    } else if (node->is_object()) {
      const std::string here = path;
      path = join(path, part);
      if (!node->contains(part)) {
        const auto it = allowed.find(here);
        const bool known = it != allowed.end() && it->second.count(part);
        if (!known || !last)
          throw InputError("--set " + item + ": unknown path '" + key + "' (no '" + part + "' at '" +
                           (here.empty() ? "scene" : here) + "')");
      }
      node = &(*node)[part];
    } else {
      throw InputError("--set " + item + ": unknown path '" + key + "' ('" + path +
                       "' is a value, not an object or list)");
    }
  }
  *node = value;
}

}  // namespace

LoadedScene load_scene_json(const nlohmann::json& j, const std::vector<std::string>& overrides,
                            const std::filesystem::path& base_dir) {
  // First pass: validate the file as written, fill in defaults, learn which optional keys each object allows.
  json filled = j;
  Loader first;
  first.base_dir = base_dir;
  Scene scene = first.load(filled);
  if (overrides.empty()) return {scene, filled};
  // Then apply --set to the filled JSON and validate again.
  for (const auto& o : overrides) apply_override(filled, o, first.allowed);
  Loader second;
  second.base_dir = base_dir;
  return {second.load(filled), filled};
}

LoadedScene load_scene_text(const std::string& text, const std::vector<std::string>& overrides,
                            const std::string& what, const std::filesystem::path& base_dir) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    // parse_error, and out_of_range for a number beyond the double range (1e999).
    throw InputError(what + ": not valid JSON: " + e.what());
  }
  return load_scene_json(j, overrides, base_dir);
}

LoadedScene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(file.string() + ": no such scene file");
  std::ifstream f(file, std::ios::binary);
  if (!f) throw InputError(file.string() + ": cannot read");
  std::ostringstream text;
  text << f.rdbuf();
  if (f.bad()) throw InputError(file.string() + ": cannot read");
  return load_scene_text(text.str(), overrides, file.string(), file.parent_path());
}

}  // namespace aortasph
