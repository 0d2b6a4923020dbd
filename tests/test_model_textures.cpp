// Textures and vertex colours of model files (docs/scene-format.md, "Textures" and "Model files
// as scenes"): files the test writes itself (OBJ + MTL with map_Kd, glTF with an embedded
// base64 PNG and a second uv set, GLB with the PNG in its buffer, a vertex-coloured PLY), paths
// as exporters write them. Expected values are the ones written into the files: texels are the
// PNG's bytes decoded by the closed form of sRGB, bottom row first; uvs and colours per vertex.
#include <gtest/gtest.h>
#include <stddef.h>
#include <stdint.h>

#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include "model_corpus.h"
#include "rvr/core/expected.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/surface_colour.h"
#include "rvr/core/texture.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/scene_io/scene_loader.h"
#include "rvr/scene_io/scene_writer.h"

namespace fs = std::filesystem;
namespace corpus = rvr::test::corpus;

namespace {

class ModelTextures : public corpus::ModelDirTest {
 protected:
  const char* folder_prefix() const override { return "rvr_textures_"; }
};

// The test image: 3 x 2 texels of distinct bytes, the top row first, as the PNG holds them.
// Byte 3 lies on sRGB's linear segment (<= 0.04045 * 255), the others on its power curve.
constexpr int kWidth = 3, kHeight = 2;
uint8_t image_byte(int x, int y_from_top, int c) {
  return uint8_t(3 + 40 * x + 90 * y_from_top + 9 * c);
}

// The PNG's bytes, written through the image codec with no transfer function (byte / 255 as
// it is) into a scratch file.
std::string png_bytes(const fs::path& scratch) {
  rvr::Image image;
  image.width = kWidth;
  image.height = kHeight;
  image.channels = 3;
  image.pixels.resize(kWidth * kHeight * 3);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = float(image_byte(x, y, c)) / 255.0f;
  EXPECT_TRUE(rvr::write_image(scratch.string(), image, false).ok());
  std::ifstream in(scratch, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  fs::remove(scratch);
  return bytes.str();
}

// IEC 61966-2-1's decoding, in double.
double srgb_to_linear(uint8_t byte) {
  const double c = byte / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// Level 0 holds the PNG decoded to linear, its bottom row first (row y is the image's row
// kHeight - 1 - y from the top).
void expect_texels_of_the_png(const rvr::Texture& t) {
  ASSERT_TRUE(t.mips) << t.file << " was not read";
  const rvr::TextureLevel& level = t.mips->levels.at(0);
  ASSERT_EQ(level.width, kWidth);
  ASSERT_EQ(level.height, kHeight);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(level.at(x, y)[c], srgb_to_linear(image_byte(x, kHeight - 1 - y, c)), 1e-6)
            << "texel " << x << ", " << y << " channel " << c;
      }
}

// The unit square in z = 0 as two triangles, each corner with its own uv (OpenGL's convention)
// and colour.
const glm::vec3 kCorners[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
const glm::vec2 kUvs[4] = {{0.125f, 0.25f}, {0.875f, 0.125f}, {0.75f, 0.9375f}, {0.0625f, 0.75f}};
const glm::vec3 kColours[4] = {
    {1.0f, 0.5f, 0.25f}, {0.0f, 1.0f, 0.125f}, {0.5f, 0.0f, 1.0f}, {0.25f, 0.75f, 0.0f}};

int corner_of(const glm::vec3& p) {
  for (int i = 0; i < 4; ++i)
    if (p == kCorners[i]) return i;
  return -1;
}

// Every vertex of the loaded square has the uv (and colour) written for its corner.
void expect_square_uvs(const rvr::TriangleMesh& mesh, bool colours) {
  ASSERT_EQ(mesh.triangle_count(), 2u);
  ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
  ASSERT_EQ(mesh.colours.size(), colours ? mesh.positions.size() : 0u);
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const int corner = corner_of(mesh.positions[v]);
    ASSERT_GE(corner, 0) << "vertex " << v << " is no corner of the square";
    EXPECT_EQ(mesh.uvs[v], kUvs[corner]) << "vertex " << v;
    if (colours) {
      EXPECT_EQ(mesh.colours[v], kColours[corner]) << "vertex " << v;
    }
  }
}

std::string obj_square(const std::string& mtl) {
  std::string s = "mtllib " + mtl + "\n";
  for (const glm::vec3& p : kCorners)
    s += "v " + corpus::num(p.x) + " " + corpus::num(p.y) + " " + corpus::num(p.z) + "\n";
  for (const glm::vec2& t : kUvs) s += "vt " + corpus::num(t.x) + " " + corpus::num(t.y) + "\n";
  return s + "usemtl wood\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
}

std::string all_warnings(const rvr::Scene& s) {
  std::string out;
  for (const std::string& w : s.warnings) out += w + "\n";
  return out.empty() ? "no warnings" : out;
}

// An exporter's path: backslashes and a case that differs from the files on disk.
TEST_F(ModelTextures, ObjMapKdWithBackslashesAndAnotherCase) {
  fs::create_directories(dir_ / "Textures");
  corpus::write_file(dir_ / "Textures" / "Wood.png", png_bytes(dir_ / "scratch.png"));
  write("square.mtl", "newmtl wood\nKd 1 1 1\nmap_Kd textures\\WOOD.PNG\n");
  std::string obj = write("square.obj", obj_square("square.mtl"));
  rvr::Scene s = rvr::load_scene(obj).value();
  EXPECT_TRUE(s.warnings.empty()) << all_warnings(s);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].file, "textures\\WOOD.PNG");
  EXPECT_EQ(fs::path(s.textures[0].resolved), dir_ / "Textures" / "Wood.png");
  EXPECT_EQ(s.textures[0].wrap_u, rvr::TextureWrap::Repeat);
  EXPECT_EQ(s.textures[0].wrap_v, rvr::TextureWrap::Repeat);
  expect_texels_of_the_png(s.textures[0]);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.materials.at(s.objects[0].material).texture, 0);
  expect_square_uvs(s.objects[0].mesh, false);
  EXPECT_TRUE(rvr::textured(s, s.objects[0]));
}

// A seam: both triangles use the same positions and normals with uvs of their own at the shared
// corners, so joining vertices must keep them apart (each corner keeps the uv its face gave).
TEST_F(ModelTextures, SeamVerticesKeepTheirOwnUvs) {
  corpus::write_file(dir_ / "wood.png", png_bytes(dir_ / "scratch.png"));
  write("square.mtl", "newmtl wood\nmap_Kd wood.png\n");
  std::string obj = "mtllib square.mtl\n";
  for (const glm::vec3& p : kCorners)
    obj += "v " + corpus::num(p.x) + " " + corpus::num(p.y) + " " + corpus::num(p.z) + "\n";
  for (const glm::vec2& t : kUvs) obj += "vt " + corpus::num(t.x) + " " + corpus::num(t.y) + "\n";
  obj += "vn 0 0 1\nusemtl wood\nf 1/1/1 2/2/1 3/3/1\nf 1/4/1 3/2/1 4/3/1\n";
  rvr::Scene s = rvr::load_scene(write("seam.obj", obj)).value();
  ASSERT_EQ(s.objects.size(), 1u);
  const rvr::TriangleMesh& mesh = s.objects[0].mesh;
  ASSERT_EQ(mesh.triangle_count(), 2u);
  ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
  const int corners[2][3] = {{0, 1, 2}, {0, 2, 3}};
  const int uvs[2][3] = {{0, 1, 2}, {3, 1, 2}};
  for (int t = 0; t < 2; ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh.triangles[t][k];
      EXPECT_EQ(mesh.positions[v], kCorners[corners[t][k]]) << t << " " << k;
      EXPECT_EQ(mesh.uvs[v], kUvs[uvs[t][k]]) << t << " " << k;
    }
  EXPECT_EQ(mesh.positions.size(), 6u);  // corners 1 and 3 twice, with other uvs
}

// A Windows absolute path (the artist's machine) and a folder that moved: the file's name is
// found below the model's folder.
TEST_F(ModelTextures, AbsoluteWindowsPathAndMovedFolderFindTheFileByName) {
  fs::create_directories(dir_ / "maps" / "wood");
  corpus::write_file(dir_ / "maps" / "wood" / "oak.png", png_bytes(dir_ / "scratch.png"));
  for (const char* named : {"C:\\Users\\artist\\Project\\tex\\oak.png", "old/place/oak.png"}) {
    SCOPED_TRACE(named);
    write("square.mtl", std::string("newmtl wood\nmap_Kd ") + named + "\n");
    rvr::Scene s = rvr::load_scene(write("square.obj", obj_square("square.mtl"))).value();
    EXPECT_TRUE(s.warnings.empty()) << all_warnings(s);
    ASSERT_EQ(s.textures.size(), 1u);
    EXPECT_EQ(fs::path(s.textures[0].resolved), dir_ / "maps" / "wood" / "oak.png");
    expect_texels_of_the_png(s.textures[0]);
  }
}

// A path from the root of the drive as Windows exporters write it for a path from the model's
// folder (\..\Maps\..., as Collada/earthCylindrical.DAE of assimp-testmodels names its image),
// with another case than the files on disk: read from the model's folder.
TEST_F(ModelTextures, PathFromTheDrivesRootIsReadFromTheModelsFolder) {
  fs::create_directories(dir_ / "collada");
  fs::create_directories(dir_ / "lwo" / "maps");
  corpus::write_file(dir_ / "lwo" / "maps" / "earthCyl.png", png_bytes(dir_ / "scratch.png"));
  corpus::write_file(dir_ / "collada" / "square.mtl",
                     "newmtl wood\nmap_Kd \\..\\LWO\\Maps\\EarthCyl.png\n");
  corpus::write_file(dir_ / "collada" / "square.obj", obj_square("square.mtl"));
  rvr::Scene s = rvr::load_scene((dir_ / "collada" / "square.obj").string()).value();
  EXPECT_TRUE(s.warnings.empty()) << all_warnings(s);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(fs::path(s.textures[0].resolved).lexically_normal(),
            dir_ / "lwo" / "maps" / "earthCyl.png");
  expect_texels_of_the_png(s.textures[0]);
}

// A Windows absolute path to a folder beside the model's (the model in FBX/, its images in
// OBJ/, as FBX/spider.fbx of assimp-testmodels names them): found by name under the parent of
// the model's folder, when the model's own folder has no such file.
TEST_F(ModelTextures, AbsoluteWindowsPathFindsTheFileInASiblingFolder) {
  fs::create_directories(dir_ / "models" / "FBX" / "deeper");
  fs::create_directories(dir_ / "models" / "OBJ");
  corpus::write_file(dir_ / "models" / "OBJ" / "drkwood.png", png_bytes(dir_ / "scratch.png"));
  corpus::write_file(dir_ / "models" / "FBX" / "square.mtl",
                     "newmtl wood\nmap_Kd D:\\projects\\test\\models\\OBJ\\drkwood.png\n");
  corpus::write_file(dir_ / "models" / "FBX" / "square.obj", obj_square("square.mtl"));
  rvr::Scene s = rvr::load_scene((dir_ / "models" / "FBX" / "square.obj").string()).value();
  EXPECT_TRUE(s.warnings.empty()) << all_warnings(s);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(fs::path(s.textures[0].resolved), dir_ / "models" / "OBJ" / "drkwood.png");
  expect_texels_of_the_png(s.textures[0]);

  // The model's own folder tree comes first: a file of that name below it wins.
  corpus::write_file(dir_ / "models" / "FBX" / "deeper" / "drkwood.png",
                     png_bytes(dir_ / "scratch.png"));
  rvr::Scene own = rvr::load_scene((dir_ / "models" / "FBX" / "square.obj").string()).value();
  ASSERT_EQ(own.textures.size(), 1u);
  EXPECT_EQ(fs::path(own.textures[0].resolved), dir_ / "models" / "FBX" / "deeper" / "drkwood.png");
}

// A texture nowhere near: the warning names both folders looked in, with the path as written
// (single backslashes) and whole however long.
TEST_F(ModelTextures, MissingTextureWarningNamesTheFoldersAndTheWholePath) {
  const std::string folder = (dir_ / "models" / std::string(120, 'f') / "FBX").string();
  fs::create_directories(folder);
  const std::string named = "D:\\projects\\" + std::string(80, 'p') + "\\nowhere_at_all.png";
  corpus::write_file(fs::path(folder) / "square.mtl", "newmtl wood\nmap_Kd " + named + "\n");
  corpus::write_file(fs::path(folder) / "square.obj", obj_square("square.mtl"));
  const std::string obj = (fs::path(folder) / "square.obj").string();
  rvr::Scene s = rvr::load_scene(obj).value();
  ASSERT_EQ(s.warnings.size(), 1u) << all_warnings(s);
  EXPECT_EQ(s.warnings[0], obj + ": material 'wood': texture '" + named +
                               "' not found (looked in '" + folder + "', '" +
                               fs::path(folder).parent_path().string() +
                               "' and their subfolders): rendered without it");
}

// A texture that is nowhere: one warning naming it, no error, the material untextured.
TEST_F(ModelTextures, MissingTextureIsAWarningNamingIt) {
  write("square.mtl", "newmtl wood\nKd 0.5 0.25 1\nmap_Kd gone.png\n");
  std::string obj = write("square.obj", obj_square("square.mtl"));
  rvr::Expected<rvr::Scene> s = rvr::load_scene(obj);
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_EQ(s->warnings.size(), 1u) << all_warnings(*s);
  EXPECT_EQ(s->warnings[0].rfind(obj + ": ", 0), 0u) << s->warnings[0];
  EXPECT_NE(s->warnings[0].find("texture 'gone.png' not found"), std::string::npos)
      << s->warnings[0];
  ASSERT_EQ(s->textures.size(), 1u);
  EXPECT_FALSE(s->textures[0].mips);
  EXPECT_FALSE(rvr::textured(*s, s->objects[0]));
  const rvr::Material& m = s->materials.at(s->objects[0].material);
  EXPECT_EQ(rvr::base_colour(*s, s->objects[0], m, 0, 0.25f, 0.25f, 0.0f),
            glm::vec3(0.5f, 0.25f, 1.0f));
}

// A texture file that is there but is no image: one warning naming it, no error.
TEST_F(ModelTextures, UndecodableTextureIsAWarningNamingIt) {
  write("wood.png", "this is not a PNG file");
  write("square.mtl", "newmtl wood\nmap_Kd wood.png\n");
  std::string obj = write("square.obj", obj_square("square.mtl"));
  rvr::Expected<rvr::Scene> s = rvr::load_scene(obj);
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_EQ(s->warnings.size(), 1u) << all_warnings(*s);
  const std::string named =
      "cannot read texture 'wood.png' at '" + (dir_ / "wood.png").string() + "' (";
  EXPECT_NE(s->warnings[0].find(named), std::string::npos) << s->warnings[0];
  EXPECT_NE(s->warnings[0].find("): rendered without it"), std::string::npos) << s->warnings[0];
  ASSERT_EQ(s->textures.size(), 1u);
  EXPECT_FALSE(s->textures[0].mips);
  EXPECT_FALSE(rvr::textured(*s, s->objects[0]));
}

// A glTF square: TEXCOORD_0 (a decoy), TEXCOORD_1 (the set the texture names), COLOR_0, a
// sampler with clamp and mirrored repeat, KHR_texture_transform; the PNG embedded as a data
// URI (.gltf) or in the GLB's buffer. glTF's uvs are v down: the mesh's are (u, 1 - v).
struct GltfSquare {
  glm::vec2 offset{0.25f, 0.125f};
  float rotation = 0.5f;
  glm::vec2 scale{2.0f, 3.0f};
};

// `uri`, when not empty, names an external image file instead of embedding `png`.
std::string gltf_square(const std::string& png, bool glb, const GltfSquare& g,
                        const std::string& uri = "") {
  std::string bin;
  for (const glm::vec3& p : kCorners)
    for (int k = 0; k < 3; ++k) corpus::put<float>(bin, p[k]);
  for (int i = 0; i < 4; ++i) {  // TEXCOORD_0: a decoy
    corpus::put<float>(bin, 0.5f);
    corpus::put<float>(bin, 0.5f);
  }
  for (const glm::vec2& t : kUvs) {
    corpus::put<float>(bin, t.x);
    corpus::put<float>(bin, 1.0f - t.y);
  }
  for (const glm::vec3& c : kColours) {
    for (int k = 0; k < 3; ++k) corpus::put<float>(bin, c[k]);
    corpus::put<float>(bin, 1.0f);  // alpha
  }
  for (uint16_t i : {0, 1, 2, 0, 2, 3}) corpus::put<uint16_t>(bin, i);  // 12 bytes
  const size_t image_at = bin.size();
  if (glb) bin += png;
  while (bin.size() % 4) bin += '\0';
  auto n = [](float x) { return corpus::num(x); };
  std::string image = !uri.empty() ? R"({"uri":")" + uri + "\"}"
                      : glb        ? R"({"bufferView":5,"mimeType":"image/png"})"
                            : R"({"uri":"data:image/png;base64,)" + corpus::base64(png) + "\"}";
  std::string views = R"({"buffer":0,"byteOffset":0,"byteLength":48},)"
                      R"({"buffer":0,"byteOffset":48,"byteLength":32},)"
                      R"({"buffer":0,"byteOffset":80,"byteLength":32},)"
                      R"({"buffer":0,"byteOffset":112,"byteLength":64},)"
                      R"({"buffer":0,"byteOffset":176,"byteLength":12})";
  if (glb) {
    views += R"(,{"buffer":0,"byteOffset":)" + std::to_string(image_at) + R"(,"byteLength":)" +
             std::to_string(png.size()) + "}";
  }
  std::string json =
      R"({"asset":{"version":"2.0"},"extensionsUsed":["KHR_texture_transform"],)"
      R"("scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1,"TEXCOORD_1":2,)"
      R"("COLOR_0":3},"indices":4,"material":0}]}],)"
      R"("materials":[{"name":"wood","pbrMetallicRoughness":{"baseColorFactor":[1,0.5,0.25,1],)"
      R"("metallicFactor":0,"baseColorTexture":{"index":0,"texCoord":1,"extensions":)"
      R"({"KHR_texture_transform":{"offset":[)" +
      n(g.offset.x) + "," + n(g.offset.y) + R"(],"rotation":)" + n(g.rotation) + R"(,"scale":[)" +
      n(g.scale.x) + "," + n(g.scale.y) +
      R"(]}}}}}],"textures":[{"source":0,"sampler":0}],)"
      R"("samplers":[{"wrapS":33071,"wrapT":33648}],"images":[)" +
      image +
      "],"
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3",)"
      R"("min":[0,0,0],"max":[1,1,0]},{"bufferView":1,"componentType":5126,"count":4,)"
      R"("type":"VEC2"},{"bufferView":2,"componentType":5126,"count":4,"type":"VEC2"},)"
      R"({"bufferView":3,"componentType":5126,"count":4,"type":"VEC4"},)"
      R"({"bufferView":4,"componentType":5123,"count":6,"type":"SCALAR"}],)"
      R"("bufferViews":[)" +
      views + R"(],"buffers":[{"byteLength":)" + std::to_string(bin.size());
  if (!glb) {
    return json + R"(,"uri":"data:application/octet-stream;base64,)" + corpus::base64(bin) +
           "\"}]}";
  }
  json += "}]}";
  while (json.size() % 4) json += ' ';
  std::string s = "glTF";
  corpus::put<uint32_t>(s, 2);
  corpus::put<uint32_t>(s, uint32_t(12 + 8 + json.size() + 8 + bin.size()));
  corpus::put<uint32_t>(s, uint32_t(json.size()));
  s += "JSON" + json;
  corpus::put<uint32_t>(s, uint32_t(bin.size()));
  s += std::string("BIN\0", 4) + bin;
  return s;
}

TEST_F(ModelTextures, GltfAndGlbEmbeddedPngUvSetColoursWrapAndTransform) {
  const std::string png = png_bytes(dir_ / "scratch.png");
  const GltfSquare g;
  for (bool glb : {false, true}) {
    SCOPED_TRACE(glb ? "glb" : "gltf");
    std::string p = write(glb ? "square.glb" : "square.gltf", gltf_square(png, glb, g));
    rvr::Scene s = rvr::load_scene(p).value();
    EXPECT_TRUE(s.warnings.empty()) << all_warnings(s);
    ASSERT_EQ(s.objects.size(), 1u);
    expect_square_uvs(s.objects[0].mesh, true);
    const rvr::Material& m = s.materials.at(s.objects[0].material);
    EXPECT_EQ(m.diffuse, glm::vec3(1.0f, 0.5f, 0.25f));
    ASSERT_EQ(m.texture, 0);
    ASSERT_EQ(s.textures.size(), 1u);
    EXPECT_TRUE(s.textures[0].resolved.empty());  // the file's own image
    EXPECT_EQ(s.textures[0].wrap_u, rvr::TextureWrap::ClampToEdge);
    EXPECT_EQ(s.textures[0].wrap_v, rvr::TextureWrap::MirroredRepeat);
    expect_texels_of_the_png(s.textures[0]);
    EXPECT_NEAR(m.uv_transform.offset.x, g.offset.x, 1e-5f);
    EXPECT_NEAR(m.uv_transform.offset.y, g.offset.y, 1e-5f);
    EXPECT_NEAR(m.uv_transform.rotation, g.rotation, 1e-6f);
    EXPECT_EQ(m.uv_transform.scale, g.scale);
  }
}

// An external image as a glTF exporter names it: a URI with an escaped space, in a folder
// whose case differs from the disk's.
TEST_F(ModelTextures, GltfExternalImageWithEscapedNameAndAnotherCase) {
  fs::create_directories(dir_ / "maps");
  corpus::write_file(dir_ / "maps" / "old oak.png", png_bytes(dir_ / "scratch.png"));
  std::string p = write("square.gltf", gltf_square("", false, {}, "Maps/old%20oak.png"));
  rvr::Scene s = rvr::load_scene(p).value();
  EXPECT_TRUE(s.warnings.empty()) << all_warnings(s);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(fs::path(s.textures[0].resolved), dir_ / "maps" / "old oak.png");
  expect_texels_of_the_png(s.textures[0]);
  expect_square_uvs(s.objects.at(0).mesh, true);
}

// `rvr scenes --export` of a GLB: the embedded image becomes an EXR beside the document, the
// mesh's uvs and colours go to its PLY, the transform and wrap modes to the material; all read
// back the same, bit for bit.
TEST_F(ModelTextures, ExportedGlbReadsBackWithItsTextureUvsAndColours) {
  std::string p = write("square.glb", gltf_square(png_bytes(dir_ / "scratch.png"), true, {}));
  rvr::Scene original = rvr::load_scene(p).value();
  fs::create_directories(dir_ / "out");
  rvr::Expected<rvr::SceneDocument> doc =
      rvr::write_scene(original, "square", (dir_ / "out").string());
  ASSERT_TRUE(doc.ok()) << doc.error().message;
  ASSERT_EQ(doc->texture_files.size(), 1u);
  EXPECT_EQ(doc->texture_files[0].name, "square.texture0.exr");
  for (const rvr::SceneMeshFile& m : doc->mesh_files)
    corpus::write_file(dir_ / "out" / m.name, m.bytes);
  for (const rvr::SceneTextureFile& t : doc->texture_files) {
    ASSERT_TRUE(rvr::write_image((dir_ / "out" / t.name).string(), t.image).ok());
  }
  rvr::Expected<rvr::Scene> back =
      rvr::parse_scene(doc->json, "square.json", (dir_ / "out").string());
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_TRUE(back->warnings.empty()) << all_warnings(*back);
  ASSERT_EQ(back->textures.size(), 1u);
  expect_texels_of_the_png(back->textures[0]);
  const rvr::TextureLevel &a = original.textures[0].mips->levels[0],
                          &b = back->textures[0].mips->levels[0];
  EXPECT_EQ(a.texels, b.texels);
  EXPECT_EQ(back->textures[0].wrap_u, rvr::TextureWrap::ClampToEdge);
  EXPECT_EQ(back->textures[0].wrap_v, rvr::TextureWrap::MirroredRepeat);
  const rvr::Material &ma = original.materials.at(original.objects[0].material),
                      &mb = back->materials.at(back->objects[0].material);
  EXPECT_EQ(mb.texture, 0);
  EXPECT_EQ(ma.uv_transform.offset, mb.uv_transform.offset);
  EXPECT_EQ(ma.uv_transform.rotation, mb.uv_transform.rotation);
  EXPECT_EQ(ma.uv_transform.scale, mb.uv_transform.scale);
  expect_square_uvs(back->objects.at(0).mesh, true);
}

// 3DS, as 3D Studio wrote it: a DOS 8.3 texture name in capitals (MAT_TEXMAP / MAT_MAPNAME)
// and one uv per vertex (TEX_VERTS); Assimp reads it Z-up turned to Y-up and one vertex per
// face corner. Every loaded vertex carries the uv written for its cube vertex.
glm::vec2 cube_uv(int v) {
  return {float(v) / 8.0f + 1.0f / 16.0f, 1.0f - float(v) / 8.0f - 1.0f / 32.0f};
}

std::string textured_cube_3ds(const std::string& map_name) {
  using corpus::chunk3ds;
  std::string white;
  for (int k = 0; k < 3; ++k) corpus::put<uint8_t>(white, 255);
  std::string material =
      chunk3ds(0xAFFF, chunk3ds(0xA000, std::string("wood\0", 5)) +
                           chunk3ds(0xA020, chunk3ds(0x0011, white)) +
                           chunk3ds(0xA200, chunk3ds(0xA300, map_name + std::string(1, '\0'))));
  std::string verts, uvs;
  corpus::put<uint16_t>(verts, 8);
  corpus::put<uint16_t>(uvs, 8);
  for (int v = 0; v < 8; ++v) {
    for (float c : corpus::cube_vertex(v)) corpus::put<float>(verts, c);
    corpus::put<float>(uvs, cube_uv(v).x);
    corpus::put<float>(uvs, cube_uv(v).y);
  }
  auto tris = corpus::cube_triangles();
  std::string faces, group = std::string("wood\0", 5);
  corpus::put<uint16_t>(faces, uint16_t(tris.size()));
  corpus::put<uint16_t>(group, uint16_t(tris.size()));
  for (size_t f = 0; f < tris.size(); ++f) {
    for (int i : tris[f]) corpus::put<uint16_t>(faces, uint16_t(i));
    corpus::put<uint16_t>(faces, 0);
    corpus::put<uint16_t>(group, uint16_t(f));
  }
  std::string mesh = chunk3ds(0x4100, chunk3ds(0x4110, verts) + chunk3ds(0x4140, uvs) +
                                          chunk3ds(0x4120, faces + chunk3ds(0x4130, group)));
  std::string object = chunk3ds(0x4000, std::string("cube\0", 5) + mesh);
  std::string version;
  corpus::put<uint32_t>(version, 3);
  std::string editor = chunk3ds(0x3D3D, chunk3ds(0x3D3E, version) + material + object);
  return chunk3ds(0x4D4D, chunk3ds(0x0002, version) + editor);
}

TEST_F(ModelTextures, ThreeDsDosNameInCapitalsAndPerVertexUvs) {
  corpus::write_file(dir_ / "wood.png", png_bytes(dir_ / "scratch.png"));
  rvr::Scene s = rvr::load_scene(write("cube.3ds", textured_cube_3ds("WOOD.PNG"))).value();
  EXPECT_TRUE(s.warnings.empty()) << all_warnings(s);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(fs::path(s.textures[0].resolved), dir_ / "wood.png");
  expect_texels_of_the_png(s.textures[0]);
  ASSERT_EQ(s.objects.size(), 1u);
  const rvr::TriangleMesh& mesh = s.objects[0].mesh;
  ASSERT_EQ(mesh.triangle_count(), 12u);
  ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
  // The cube vertex of each loaded vertex, found by its uv (all 8 differ); the turn to Y-up is
  // a rotation, so distances from vertex 0 are kept: |p - p0| = |cube_vertex(v) - 0|.
  int origin = -1;
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    if (mesh.uvs[v] == cube_uv(0)) origin = int(v);
  ASSERT_GE(origin, 0) << "no vertex has the uv of cube vertex 0";
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    int written = -1;
    for (int c = 0; c < 8; ++c)
      if (mesh.uvs[v] == cube_uv(c)) written = c;
    ASSERT_GE(written, 0) << "vertex " << v << " has a uv no vertex was given";
    auto corner = corpus::cube_vertex(written);
    const float expected =
        std::sqrt(corner[0] * corner[0] + corner[1] * corner[1] + corner[2] * corner[2]);
    EXPECT_NEAR(glm::length(mesh.positions[v] - mesh.positions[size_t(origin)]), expected, 1e-5f)
        << "vertex " << v;
  }
}

// PLY vertex colours (bytes, Assimp divides by 255) are kept per vertex, not averaged.
TEST_F(ModelTextures, PlyVertexColoursArrivePerVertex) {
  const uint8_t bytes[4][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {10, 128, 250}};
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < 4; ++i) {
    ply += corpus::num(kCorners[i].x) + " " + corpus::num(kCorners[i].y) + " 0";
    for (int c = 0; c < 3; ++c) {
      ply += ' ';
      ply += std::to_string(bytes[i][c]);
    }
    ply += "\n";
  }
  ply += "3 0 1 2\n3 0 2 3\n";
  rvr::Scene s = rvr::load_scene(write("square.ply", ply)).value();
  ASSERT_EQ(s.objects.size(), 1u);
  const rvr::TriangleMesh& mesh = s.objects[0].mesh;
  ASSERT_EQ(mesh.colours.size(), mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const int corner = corner_of(mesh.positions[v]);
    ASSERT_GE(corner, 0);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mesh.colours[v][c], bytes[corner][c] / 255.0, 1e-6);
  }
  const rvr::Material& m = s.materials.at(s.objects[0].material);
  EXPECT_EQ(m.diffuse, glm::vec3(1.0f));
  EXPECT_TRUE(rvr::varies_in_colour(s, s.objects[0]));
  // What every renderer shades with (surface_colour.h): at a corner, that corner's colour.
  for (int k = 0; k < 3; ++k) {
    const float b1 = k == 1 ? 1.0f : 0.0f, b2 = k == 2 ? 1.0f : 0.0f;
    const int corner = corner_of(mesh.positions[mesh.triangles[0][k]]);
    const glm::vec3 c = rvr::base_colour(s, s.objects[0], m, 0, b1, b2, 0.0f);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(c[ch], bytes[corner][ch] / 255.0, 1e-6);
  }
}

}  // namespace
