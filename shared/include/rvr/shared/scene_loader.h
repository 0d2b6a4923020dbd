// Loading and validating rvr-scene/1 files and built-in scenes.
#pragma once

#include <string>
#include <vector>

#include "rvr/shared/expected.h"
#include "rvr/shared/scene.h"

namespace rvr {

// Reads and validates a scene file. Errors name the file, the JSON path and what is wrong:
// "scenes/bad.json: objects[3].radius: must be > 0, got -1" or
// "scenes/bad.json:12:5: JSON syntax: expected ',' or '}'".
Expected<Scene> load_scene_file(const std::string& path);

// Parses scene JSON text; `source` names it in messages and `base_dir` resolves mesh paths.
Expected<Scene> parse_scene(const std::string& json_text, const std::string& source,
                            const std::string& base_dir);

// "builtin:NAME" or a path.
Expected<Scene> load_scene(const std::string& spec);

struct BuiltinSceneInfo {
  std::string name;         // e.g. "occluders:N"
  std::string description;  // one line
};
std::vector<BuiltinSceneInfo> builtin_scenes();

// NAME as in "cornell", "soup:1000".
Expected<Scene> make_builtin_scene(const std::string& name);

}  // namespace rvr
