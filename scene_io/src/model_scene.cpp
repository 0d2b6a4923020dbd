// A model file as a scene: the file's meshes, materials, first camera and point lights, with
// a framing camera and default lights where it has none or where asked, turned so that its up
// is +y, and an automatic exposure (docs/scene-format.md).
#include <fmt/format.h>
#include <stddef.h>
#include <stdint.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <glm/glm.hpp>
#include <new>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "mesh_import.h"
#include "mesh_repair.h"
#include "rvr/core/expected.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/scene_io/camera_framing.h"
#include "rvr/scene_io/scene_loader.h"
#include "scene_json_errors.h"
#include "scene_textures.h"
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

// The rotation that turns `up` (a unit axis, +-x, +-y or +-z) to +y by the smallest angle
// (90 degrees about an axis in the horizontal plane, or 180 about x for -y).
glm::mat3 turn_up_to_y(const glm::vec3& up) {
  const glm::vec3 y(0.0f, 1.0f, 0.0f);
  float c = glm::dot(up, y);
  if (c > 0.5f) return glm::mat3(1.0f);
  if (c < -0.5f) return glm::mat3(glm::vec3(1, 0, 0), glm::vec3(0, -1, 0), glm::vec3(0, 0, -1));
  // up is horizontal: a quarter turn about k = up x y, which takes up to y and y to -up.
  glm::vec3 k = glm::cross(up, y);
  // Rodrigues at 90 degrees: R v = (k.v) k + k x v.
  glm::mat3 r;
  for (int i = 0; i < 3; ++i) {
    glm::vec3 e(0.0f);
    e[i] = 1.0f;
    r[i] = glm::dot(k, e) * k + glm::cross(k, e);
  }
  return r;
}

// Turns the whole model (meshes, camera, lights) by `r` about the origin.
void turn_model(ImportedModel& model, const glm::mat3& r) {
  for (ModelPart& part : model.parts) {
    for (glm::vec3& p : part.mesh.positions) p = r * p;
    for (glm::vec3& n : part.mesh.normals) n = r * n;
  }
  if (model.camera) {
    model.camera->eye = r * model.camera->eye;
    model.camera->target = r * model.camera->target;
    model.camera->up = r * model.camera->up;
  }
  for (Light& l : model.lights) l.position = r * l.position;
}

// Why a file camera does not frame the model (view_of_model, kMinSeen, kMinSize), or "" when
// it does.
std::string camera_problem(const ViewOfModel& view) {
  auto percent = [](float share) { return fmt::format("{:.0f}%", 100.0f * share); };
  if (view.seen == 0.0f) return "sees none of the model";
  if (view.seen < kMinSeen) {
    return fmt::format("sees {} of the model's surface (under {}: a part or a close-up)",
                       percent(view.seen), percent(kMinSeen));
  }
  if (view.size < kMinSize) {
    return fmt::format("shows the model {} of the frame across (under {})", percent(view.size),
                       percent(kMinSize));
  }
  return {};
}

// The automatic exposure of a model file: the brightest a diffuse surface of the model can
// be, per channel, is emission + diffuse * (ambient + E), E bounding the irradiance of the
// lights anywhere in the bounding sphere: sum of I / (distance from the light to the sphere)^2,
// that distance taken as at least half the radius (a light inside the sphere). The exposure
// brings that to 1 when it is above (EV = -log2 of it), and is 0 otherwise: diffuse shading
// then never clips, and only specular highlights can. From the scene alone, so every renderer
// gets the same value.
float automatic_exposure(const Scene& scene, const BoundingSphere& bounds) {
  glm::vec3 irradiance(0.0f);
  for (const Light& l : scene.lights) {
    glm::vec3 at =
        l.type == LightType::Point ? l.position : l.corner + 0.5f * (l.edge_u + l.edge_v);
    float gap = std::max(glm::length(at - bounds.centre) - bounds.radius, 0.5f * bounds.radius);
    irradiance += l.intensity / (gap * gap);
  }
  float peak = 0.0f;
  std::vector<bool> used(scene.materials.size(), false);
  for (const Object& o : scene.objects) used[o.material] = true;
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    if (!used[m]) continue;
    const Material& mat = scene.materials[m];
    glm::vec3 brightest = mat.emission + mat.diffuse * (scene.ambient + irradiance);
    peak = std::max({peak, brightest.r, brightest.g, brightest.b});
  }
  if (!(peak > 1.0f) || !std::isfinite(peak)) return 0.0f;
  return std::max(-std::log2(peak), -kMaxExposure);
}

std::string unique_name(const std::string& wanted, std::set<std::string>& taken) {
  std::string name = wanted.empty() ? "material" : wanted;
  for (int i = 2; taken.count(name) || name == "default"; ++i) {
    name = fmt::format("{}#{}", wanted.empty() ? "material" : wanted, i);
  }
  taken.insert(name);
  return name;
}

// The scene of an imported model; `path` names it in warnings and its folder is where the
// model's texture files are found. Model files and meshes from memory (load_mesh_scene).
Scene scene_of_model(ImportedModel model, const std::string& path,
                     const SceneOverrides& overrides) {
  const std::optional<glm::vec3>& view_from = overrides.view_from;
  // Up: the file's (auto) or the one asked for, turned to +y before anything is framed.
  glm::vec3 up = overrides.up == UpAxis::Auto ? model.up
                 : overrides.up == UpAxis::Z  ? glm::vec3(0.0f, 0.0f, 1.0f)
                                              : glm::vec3(0.0f, 1.0f, 0.0f);
  if (up != glm::vec3(0.0f, 1.0f, 0.0f)) turn_model(model, turn_up_to_y(up));
  Scene scene;
  scene.source = path;
  scene.materials.push_back(default_material());
  std::set<std::string> taken;
  size_t dropped = 0, repaired = 0;
  std::vector<std::string> texture_warnings;
  SceneTextures textures(scene, texture_warnings);
  const std::string folder = fs::path(path).parent_path().string();
  for (ModelPart& part : model.parts) {
    Object o;
    o.name = part.name;
    o.type = ObjectType::Triangles;
    o.mesh = std::move(part.mesh);
    finish_mesh(o.mesh, Transform{}, "", &dropped, &repaired);
    if (o.mesh.triangles.empty()) continue;
    if (part.material) {
      part.material->name = unique_name(part.material->name, taken);
      if (part.texture) {
        part.material->texture =
            textures.add(part.texture->file, folder, part.texture->wrap_u, part.texture->wrap_v,
                         &model.images, "material " + quote_json(part.material->name));
        part.material->uv_transform = part.texture->transform;
      }
      scene.materials.push_back(*part.material);
      o.material = static_cast<uint32_t>(scene.materials.size() - 1);
    }
    scene.objects.push_back(std::move(o));
  }
  if (scene.objects.empty()) fail("", "all triangles are degenerate (zero area)");
  BoundingSphere bounds = scene_bounds(scene);
  if (model.camera && !view_from && overrides.camera == FromFile::File &&
      overrides.judge_file_camera) {
    // A file camera that shows a part of the model, a close-up, a speck or nothing at all (an
    // exporter's camera left where it was) is replaced by the framing camera, with a warning.
    // Judged in the frame the image will have: a height given makes its shape, else the
    // camera's aspect ratio does (below).
    const float width = float(overrides.width.value_or(scene.image.width));
    const float aspect = overrides.height             ? width / float(*overrides.height)
                         : model.camera_aspect > 0.0f ? model.camera_aspect
                                                      : width / float(scene.image.height);
    if (const std::string problem = camera_problem(view_of_model(scene, *model.camera, aspect));
        !problem.empty()) {
      model.warnings.push_back("the file's camera " + problem +
                               "; framing the model instead (--camera file-always keeps it)");
      model.camera.reset();
    }
  }
  bool own_camera = model.camera && !view_from && overrides.camera == FromFile::File;
  if (own_camera && model.camera_aspect > 0.0f) {  // the image takes the camera's shape
    scene.image.width = overrides.width.value_or(scene.image.width);
    scene.image.height =
        std::clamp(int(std::lround(scene.image.width / model.camera_aspect)), 1, kMaxImageSize);
  }
  if (overrides.width) scene.image.width = *overrides.width;
  if (overrides.height) scene.image.height = *overrides.height;
  if (own_camera) {
    scene.camera = *model.camera;
  } else {
    frame_camera(scene, bounds, view_from ? *view_from : default_view_from());
  }
  if (model.lights.empty() || overrides.lights == FromFile::Auto) {
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
  scene.image.exposure = overrides.exposure.value_or(automatic_exposure(scene, bounds));
  scene.warnings = model.warnings;
  scene.warnings.insert(scene.warnings.end(), texture_warnings.begin(), texture_warnings.end());
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
  for (std::string& w : scene.warnings) w.insert(0, path + ": ");
  return scene;
}

Scene build_model_scene(const std::string& path, const SceneOverrides& overrides) {
  return scene_of_model(import_model(path, "", ""), path, overrides);
}

// A mesh from memory checked as a model file's is by its importer: every index names a vertex,
// positions are finite, normals and colours are one per vertex when given.
void check_mesh(const TriangleMesh& mesh) {
  const size_t n = mesh.positions.size();
  if (mesh.triangles.empty()) fail("indices", "no triangle");
  if (!mesh.normals.empty() && mesh.normals.size() != n)
    fail("normals", fmt::format("{} normals for {} vertices", mesh.normals.size(), n));
  if (!mesh.colours.empty() && mesh.colours.size() != n)
    fail("colors", fmt::format("{} colours for {} vertices", mesh.colours.size(), n));
  for (size_t i = 0; i < n; ++i) {
    if (!finite(mesh.positions[i])) fail(fmt::format("vertices[{}]", i), "must be finite numbers");
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (mesh.triangles[t][k] >= n)
        fail(fmt::format("indices[{}]", t),
             fmt::format("vertex {} is past the last of the {} vertices", mesh.triangles[t][k], n));
    }
  }
}

}  // namespace scene_load

bool is_model_file_name(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext.empty() || ext == ".json") return false;
  return scene_load::model_extension_supported(ext);
}

namespace {

// `build` (a model scene's) with its errors as values: bad input naming `source`, the JSON
// path and what is wrong; internal errors otherwise.
template <class Build>
Expected<Scene> model_scene_or_error(const std::string& source, Build&& build) {
  try {
    return build();
  } catch (const scene_load::LoadError& e) {
    return bad_input(source + ": " + (e.path.empty() ? "" : e.path + ": ") + e.what);
  } catch (const std::bad_alloc&) {
    return internal_error(source + ": out of memory while loading the model");
  } catch (const std::exception& e) {
    return internal_error(source + ": internal error while loading the model: " + e.what());
  } catch (...) {
    return internal_error(source + ": internal error while loading the model");
  }
}

}  // namespace

Expected<Scene> load_model_scene(const std::string& path, const SceneOverrides& overrides) {
  return model_scene_or_error(path, [&] { return scene_load::build_model_scene(path, overrides); });
}

Expected<Scene> load_mesh_scene(TriangleMesh mesh, const std::string& source,
                                const SceneOverrides& overrides) {
  return model_scene_or_error(source, [&] {
    scene_load::check_mesh(mesh);
    scene_load::ImportedModel model;  // up +y unless overrides.up says z
    scene_load::ModelPart part;
    part.name = source;
    part.mesh = std::move(mesh);
    model.parts.push_back(std::move(part));
    return scene_load::scene_of_model(std::move(model), source, overrides);
  });
}

}  // namespace rvr
