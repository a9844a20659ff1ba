// Snapshot: a copy of what the renderer needs at one output time. The simulation fills it and hands it to the
// render thread (render/pipeline), so the renderer never touches live simulation state.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "scene.hpp"

namespace aortasph {

// Triangle mesh in single precision, used for wall surfaces (render: "surface").
struct SurfaceMesh {
  std::vector<std::array<float, 3>> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;  // counter-clockwise seen from outside (normal points out)
  bool empty() const { return triangles.empty(); }
};

struct BodyView {
  std::string name;
  MaterialType type = MaterialType::Fluid;
  std::array<float, 3> color = {0.2f, 0.4f, 0.9f};  // rgb 0..1, from the scene or a default per material
  RenderMode render = RenderMode::Particles;
  SurfaceMesh mesh;  // in world coordinates at this snapshot's time (may be empty)
  // Shell bodies: triangles through the body's particles (indices into Snapshot::position), oriented along
  // the shell normals; drawn as a lit, two-sided, opaque sheet instead of the particles (may be empty).
  std::vector<std::array<uint32_t, 3>> sheet;
};

// One per-particle field a camera colours by.
struct SnapshotField {
  std::string name;           // e.g. "speed"
  std::string unit;           // e.g. "m/s"
  std::vector<float> values;  // n values
};

// The unit of a field cameras colour by (SnapshotField::unit; the colour bar's label), "" for none.
inline const char* field_unit(const std::string& field) {
  if (field == "speed") return "m/s";
  if (field == "pressure" || field == "stress") return "Pa";
  if (field == "displacement") return "m";
  return "";
}

struct Snapshot {
  double time = 0.0;
  int frame = 0;                      // output index k: time = k * output_interval
  double spacing = 0.01;              // particle spacing: splat radius = spacing / 2
  std::vector<float> position;        // 3 * n, xyz per particle
  std::vector<uint16_t> body;         // body index per particle (index into bodies)
  std::vector<SnapshotField> fields;  // each field some camera colours by, once (none for "material")
  std::vector<BodyView> bodies;
  size_t size() const { return body.size(); }
  // The field of that name, or nullptr.
  const SnapshotField* field(const std::string& name) const {
    for (const SnapshotField& f : fields)
      if (f.name == name) return &f;
    return nullptr;
  }
};

}  // namespace aortasph
