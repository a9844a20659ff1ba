// Scene files (SPEC.md section 2): JSON -> validated Scene. Every error names the JSON path of the value at
// fault
// ("bodies[2].shape.box.max: expected 3 numbers, got 2") and is thrown as InputError (exit code 2) before
// anything is simulated.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene.hpp"

namespace aortasph {

struct LoadedScene {
  Scene scene;
  nlohmann::json resolved;  // the JSON after --set overrides, every default filled in (written to run.json)
};

// overrides: "KEY=VALUE" strings from --set (dotted path with list indices; VALUE is JSON, or else a string).
LoadedScene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides);
// The text of a scene file (what load_scene reads); `what` names it in messages. base_dir: the folder that
// files the scene names (waveforms) are relative to; load_scene() passes the scene file's folder.
LoadedScene load_scene_text(const std::string& text, const std::vector<std::string>& overrides,
                            const std::string& what = "scene", const std::filesystem::path& base_dir = {});
LoadedScene load_scene_json(const nlohmann::json& j, const std::vector<std::string>& overrides,
                            const std::filesystem::path& base_dir = {});

}  // namespace aortasph
