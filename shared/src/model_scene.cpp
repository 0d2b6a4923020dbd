// A model file as a scene: the file's meshes, materials, first camera and point lights, with
// a framing camera and default lights where it has none (docs/scene-format.md).
#include <fmt/format.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <filesystem>
#include <new>
#include <set>

#include "mesh_import.h"
#include "mesh_repair.h"
#include "rvr/shared/camera_framing.h"
#include "rvr/shared/scene_loader.h"
#include "scene_json_errors.h"
#include "scene_transforms.h"

namespace rvr {
namespace fs = std::filesystem;

namespace scene_load {

// Default lighting when the file has no point lights: ambient, and one white key light above
// and to the left of the eye so that faces turned to the camera are lit and shadows fall
// behind the model. Its intensity gives an irradiance of 1 at the model's centre.
constexpr float kDefaultAmbient = 0.15f;

void add_default_lights(Scene& scene, const BoundingSphere& bounds) {
  const Camera& c = scene.camera;
  glm::vec3 forward = glm::normalize(c.target - c.eye);
  glm::vec3 right = glm::normalize(glm::cross(forward, c.up));
  glm::vec3 up = glm::cross(right, forward);
  float distance = glm::length(c.eye - bounds.centre);
  Light key;
  key.type = LightType::Point;
  key.position = c.eye + (0.5f * up - 0.3f * right) * distance;
  float d2 = glm::dot(key.position - bounds.centre, key.position - bounds.centre);
  key.intensity = glm::vec3(d2);
  scene.lights.push_back(key);
  scene.ambient = glm::vec3(kDefaultAmbient);
}

std::string unique_name(const std::string& wanted, std::set<std::string>& taken) {
  std::string name = wanted.empty() ? "material" : wanted;
  for (int i = 2; taken.count(name) || name == "default"; ++i) {
    name = fmt::format("{}#{}", wanted.empty() ? "material" : wanted, i);
  }
  taken.insert(name);
  return name;
}

Scene build_model_scene(const std::string& path, const SceneOverrides& overrides) {
  const std::optional<glm::vec3>& view_from = overrides.view_from;
  ImportedModel model = import_model(path, "", "");
  Scene scene;
  scene.source = path;
  scene.materials.push_back(default_material());
  std::set<std::string> taken;
  size_t dropped = 0, repaired = 0;
  for (ModelPart& part : model.parts) {
    Object o;
    o.name = part.name;
    o.type = ObjectType::Triangles;
    o.mesh = std::move(part.mesh);
    finish_mesh(o.mesh, Transform{}, "", &dropped, &repaired);
    if (o.mesh.triangles.empty()) continue;
    if (part.material) {
      part.material->name = unique_name(part.material->name, taken);
      scene.materials.push_back(*part.material);
      o.material = static_cast<uint32_t>(scene.materials.size() - 1);
    }
    scene.objects.push_back(std::move(o));
  }
  if (scene.objects.empty()) fail("", "all triangles are degenerate (zero area)");
  BoundingSphere bounds = scene_bounds(scene);
  bool own_camera = model.camera && !view_from;
  if (own_camera && model.camera_aspect > 0.0f) {  // the image takes the camera's shape
    scene.image.width = overrides.width.value_or(scene.image.width);
    scene.image.height =
        std::clamp(int(std::lround(scene.image.width / model.camera_aspect)), 1, 16384);
  }
  if (overrides.width) scene.image.width = *overrides.width;
  if (overrides.height) scene.image.height = *overrides.height;
  if (own_camera) {
    scene.camera = *model.camera;
  } else {
    frame_camera(scene, bounds, view_from ? *view_from : default_view_from());
  }
  if (model.lights.empty()) {
    add_default_lights(scene, bounds);
  } else {
    scene.lights = model.lights;
    // A light without falloff (Collada's default) gives the same irradiance at the model's
    // centre as the rvr point light (inverse square) of intensity colour x distance^2.
    for (size_t i : model.unattenuated_lights) {
      Light& l = scene.lights[i];
      glm::vec3 d = l.position - bounds.centre;
      l.intensity *= std::max(glm::dot(d, d), 1e-6f);
    }
    scene.ambient = glm::vec3(0.05f);
  }
  scene.warnings = model.warnings;
  if (model.skipped_primitives > 0) {
    scene.warnings.push_back(
        fmt::format("ignored {} point/line primitives", model.skipped_primitives));
  }
  if (dropped > 0) {
    scene.warnings.push_back(
        fmt::format("dropped {} degenerate triangle{}", dropped, dropped == 1 ? "" : "s"));
  }
  if (repaired > 0) {
    scene.warnings.push_back(
        fmt::format("replaced {} zero or non-finite vertex normal{} by face "
                    "normals",
                    repaired, repaired == 1 ? "" : "s"));
  }
  for (std::string& w : scene.warnings) w = path + ": " + w;
  return scene;
}

}  // namespace scene_load

bool is_model_file_name(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext.empty() || ext == ".json") return false;
  return Assimp::Importer().IsExtensionSupported(ext);
}

Expected<Scene> load_model_scene(const std::string& path, const SceneOverrides& overrides) {
  try {
    return scene_load::build_model_scene(path, overrides);
  } catch (const scene_load::LoadError& e) {
    return bad_input(path + ": " + (e.path.empty() ? "" : e.path + ": ") + e.what);
  } catch (const std::bad_alloc&) {
    return internal_error(path + ": out of memory while loading the model");
  } catch (const std::exception& e) {
    return internal_error(path + ": internal error while loading the model: " + e.what());
  } catch (...) {
    return internal_error(path + ": internal error while loading the model");
  }
}

}  // namespace rvr
