// The byte layout of model_wire.h: plain values as their bytes (parent and child are the same
// program), strings and arrays as a 64-bit count then their elements.
#include "model_wire.h"

#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "rvr/core/scene.h"
#include "rvr/core/texture.h"

namespace rvr::scene_load {
namespace {

class Writer {
 public:
  template <typename T>
  void pod(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <typename T>
  void array(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    pod(uint64_t(v.size()));
    out_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void text(const std::string& s) {
    pod(uint64_t(s.size()));
    out_.append(s);
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(const std::string& in) : in_(in) {}
  template <typename T>
  T pod() {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    std::memcpy(&v, take(sizeof v), sizeof v);
    return v;
  }
  template <typename T>
  std::vector<T> array() {
    uint64_t n = count(sizeof(T));
    std::vector<T> v(n);
    if (n > 0) std::memcpy(v.data(), take(n * sizeof(T)), n * sizeof(T));
    return v;
  }
  std::string text() {
    uint64_t n = count(1);
    return std::string(take(n), n);
  }
  void expect_end() const {
    if (pos_ != in_.size()) throw std::runtime_error("model bytes: trailing data");
  }

 private:
  uint64_t count(size_t element) {
    uint64_t n = pod<uint64_t>();
    if (n > (in_.size() - pos_) / element) throw std::runtime_error("model bytes: truncated");
    return n;
  }
  const char* take(size_t n) {
    if (n > in_.size() - pos_) throw std::runtime_error("model bytes: truncated");
    const char* p = in_.data() + pos_;
    pos_ += n;
    return p;
  }
  const std::string& in_;
  size_t pos_ = 0;
};

void put(Writer& w, const TriangleMesh& m) {
  w.array(m.positions);
  w.array(m.normals);
  w.array(m.triangles);
  w.array(m.uvs);
  w.array(m.colours);
}

TriangleMesh get_mesh(Reader& r) {
  TriangleMesh m;
  m.positions = r.array<glm::vec3>();
  m.normals = r.array<glm::vec3>();
  m.triangles = r.array<glm::uvec3>();
  m.uvs = r.array<glm::vec2>();
  m.colours = r.array<glm::vec3>();
  return m;
}

void put(Writer& w, const Material& m) {
  w.text(m.name);
  w.pod(m.diffuse);
  w.pod(m.specular);
  w.pod(m.emission);
  w.pod(m.shininess);
  w.pod(m.mirror);
  w.pod(m.transparency);
  w.pod(m.ior);
}

Material get_material(Reader& r) {
  Material m;
  m.name = r.text();
  m.diffuse = r.pod<glm::vec3>();
  m.specular = r.pod<glm::vec3>();
  m.emission = r.pod<glm::vec3>();
  m.shininess = r.pod<float>();
  m.mirror = r.pod<float>();
  m.transparency = r.pod<float>();
  m.ior = r.pod<float>();
  return m;
}

void put(Writer& w, const ModelTexture& t) {
  static_assert(std::is_trivially_copyable_v<UvTransform>);
  w.text(t.file);
  w.pod(t.wrap_u);
  w.pod(t.wrap_v);
  w.pod(t.transform);
}

ModelTexture get_texture(Reader& r) {
  ModelTexture t;
  t.file = r.text();
  t.wrap_u = r.pod<TextureWrap>();
  t.wrap_v = r.pod<TextureWrap>();
  t.transform = r.pod<UvTransform>();
  if (uint8_t(t.wrap_u) > uint8_t(TextureWrap::MirroredRepeat) ||
      uint8_t(t.wrap_v) > uint8_t(TextureWrap::MirroredRepeat)) {
    throw std::runtime_error("model bytes: bad wrap mode");
  }
  return t;
}

void put(Writer& w, const EmbeddedImage& i) {
  w.text(i.name);
  w.text(i.format);
  w.pod(i.width);
  w.pod(i.height);
  w.text(i.bytes);
}

EmbeddedImage get_image(Reader& r) {
  EmbeddedImage i;
  i.name = r.text();
  i.format = r.text();
  i.width = r.pod<int>();
  i.height = r.pod<int>();
  i.bytes = r.text();
  return i;
}

}  // namespace

std::string encode(const TriangleMesh& mesh, size_t skipped_primitives,
                   const std::vector<std::string>& warnings) {
  Writer w;
  put(w, mesh);
  w.pod(uint64_t(skipped_primitives));
  w.pod(uint64_t(warnings.size()));
  for (const std::string& s : warnings) w.text(s);
  return w.take();
}

TriangleMesh decode_mesh(const std::string& bytes, size_t* skipped_primitives,
                         std::vector<std::string>* warnings) {
  Reader r(bytes);
  TriangleMesh mesh = get_mesh(r);
  *skipped_primitives += size_t(r.pod<uint64_t>());
  uint64_t warning_count = r.pod<uint64_t>();
  for (uint64_t i = 0; i < warning_count; ++i) warnings->push_back(r.text());
  r.expect_end();
  return mesh;
}

std::string encode(const ImportedModel& model) {
  static_assert(std::is_trivially_copyable_v<Camera> && std::is_trivially_copyable_v<Light>);
  Writer w;
  w.pod(uint64_t(model.parts.size()));
  for (const ModelPart& part : model.parts) {
    w.text(part.name);
    put(w, part.mesh);
    w.pod(uint8_t(part.material.has_value()));
    if (part.material) put(w, *part.material);
    w.pod(uint8_t(part.texture.has_value()));
    if (part.texture) put(w, *part.texture);
  }
  w.pod(uint8_t(model.camera.has_value()));
  if (model.camera) w.pod(*model.camera);
  w.pod(model.camera_aspect);
  w.pod(model.up);
  w.array(model.lights);
  std::vector<uint64_t> unattenuated(model.unattenuated_lights.begin(),
                                     model.unattenuated_lights.end());
  w.array(unattenuated);
  w.pod(uint64_t(model.skipped_primitives));
  w.pod(uint64_t(model.warnings.size()));
  for (const std::string& s : model.warnings) w.text(s);
  w.pod(uint64_t(model.images.size()));
  for (const EmbeddedImage& i : model.images) put(w, i);
  return w.take();
}

ImportedModel decode_model(const std::string& bytes) {
  Reader r(bytes);
  ImportedModel model;
  uint64_t parts = r.pod<uint64_t>();
  for (uint64_t i = 0; i < parts; ++i) {
    ModelPart part;
    part.name = r.text();
    part.mesh = get_mesh(r);
    if (r.pod<uint8_t>()) part.material = get_material(r);
    if (r.pod<uint8_t>()) part.texture = get_texture(r);
    model.parts.push_back(std::move(part));
  }
  if (r.pod<uint8_t>()) model.camera = r.pod<Camera>();
  model.camera_aspect = r.pod<float>();
  model.up = r.pod<glm::vec3>();
  model.lights = r.array<Light>();
  for (uint64_t i : r.array<uint64_t>()) model.unattenuated_lights.push_back(size_t(i));
  model.skipped_primitives = size_t(r.pod<uint64_t>());
  uint64_t warnings = r.pod<uint64_t>();
  for (uint64_t i = 0; i < warnings; ++i) model.warnings.push_back(r.text());
  uint64_t images = r.pod<uint64_t>();
  for (uint64_t i = 0; i < images; ++i) model.images.push_back(get_image(r));
  r.expect_end();
  return model;
}

}  // namespace rvr::scene_load
