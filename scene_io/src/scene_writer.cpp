// Writing a Scene as rvr-scene/1 (the inverse of scene_loader.cpp for what the format can
// express). Internally a WriteError is thrown and turned into an rvr::Error at the boundary.
#include "rvr/scene_io/scene_writer.h"

#include <fmt/format.h>

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <glm/glm.hpp>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>

#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/scene_field.h"
#include "rvr/core/shapes/shape_list.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/texture.h"

namespace rvr {
namespace {

using json = nlohmann::ordered_json;

struct WriteError {
  std::string what;
};

[[noreturn]] void fail(std::string what) {
  throw WriteError{std::move(what)};
}

// The shortest decimal that reads back (decimal -> double -> float, as the loader does) to
// exactly f; whole numbers as JSON integers; -0 stays -0.
json num(float f, const std::string& path) {
  if (!std::isfinite(f)) fail(fmt::format("{}: {} is not finite", path, f));
  if (f == 0.0f) return std::signbit(f) ? json(-0.0) : json(0);
  char buf[64];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf - 1, f);
  double d = double(f);
  if (ec == std::errc()) {
    *end = '\0';
    double shortest = std::strtod(buf, nullptr);
    // Kept unless it reads back otherwise (double rounding) or lies past FLT_MAX, which the
    // loader refuses even where it would round to FLT_MAX: 3.4028235e38 does.
    if (float(shortest) == f && std::abs(shortest) <= double(std::numeric_limits<float>::max())) {
      d = shortest;
    }
  }
  if (d == std::floor(d) && std::abs(d) < 9.0e15) return json(int64_t(d));
  return json(d);
}

json vec(const glm::vec3& v, const std::string& path) {
  return json::array({num(v.x, path + "[0]"), num(v.y, path + "[1]"), num(v.z, path + "[2]")});
}

json vec2(const glm::vec2& v, const std::string& path) {
  return json::array({num(v.x, path + "[0]"), num(v.y, path + "[1]")});
}

const char* wrap_name(TextureWrap w) {
  switch (w) {
    case TextureWrap::ClampToEdge:
      return "clamp";
    case TextureWrap::MirroredRepeat:
      return "mirror";
    case TextureWrap::Repeat:
      break;
  }
  return "repeat";
}

// Level 0 of a texture as an image, the top row first (the level's last row).
Image texture_image(const MipChain& mips) {
  const TextureLevel& level = mips.levels.at(0);
  Image img;
  img.width = level.width;
  img.height = level.height;
  img.channels = 3;
  img.channel_names = {"R", "G", "B"};
  img.pixels.resize(size_t(level.width) * size_t(level.height) * 3);
  for (int y = 0; y < level.height; ++y) {
    for (int x = 0; x < level.width; ++x) {
      const glm::vec3& c = level.at(x, level.height - 1 - y);
      for (int k = 0; k < 3; ++k) img.at(x, y, k) = c[k];
    }
  }
  return img;
}

// Where the document names texture i: its file relative to the document's folder when it lies
// under that folder, else its absolute path or (`copy`) a copy beside the document; a file
// written beside the document for a texture in memory only; the name it had for one that was
// not found.
std::string texture_file(const Scene& scene, size_t i, const std::string& mesh_prefix,
                         const std::string& document_folder, bool copy, SceneDocument& doc) {
  namespace fs = std::filesystem;
  const Texture& t = scene.textures[i];
  if (!t.resolved.empty()) {
    std::error_code ec;
    const fs::path file = fs::absolute(t.resolved, ec).lexically_normal();
    const fs::path folder =
        fs::absolute(document_folder.empty() ? "." : document_folder, ec).lexically_normal();
    const fs::path relative = file.lexically_relative(folder);
    if (!ec && !relative.empty() && *relative.begin() != "..") return relative.generic_string();
    if (!copy) return file.generic_string();
    std::string name = fmt::format("{}.texture{}{}", mesh_prefix, i, file.extension().string());
    doc.copied_files.push_back({name, file.string()});
    return name;
  }
  if (!t.mips || t.mips->levels.empty()) return t.file;
  std::string name = fmt::format("{}.texture{}.exr", mesh_prefix, i);
  doc.texture_files.push_back({name, texture_image(*t.mips)});
  return name;
}

json texture_json(const Material& m, const std::string& file, const std::string& path,
                  const Scene& scene) {
  const Texture& t = scene.textures[size_t(m.texture)];
  json o = json::object();
  o["file"] = file;
  o["wrap"] = t.wrap_u == t.wrap_v ? json(wrap_name(t.wrap_u))
                                   : json::array({wrap_name(t.wrap_u), wrap_name(t.wrap_v)});
  if (!m.uv_transform.identity()) {
    const UvTransform& u = m.uv_transform;
    o["transform"] = {{"offset", vec2(u.offset, path + ".transform.offset")},
                      {"rotation", num(u.rotation, path + ".transform.rotation")},
                      {"scale", vec2(u.scale, path + ".transform.scale")}};
  }
  return o;
}

json material_json(const Material& m, const std::string& path) {
  json o = json::object();
  o["diffuse"] = vec(m.diffuse, path + ".diffuse");
  o["specular"] = vec(m.specular, path + ".specular");
  o["emission"] = vec(m.emission, path + ".emission");
  o["shininess"] = num(m.shininess, path + ".shininess");
  o["mirror"] = num(m.mirror, path + ".mirror");
  o["transparency"] = num(m.transparency, path + ".transparency");
  o["ior"] = num(m.ior, path + ".ior");
  return o;
}

bool same_material(const Material& a, const Material& b) {
  return a.diffuse == b.diffuse && a.specular == b.specular && a.emission == b.emission &&
         a.shininess == b.shininess && a.mirror == b.mirror && a.transparency == b.transparency &&
         a.ior == b.ior && a.texture == b.texture && a.uv_transform.identity() &&
         b.uv_transform.identity();
}

// An analytic shape's type and keys, as its scene_fields state them (scene_field.h).
template <class Shape>
json shape_members(json o, const Shape& shape, const std::string& path) {
  o["type"] = Shape::kSceneType;
  Shape::scene_fields(shape, [&](const SceneField& f, const auto& member) {
    const std::string key_path = path + "." + f.key;
    if constexpr (std::is_same_v<std::decay_t<decltype(member)>, float>) {
      o[f.key] = num(member, key_path);
    } else {
      o[f.key] = vec(member, key_path);
    }
  });
  return o;
}

// A csg node below the object: a leaf is a sphere, an inner node a nested csg.
json csg_node(const CsgNode& n, const std::string& path, int depth) {
  if (depth > 64) fail(path + ": csg tree nested deeper than 64 levels");
  if (n.is_leaf) return shape_members(json::object(), n.sphere, path);
  if (!n.a || !n.b) fail(path + ": csg node without two children");
  static const char* kOps[] = {"union", "intersection", "difference"};
  json o = json::object();
  if (depth > 1) o["type"] = "csg";
  o["op"] = kOps[int(n.op)];
  o["a"] = csg_node(*n.a, path + ".a", depth + 1);
  o["b"] = csg_node(*n.b, path + ".b", depth + 1);
  return o;
}

// Indented like dump(2), but an array of scalars, or of arrays of scalars, on one line.
bool flat(const json& v) {
  if (!v.is_array()) return !v.is_object();
  for (const json& e : v) {
    if (e.is_object() || (e.is_array() && !flat(e))) return false;
  }
  return true;
}

void print(const json& v, int indent, std::string& out) {
  if (v.is_array() && flat(v)) {
    out += '[';
    for (size_t i = 0; i < v.size(); ++i) {
      if (i) out += ", ";
      print(v[i], indent, out);
    }
    out += ']';
  } else if (v.is_array() || v.is_object()) {
    if (v.empty()) {
      out += v.is_array() ? "[]" : "{}";
      return;
    }
    out += v.is_array() ? "[\n" : "{\n";
    size_t i = 0;
    for (auto it = v.begin(); it != v.end(); ++it, ++i) {
      out.append(size_t(indent) + 2, ' ');
      if (v.is_object()) out += json(it.key()).dump() + ": ";
      print(*it, indent + 2, out);
      out += i + 1 < v.size() ? ",\n" : "\n";
    }
    out.append(size_t(indent), ' ');
    out += v.is_array() ? ']' : '}';
  } else {
    out += v.dump();
  }
}

void put_u8(std::string& out, uint8_t v) {
  out.push_back(char(v));
}
void put_i32(std::string& out, int32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);  // x86 and every platform rvr builds on are little-endian
  out.append(b, 4);
}
void put_f32(std::string& out, float v) {
  char b[4];
  std::memcpy(b, &v, 4);
  out.append(b, 4);
}

std::string ply(const TriangleMesh& mesh, const std::string& path) {
  if (mesh.positions.size() > uint64_t(INT32_MAX)) fail(path + ": too many vertices for PLY");
  const size_t n = mesh.positions.size();
  const bool smooth = mesh.smooth(), uvs = mesh.textured(), colours = mesh.coloured();
  if (smooth && mesh.normals.size() != n) fail(path + ": normals and positions differ in number");
  if (uvs && mesh.uvs.size() != n) fail(path + ": uvs and positions differ in number");
  if (colours && mesh.colours.size() != n) fail(path + ": colours and positions differ in number");
  std::string out = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment written by rvr scenes --export\n"
      "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
      n);
  if (smooth) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (uvs) out += "property float s\nproperty float t\n";
  if (colours) out += "property float red\nproperty float green\nproperty float blue\n";
  out += fmt::format("element face {}\nproperty list uchar int vertex_indices\nend_header\n",
                     mesh.triangles.size());
  auto finite_values = [&](const float* v, int count, const char* what) {
    for (int k = 0; k < count; ++k) {
      if (!std::isfinite(v[k])) fail(path + ": " + what + " is not finite");
      put_f32(out, v[k]);
    }
  };
  for (size_t i = 0; i < n; ++i) {
    finite_values(&mesh.positions[i].x, 3, "a vertex");
    if (smooth) {
      for (int k = 0; k < 3; ++k) put_f32(out, mesh.normals[i][k]);
    }
    if (uvs) finite_values(&mesh.uvs[i].x, 2, "a texture coordinate");
    if (colours) finite_values(&mesh.colours[i].x, 3, "a vertex colour");
  }
  for (const glm::uvec3& t : mesh.triangles) {
    put_u8(out, 3);
    for (int k = 0; k < 3; ++k) {
      if (t[k] >= mesh.positions.size()) fail(path + ": a vertex index is out of range");
      put_i32(out, int32_t(t[k]));
    }
  }
  return out;
}

// The scene's lights as the file's "lights" array.
json lights_json(const std::vector<Light>& scene_lights) {
  json lights = json::array();
  for (size_t i = 0; i < scene_lights.size(); ++i) {
    const Light& l = scene_lights[i];
    std::string path = fmt::format("lights[{}]", i);
    if (l.type == LightType::Point) {
      lights.push_back({{"type", "point"},
                        {"position", vec(l.position, path + ".position")},
                        {"intensity", vec(l.intensity, path + ".intensity")}});
    } else {
      lights.push_back({{"type", "area"},
                        {"corner", vec(l.corner, path + ".corner")},
                        {"edge_u", vec(l.edge_u, path + ".edge_u")},
                        {"edge_v", vec(l.edge_v, path + ".edge_v")},
                        {"intensity", vec(l.intensity, path + ".intensity")},
                        {"samples", l.samples}});
    }
  }
  return lights;
}

// A one-triangle flat mesh as a "triangle" object: its vertices, and uvs and colours when it
// has them.
json triangle_members(json j, const TriangleMesh& mesh, const std::string& path) {
  j["type"] = "triangle";
  json verts = json::array();
  for (int k = 0; k < 3; ++k) {
    uint32_t v = mesh.triangles[0][k];
    if (v >= mesh.positions.size()) fail(path + ": a vertex index is out of range");
    verts.push_back(vec(mesh.positions[v], fmt::format("{}.vertices[{}]", path, k)));
  }
  j["vertices"] = std::move(verts);
  if (mesh.textured() || mesh.coloured()) {
    json uvs = json::array(), colours = json::array();
    for (int k = 0; k < 3; ++k) {
      uint32_t v = mesh.triangles[0][k];
      if (mesh.textured()) {
        if (v >= mesh.uvs.size()) fail(path + ": uvs and positions differ in number");
        uvs.push_back(vec2(mesh.uvs[v], fmt::format("{}.uvs[{}]", path, k)));
      }
      if (mesh.coloured()) {
        if (v >= mesh.colours.size()) fail(path + ": colours and positions differ in number");
        colours.push_back(vec(mesh.colours[v], fmt::format("{}.colors[{}]", path, k)));
      }
    }
    if (mesh.textured()) j["uvs"] = std::move(uvs);
    if (mesh.coloured()) j["colors"] = std::move(colours);
  }
  return j;
}

SceneDocument write(const Scene& scene, const std::string& mesh_prefix,
                    const std::string& document_folder, bool copy_texture_files) {
  SceneDocument doc;
  json root = json::object();
  root["format"] = "rvr-scene/1";

  const ImageSettings& im = scene.image;
  root["image"] = {{"width", im.width},
                   {"height", im.height},
                   {"background", vec(im.background, "image.background")},
                   {"samples_per_pixel", im.samples_per_pixel}};
  if (im.exposure != 0.0f) root["image"]["exposure"] = num(im.exposure, "image.exposure");

  const Camera& c = scene.camera;
  root["camera"] = {{"eye", vec(c.eye, "camera.eye")},
                    {"target", vec(c.target, "camera.target")},
                    {"up", vec(c.up, "camera.up")},
                    {"fov_y_deg", num(c.fov_y_deg, "camera.fov_y_deg")},
                    {"near", num(c.near, "camera.near")},
                    {"far", num(c.far, "camera.far")},
                    {"aperture_radius", num(c.aperture_radius, "camera.aperture_radius")},
                    {"focus_distance", num(c.focus_distance, "camera.focus_distance")}};
  root["ambient"] = vec(scene.ambient, "ambient");

  if (scene.materials.empty() || !same_material(scene.materials[0], default_material())) {
    fail("materials[0]: is not the built-in default material, which a file cannot redefine");
  }
  json materials = json::object();
  std::set<std::string> names;
  std::map<size_t, std::string> texture_files;  // texture index -> the name written
  for (size_t i = 1; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    std::string path = fmt::format("materials[{}]", i);
    if (m.name.empty()) fail(path + ": has no name");
    if (!names.insert(m.name).second) fail(path + ": duplicate material name '" + m.name + "'");
    materials[m.name] = material_json(m, path);
    if (m.texture >= 0) {
      if (size_t(m.texture) >= scene.textures.size()) fail(path + ": texture index out of range");
      auto [it, added] = texture_files.try_emplace(size_t(m.texture));
      if (added) {
        it->second = texture_file(scene, size_t(m.texture), mesh_prefix, document_folder,
                                  copy_texture_files, doc);
      }
      materials[m.name]["texture"] = texture_json(m, it->second, path + ".texture", scene);
    }
  }
  root["materials"] = std::move(materials);

  root["lights"] = lights_json(scene.lights);

  json objects = json::array();
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const Object& o = scene.objects[i];
    std::string path = fmt::format("objects[{}]", i);
    if (o.material >= scene.materials.size()) fail(path + ": material index out of range");
    json j = json::object();
    j["type"] = "";  // first in the object; set below
    j["name"] = o.name;
    if (o.type == ObjectType::Triangles) {
      const TriangleMesh& mesh = o.mesh;
      if (mesh.triangles.empty()) fail(path + ": a mesh with no triangles");
      if (mesh.triangles.size() == 1 && !mesh.smooth()) {
        j = triangle_members(std::move(j), mesh, path);
      } else {
        std::string file = fmt::format("{}.mesh{}.ply", mesh_prefix, i);
        j["type"] = "mesh";
        j["file"] = file;
        j["smooth"] = mesh.smooth();
        doc.mesh_files.push_back({file, ply(mesh, path)});
      }
    } else if (o.type == ObjectType::Csg) {
      if (!o.csg || o.csg->is_leaf) fail(path + ": a csg object needs an operation at its root");
      json tree = csg_node(*o.csg, path, 1);
      j["type"] = "csg";
      for (auto& [k, v] : tree.items()) j[k] = v;
    } else {  // one of shape_list.h's analytic shapes
#define RVR_WRITE_SHAPE(Type, Enumerator, member) \
  if (o.type == ObjectType::Enumerator) j = shape_members(std::move(j), o.member, path);
      RVR_ANALYTIC_SHAPES(RVR_WRITE_SHAPE)
#undef RVR_WRITE_SHAPE
    }
    if (o.material != 0) j["material"] = scene.materials[o.material].name;
    objects.push_back(std::move(j));
  }
  root["objects"] = std::move(objects);
  print(root, 0, doc.json);
  doc.json += '\n';
  return doc;
}

}  // namespace

Expected<SceneDocument> write_scene(const Scene& scene, const std::string& mesh_prefix,
                                    const std::string& document_folder, bool copy_texture_files) {
  std::string source = scene.source.empty() ? "scene" : scene.source;
  try {
    return write(scene, mesh_prefix, document_folder, copy_texture_files);
  } catch (const WriteError& e) {
    return bad_input(source + ": " + e.what);
  } catch (const std::exception& e) {
    return internal_error(source + ": internal error while writing the scene: " + e.what());
  }
}

}  // namespace rvr
