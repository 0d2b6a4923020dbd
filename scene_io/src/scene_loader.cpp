// Loading and validating rvr-scene/1 files (see docs/scene-format.md).
//
// Errors are reported as "FILE: json.path: what is wrong" or, for JSON syntax,
// "FILE:LINE:COL: JSON syntax: what". Internally the reader throws a LoadError and the public
// functions turn it (and anything else, e.g. std::bad_alloc) into an rvr::Error: no exception
// escapes.
//
// Decisions the format's key table leaves open (all documented in docs/scene-format.md):
// - `transform` is accepted on every object type. On `mesh` and `triangle` it is a full affine
//   map (normals by the inverse transpose). On the analytic shapes (`sphere`, `plane`, `disc`,
//   `csg`) it moves centres/points and turns normals; the scale must then be uniform in magnitude
//   (|sx| = |sy| = |sz|), since a sphere would otherwise become an ellipsoid and a square a
//   rectangle and a disc an ellipse, which the model cannot express. A plane's square keeps the
//   in-plane orientation given by plane_axes(normal) (a rotation about the normal has no effect).
// - A `triangle` object whose triangle is degenerate (zero area) is an error; in a `mesh`,
//   degenerate triangles are dropped with a warning, and a mesh left with none is an error.
// - Duplicate keys in a JSON object are an error (the last one would silently win).
// - Limits against hostile input: JSON nesting <= 512, csg nesting <= 64, light samples per
//   side <= 64, samples per pixel <= 4096, meshes <= 50 million triangles.
#include "rvr/scene_io/scene_loader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <memory>
#include <new>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <variant>

#include "json_fields.h"
#include "mesh_import.h"
#include "mesh_repair.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/scene_field.h"
#include "rvr/core/shapes/shape_list.h"
#include "rvr/core/texture.h"
#include "rvr/scene_io/camera_framing.h"
#include "scene_json_errors.h"
#include "scene_json_parse.h"
#include "scene_textures.h"
#include "scene_transforms.h"

namespace rvr {
namespace fs = std::filesystem;

namespace scene_load {
namespace {

constexpr int kMaxCsgDepth = 64;
constexpr int kMaxSamplesPerPixel = 4096;
constexpr int kMaxLightSamples = 64;
constexpr const char* kFormat = "rvr-scene/1";
// A mesh object's material that keeps the mesh file's own materials; no material may be
// named so.
constexpr const char* kFromFile = "from_file";

// ------------------------------------------------------------------------------------------
// The scene reader.

class Reader {
 public:
  Reader(Scene& scene, std::string base_dir, std::vector<std::string> material_order)
      : scene_(scene),
        base_dir_(std::move(base_dir)),
        material_order_(std::move(material_order)),
        textures_(scene, scene.warnings) {}

  void read(const json& root) {
    check_object(root, "");
    check_keys(root, "",
               {"format", "image", "camera", "ambient", "materials", "lights", "objects"});
    if (const json* f = find(root, "format")) {
      const std::string& s = string(*f, "format");
      if (s != kFormat) {
        fail("format", fmt::format("must be '{}', got {}", kFormat, quote_json(s)));
      }
    }
    if (const json* image = find(root, "image")) read_image(*image);
    read_camera(require(root, "", "camera", "eye, target and up at least"));
    if (const json* a = find(root, "ambient")) scene_.ambient = colour(*a, "ambient");
    scene_.materials.clear();
    scene_.materials.push_back(default_material());
    if (const json* m = find(root, "materials")) read_materials(*m);
    if (const json* l = find(root, "lights")) read_lights(*l);
    if (const json* o = find(root, "objects")) read_objects(*o);
  }

 private:
  void read_image(const json& v) {
    const std::string path = "image";
    check_object(v, path);
    check_keys(v, path, {"width", "height", "background", "samples_per_pixel", "exposure"});
    ImageSettings& im = scene_.image;
    if (const json* w = find(v, "width")) im.width = integer(*w, "image.width", 1, kMaxImageSize);
    if (const json* h = find(v, "height")) {
      im.height = integer(*h, "image.height", 1, kMaxImageSize);
    }
    if (const json* b = find(v, "background")) im.background = colour(*b, "image.background");
    if (const json* s = find(v, "samples_per_pixel")) {
      im.samples_per_pixel = integer(*s, "image.samples_per_pixel", 1, kMaxSamplesPerPixel,
                                     " (capped at " + std::to_string(kMaxSamplesPerPixel) + ")");
    }
    if (const json* e = find(v, "exposure")) {
      im.exposure = real(*e, "image.exposure");
      if (!(std::fabs(im.exposure) <= kMaxExposure)) {
        fail("image.exposure",
             fmt::format("must be between -{0} and {0} stops, got {1}", kMaxExposure, e->dump()));
      }
    }
  }

  void read_camera(const json& v) {
    const std::string path = "camera";
    check_object(v, path);
    check_keys(
        v, path,
        {"eye", "target", "up", "fov_y_deg", "near", "far", "aperture_radius", "focus_distance"});
    Camera& c = scene_.camera;
    c.eye = vec3(require(v, path, "eye"), "camera.eye");
    c.target = vec3(require(v, path, "target"), "camera.target");
    c.up = vec3(require(v, path, "up"), "camera.up");
    glm::dvec3 view = glm::dvec3(c.target) - glm::dvec3(c.eye);
    if (glm::length(view) == 0.0) {
      fail("camera.target", "must differ from camera.eye (both are " + vec_text(c.eye) + ")");
    }
    glm::vec3 view_f = c.target - c.eye;
    float view_len = glm::length(view_f);
    if (!std::isfinite(view_len) || !(view_len > 0.0f) || !finite(glm::normalize(view_f))) {
      fail("camera.target", "is too far from or too close to camera.eye for 32-bit floats");
    }
    glm::dvec3 up(c.up);
    if (glm::length(up) == 0.0) fail("camera.up", "must be non-zero");
    double sine = glm::length(glm::cross(glm::normalize(view), glm::normalize(up)));
    if (!(sine > 1e-6)) {
      fail("camera.up", "must not be parallel to target - eye, got up " + vec_text(c.up) +
                            " and target - eye " + vec_text(view_f));
    }
    // Only its direction matters; unit length keeps float camera maths away from underflow.
    c.up = glm::vec3(glm::normalize(up));
    if (const json* f = find(v, "fov_y_deg")) {
      c.fov_y_deg = real(*f, "camera.fov_y_deg");
      if (!(c.fov_y_deg > 0.0f && c.fov_y_deg < 180.0f)) {
        fail("camera.fov_y_deg", "must be in (0, 180), got " + fmt_num(f->get<double>()));
      }
    }
    if (const json* n = find(v, "near")) c.near = real_at_least(*n, "camera.near", 0, Bound::Open);
    if (const json* f = find(v, "far")) c.far = real(*f, "camera.far");
    if (!(c.far > c.near)) {
      fail("camera.far",
           fmt::format("must be > camera.near ({}), got {}", fmt_num(c.near), fmt_num(c.far)));
    }
    if (const json* a = find(v, "aperture_radius")) {
      c.aperture_radius = real_at_least(*a, "camera.aperture_radius", 0, Bound::Closed);
    }
    if (const json* f = find(v, "focus_distance")) {
      c.focus_distance = real_at_least(*f, "camera.focus_distance", 0, Bound::Open);
    } else {
      c.focus_distance = view_len;
    }
  }

  void read_materials(const json& v) {
    const std::string path = "materials";
    check_object(v, path);
    // File order (recorded while parsing); the DOM's own order is alphabetical.
    std::vector<std::string> names = material_order_;
    if (names.size() != v.size()) {
      names.clear();
      for (const auto& [name, m] : v.items()) names.push_back(name);
    }
    for (const std::string& name : names) {
      std::string p = key_path(path, name);
      if (name.empty()) fail(path, "material names must not be empty");
      if (name == kFromFile) {
        fail(p,
             "the name \"from_file\" is reserved (a mesh's \"material\": \"from_file\" "
             "keeps the file's own materials)");
      }
      scene_.materials.push_back(read_material(v.at(name), p, name));
      material_index_[name] = static_cast<uint32_t>(scene_.materials.size() - 1);
    }
  }

  Material read_material(const json& v, const std::string& path, const std::string& name) {
    check_object(v, path);
    check_keys(v, path,
               {"diffuse", "specular", "emission", "shininess", "mirror", "transparency", "ior",
                "texture"});
    Material m;
    m.name = name;
    if (const json* d = find(v, "diffuse")) m.diffuse = colour(*d, key_path(path, "diffuse"));
    if (const json* s = find(v, "specular")) m.specular = colour(*s, key_path(path, "specular"));
    if (const json* e = find(v, "emission")) m.emission = colour(*e, key_path(path, "emission"));
    if (const json* s = find(v, "shininess")) {
      m.shininess = real_at_least(*s, key_path(path, "shininess"), 0, Bound::Closed);
    }
    if (const json* r = find(v, "mirror")) m.mirror = real_in_unit(*r, key_path(path, "mirror"));
    if (const json* t = find(v, "transparency")) {
      m.transparency = real_in_unit(*t, key_path(path, "transparency"));
    }
    if (double(m.mirror) + double(m.transparency) > 1.0 + 1e-6) {
      fail(path, fmt::format("mirror + transparency must be <= 1, got {} + {}",
                             fmt_num(find(v, "mirror")->get<double>()),
                             fmt_num(find(v, "transparency")->get<double>())));
    }
    if (const json* i = find(v, "ior")) {
      m.ior = real_at_least(*i, key_path(path, "ior"), 1, Bound::Closed);
    }
    if (const json* t = find(v, "texture")) read_texture(*t, key_path(path, "texture"), m);
    return m;
  }

  // "texture": "FILE" or {"file", "wrap", "transform"}. A file that cannot be found or read is
  // a warning (SceneTextures); a malformed value is an error.
  void read_texture(const json& v, const std::string& path, Material& m) {
    std::string file_path = path;
    const json* file = &v;
    TextureWrap wrap_u = TextureWrap::Repeat, wrap_v = TextureWrap::Repeat;
    if (v.is_object()) {
      check_keys(v, path, {"file", "wrap", "transform"}, "a texture");
      file_path = key_path(path, "file");
      file = &require(v, path, "file", "the image file");
      if (const json* w = find(v, "wrap")) read_wrap(*w, key_path(path, "wrap"), wrap_u, wrap_v);
      if (const json* t = find(v, "transform")) {
        m.uv_transform = read_uv_transform(*t, key_path(path, "transform"));
      }
    } else if (!v.is_string()) {
      fail(path, "must be an image file name or an object with \"file\", got " + describe(v));
    }
    const std::string& name = string(*file, file_path);
    if (name.empty()) fail(file_path, "must not be empty");
    if (name.find('\0') != std::string::npos) fail(file_path, "must not contain a NUL character");
    m.texture = textures_.add(name, base_dir_, wrap_u, wrap_v, nullptr, path);
  }

  static TextureWrap wrap_mode(const json& v, const std::string& path) {
    static const std::vector<std::string> kModes = {"repeat", "clamp", "mirror"};
    const std::string& mode = string(v, path);
    for (size_t i = 0; i < kModes.size(); ++i) {
      if (mode == kModes[i]) return TextureWrap(i);
    }
    std::string s = suggestion(mode, kModes);
    fail(path, "unknown wrap mode " + quote_json(mode) +
                   (s.empty() ? "" : " (did you mean '" + s + "'?)") + "; expected one of " +
                   join(kModes));
  }

  // "repeat", or ["clamp", "repeat"] for u and v.
  static void read_wrap(const json& v, const std::string& path, TextureWrap& u, TextureWrap& w) {
    if (v.is_array()) {
      if (v.size() != 2) fail(path, "must be a wrap mode or an array of 2, got " + describe(v));
      u = wrap_mode(v[0], index_path(path, 0));
      w = wrap_mode(v[1], index_path(path, 1));
      return;
    }
    u = w = wrap_mode(v, path);
  }

  static glm::vec2 vec2(const json& v, const std::string& path) {
    if (!v.is_array() || v.size() != 2) {
      fail(path, "must be an array of 2 numbers, got " + describe(v));
    }
    return {real(v[0], index_path(path, 0)), real(v[1], index_path(path, 1))};
  }

  static UvTransform read_uv_transform(const json& v, const std::string& path) {
    check_object(v, path);
    check_keys(v, path, {"offset", "rotation", "scale"}, "a texture transform");
    UvTransform t;
    if (const json* o = find(v, "offset")) t.offset = vec2(*o, key_path(path, "offset"));
    if (const json* r = find(v, "rotation")) t.rotation = real(*r, key_path(path, "rotation"));
    if (const json* s = find(v, "scale")) {
      t.scale = vec2(*s, key_path(path, "scale"));
      for (int i = 0; i < 2; ++i) {
        if (t.scale[i] == 0.0f)
          fail(index_path(key_path(path, "scale"), size_t(i)), "must not be 0");
      }
    }
    return t;
  }

  // "uvs" and "colors" of a triangle or mesh object: one per vertex of the mesh as loaded.
  static void read_vertex_values(const json& v, const std::string& path, TriangleMesh& mesh,
                                 const std::string& vertices) {
    const size_t n = mesh.positions.size();
    auto check_count = [&](const json& a, const std::string& p) {
      if (!a.is_array() || a.size() != n) {
        fail(p, fmt::format("must be an array of {} (one per vertex{}), got {}", n, vertices,
                            describe(a)));
      }
    };
    if (const json* u = find(v, "uvs")) {
      std::string p = key_path(path, "uvs");
      check_count(*u, p);
      mesh.uvs.clear();
      for (size_t i = 0; i < n; ++i) mesh.uvs.push_back(vec2((*u)[i], index_path(p, i)));
    }
    if (const json* c = find(v, "colors")) {
      std::string p = key_path(path, "colors");
      check_count(*c, p);
      mesh.colours.clear();
      for (size_t i = 0; i < n; ++i) mesh.colours.push_back(colour((*c)[i], index_path(p, i)));
    }
  }

  void read_lights(const json& v) {
    if (!v.is_array()) fail("lights", "must be an array, got " + describe(v));
    for (size_t i = 0; i < v.size(); ++i) scene_.lights.push_back(read_light(v[i], i));
  }

  Light read_light(const json& v, size_t index) {
    std::string path = index_path("lights", index);
    check_object(v, path);
    std::string tp = key_path(path, "type");
    const std::string& type = string(require(v, path, "type", "\"point\" or \"area\""), tp);
    Light l;
    if (type == "point") {
      check_keys(v, path, {"type", "position", "intensity"}, "a point light");
      l.type = LightType::Point;
      l.position = vec3(require(v, path, "position"), key_path(path, "position"));
      l.intensity = colour(require(v, path, "intensity"), key_path(path, "intensity"));
    } else if (type == "area") {
      check_keys(v, path, {"type", "corner", "edge_u", "edge_v", "intensity", "samples"},
                 "an area light");
      l.type = LightType::Area;
      l.corner = vec3(require(v, path, "corner"), key_path(path, "corner"));
      l.edge_u = vec3(require(v, path, "edge_u"), key_path(path, "edge_u"));
      l.edge_v = vec3(require(v, path, "edge_v"), key_path(path, "edge_v"));
      l.intensity = colour(require(v, path, "intensity"), key_path(path, "intensity"));
      if (const json* s = find(v, "samples")) {
        l.samples =
            integer(*s, key_path(path, "samples"), 1, kMaxLightSamples,
                    " (samples per side, capped at " + std::to_string(kMaxLightSamples) + ")");
      }
      glm::dvec3 u(l.edge_u), w(l.edge_v);
      if (glm::length(u) == 0.0) fail(key_path(path, "edge_u"), "must be non-zero");
      if (glm::length(w) == 0.0) fail(key_path(path, "edge_v"), "must be non-zero");
      if (!(glm::length(glm::cross(glm::normalize(u), glm::normalize(w))) > 1e-6)) {
        fail(key_path(path, "edge_v"), "is parallel to edge_u (the light would have zero area)");
      }
    } else {
      std::string s = suggestion(type, {"point", "area"});
      fail(tp, "unknown light type " + quote_json(type) +
                   (s.empty() ? "" : " (did you mean '" + s + "'?)") +
                   "; expected \"point\" or \"area\"");
    }
    return l;
  }

  void read_objects(const json& v) {
    if (!v.is_array()) fail("objects", "must be an array, got " + describe(v));
    for (size_t i = 0; i < v.size(); ++i) read_object(v[i], i);
  }

  // The object's "material": sets o.material, or returns true for "from_file" (a mesh keeps its
  // file's own materials).
  bool read_object_material(const json& v, const std::string& path, const std::string& type,
                            Object& o) {
    const json* m = find(v, "material");
    if (!m) return false;
    std::string mp = key_path(path, "material");
    const std::string& name = string(*m, mp);
    if (name == kFromFile) {
      if (type != "mesh") {
        fail(mp, "\"from_file\" keeps a mesh file's own materials: only for mesh objects");
      }
      return true;
    }
    auto it = material_index_.find(name);
    if (it == material_index_.end()) {
      std::vector<std::string> known;
      for (const auto& [k, idx] : material_index_) known.push_back(k);
      std::string s = suggestion(name, known);
      fail(mp, "unknown material " + quote_json(name) +
                   (s.empty() ? "" : " (did you mean '" + s + "'?)"));
    }
    o.material = it->second;
    return false;
  }

  // A "triangle" object: its three vertices (and their uvs and colours).
  void read_triangle_object(const json& v, const std::string& path, const Transform& t, Object& o) {
    o.type = ObjectType::Triangles;
    std::string vp = key_path(path, "vertices");
    const json& verts = require(v, path, "vertices");
    if (!verts.is_array() || verts.size() != 3) {
      fail(vp, "must be an array of 3 vertices, got " + describe(verts));
    }
    for (size_t k = 0; k < 3; ++k) o.mesh.positions.push_back(vec3(verts[k], index_path(vp, k)));
    o.mesh.triangles.emplace_back(0, 1, 2);
    read_vertex_values(v, path, o.mesh, "");
    size_t dropped = 0, repaired = 0;
    finish_mesh(o.mesh, t, path, &dropped, &repaired);
    if (dropped > 0) fail(vp, "the triangle is degenerate (zero area)");
  }

  // A "mesh" object read from its file into o, with the loader's warnings; false when it was
  // "material": "from_file" and its parts were appended to the scene already.
  bool read_mesh_object(const json& v, const std::string& path, const Transform& t, bool from_file,
                        const std::string& label, Object& o) {
    o.type = ObjectType::Triangles;
    std::string fp = key_path(path, "file");
    const std::string& file = string(require(v, path, "file"), fp);
    bool smooth = false;
    if (const json* s = find(v, "smooth")) smooth = boolean(*s, key_path(path, "smooth"));
    if (from_file) {
      for (const char* k : {"uvs", "colors"}) {
        if (find(v, k)) {
          fail(key_path(path, k),
               "is not allowed with \"material\": \"from_file\" (the "
               "file's own are kept)");
        }
      }
      read_mesh_from_file(o, file, fp, t, label);
      return false;
    }
    size_t skipped = 0, dropped = 0, repaired = 0;
    std::vector<std::string> file_warnings;
    o.mesh = import_mesh(file, base_dir_, fp, smooth, &skipped, &file_warnings);
    for (const std::string& w : file_warnings)
      scene_.warnings.push_back(fmt::format("{}: {}", label, w));
    read_vertex_values(v, path, o.mesh, fmt::format(" of {} as loaded", quote_path(file)));
    size_t total = o.mesh.triangles.size();
    finish_mesh(o.mesh, t, path, &dropped, &repaired);
    if (o.mesh.triangles.empty()) {
      fail(fp,
           fmt::format("{}: all {} triangles are degenerate (zero area)", quote_path(file), total));
    }
    if (skipped > 0) {
      scene_.warnings.push_back(
          fmt::format("{}: ignored {} point/line primitives", label, skipped));
    }
    if (dropped > 0) {
      scene_.warnings.push_back(fmt::format("{}: dropped {} degenerate triangle{}", label, dropped,
                                            dropped == 1 ? "" : "s"));
    }
    if (repaired > 0) {
      scene_.warnings.push_back(
          fmt::format("{}: replaced {} zero or non-finite vertex normal{} by face normals", label,
                      repaired, repaired == 1 ? "" : "s"));
    }
    return true;
  }

  // Appends the object to the scene: one, or for a mesh with "material": "from_file" one per
  // material of the file.
  void read_object(const json& v, size_t index) {
    static const std::vector<std::string> kTypes = object_types();
    std::string path = index_path("objects", index);
    check_object(v, path);
    std::string tp = key_path(path, "type");
    const std::string& type = string(require(v, path, "type", "one of " + join(kTypes)), tp);
    std::vector<std::string> keys = {"name", "type", "material", "transform"};
    if (std::optional<std::vector<std::string>> shape_keys = analytic_shape_keys(type)) {
      keys.insert(keys.end(), shape_keys->begin(), shape_keys->end());
    } else if (type == "triangle") {
      keys.insert(keys.end(), {"vertices", "uvs", "colors"});
    } else if (type == "mesh") {
      keys.insert(keys.end(), {"file", "smooth", "uvs", "colors"});
    } else if (type == "csg") {
      keys.insert(keys.end(), {"op", "a", "b"});
    } else {
      std::string s = suggestion(type, kTypes);
      fail(tp, "unknown object type " + quote_json(type) +
                   (s.empty() ? "" : " (did you mean '" + s + "'?)") + "; expected one of " +
                   join(kTypes));
    }
    check_keys(v, path, keys, "a " + type);

    Object o;
    o.name = type + "#" + std::to_string(index);
    if (const json* n = find(v, "name")) o.name = string(*n, key_path(path, "name"));
    const bool from_file = read_object_material(v, path, type, o);
    Transform t;
    if (const json* tr = find(v, "transform"))
      t = parse_transform(*tr, key_path(path, "transform"));
    std::string label = path + " (" + o.name + ")";

    if (type == "triangle") {
      read_triangle_object(v, path, t, o);
    } else if (type == "mesh") {
      if (!read_mesh_object(v, path, t, from_file, label, o)) return;
    } else if (type == "csg") {
      o.type = ObjectType::Csg;
      o.csg = read_csg_inner(v, path, 1, t);
    } else {  // one of shape_list.h's analytic shapes: the type is checked above
      read_analytic_shape(v, path, type, t, o);
    }
    scene_.objects.push_back(std::move(o));
  }

  // "material": "from_file": one object per mesh of the file, each with the file's material
  // (the default one where the file gives none), named NAME/MESH. The file's own normals
  // shade smoothly, as in a model file given as the scene; `smooth` is not used.
  void read_mesh_from_file(const Object& proto, const std::string& file, const std::string& fp,
                           const Transform& t, const std::string& label) {
    ImportedModel model = import_model(file, base_dir_, fp);
    size_t before = scene_.objects.size(), dropped = 0, repaired = 0;
    for (ModelPart& part : model.parts) {
      Object o = proto;
      o.name = proto.name + "/" + part.name;
      o.mesh = std::move(part.mesh);
      finish_mesh(o.mesh, t, proto.name, &dropped, &repaired);
      if (o.mesh.triangles.empty()) continue;
      o.material = 0;
      if (part.material) {
        part.material->name = file_material_name(file, part.material->name);
        if (part.texture) {
          const std::string folder =
              (fs::path(file).is_absolute() ? fs::path(file) : fs::path(base_dir_) / file)
                  .parent_path()
                  .string();
          part.material->texture =
              textures_.add(part.texture->file, folder, part.texture->wrap_u, part.texture->wrap_v,
                            &model.images, label + ": material " + quote_json(part.material->name));
          part.material->uv_transform = part.texture->transform;
        }
        scene_.materials.push_back(*part.material);
        o.material = static_cast<uint32_t>(scene_.materials.size() - 1);
      }
      scene_.objects.push_back(std::move(o));
    }
    if (scene_.objects.size() == before) {
      fail(fp, quote_path(file) + ": all triangles are degenerate (zero area)");
    }
    for (const std::string& w : model.warnings)
      scene_.warnings.emplace_back(label + ": ").append(w);
    if (model.skipped_primitives > 0) {
      scene_.warnings.push_back(
          fmt::format("{}: ignored {} point/line primitives", label, model.skipped_primitives));
    }
    if (dropped > 0) {
      scene_.warnings.push_back(fmt::format("{}: dropped {} degenerate triangle{}", label, dropped,
                                            dropped == 1 ? "" : "s"));
    }
    if (repaired > 0) {
      scene_.warnings.push_back(
          fmt::format("{}: replaced {} zero or non-finite vertex normal{} by face normals", label,
                      repaired, repaired == 1 ? "" : "s"));
    }
  }

  // A file's material named after the file, unique among the scene's materials (rvr-scene/1
  // names are unique, so that an exported scene reads back).
  std::string file_material_name(const std::string& file, const std::string& material) {
    std::string wanted = file + ":" + material;
    std::string name = wanted;
    for (int i = 2;; ++i) {
      bool taken = std::any_of(scene_.materials.begin(), scene_.materials.end(),
                               [&](const Material& m) { return m.name == name; });
      if (!taken) return name;
      name = fmt::format("{}#{}", wanted, i);
    }
  }

  // The scene format's object types: the analytic shapes of shape_list.h, then the others.
  static std::vector<std::string> object_types() {
#define RVR_SHAPE_TYPE(Type, Enumerator, member) Type::kSceneType,
    return {RVR_ANALYTIC_SHAPES(RVR_SHAPE_TYPE) "triangle", "mesh", "csg"};
#undef RVR_SHAPE_TYPE
  }

  // The keys of the analytic shape called `type` in the file; nullopt when no shape is.
  static std::optional<std::vector<std::string>> analytic_shape_keys(const std::string& type) {
    std::optional<std::vector<std::string>> keys;
    auto keys_of = [&](auto shape_type) {
      using Shape = typename decltype(shape_type)::type;
      Shape shape;
      keys.emplace();
      Shape::scene_fields(shape, [&](const SceneField& f, auto&) { keys->push_back(f.key); });
    };
#define RVR_SHAPE_KEYS(Type, Enumerator, member) \
  if (type == Type::kSceneType) keys_of(std::type_identity<Type>{});
    RVR_ANALYTIC_SHAPES(RVR_SHAPE_KEYS)
#undef RVR_SHAPE_KEYS
    return keys;
  }

  // Reads the object as the analytic shape called `type`, transformed.
  static void read_analytic_shape(const json& v, const std::string& path, const std::string& type,
                                  const Transform& t, Object& o) {
#define RVR_READ_SHAPE(Type, Enumerator, member)                    \
  if (type == Type::kSceneType) {                                   \
    o.type = ObjectType::Enumerator;                                \
    o.member = transform_shape(read_shape<Type>(v, path), t, path); \
  }
    RVR_ANALYTIC_SHAPES(RVR_READ_SHAPE)
#undef RVR_READ_SHAPE
  }

  // A shape's keys as its scene_fields state them, checked but not transformed (directions
  // are normalised by transform_shape).
  template <class Shape>
  static Shape read_shape(const json& v, const std::string& path) {
    Shape shape;
    Shape::scene_fields(shape, [&](const SceneField& f, auto& member) {
      const std::string kp = key_path(path, f.key);
      const json* value = f.required ? &require(v, path, f.key) : find(v, f.key);
      if (!value) return;
      if constexpr (std::is_same_v<std::decay_t<decltype(member)>, float>) {
        member = real_at_least(*value, kp, 0, Bound::Open);  // SceneFieldKind::Length
      } else {
        member = vec3(*value, kp);
        if (f.kind == SceneFieldKind::Direction && glm::length(glm::dvec3(member)) == 0.0)
          fail(kp, "must be non-zero");
      }
    });
    return shape;
  }

  static void require_uniform(const Transform& t, const std::string& path, const char* what) {
    if (!t.uniform()) {
      fail(path + ".transform.scale",
           fmt::format("{} needs a uniform scale (one number, or three of equal magnitude), got "
                       "[{}, {}, {}]",
                       what, fmt_num(t.scale.x), fmt_num(t.scale.y), fmt_num(t.scale.z)));
    }
  }

  // The shape moved, turned and scaled by `t` (whose scale must then be uniform: an analytic
  // shape cannot be stretched), its directions normalised (in double precision).
  template <class Shape>
  static Shape transform_shape(Shape shape, const Transform& t, const std::string& path) {
    if (!t.identity) {
      require_uniform(t, path, (std::string("a ") + Shape::kSceneType).c_str());
      Shape::scene_fields(shape, [&](const SceneField& f, auto& member) {
        if constexpr (std::is_same_v<std::decay_t<decltype(member)>, float>) {
          const double scaled = double(member) * std::abs(t.scale.x);
          if (!(float(scaled) > 0.0f) || !std::isfinite(float(scaled))) {
            fail(path + ".transform.scale",
                 fmt::format("makes {} leave the 32-bit float range", f.what));
          }
          member = float(scaled);
        } else if (f.kind == SceneFieldKind::Point) {
          member = to_float(t.point(glm::dvec3(member)), path, f.what);
        }
      });
    }
    Shape::scene_fields(shape, [&](const SceneField& f, auto& member) {
      if constexpr (!std::is_same_v<std::decay_t<decltype(member)>, float>) {
        if (f.kind != SceneFieldKind::Direction) return;
        glm::dvec3 d(member);
        if (!t.identity) d = t.normal(d);
        member = glm::vec3(glm::normalize(d));
        if (!finite(member) || glm::length(member) == 0.0f)
          fail(key_path(path, f.key), "cannot be normalised");
      }
    });
    return shape;
  }

  // The csg object itself (depth 1) or a nested child; leaves are spheres.
  std::shared_ptr<const CsgNode> read_csg_inner(const json& v, const std::string& path, int depth,
                                                const Transform& t) {
    if (depth > kMaxCsgDepth) {
      fail(path, fmt::format("csg tree nested deeper than {} levels", kMaxCsgDepth));
    }
    auto node = std::make_shared<CsgNode>();
    node->is_leaf = false;
    std::string op_path = key_path(path, "op");
    const std::string& op =
        string(require(v, path, "op", "union, intersection or difference"), op_path);
    if (op == "union") {
      node->op = CsgOp::Union;
    } else if (op == "intersection") {
      node->op = CsgOp::Intersection;
    } else if (op == "difference") {
      node->op = CsgOp::Difference;
    } else {
      std::string s = suggestion(op, {"union", "intersection", "difference"});
      fail(op_path, "unknown csg op " + quote_json(op) +
                        (s.empty() ? "" : " (did you mean '" + s + "'?)") +
                        "; expected union, intersection or difference");
    }
    node->a = read_csg_child(require(v, path, "a"), key_path(path, "a"), depth + 1, t);
    node->b = read_csg_child(require(v, path, "b"), key_path(path, "b"), depth + 1, t);
    return node;
  }

  std::shared_ptr<const CsgNode> read_csg_child(const json& v, const std::string& path, int depth,
                                                const Transform& t) {
    check_object(v, path);
    if (depth > kMaxCsgDepth) {
      fail(path, fmt::format("csg tree nested deeper than {} levels", kMaxCsgDepth));
    }
    std::string kind;
    if (const json* type = find(v, "type")) {
      kind = string(*type, key_path(path, "type"));
      if (kind != "sphere" && kind != "csg") {
        fail(key_path(path, "type"),
             "must be 'sphere' or 'csg' inside a csg tree, got " + quote_json(kind));
      }
    } else {
      kind = find(v, "op") ? "csg" : "sphere";
    }
    for (const char* k : {"material", "name", "transform"}) {
      if (find(v, k)) {
        fail(path, std::string("'") + k +
                       "' is not allowed inside a csg tree (set it on the csg object)");
      }
    }
    if (kind == "sphere") {
      check_keys(v, path, {"type", "center", "radius"}, "a csg sphere");
      auto leaf = std::make_shared<CsgNode>();
      leaf->is_leaf = true;
      leaf->sphere = transform_shape(read_shape<Sphere>(v, path), t, path);
      return leaf;
    }
    check_keys(v, path, {"type", "op", "a", "b"}, "a csg node");
    return read_csg_inner(v, path, depth, t);
  }

  Scene& scene_;
  std::string base_dir_;
  std::vector<std::string> material_order_;
  std::map<std::string, uint32_t> material_index_;
  SceneTextures textures_;
};

Expected<Scene> parse_scene_impl(const std::string& text, const std::string& source,
                                 const std::string& base_dir) {
  try {
    check_nesting(text);
    json root;
    SceneSax sax(root);
    bool parsed = json::sax_parse(text, &sax, json::input_format_t::json, true, false);
    sax.raise(text, parsed);
    Scene scene;
    scene.source = source;
    Reader reader(scene, base_dir, std::move(sax.material_order));
    reader.read(root);
    return scene;
  } catch (const SyntaxError& e) {
    auto [line, column] = line_column(text, e.offset);
    return bad_input(fmt::format("{}:{}:{}: JSON syntax: {}", source, line, column, e.what));
  } catch (const LoadError& e) {
    return bad_input(fmt::format("{}: {}: {}", source, where(e.path), e.what));
  } catch (const std::bad_alloc&) {
    return internal_error(source + ": out of memory while loading the scene");
  } catch (const std::exception& e) {
    return internal_error(source + ": internal error while loading the scene: " + e.what());
  } catch (...) {
    return internal_error(source + ": internal error while loading the scene");
  }
}

}  // namespace
}  // namespace scene_load

constexpr size_t kMaxSceneFileBytes = size_t(256) << 20;

Expected<Scene> parse_scene(const std::string& json_text, const std::string& source,
                            const std::string& base_dir) {
  return scene_load::parse_scene_impl(json_text, source, base_dir);
}

Expected<Scene> load_scene_file(const std::string& path) {
  try {
    std::error_code ec;
    if (fs::is_directory(path, ec))
      return bad_input(path + ": cannot read: " + std::strerror(EISDIR));
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return bad_input(path + ": cannot read: " + std::strerror(errno));
    std::string text;
    char buffer[1 << 16];
    size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) {
      text.append(buffer, n);
      if (text.size() > kMaxSceneFileBytes) {  // also ends endless inputs such as /dev/zero
        std::fclose(f);
        return bad_input(
            fmt::format("{}: the scene file is over {} MiB (meshes belong in mesh "
                        "files)",
                        path, kMaxSceneFileBytes >> 20));
      }
    }
    int read_error = std::ferror(f) ? errno : 0;
    std::fclose(f);
    if (read_error) return bad_input(path + ": cannot read: " + std::strerror(read_error));
    std::string base_dir = fs::path(path).parent_path().string();
    return scene_load::parse_scene_impl(text, path, base_dir.empty() ? "." : base_dir);
  } catch (const std::bad_alloc&) {
    return internal_error(path + ": out of memory while reading the scene");
  } catch (const std::exception& e) {
    return internal_error(path + ": internal error while reading the scene: " + e.what());
  } catch (...) {
    return internal_error(path + ": internal error while reading the scene");
  }
}

namespace {

// Whether a file whose extension says nothing (neither .json nor a model format) starts like
// JSON: its first character other than white space (and a UTF-8 byte order mark) is '{' or '['.
// An empty or unreadable file counts as JSON, so that its error stays the scene reader's.
bool starts_like_json(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return true;
  char head[512];
  size_t n = std::fread(head, 1, sizeof head, f);
  std::fclose(f);
  size_t i = n >= 3 && std::memcmp(head, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0;
  while (i < n && std::strchr(" \t\r\n", head[i])) ++i;
  return i == n || head[i] == '{' || head[i] == '[';
}

// A path: a model file by its extension; a scene file by .json; otherwise a model file when
// Assimp recognises the content, else a scene file (whose error is reported). `model` says
// which it was.
Expected<Scene> load_path(const std::string& path, const SceneOverrides& overrides, bool* model) {
  *model = true;
  // Missing files, folders and devices: the scene reader's messages, as before model files.
  std::error_code ec;
  bool regular = fs::is_regular_file(path, ec);
  if (regular && is_model_file_name(path)) return load_model_scene(path, overrides);
  std::string ext = fs::path(path).extension().string();
  bool named_json = ext == ".json" || ext == ".JSON";
  if (!named_json && regular && !starts_like_json(path)) {
    Expected<Scene> scene = load_model_scene(path, overrides);
    if (scene.ok()) return scene;
  }
  *model = false;
  return load_scene_file(path);
}

Expected<Scene> load_builtin(const std::string& spec, const std::string& name) {
  try {
    Expected<Scene> scene = make_builtin_scene(name);
    if (scene.ok() && scene->source.empty()) scene->source = spec;
    return scene;
  } catch (const std::bad_alloc&) {
    return internal_error(spec + ": out of memory while building the scene");
  } catch (const std::exception& e) {
    return internal_error(spec + ": internal error while building the scene: " + e.what());
  } catch (...) {
    return internal_error(spec + ": internal error while building the scene");
  }
}

// Scene files and built-in scenes: the image size, then the framing.
void apply_overrides(Scene& scene, const SceneOverrides& overrides) {
  if (overrides.width) scene.image.width = *overrides.width;
  if (overrides.height) scene.image.height = *overrides.height;
  if (overrides.view_from && !scene.objects.empty()) {
    frame_camera(scene, scene_bounds(scene), *overrides.view_from);
  }
  if (overrides.exposure) scene.image.exposure = *overrides.exposure;
}

// The overrides' own errors, before anything is loaded.
Status check_overrides(const std::string& spec, const SceneOverrides& overrides) {
  if (overrides.view_from && !(std::isfinite(glm::length(*overrides.view_from)) &&
                               glm::length(*overrides.view_from) > 0.0f)) {
    return bad_input(spec + ": the view direction must be finite and non-zero");
  }
  if (overrides.exposure && !(std::fabs(*overrides.exposure) <= kMaxExposure)) {
    return bad_input(fmt::format("{}: the exposure must be between -{} and {} stops", spec,
                                 kMaxExposure, kMaxExposure));
  }
  return ok_status();
}

}  // namespace

Expected<Scene> load_scene_text(const std::string& json_text, const std::string& source,
                                const std::string& base_dir, const SceneOverrides& overrides) {
  RVR_TRY(check_overrides(source, overrides));
  Expected<Scene> scene = parse_scene(json_text, source, base_dir);
  if (scene.ok()) apply_overrides(*scene, overrides);
  return scene;
}

Expected<Scene> load_scene(const std::string& spec, const SceneOverrides& overrides) {
  RVR_TRY(check_overrides(spec, overrides));
  static const std::string kBuiltin = "builtin:";
  bool model = false;
  Expected<Scene> scene = spec.rfind(kBuiltin, 0) == 0
                              ? load_builtin(spec, spec.substr(kBuiltin.size()))
                              : load_path(spec, overrides, &model);
  if (scene.ok() && !model) apply_overrides(*scene, overrides);
  return scene;
}

}  // namespace rvr
