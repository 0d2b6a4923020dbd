// The scene writer: every built-in scene, written as rvr-scene/1 (meshes as PLY beside it)
// and read back by the loader, is the same scene field by field.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <initializer_list>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/disc.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/square.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/texture.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/scene_io/scene_loader.h"
#include "rvr/scene_io/scene_writer.h"

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
// normals are renormalised by the loader (in double), which may move the last bit; texture
// coordinates and vertex colours must come back bit for bit.
void expect_same_mesh(const TriangleMesh& a, const TriangleMesh& b) {
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  ASSERT_EQ(a.smooth(), b.smooth());
  ASSERT_EQ(a.textured(), b.textured());
  ASSERT_EQ(a.coloured(), b.coloured());
  for (size_t t = 0; t < a.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (a.textured()) {
        const glm::vec2 ua = a.uvs[a.triangles[t][k]], ub = b.uvs[b.triangles[t][k]];
        if (!same_bits(ua.x, ub.x) || !same_bits(ua.y, ub.y)) {
          ADD_FAILURE() << "triangle " << t << " corner " << k << " uv differs";
          return;
        }
      }
      if (a.coloured() && !same3("original", "loaded", a.colours[a.triangles[t][k]],
                                 b.colours[b.triangles[t][k]])) {
        ADD_FAILURE() << "triangle " << t << " corner " << k << " colour differs";
        return;
      }
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
    EXPECT_EQ(ma.texture, mb.texture);
    EXPECT_SAME(ma.uv_transform.offset.x, mb.uv_transform.offset.x);
    EXPECT_SAME(ma.uv_transform.offset.y, mb.uv_transform.offset.y);
    EXPECT_SAME(ma.uv_transform.rotation, mb.uv_transform.rotation);
    EXPECT_SAME(ma.uv_transform.scale.x, mb.uv_transform.scale.x);
    EXPECT_SAME(ma.uv_transform.scale.y, mb.uv_transform.scale.y);
  }

  ASSERT_EQ(a.textures.size(), b.textures.size());
  for (size_t i = 0; i < a.textures.size(); ++i) {
    SCOPED_TRACE("textures[" + std::to_string(i) + "]");
    const Texture &ta = a.textures[i], &tb = b.textures[i];
    EXPECT_EQ(ta.wrap_u, tb.wrap_u);
    EXPECT_EQ(ta.wrap_v, tb.wrap_v);
    ASSERT_EQ(bool(ta.mips), bool(tb.mips));
    if (!ta.mips) continue;
    ASSERT_EQ(ta.mips->levels.size(), tb.mips->levels.size());
    const TextureLevel &la = ta.mips->levels[0], &lb = tb.mips->levels[0];
    ASSERT_EQ(la.width, lb.width);
    ASSERT_EQ(la.height, lb.height);
    for (size_t t = 0; t < la.texels.size(); ++t) {
      if (!same3("original", "loaded", la.texels[t], lb.texels[t])) {
        ADD_FAILURE() << "texel " << t << " differs";
        break;
      }
    }
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
      case ObjectType::Disc:
        EXPECT_SAME3(oa.disc.center, ob.disc.center);
        EXPECT_SAME3(oa.disc.normal, ob.disc.normal);
        EXPECT_SAME(oa.disc.radius, ob.disc.radius);
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
  Expected<SceneDocument> doc = write_scene(*original, "scene", dir.string());
  ASSERT_TRUE(doc.ok()) << doc.error().message;
  for (const SceneMeshFile& m : doc->mesh_files) {
    std::ofstream out(dir / m.name, std::ios::binary);
    out.write(m.bytes.data(), std::streamsize(m.bytes.size()));
    ASSERT_TRUE(out.good());
  }
  // Textures held in memory (builtin:textured's checkerboard) are written as EXR beside it.
  for (const SceneTextureFile& t : doc->texture_files) {
    Status written = write_image((dir / t.name).string(), t.image);
    ASSERT_TRUE(written.ok()) << written.error().message;
  }
  Expected<Scene> loaded = parse_scene(doc->json, "exported", dir.string());
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  expect_same_scene(*original, *loaded);

  // Writing the loaded scene again gives the same document (a fixed point): its textures are
  // files now, named relative to the same folder.
  Expected<SceneDocument> again = write_scene(*loaded, "scene", dir.string());
  fs::remove_all(dir.parent_path());
  ASSERT_TRUE(again.ok()) << again.error().message;
  EXPECT_EQ(doc->json, again->json);
}

INSTANTIATE_TEST_SUITE_P(Builtin, SceneWriter, ::testing::ValuesIn(names()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string n = info.param;
                           for (char& c : n) c = std::isalnum((unsigned char)c) ? c : '_';
                           return n;
                         });

// A scene with a texture read from a file (in another folder than the exported document), a
// transform and wrap modes per axis, a mesh with texture coordinates and vertex colours (to
// PLY) and a triangle with both (inline): exported, read back, the same; the texture, which
// lies outside the document's folder, named by its absolute path (a relative one would climb
// out of the folder and break when it moves) and not copied.
TEST(SceneWriterTextures, FileTexturesUvsAndColoursReadBackTheSame) {
  fs::path dir = fs::temp_directory_path() / ("rvr-scene-writer-tex-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "in" / "img");
  fs::create_directories(dir / "out");
  Image image;
  image.width = 2;
  image.height = 2;
  image.channels = 3;
  image.pixels = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f, 1.0f, 0.0f, 0.5f};
  ASSERT_TRUE(write_image((dir / "in" / "img" / "t.png").string(), image, false).ok());
  std::ofstream(dir / "in" / "strip.ply", std::ios::binary)
      << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
         "property float z\nproperty float s\nproperty float t\nproperty uchar red\n"
         "property uchar green\nproperty uchar blue\nelement face 2\n"
         "property list uchar int vertex_indices\nend_header\n"
         "0 0 0 0.1 0.2 255 0 0\n1 0 0 0.9 0.3 0 255 0\n1 1 0 0.7 0.8 0 0 255\n"
         "0 1 0 0.3 0.6 10 20 30\n3 0 1 2\n3 0 2 3\n";
  const std::string text = R"({"camera": {"eye": [0, 0, 4], "target": [0, 0, 0], "up": [0, 1, 0]},
    "materials": {"tex": {"texture": {"file": "img/t.png", "wrap": ["clamp", "mirror"],
                  "transform": {"offset": [0.25, 0.5], "rotation": 0.3, "scale": [2, 3]}}}},
    "objects": [
      {"type": "mesh", "file": "strip.ply", "material": "tex"},
      {"type": "triangle", "vertices": [[0,0,1],[1,0,1],[0,1,1]], "material": "tex",
       "uvs": [[0.5, 0.25], [1, 0], [0, 1]], "colors": [[1, 0.5, 0], [0, 1, 0.5], [0.5, 0, 1]]}]})";
  Expected<Scene> original = parse_scene(text, "in.json", (dir / "in").string());
  ASSERT_TRUE(original.ok()) << original.error().message;
  ASSERT_TRUE(original->warnings.empty()) << original->warnings.front();
  ASSERT_TRUE(original->objects[0].mesh.textured() && original->objects[0].mesh.coloured());
  Expected<SceneDocument> doc = write_scene(*original, "scene", (dir / "out").string());
  ASSERT_TRUE(doc.ok()) << doc.error().message;
  EXPECT_TRUE(doc->texture_files.empty());
  EXPECT_TRUE(doc->copied_files.empty());
  EXPECT_NE(doc->json.find("\"file\": \"" + (dir / "in" / "img" / "t.png").generic_string() + "\""),
            std::string::npos)
      << doc->json;
  for (const SceneMeshFile& m : doc->mesh_files) {
    std::ofstream(dir / "out" / m.name, std::ios::binary) << m.bytes;
  }
  Expected<Scene> loaded = parse_scene(doc->json, "out.json", (dir / "out").string());
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  expect_same_scene(*original, *loaded);
  fs::remove_all(dir);
}

// Where an exported document names a texture file: relative to the document's folder when it
// lies below it, absolute when it lies elsewhere, and with copy_texture_files a copy beside the
// document (PREFIX.textureI.EXT) for one elsewhere. Each document reads back with its texture
// after its folder has moved.
TEST(SceneWriterTextures, TexturePathsSurviveTheDocumentsFolderMoving) {
  fs::path dir =
      fs::temp_directory_path() / ("rvr-scene-writer-move-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "in");
  fs::create_directories(dir / "out" / "maps");
  Image image;
  image.width = image.height = 1;
  image.channels = 3;
  image.pixels = {0.25f, 0.5f, 0.75f};
  ASSERT_TRUE(write_image((dir / "in" / "far.png").string(), image, false).ok());
  ASSERT_TRUE(write_image((dir / "out" / "maps" / "near.png").string(), image, false).ok());
  const std::string text = R"({"camera": {"eye": [0, 0, 4], "target": [0, 0, 0], "up": [0, 1, 0]},
    "materials": {"far": {"texture": "far.png"}, "near": {"texture": "../out/maps/near.png"}},
    "objects": [
      {"type": "triangle", "vertices": [[0,0,0],[1,0,0],[0,1,0]], "material": "far",
       "uvs": [[0, 0], [1, 0], [0, 1]]},
      {"type": "triangle", "vertices": [[0,0,1],[1,0,1],[0,1,1]], "material": "near",
       "uvs": [[0, 0], [1, 0], [0, 1]]}]})";
  Expected<Scene> original = parse_scene(text, "in.json", (dir / "in").string());
  ASSERT_TRUE(original.ok()) << original.error().message;
  ASSERT_TRUE(original->warnings.empty()) << original->warnings.front();
  for (const bool copy : {false, true}) {
    SCOPED_TRACE(copy ? "copied" : "named where it is");
    Expected<SceneDocument> doc = write_scene(*original, "scene", (dir / "out").string(), copy);
    ASSERT_TRUE(doc.ok()) << doc.error().message;
    EXPECT_NE(doc->json.find(R"("file": "maps/near.png")"), std::string::npos) << doc->json;
    const std::string far = copy ? "scene.texture0.png" : (dir / "in" / "far.png").generic_string();
    EXPECT_NE(doc->json.find("\"file\": \"" + far + "\""), std::string::npos) << doc->json;
    ASSERT_EQ(doc->copied_files.size(), copy ? 1u : 0u);
    // Written as `rvr scenes --export` writes it, then the folder moved one level down.
    fs::remove_all(dir / "moved");
    fs::create_directories(dir / "moved");
    fs::copy(dir / "out", dir / "moved" / "out", fs::copy_options::recursive);
    for (const SceneCopiedFile& c : doc->copied_files) {
      EXPECT_EQ(c.name, "scene.texture0.png");
      EXPECT_EQ(fs::path(c.source), dir / "in" / "far.png");
      fs::copy_file(c.source, dir / "moved" / "out" / c.name);
    }
    const fs::path moved = dir / "moved" / "out";
    Expected<Scene> loaded = parse_scene(doc->json, "scene.json", moved.string());
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    EXPECT_TRUE(loaded->warnings.empty()) << loaded->warnings.front();
    ASSERT_EQ(loaded->textures.size(), 2u);
    EXPECT_EQ(fs::path(loaded->textures[1].resolved), moved / "maps" / "near.png");
    EXPECT_EQ(fs::path(loaded->textures[0].resolved),
              copy ? moved / "scene.texture0.png" : dir / "in" / "far.png");
    for (const Texture& t : loaded->textures) EXPECT_TRUE(t.mips) << t.file;
  }
  fs::remove_all(dir);
}

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
