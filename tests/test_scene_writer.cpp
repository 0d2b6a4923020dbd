// The scene writer: every built-in scene, written as rvr-scene/1 (meshes as PLY beside it)
// and read back by the loader, is the same scene field by field.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "rvr/shared/scene_loader.h"
#include "rvr/shared/scene_writer.h"

namespace fs = std::filesystem;
using namespace rvr;

namespace {

// Bitwise, so that -0 and +0 or two NaNs are told apart.
bool same_bits(float a, float b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

::testing::AssertionResult same3(const char* ea, const char* eb, const glm::vec3& a,
                                 const glm::vec3& b) {
  for (int k = 0; k < 3; ++k) {
    if (!same_bits(a[k], b[k])) {
      return ::testing::AssertionFailure()
             << ea << " != " << eb << " at [" << k << "]: " << a[k] << " vs " << b[k];
    }
  }
  return ::testing::AssertionSuccess();
}
#define EXPECT_SAME3(a, b) EXPECT_PRED_FORMAT2(same3, a, b)
#define EXPECT_SAME(a, b) EXPECT_TRUE(same_bits(a, b)) << #a << " " << (a) << " vs " << (b)

void expect_same_csg(const CsgNode& a, const CsgNode& b, const std::string& path) {
  SCOPED_TRACE(path);
  ASSERT_EQ(a.is_leaf, b.is_leaf);
  if (a.is_leaf) {
    EXPECT_SAME3(a.sphere.center, b.sphere.center);
    EXPECT_SAME(a.sphere.radius, b.sphere.radius);
    return;
  }
  EXPECT_EQ(int(a.op), int(b.op));
  ASSERT_TRUE(a.a && a.b && b.a && b.b);
  expect_same_csg(*a.a, *b.a, path + ".a");
  expect_same_csg(*a.b, *b.b, path + ".b");
}

// The loader may join identical vertices of a mesh file, so meshes are compared triangle by
// triangle, corner by corner (triangle order is the primitive id and must be kept). Vertex
// normals are renormalised by the loader (in double), which may move the last bit.
void expect_same_mesh(const TriangleMesh& a, const TriangleMesh& b) {
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  ASSERT_EQ(a.smooth(), b.smooth());
  for (size_t t = 0; t < a.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& pa = a.positions[a.triangles[t][k]];
      const glm::vec3& pb = b.positions[b.triangles[t][k]];
      if (!same3("original", "loaded", pa, pb)) {
        ADD_FAILURE() << "triangle " << t << " corner " << k << " position differs";
        return;
      }
      if (a.smooth()) {
        const glm::vec3& na = a.normals[a.triangles[t][k]];
        const glm::vec3& nb = b.normals[b.triangles[t][k]];
        if (glm::length(na - nb) > 1e-6f) {
          ADD_FAILURE() << "triangle " << t << " corner " << k << " normal differs";
          return;
        }
      }
    }
  }
}

void expect_same_scene(const Scene& a, const Scene& b) {
  EXPECT_EQ(a.image.width, b.image.width);
  EXPECT_EQ(a.image.height, b.image.height);
  EXPECT_SAME3(a.image.background, b.image.background);
  EXPECT_EQ(a.image.samples_per_pixel, b.image.samples_per_pixel);

  EXPECT_SAME3(a.camera.eye, b.camera.eye);
  EXPECT_SAME3(a.camera.target, b.camera.target);
  EXPECT_SAME3(a.camera.up, b.camera.up);
  EXPECT_SAME(a.camera.fov_y_deg, b.camera.fov_y_deg);
  EXPECT_SAME(a.camera.near, b.camera.near);
  EXPECT_SAME(a.camera.far, b.camera.far);
  EXPECT_SAME(a.camera.aperture_radius, b.camera.aperture_radius);
  EXPECT_SAME(a.camera.focus_distance, b.camera.focus_distance);
  EXPECT_SAME3(a.ambient, b.ambient);

  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (size_t i = 0; i < a.materials.size(); ++i) {
    SCOPED_TRACE("materials[" + std::to_string(i) + "]");
    const Material &ma = a.materials[i], &mb = b.materials[i];
    EXPECT_EQ(ma.name, mb.name);
    EXPECT_SAME3(ma.diffuse, mb.diffuse);
    EXPECT_SAME3(ma.specular, mb.specular);
    EXPECT_SAME3(ma.emission, mb.emission);
    EXPECT_SAME(ma.shininess, mb.shininess);
    EXPECT_SAME(ma.mirror, mb.mirror);
    EXPECT_SAME(ma.transparency, mb.transparency);
    EXPECT_SAME(ma.ior, mb.ior);
  }

  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (size_t i = 0; i < a.lights.size(); ++i) {
    SCOPED_TRACE("lights[" + std::to_string(i) + "]");
    const Light &la = a.lights[i], &lb = b.lights[i];
    ASSERT_EQ(la.type, lb.type);
    EXPECT_SAME3(la.intensity, lb.intensity);
    if (la.type == LightType::Point) {
      EXPECT_SAME3(la.position, lb.position);
    } else {
      EXPECT_SAME3(la.corner, lb.corner);
      EXPECT_SAME3(la.edge_u, lb.edge_u);
      EXPECT_SAME3(la.edge_v, lb.edge_v);
      EXPECT_EQ(la.samples, lb.samples);
    }
  }

  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (size_t i = 0; i < a.objects.size(); ++i) {
    SCOPED_TRACE("objects[" + std::to_string(i) + "] " + a.objects[i].name);
    const Object &oa = a.objects[i], &ob = b.objects[i];
    EXPECT_EQ(oa.name, ob.name);
    ASSERT_EQ(oa.type, ob.type);
    EXPECT_EQ(oa.material, ob.material);
    switch (oa.type) {
      case ObjectType::Sphere:
        EXPECT_SAME3(oa.sphere.center, ob.sphere.center);
        EXPECT_SAME(oa.sphere.radius, ob.sphere.radius);
        break;
      case ObjectType::Plane:
        EXPECT_SAME3(oa.plane.point, ob.plane.point);
        EXPECT_SAME3(oa.plane.normal, ob.plane.normal);
        EXPECT_SAME(oa.plane.half_size, ob.plane.half_size);
        break;
      case ObjectType::Triangles:
        expect_same_mesh(oa.mesh, ob.mesh);
        break;
      case ObjectType::Csg:
        ASSERT_TRUE(oa.csg && ob.csg);
        expect_same_csg(*oa.csg, *ob.csg, "csg");
        break;
    }
  }
  EXPECT_TRUE(b.warnings.empty()) << b.warnings.front();
}

std::vector<std::string> names() {
  std::vector<std::string> out;
  for (const BuiltinSceneInfo& info : builtin_scenes()) {
    std::string n = info.name;
    if (size_t colon = n.find(':'); colon != std::string::npos) n.resize(colon);
    out.push_back(n);
  }
  for (const char* extra : {"occluders:3", "soup:257", "tessphere:2000", "tessphere:50"})
    out.push_back(extra);
  return out;
}

class SceneWriter : public ::testing::TestWithParam<std::string> {};

TEST_P(SceneWriter, BuiltinSceneReadsBackTheSame) {
  Expected<Scene> original = make_builtin_scene(GetParam());
  ASSERT_TRUE(original.ok()) << original.error().message;
  fs::path dir =
      fs::temp_directory_path() / ("rvr-scene-writer-" + std::to_string(::getpid()) + "-" +
                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::string safe = GetParam();
  for (char& c : safe) c = c == ':' ? '_' : c;
  dir /= safe;
  fs::create_directories(dir);
  Expected<SceneDocument> doc = write_scene(*original, "scene");
  ASSERT_TRUE(doc.ok()) << doc.error().message;
  for (const SceneMeshFile& m : doc->mesh_files) {
    std::ofstream out(dir / m.name, std::ios::binary);
    out.write(m.bytes.data(), std::streamsize(m.bytes.size()));
    ASSERT_TRUE(out.good());
  }
  Expected<Scene> loaded = parse_scene(doc->json, "exported", dir.string());
  fs::remove_all(dir.parent_path());
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  expect_same_scene(*original, *loaded);

  // Writing the loaded scene again gives the same document (a fixed point).
  Expected<SceneDocument> again = write_scene(*loaded, "scene");
  ASSERT_TRUE(again.ok()) << again.error().message;
  EXPECT_EQ(doc->json, again->json);
}

INSTANTIATE_TEST_SUITE_P(Builtin, SceneWriter, ::testing::ValuesIn(names()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string n = info.param;
                           for (char& c : n) c = std::isalnum((unsigned char)c) ? c : '_';
                           return n;
                         });

TEST(SceneWriterFloats, ShortestDecimalReadsBackToTheSameFloat) {
  // Awkward floats in every float field of a material, through the loader and back.
  Expected<Scene> base = make_builtin_scene("spheres");
  ASSERT_TRUE(base.ok());
  Scene s = *base;
  const float values[] = {0.1f,          1.0f / 3.0f, 16777215.0f, 1e-30f,
                          3.4028235e38f, 2.5e-7f,     0.30000001f, 7.0f};
  for (float v : values) {
    s.ambient = glm::vec3(v);
    s.camera.far = v * 2.0f < 3.0e38f ? std::max(v, 1000.0f) : v;
    Expected<SceneDocument> doc = write_scene(s, "x");
    ASSERT_TRUE(doc.ok()) << doc.error().message;
    Expected<Scene> back = parse_scene(doc->json, "x", ".");
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_SAME3(back->ambient, s.ambient);
    EXPECT_SAME(back->camera.far, s.camera.far);
  }
}

TEST(SceneWriterErrors, RefusesWhatTheFormatCannotSay) {
  Expected<Scene> base = make_builtin_scene("cornell");
  ASSERT_TRUE(base.ok());
  Scene s = *base;
  s.materials[0].diffuse = glm::vec3(0.5f);
  Expected<SceneDocument> doc = write_scene(s, "x");
  ASSERT_FALSE(doc.ok());
  EXPECT_NE(doc.error().message.find("materials[0]"), std::string::npos) << doc.error().message;

  s = *base;
  s.materials.push_back(s.materials[1]);
  doc = write_scene(s, "x");
  ASSERT_FALSE(doc.ok());
  EXPECT_NE(doc.error().message.find("duplicate material name"), std::string::npos);

  s = *base;
  s.ambient.x = std::nanf("");
  EXPECT_FALSE(write_scene(s, "x").ok());
}

}  // namespace
