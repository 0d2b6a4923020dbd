// Model files as scenes (docs/scene-format.md, "Model files as scenes"): a corpus of real
// exporters' quirks, each checked against Assimp called directly as the independent oracle
// (Assimp loads it with N triangles => rvr loads it with N triangles), and the camera, lights
// and colours taken from the files, checked against the values written into them.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "model_corpus.h"
#include "rvr/core/camera.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/isa.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/camera_framing.h"
#include "rvr/scene_io/scene_loader.h"

namespace fs = std::filesystem;
namespace corpus = rvr::test::corpus;

namespace {

class ModelFiles : public corpus::ModelDirTest {
 protected:
  const char* folder_prefix() const override { return "rvr_models_"; }
};

// The oracle: Assimp on its own, triangulating, nothing of rvr's. -1 when it refuses the file.
long assimp_triangles(const std::string& path) {
  Assimp::Importer importer;
  const aiScene* ai = importer.ReadFile(path, aiProcess_Triangulate);
  if (!ai) return -1;
  long n = 0;
  for (unsigned m = 0; m < ai->mNumMeshes; ++m)
    for (unsigned f = 0; f < ai->mMeshes[m]->mNumFaces; ++f)
      n += ai->mMeshes[m]->mFaces[f].mNumIndices == 3;
  return n;
}

// Loads `path` as the scene and as a `mesh` object of a scene file, and expects both to have
// as many triangles as Assimp finds (and as the corpus wrote, so a file Assimp reads
// differently from what the test meant shows up too).
void expect_loads_like_assimp(const std::string& path, long written_triangles) {
  SCOPED_TRACE(path);
  long oracle = assimp_triangles(path);
  ASSERT_EQ(oracle, written_triangles) << "Assimp reads the corpus file differently";
  rvr::Expected<rvr::Scene> as_scene = rvr::load_scene(path);
  ASSERT_TRUE(as_scene.ok()) << as_scene.error().message;
  EXPECT_EQ(long(as_scene->triangle_count()), oracle);
  std::string scene_json = R"({"camera":{"eye":[3,3,3],"target":[0,0,0],"up":[0,1,0]},)"
                           R"("objects":[{"type":"mesh","file":")" +
                           fs::path(path).filename().string() + R"("}]})";
  rvr::Expected<rvr::Scene> as_object =
      rvr::parse_scene(scene_json, "inline.json", fs::path(path).parent_path().string());
  ASSERT_TRUE(as_object.ok()) << as_object.error().message;
  EXPECT_EQ(long(as_object->triangle_count()), oracle);
}

const rvr::Material& material_of(const rvr::Scene& s, size_t object = 0) {
  return s.materials.at(s.objects.at(object).material);
}

void expect_near3(const glm::vec3& got, const glm::vec3& want, float tol) {
  EXPECT_NEAR(got.x, want.x, tol);
  EXPECT_NEAR(got.y, want.y, tol);
  EXPECT_NEAR(got.z, want.z, tol);
}

// Colours written as bytes read back within half a step of 1/255.
constexpr float kByteTolerance = 0.5f / 255.0f + 1e-6f;
// Decimal colours and positions written with %g (6 significant digits).
constexpr float kTextTolerance = 1e-5f;

TEST_F(ModelFiles, BlenderPlyHeaderWithFreeTextLineLoads) {
  // Refused before issue 15 with "PLY header line 3: unknown keyword".
  std::string p = write("blender.ply", corpus::blender_ply_cube(200, 30, 20));
  expect_loads_like_assimp(p, 12);
  rvr::Scene s = rvr::load_scene(p).value();
  // No material in PLY: a white one, and the vertex colours (bytes / 255) on every vertex.
  expect_near3(material_of(s).diffuse, glm::vec3(1.0f), 0.0f);
  const rvr::TriangleMesh& mesh = s.objects.at(0).mesh;
  ASSERT_EQ(mesh.colours.size(), mesh.positions.size());
  for (const glm::vec3& c : mesh.colours)
    expect_near3(c, glm::vec3(200, 30, 20) / 255.0f, kByteTolerance);
}

TEST_F(ModelFiles, ObjWithMissingMtllibLoadsWithTheDefaultMaterial) {
  std::string p = write("nomtl.obj", corpus::obj_cube("mtllib not_here.mtl\n", "Red"));
  expect_loads_like_assimp(p, 12);
  // `usemtl Red` without its library names no colour: grey (Assimp's 0.6, or rvr's default).
  glm::vec3 d = material_of(rvr::load_scene(p).value()).diffuse;
  EXPECT_EQ(d.r, d.g);
  EXPECT_EQ(d.g, d.b);
}

TEST_F(ModelFiles, ObjWithCrlfLineEnds) {
  expect_loads_like_assimp(write("crlf.obj", corpus::obj_cube("# CRLF\r\n", "", "\r\n")), 12);
}

// Assimp's OBJ reader makes one vertex per face corner; rvr joins those that are the same
// bits (position and normal). A unit cube: 8 corners without normals, 6 faces x 4 corners with
// one normal per face; every triangle's corners are cube corners, the faces cover area 6.
void expect_joined_cube(const rvr::Scene& s, size_t vertices) {
  ASSERT_EQ(s.objects.size(), 1u);
  const rvr::TriangleMesh& mesh = s.objects[0].mesh;
  EXPECT_EQ(mesh.positions.size(), vertices);
  ASSERT_EQ(mesh.triangles.size(), 12u);
  double area = 0.0;
  for (const glm::uvec3& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_LT(t[k], mesh.positions.size());
      const glm::vec3 p = mesh.positions[t[k]];
      bool corner = false;
      for (int v = 0; v < 8; ++v) {
        const auto c = corpus::cube_vertex(v);
        corner |= p == glm::vec3(c[0], c[1], c[2]);  // written exactly (0 and 1)
      }
      EXPECT_TRUE(corner) << p.x << " " << p.y << " " << p.z;
    }
    const glm::vec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  EXPECT_DOUBLE_EQ(area, 6.0);  // halves of unit squares: exact in floats
}

TEST_F(ModelFiles, ObjFaceCornersAreJoinedWithTheFilesCoordinates) {
  expect_joined_cube(rvr::load_scene(write("joined.obj", corpus::obj_cube("", ""))).value(), 8);
  // One normal per face: corners of different faces keep their own normals.
  std::string s;
  for (int v = 0; v < 8; ++v) {
    auto p = corpus::cube_vertex(v);
    s += "v " + corpus::num(p[0]) + " " + corpus::num(p[1]) + " " + corpus::num(p[2]) + "\n";
  }
  for (const char* n : {"-1 0 0", "1 0 0", "0 -1 0", "0 1 0", "0 0 -1", "0 0 1"})
    s += std::string("vn ") + n + "\n";
  int face = 1;
  for (const auto& q : corpus::cube_quads()) {
    s += "f";
    for (int i : q) {  // appended piecewise: GCC 12 warns falsely on " " + string
      s += ' ';
      s += std::to_string(i + 1);
      s += "//";
      s += std::to_string(face);
    }
    s += "\n";
    ++face;
  }
  rvr::Scene with_normals = rvr::load_scene(write("normals.obj", s)).value();
  expect_joined_cube(with_normals, 24);
  EXPECT_EQ(with_normals.objects[0].mesh.normals.size(), 24u);
}

TEST_F(ModelFiles, ObjWithNegativeIndices) {
  std::string s;
  for (int v = 0; v < 8; ++v) {
    auto p = corpus::cube_vertex(v);
    s += "v " + corpus::num(p[0]) + " " + corpus::num(p[1]) + " " + corpus::num(p[2]) + "\n";
  }
  for (const auto& q : corpus::cube_quads()) {
    s += "f";
    for (int i : q)
      s.append(1, ' ').append(std::to_string(i - 8));  // -8 is the first of the 8 above
    s += "\n";
  }
  expect_loads_like_assimp(write("negative.obj", s), 12);
}

TEST_F(ModelFiles, ObjWithQuadsAndNgonsAndNoNormals) {
  // A quad, a pentagon and a hexagon (convex, in z = 0): 2 + 3 + 4 triangles.
  std::string s;
  int base = 1;
  for (int sides : {4, 5, 6}) {
    for (int k = 0; k < sides; ++k) {
      float a = 2.0f * glm::pi<float>() * float(k) / float(sides);
      s += "v " + corpus::num(3.0f * float(sides) + std::cos(a)) + " " + corpus::num(std::sin(a)) +
           " 0\n";
    }
    s += "f";
    for (int k = 0; k < sides; ++k) s.append(1, ' ').append(std::to_string(base + k));
    s += "\n";
    base += sides;
  }
  expect_loads_like_assimp(write("ngons.obj", s), 9);
}

TEST_F(ModelFiles, MtlColoursSpecularEmissionAndShininess) {
  write("paint.mtl",
        "newmtl paint\nKd 0.8 0.2 0.1\nKs 0.5 0.4 0.3\nKe 0.3 0.1 0\nNs 64\nillum 2\n");
  std::string p = write("painted.obj", corpus::obj_cube("mtllib paint.mtl\n", "paint"));
  expect_loads_like_assimp(p, 12);
  rvr::Scene s = rvr::load_scene(p).value();
  const rvr::Material& m = material_of(s);
  expect_near3(m.diffuse, {0.8f, 0.2f, 0.1f}, kTextTolerance);
  expect_near3(m.specular, {0.5f, 0.4f, 0.3f}, kTextTolerance);
  expect_near3(m.emission, {0.3f, 0.1f, 0.0f}, kTextTolerance);
  EXPECT_NEAR(m.shininess, 64.0f, kTextTolerance);
}

TEST_F(ModelFiles, BinaryStlWhoseHeaderStartsWithSolid) {
  expect_loads_like_assimp(write("cad.stl", corpus::binary_stl_cube()), 12);
}

TEST_F(ModelFiles, AsciiStl) {
  expect_loads_like_assimp(write("ascii.stl", corpus::ascii_stl_cube()), 12);
}

TEST_F(ModelFiles, OffWithComments) {
  expect_loads_like_assimp(write("comments.off", corpus::off_cube_with_comments()), 12);
}

// glTF and GLB: baseColorFactor, emissiveFactor, the camera (node translation, yfov,
// aspectRatio) and a KHR_lights_punctual point light (node translation, colour x intensity).
void expect_gltf_contents(const rvr::Scene& s, const corpus::GltfExtras& e) {
  const rvr::Material& m = material_of(s);
  expect_near3(m.diffuse, {e.base_colour[0], e.base_colour[1], e.base_colour[2]}, kTextTolerance);
  expect_near3(m.emission, {e.emissive[0], e.emissive[1], e.emissive[2]}, kTextTolerance);
  expect_near3(s.camera.eye, {e.camera_at[0], e.camera_at[1], e.camera_at[2]}, kTextTolerance);
  // A glTF camera looks down its node's -z with +y up.
  expect_near3(glm::normalize(s.camera.target - s.camera.eye), {0, 0, -1}, 1e-5f);
  expect_near3(s.camera.up, {0, 1, 0}, 1e-5f);
  // yfov in radians; Assimp keeps a horizontal angle, so the round trip through tan and the
  // aspect costs a little float precision: 0.01 degree.
  EXPECT_NEAR(s.camera.fov_y_deg, e.yfov * 180.0f / glm::pi<float>(), 0.01f);
  EXPECT_NEAR(float(s.image.width) / float(s.image.height), e.aspect, 0.01f);
  ASSERT_EQ(s.lights.size(), 1u);
  expect_near3(s.lights[0].position, {e.light_at[0], e.light_at[1], e.light_at[2]}, kTextTolerance);
  // glTF point lights fall off with the inverse square, as rvr's: intensity in candela.
  glm::vec3 want =
      glm::vec3(e.light_colour[0], e.light_colour[1], e.light_colour[2]) * e.light_intensity;
  expect_near3(s.lights[0].intensity, want, 1e-4f);
}

TEST_F(ModelFiles, GltfBaseColourCameraAndPunctualLight) {
  corpus::GltfExtras e;
  e.camera = e.light = true;
  e.emissive = {0.2f, 0.1f, 0.0f};
  std::string p = write("cube.gltf", corpus::gltf_json(e, false));
  expect_loads_like_assimp(p, 12);
  expect_gltf_contents(rvr::load_scene(p).value(), e);
}

TEST_F(ModelFiles, GlbBaseColourCameraAndPunctualLight) {
  corpus::GltfExtras e;
  e.camera = e.light = true;
  e.base_colour = {0.9f, 0.8f, 0.1f, 1.0f};
  std::string p = write("cube.glb", corpus::glb(e));
  expect_loads_like_assimp(p, 12);
  expect_gltf_contents(rvr::load_scene(p).value(), e);
}

// The corpus cube names a texture but has no texture coordinates: its colour factor alone,
// and a warning naming the mesh.
TEST_F(ModelFiles, TexturedMaterialWithoutTextureCoordinatesUsesItsFactorAndWarns) {
  corpus::GltfExtras e;
  e.texture = true;
  std::string p = write("textured.gltf", corpus::gltf_json(e, false));
  expect_loads_like_assimp(p, 12);
  rvr::Scene s = rvr::load_scene(p).value();
  expect_near3(material_of(s).diffuse, {e.base_colour[0], e.base_colour[1], e.base_colour[2]},
               kTextTolerance);
  EXPECT_EQ(material_of(s).texture, -1);
  bool warned = false;
  for (const std::string& w : s.warnings)
    warned |= w.find("has a colour texture but no texture coordinates") != std::string::npos;
  EXPECT_TRUE(warned) << (s.warnings.empty() ? "no warnings" : s.warnings.front());
}

TEST_F(ModelFiles, ThreeDsMaterialColour) {
  std::string p = write("cube.3ds", corpus::cube_3ds(40, 200, 60));
  expect_loads_like_assimp(p, 12);
  rvr::Scene s = rvr::load_scene(p).value();
  expect_near3(material_of(s).diffuse, glm::vec3(40, 200, 60) / 255.0f, kByteTolerance);
}

TEST_F(ModelFiles, ColladaCameraLightAndColour) {
  corpus::DaeExtras e;
  std::string p = write("cube.dae", corpus::dae_cube(e));
  expect_loads_like_assimp(p, 12);
  rvr::Scene s = rvr::load_scene(p).value();
  expect_near3(material_of(s).diffuse, {e.diffuse[0], e.diffuse[1], e.diffuse[2]}, kTextTolerance);
  expect_near3(s.camera.eye, {e.camera_at[0], e.camera_at[1], e.camera_at[2]}, kTextTolerance);
  expect_near3(glm::normalize(s.camera.target - s.camera.eye), {0, 0, -1}, 1e-5f);
  // yfov in degrees, through Assimp's horizontal angle and back: float precision.
  EXPECT_NEAR(s.camera.fov_y_deg, e.yfov_deg, 0.01f);
  EXPECT_NEAR(float(s.image.width) / float(s.image.height), e.aspect, 0.01f);
  ASSERT_EQ(s.lights.size(), 1u);
  expect_near3(s.lights[0].position, {e.light_at[0], e.light_at[1], e.light_at[2]}, kTextTolerance);
  // No falloff in the file: the same irradiance at the model's centre (the cube's, 0.5^3)
  // as rvr's inverse-square light, colour x distance^2.
  glm::vec3 d = glm::vec3(e.light_at[0], e.light_at[1], e.light_at[2]) - glm::vec3(0.5f);
  EXPECT_NEAR(s.lights[0].intensity.x, glm::dot(d, d), 1e-3f);
}

// A Collada file in centimetres (<unit meter="0.01">) with a camera: Assimp scales the
// positions to metres through the root node; near and far, distances along the camera's view
// direction, scale with them. The camera 500 cm in front of a 100 cm cube with znear 10 cm
// and zfar 10000 cm: eye at 5 m, near 0.1 m, far 100 m (near at 10 m was beyond the cube, an
// image of background only).
TEST_F(ModelFiles, ColladaInCentimetresScalesTheCamerasNearAndFar) {
  std::string positions, indices;
  for (int v = 0; v < 8; ++v) {
    auto p = corpus::cube_vertex(v);
    positions += std::to_string(100 * p[0]) + " " + std::to_string(100 * p[1]) + " " +
                 std::to_string(100 * p[2]) + " ";
  }
  for (const auto& q : corpus::cube_quads())
    for (int i : q) indices += std::to_string(i) + " ";
  std::string dae = R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit meter="0.01" name="centimeter"/><up_axis>Y_UP</up_axis></asset>
  <library_cameras><camera id="cam" name="cam"><optics><technique_common><perspective>
    <yfov>40</yfov><aspect_ratio>1.5</aspect_ratio><znear>10</znear><zfar>10000</zfar>
  </perspective></technique_common></optics></camera></library_cameras>
  <library_geometries><geometry id="cube-mesh" name="cube"><mesh>
    <source id="cube-pos"><float_array id="cube-pos-array" count="24">)" +
                    positions + R"(</float_array>
      <technique_common><accessor source="#cube-pos-array" count="8" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <vertices id="cube-verts"><input semantic="POSITION" source="#cube-pos"/></vertices>
    <polylist count="6"><input semantic="VERTEX" source="#cube-verts" offset="0"/>
      <vcount>4 4 4 4 4 4</vcount><p>)" +
                    indices + R"(</p></polylist>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="scene">
    <node id="cube-node" name="cube"><instance_geometry url="#cube-mesh"/></node>
    <node id="cam-node" name="cam-node"><translate>50 50 500</translate><instance_camera url="#cam"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
  std::string p = write("cm.dae", dae);
  expect_loads_like_assimp(p, 12);
  rvr::Scene s = rvr::load_scene(p).value();
  expect_near3(s.camera.eye, {0.5f, 0.5f, 5.0f}, 1e-5f);
  expect_near3(glm::normalize(s.camera.target - s.camera.eye), {0, 0, -1}, 1e-5f);
  EXPECT_NEAR(s.camera.near, 0.1f, 1e-6f);
  EXPECT_NEAR(s.camera.far, 100.0f, 1e-3f);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  // --camera auto: the framing camera instead, from the default direction.
  rvr::SceneOverrides o;
  o.camera = rvr::FromFile::Auto;
  rvr::Scene framed = rvr::load_scene(p, o).value();
  expect_near3(framed.camera.target, glm::vec3(0.5f), 1e-5f);
  expect_near3(glm::normalize(framed.camera.eye - framed.camera.target), rvr::default_view_from(),
               1e-5f);
}

// The file's lights replaced by the default key light and ambient with --lights auto, and its
// camera by the framing one with --camera auto; each on its own.
TEST_F(ModelFiles, CameraAndLightsAutoReplaceTheFilesOwn) {
  corpus::DaeExtras e;
  std::string p = write("cube.dae", corpus::dae_cube(e));
  rvr::SceneOverrides o;
  o.lights = rvr::FromFile::Auto;
  rvr::Scene s = rvr::load_scene(p, o).value();
  expect_near3(s.camera.eye, {e.camera_at[0], e.camera_at[1], e.camera_at[2]}, kTextTolerance);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.ambient, glm::vec3(0.15f));
  // The default key light gives an irradiance of 1 at the centre: intensity = distance^2.
  glm::vec3 d = s.lights[0].position - glm::vec3(0.5f);
  EXPECT_NEAR(s.lights[0].intensity.x, glm::dot(d, d), 1e-3f);
  EXPECT_GT(
      glm::length(s.lights[0].position - glm::vec3(e.light_at[0], e.light_at[1], e.light_at[2])),
      0.1f);
  o = {};
  o.camera = rvr::FromFile::Auto;
  rvr::Scene c = rvr::load_scene(p, o).value();
  expect_near3(glm::normalize(c.camera.eye - c.camera.target), rvr::default_view_from(), 1e-5f);
  expect_near3(c.lights.at(0).position, {e.light_at[0], e.light_at[1], e.light_at[2]},
               kTextTolerance);
}

// view_of_model against the closed form: the square [0, 2] x [0, 1] in z = 0 seen straight on
// from (2, 0.5, 1) with a 90-degree field of view and a square frame covers x in [1, 3] and
// y in [-0.5, 1.5] at z = 0: it sees the half x >= 1 (50 % of the area), which spans x - 2 in
// [-1, 0] and y - 0.5 in [-0.5, 0.5] of the frame's [-1, 1]: half the frame across. Behind the
// camera, or beyond far, it sees nothing.
TEST(ViewOfModel, SeenShareAndSizeOfASquareHalfInView) {
  rvr::Scene s;
  rvr::Object o;
  o.type = rvr::ObjectType::Triangles;
  o.mesh.positions = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}};
  o.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.objects.push_back(o);
  rvr::Camera c;
  c.eye = {2.0f, 0.5f, 1.0f};
  c.target = {2.0f, 0.5f, 0.0f};
  c.up = {0.0f, 1.0f, 0.0f};
  c.fov_y_deg = 90.0f;
  c.near = 0.1f;
  c.far = 10.0f;
  rvr::ViewOfModel v = rvr::view_of_model(s, c, 1.0f);
  // 4096 points in proportion to area: the share within half a percent of 1/2; the extreme
  // points seen within a few hundredths of the edges.
  EXPECT_NEAR(v.seen, 0.5f, 0.005f);
  EXPECT_NEAR(v.size, 0.5f, 0.03f);
  // Twice as far: the frame covers x in [0, 4] at z = 0, the whole square, 2 wide of 4 across.
  c.eye.z = 2.0f;
  v = rvr::view_of_model(s, c, 1.0f);
  EXPECT_EQ(v.seen, 1.0f);
  EXPECT_NEAR(v.size, 0.5f, 0.03f);
  c.far = 1.5f;  // the square lies beyond far
  EXPECT_EQ(rvr::view_of_model(s, c, 1.0f).seen, 0.0f);
  c.far = 10.0f;
  c.target = {2.0f, 0.5f, 3.0f};  // looking away
  v = rvr::view_of_model(s, c, 1.0f);
  EXPECT_EQ(v.seen, 0.0f);
  EXPECT_EQ(v.size, 0.0f);
}

// The share of the model's vertices inside the camera's frame, by GLM's projection (an
// independent computation of what the image shows), for the camera a scene was given.
// `extent`, when given, receives how large the vertices are in the frame: the larger of the
// width and the height of the rectangle round their projections, as shares of the frame's.
double vertices_in_frame(const rvr::Scene& s, double* extent = nullptr) {
  const rvr::Camera& c = s.camera;
  const glm::mat4 m =
      glm::perspective(glm::radians(c.fov_y_deg), float(s.image.width) / float(s.image.height),
                       c.near, c.far) *
      glm::lookAt(c.eye, c.target, c.up);
  size_t in = 0, all = 0;
  double x0 = 1, x1 = -1, y0 = 1, y1 = -1;
  for (const rvr::Object& o : s.objects) {
    for (const glm::vec3& p : o.mesh.positions) {
      const glm::vec4 q = m * glm::vec4(p, 1.0f);
      ++all;
      if (q.w > 0.0f) {
        x0 = std::min(x0, double(q.x / q.w)), x1 = std::max(x1, double(q.x / q.w));
        y0 = std::min(y0, double(q.y / q.w)), y1 = std::max(y1, double(q.y / q.w));
      }
      in += q.w > 0.0f && std::fabs(q.x) <= q.w && std::fabs(q.y) <= q.w && std::fabs(q.z) <= q.w;
    }
  }
  if (extent) *extent = std::max(x1 - x0, y1 - y0) / 2;
  return all ? double(in) / double(all) : 0.0;
}

std::string camera_warning(const rvr::Scene& s) {
  for (const std::string& w : s.warnings)
    if (w.find("the file's camera") != std::string::npos) return w;
  return {};
}

// A file camera is judged by how much of the model it sees and how large the model is in
// frame: a close-up of one face, a camera so far that the cube is a speck, and one that cuts
// the cube in half are replaced by the framing camera (which shows every vertex), each with a
// warning saying why; the corpus' own camera, which shows the whole cube, is kept, and
// judge_file_camera = false (--camera file-always) keeps any of them.
TEST_F(ModelFiles, FileCameraThatDoesNotFrameTheModelIsReplacedSayingWhy) {
  struct Case {
    const char* name;
    std::array<float, 3> at;
    const char* why;  // empty: kept
  };
  const Case cases[] = {
      {"kept", {0.5f, 0.5f, 4.0f}, ""},
      // 0.3 in front of the face z = 1, of which the frame holds 0.22 x 0.33: a close-up (the
      // view volume takes in more of the faces behind, hidden or not).
      {"closeup", {0.5f, 0.5f, 1.3f}, "the file's camera sees "},
      // From 90 away (far is 100) the unit cube spans about 1 / (2 * 89 * tan(20 deg)) = 1.5 % of
      // the frame's height.
      {"speck", {0.5f, 0.5f, 90.0f}, "the file's camera shows the model "},
      // Centred on the edge x = 1 from 1.5 in front of the face z = 1: the frame, 2 * 1.5 *
      // tan(20 deg) * 1.5 = 1.64 wide there, holds x > 0.18 of that face, z < 0.67 of the face
      // x = 0 and 97 % of the top and bottom: 91 % of the surface, the cube cut.
      {"cut", {1.0f, 0.5f, 2.5f}, "the file's camera sees 9"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    corpus::GltfExtras e;
    e.camera = true;
    e.camera_at = c.at;
    const std::string p = write(std::string(c.name) + ".gltf", corpus::gltf_json(e, false));
    rvr::Scene s = rvr::load_scene(p).value();
    rvr::SceneOverrides keep;
    keep.judge_file_camera = false;
    rvr::Scene as_is = rvr::load_scene(p, keep).value();
    expect_near3(as_is.camera.eye, {c.at[0], c.at[1], c.at[2]}, kTextTolerance);
    EXPECT_EQ(camera_warning(as_is), "");
    if (std::string(c.why).empty()) {
      EXPECT_EQ(camera_warning(s), "");
      expect_near3(s.camera.eye, {c.at[0], c.at[1], c.at[2]}, kTextTolerance);
      EXPECT_EQ(vertices_in_frame(s), 1.0);
      continue;
    }
    const std::string w = camera_warning(s);
    EXPECT_EQ(w.rfind(p + ": " + c.why, 0), 0u) << w;
    double extent = 0;
    const double in_frame = vertices_in_frame(as_is, &extent);
    if (std::string(c.name) == "speck") {
      EXPECT_LT(extent, 0.1);
    } else {
      EXPECT_LT(in_frame, 1.0);
    }
    EXPECT_NE(w.find("; framing the model instead (--camera file-always keeps it)"),
              std::string::npos)
        << w;
    rvr::SceneOverrides o;
    o.camera = rvr::FromFile::Auto;
    rvr::Scene framed = rvr::load_scene(p, o).value();
    EXPECT_EQ(s.camera.eye, framed.camera.eye);
    EXPECT_EQ(s.camera.target, framed.camera.target);
    EXPECT_EQ(vertices_in_frame(s), 1.0);
  }
}

// --up z: a Z-up OBJ turned so that its +z is +y, by the quarter turn about x that takes
// (x, y, z) to (x, z, -y). The triangle standing 2 high along z stands 2 high along y.
TEST_F(ModelFiles, UpZTurnsTheModelSoItsZIsUp) {
  std::string p = write("zup.obj", "v 0 0 0\nv 1 0 0\nv 0 1 2\nf 1 2 3\n");
  rvr::Scene as_read = rvr::load_scene(p).value();
  ASSERT_EQ(as_read.objects.size(), 1u);
  expect_near3(as_read.objects[0].mesh.positions.at(2), {0, 1, 2}, 0.0f);
  rvr::SceneOverrides o;
  o.up = rvr::UpAxis::Z;
  rvr::Scene s = rvr::load_scene(p, o).value();
  const std::vector<glm::vec3>& v = s.objects.at(0).mesh.positions;
  ASSERT_EQ(v.size(), 3u);
  expect_near3(v[0], {0, 0, 0}, 0.0f);
  expect_near3(v[1], {1, 0, 0}, 0.0f);
  expect_near3(v[2], {0, 2, -1}, 1e-6f);
  // Framed after turning: the camera's up is still +y and it looks at the turned model.
  EXPECT_EQ(s.camera.up, glm::vec3(0, 1, 0));
  expect_near3(s.camera.target, {0.5f, 1.0f, -0.5f}, 1e-6f);
  o.up = rvr::UpAxis::Y;  // as read
  expect_near3(rvr::load_scene(p, o)->objects.at(0).mesh.positions.at(2), {0, 1, 2}, 0.0f);
}

// An ASCII FBX 7.4 in metres (UnitScaleFactor 100) saying it is Z-up (GlobalSettings UpAxis 2,
// UpAxisSign 1), with the viewport camera "Producer Perspective" of FBX 6 exporters as a model of
// its own, and a camera the user placed, "shot", at (-5, 0.5, 1) looking along its node's +x
// (Assimp's FBX camera convention). Assimp reads both cameras and the axes into the scene's
// metadata without applying them. rvr takes "shot" (40 degrees across, which frames the
// triangle), not the viewport camera, and turns the model (x, y, z) -> (x, z, -y): the
// triangle's (0, 1, 2) to (0, 2, -1), the eye to (-5, 1, -0.5).
TEST_F(ModelFiles, FbxUpAxisFromItsMetadataAndItsViewportCameraSkipped) {
  std::string p = write("cam.fbx", R"FBX(; FBX 7.4.0 project file
FBXHeaderExtension:  {
	FBXHeaderVersion: 1003
	FBXVersion: 7400
	Creator: "rvr test"
}
GlobalSettings:  {
	Version: 1000
	Properties70:  {
		P: "UpAxis", "int", "Integer", "",2
		P: "UpAxisSign", "int", "Integer", "",1
		P: "FrontAxis", "int", "Integer", "",1
		P: "FrontAxisSign", "int", "Integer", "",-1
		P: "CoordAxis", "int", "Integer", "",0
		P: "CoordAxisSign", "int", "Integer", "",1
		P: "UnitScaleFactor", "double", "Number", "",100
		P: "DefaultCamera", "KString", "", "", "Producer Perspective"
	}
}
Objects:  {
	Geometry: 1000, "Geometry::tri", "Mesh" {
		Vertices: *9 {
			a: 0,0,0,1,0,0,0,1,2
		}
		PolygonVertexIndex: *3 {
			a: 0,1,-3
		}
		GeometryVersion: 124
	}
	Model: 2000, "Model::tri", "Mesh" {
		Version: 232
	}
	NodeAttribute: 3000, "NodeAttribute::Producer Perspective", "Camera" {
		TypeFlags: "Camera"
	}
	Model: 4000, "Model::Producer Perspective", "Camera" {
		Version: 232
		Properties70:  {
			P: "Lcl Translation", "Lcl Translation", "", "A",-10,0.5,1
		}
	}
	NodeAttribute: 5000, "NodeAttribute::shot", "Camera" {
		TypeFlags: "Camera"
		Properties70:  {
			P: "FieldOfView", "FieldOfView", "", "A",40
		}
	}
	Model: 6000, "Model::shot", "Camera" {
		Version: 232
		Properties70:  {
			P: "Lcl Translation", "Lcl Translation", "", "A",-5,0.5,1
		}
	}
}
Connections:  {
	C: "OO",2000,0
	C: "OO",1000,2000
	C: "OO",4000,0
	C: "OO",3000,4000
	C: "OO",6000,0
	C: "OO",5000,6000
}
)FBX");
  rvr::Scene s = rvr::load_scene(p).value();
  const std::vector<glm::vec3>& v = s.objects.at(0).mesh.positions;
  ASSERT_EQ(v.size(), 3u);
  expect_near3(v[2], {0, 2, -1}, 1e-6f);
  expect_near3(s.camera.eye, {-5, 1, -0.5f}, 1e-5f);
  expect_near3(glm::normalize(s.camera.target - s.camera.eye), {1, 0, 0}, 1e-6f);
  bool warned = false;
  for (const std::string& w : s.warnings)
    warned |= w.find("ignored the exporter's viewport camera 'Producer Perspective'") !=
              std::string::npos;
  EXPECT_TRUE(warned) << (s.warnings.empty() ? "no warnings" : s.warnings.front());
  // --up y: the coordinates as Assimp reads them.
  rvr::SceneOverrides o;
  o.up = rvr::UpAxis::Y;
  rvr::Scene as_read = rvr::load_scene(p, o).value();
  expect_near3(as_read.objects.at(0).mesh.positions.at(2), {0, 1, 2}, 0.0f);
  expect_near3(as_read.camera.eye, {-5, 0.5f, 1}, 1e-5f);
}

// FBX units: positions in UnitScaleFactor centimetres per unit (centimetres when the file does
// not say), which Assimp reports and does not apply. The same scene written in centimetres
// (no UnitScaleFactor line), in inches (2.54) and in metres (100): the triangle's corners
// (0, 0, 2s) and (0, s, 0) are (0, 0, 2) m and (0, 1, 0) m, the camera's eye (-5, 0.5, 1) m, near
// 0.1 m and far 100 m in every one; as a mesh object of a scene file too.
TEST_F(ModelFiles, FbxUnitScaleFactorGivesMetres) {
  struct Case {
    std::string name, factor;
    float metres_per_unit;
  };
  for (const Case& c :
       {Case{"cm.fbx", "", 0.01f}, Case{"inch.fbx", "2.54", 0.0254f}, Case{"m.fbx", "100", 1.0f}}) {
    SCOPED_TRACE(c.name);
    std::string p =
        write(c.name, corpus::fbx_triangle_and_camera(1.0f / c.metres_per_unit, c.factor));
    rvr::Expected<rvr::Scene> loaded = rvr::load_scene(p);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    const rvr::Scene& s = *loaded;
    const std::vector<glm::vec3>& v = s.objects.at(0).mesh.positions;
    ASSERT_EQ(v.size(), 3u);
    expect_near3(v[0], {0, 0, 0}, 1e-6f);
    expect_near3(v[1], {0, 0, 2}, 1e-5f);
    expect_near3(v[2], {0, 1, 0}, 1e-5f);
    expect_near3(s.camera.eye, {-5, 0.5f, 1}, 1e-4f);
    expect_near3(glm::normalize(s.camera.target - s.camera.eye), {1, 0, 0}, 1e-6f);
    EXPECT_NEAR(s.camera.near, 0.1f, 1e-6f);
    EXPECT_NEAR(s.camera.far, 100.0f, 1e-3f);
    EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
    for (const char* material : {"", R"(,"material":"from_file")"}) {
      SCOPED_TRACE(material);
      auto o = rvr::parse_scene(R"({"camera":{"eye":[3,3,3],"target":[0,0,0],"up":[0,1,0]},)"
                                R"("objects":[{"type":"mesh","file":")" +
                                    c.name + "\"" + material + "}]}",
                                "t.json", dir_.string());
      ASSERT_TRUE(o.ok()) << o.error().message;
      glm::vec3 high(-1e9f);
      for (const glm::vec3& q : o->objects.at(0).mesh.positions) high = glm::max(high, q);
      expect_near3(high, {0, 1, 2}, 1e-5f);
    }
  }
}

// A Z-up 3DS file (3D Studio's z is up; Assimp turns it to +y as it reads): a box 1 along the
// file's x, 2 along y and 3 along z stands upright with --up auto, its tall axis (3) along +y,
// and the file's y along z: extents (1, 3, 2).
TEST_F(ModelFiles, ThreeDsIsZUpAndStandsUpright) {
  std::string p = write("tall.3ds", corpus::cube_3ds(200, 200, 200, {1.0f, 2.0f, 3.0f}));
  rvr::Scene s = rvr::load_scene(p).value();
  glm::vec3 low(1e9f), high(-1e9f);
  for (const rvr::Object& o : s.objects) {
    for (const glm::vec3& q : o.mesh.positions) {
      low = glm::min(low, q);
      high = glm::max(high, q);
    }
  }
  expect_near3(high - low, {1, 3, 2}, 1e-5f);
  EXPECT_EQ(s.camera.up, glm::vec3(0, 1, 0));
}

// The automatic exposure on every model file of the corpus, rendered by softraster at 160x120
// with the file's own camera and lights where it has them: under 1 % of the model's pixels
// have a linear colour above 1 in any channel.
TEST_F(ModelFiles, AutomaticExposureClipsUnderOnePercentOfEveryCorpusModel) {
  std::vector<std::string> files;
  for (const corpus::CorpusFile& f : corpus::every_file()) {
    std::string p = write(f.name, f.bytes);
    if (f.model) files.push_back(p);
  }
  auto renderer = rvr::make_renderer("softraster").value();
  for (const std::string& p : files) {
    SCOPED_TRACE(p);
    rvr::SceneOverrides o;
    o.width = 160;
    o.height = 120;
    rvr::Expected<rvr::Scene> s = rvr::load_scene(p, o);
    ASSERT_TRUE(s.ok()) << s.error().message;
    rvr::FrameBuffers b = renderer->render(*s, {}).value().buffers;
    size_t model = 0, clipped = 0;
    for (size_t i = 0; i < b.colour.size(); ++i) {
      if (b.object_id[i] == rvr::kNoId) continue;
      ++model;
      clipped += b.colour[i].r > 1.0f || b.colour[i].g > 1.0f || b.colour[i].b > 1.0f;
    }
    EXPECT_GT(model, 100u);
    EXPECT_LT(clipped * 100, model) << clipped << " of " << model << " pixels clip";
    std::printf("%-40s %zu of %zu model pixels clip\n", fs::path(p).filename().c_str(), clipped,
                model);
  }
}

// The automatic exposure: a white cube (diffuse 1, from an MTL) under the default key light
// clips most of its lit faces at exposure 0; the automatic exposure is below 0 and leaves
// under 1 % of the cube's pixels above 1 in a render.
TEST_F(ModelFiles, AutomaticExposureClipsUnderOnePercentOfTheModel) {
  write("white.mtl", "newmtl white\nKd 1 1 1\nKs 0 0 0\n");
  std::string p = write("white.obj", corpus::obj_cube("mtllib white.mtl\n", "white"));
  rvr::Scene s = rvr::load_scene(p).value();
  EXPECT_LT(s.image.exposure, 0.0f);
  rvr::SceneOverrides o;
  o.exposure = 0.0f;
  EXPECT_EQ(rvr::load_scene(p, o)->image.exposure, 0.0f);
  auto count = [](const rvr::Scene& scene, size_t* model) {
    auto r = rvr::make_renderer("raytrace").value();
    rvr::FrameBuffers b = r->render(scene, {}).value().buffers;
    size_t clipped = 0;
    *model = 0;
    for (size_t i = 0; i < b.colour.size(); ++i) {
      if (b.object_id[i] == rvr::kNoId) continue;
      ++*model;
      clipped += b.colour[i].r > 1.0f || b.colour[i].g > 1.0f || b.colour[i].b > 1.0f;
    }
    return clipped;
  };
  size_t model = 0;
  rvr::Scene unexposed = s;
  unexposed.image.exposure = 0.0f;
  size_t before = count(unexposed, &model);
  EXPECT_GT(before, model / 10) << "the test cube should clip without the exposure";
  size_t after = count(s, &model);
  EXPECT_GT(model, 1000u);
  EXPECT_LT(after, model / 100);
}

// A model without a camera: the default three-quarter view from above (35 degrees round from
// +z towards +x, 30 up), and every vertex of the model inside the image and between near and
// far, checked by projecting the vertices through the camera.
TEST_F(ModelFiles, DefaultCameraFramesTheModelFromThreeQuartersAbove) {
  std::string p = write("bare.obj", corpus::obj_cube("", ""));
  rvr::Scene s = rvr::load_scene(p).value();
  const float az = 35.0f * glm::pi<float>() / 180.0f, el = 30.0f * glm::pi<float>() / 180.0f;
  glm::vec3 from(std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el));
  expect_near3(s.camera.target, glm::vec3(0.5f), 1e-6f);
  expect_near3(glm::normalize(s.camera.eye - s.camera.target), from, 1e-5f);
  rvr::CameraFrame f = rvr::make_camera_frame(s.camera, s.image.width, s.image.height);
  float largest = 0.0f;
  for (int v = 0; v < 8; ++v) {
    auto c = corpus::cube_vertex(v);
    glm::vec3 d = glm::vec3(c[0], c[1], c[2]) - f.eye;
    float depth = glm::dot(d, f.forward);
    EXPECT_GT(depth, s.camera.near);
    EXPECT_LT(depth, s.camera.far);
    float x = glm::dot(d, f.right) / (depth * f.tan_half_fov_y * f.aspect);
    float y = glm::dot(d, f.up) / (depth * f.tan_half_fov_y);
    EXPECT_LT(std::abs(x), 1.0f);
    EXPECT_LT(std::abs(y), 1.0f);
    largest = std::max({largest, std::abs(x), std::abs(y)});
  }
  // Framed, not lost in the middle: the bounding sphere (radius sqrt(3)/2) fills the height
  // with a 10 % margin, so the cube's farthest corner reaches at least half way out.
  EXPECT_GT(largest, 0.5f);
  // The default lights: one point light and ambient.
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_GT(s.ambient.x, 0.0f);
}

TEST_F(ModelFiles, CameraFromAndImageSizeOverrides) {
  std::string p = write("bare.obj", corpus::obj_cube("", ""));
  rvr::SceneOverrides o;
  o.view_from = glm::vec3(0, 0, 2);
  o.width = 300;
  o.height = 100;
  rvr::Scene s = rvr::load_scene(p, o).value();
  EXPECT_EQ(s.image.width, 300);
  EXPECT_EQ(s.image.height, 100);
  expect_near3(glm::normalize(s.camera.eye - s.camera.target), {0, 0, 1}, 1e-6f);
  // Straight down: +y cannot be up, -z is.
  o.view_from = glm::vec3(0, 5, 0);
  rvr::Scene down = rvr::load_scene(p, o).value();
  expect_near3(glm::normalize(down.camera.eye - down.camera.target), {0, 1, 0}, 1e-6f);
  EXPECT_GT(glm::length(glm::cross(down.camera.up, glm::vec3(0, 1, 0))), 0.99f);
  o.view_from = glm::vec3(0);
  EXPECT_FALSE(rvr::load_scene(p, o).ok());
}

TEST_F(ModelFiles, SceneFileMeshMayKeepTheFilesMaterials) {
  write("paint.mtl", "newmtl paint\nKd 0.8 0.2 0.1\n");
  write("painted.obj", corpus::obj_cube("mtllib paint.mtl\n", "paint"));
  auto scene_with = [&](const std::string& material) {
    std::string text = R"({"camera":{"eye":[3,3,3],"target":[0,0,0],"up":[0,1,0]},)"
                       R"("materials":{"blue":{"diffuse":[0,0,1]}},)"
                       R"("objects":[{"type":"mesh","file":"painted.obj","material":")" +
                       material + R"(","transform":{"translate":[1,0,0]}}]})";
    return rvr::parse_scene(text, "inline.json", dir_.string());
  };
  rvr::Scene from_file = scene_with("from_file").value();
  ASSERT_EQ(from_file.objects.size(), 1u);
  expect_near3(material_of(from_file).diffuse, {0.8f, 0.2f, 0.1f}, kTextTolerance);
  // The transform applies to the file's meshes.
  float min_x = 1e9f;
  for (const glm::vec3& v : from_file.objects[0].mesh.positions) min_x = std::min(min_x, v.x);
  EXPECT_FLOAT_EQ(min_x, 1.0f);
  rvr::Scene named = scene_with("blue").value();
  expect_near3(material_of(named).diffuse, {0, 0, 1}, 0.0f);
  // Only meshes have a file to keep materials from; the name is reserved.
  auto sphere = rvr::parse_scene(
      R"({"camera":{"eye":[3,3,3],"target":[0,0,0],"up":[0,1,0]},)"
      R"("objects":[{"type":"sphere","center":[0,0,0],"radius":1,"material":"from_file"}]})",
      "s.json", dir_.string());
  ASSERT_FALSE(sphere.ok());
  EXPECT_NE(sphere.error().message.find("objects[0].material"), std::string::npos);
  auto reserved = rvr::parse_scene(R"({"camera":{"eye":[3,3,3],"target":[0,0,0],"up":[0,1,0]},)"
                                   R"("materials":{"from_file":{"diffuse":[1,0,0]}}})",
                                   "r.json", dir_.string());
  ASSERT_FALSE(reserved.ok());
  EXPECT_NE(reserved.error().message.find("reserved"), std::string::npos);
}

TEST_F(ModelFiles, ErrorsNameTheFileOnOneLine) {
  std::string broken = write("broken.obj", "v 0 0 0\nf 1 2 3\n");  // indices past the vertices
  auto bad = rvr::load_scene(broken);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message.rfind(broken + ": ", 0), 0u) << bad.error().message;
  EXPECT_EQ(bad.error().message.find('\n'), std::string::npos) << bad.error().message;
  // Scene files keep their errors: bad JSON is a JSON syntax error whatever the extension.
  for (const char* name : {"bad.json", "bad.txt", "bad"}) {
    std::string p = write(name, "{\"camera\": }");
    auto r = rvr::load_scene(p);
    ASSERT_FALSE(r.ok()) << name;
    EXPECT_NE(r.error().message.find("JSON syntax"), std::string::npos) << r.error().message;
  }
  std::string garbage = write("garbage.txt", "hello");
  auto g = rvr::load_scene(garbage);
  ASSERT_FALSE(g.ok());
  EXPECT_NE(g.error().message.find("JSON syntax"), std::string::npos) << g.error().message;
}

// Small files whose headers declare hundreds of millions of vertices or faces: Assimp 5.2's
// OFF, ASCII PLY and Collada readers allocate (and zero) what the header says before finding
// the file empty, gigabytes and seconds (found by fuzzing, tests/fuzz/regressions/mesh). The
// import's memory budget (256 MiB plus 64 bytes per byte of file) refuses them with their own
// error, before the memory is touched.
TEST_F(ModelFiles, HeaderCountsPastTheFileAreRefusedUntouched) {
  struct Case {
    const char* name;
    std::string text;
  };
  const Case cases[] = {
      {"counts.off", "OFF\n300000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
      {"counts.ply",
       "ply\nformat ascii 1.0\nelement vertex 300000000\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
      {"counts.dae",
       R"(<?xml version="1.0"?><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" )"
       R"(version="1.4.1"><library_geometries><geometry id="g"><mesh><source id="p">)"
       R"(<float_array id="pa" count="9">0 0 0 1 0 0 0 1 0</float_array><technique_common>)"
       R"(<accessor source="#pa" count="3" stride="3"><param name="X" type="float"/>)"
       R"(<param name="Y" type="float"/><param name="Z" type="float"/></accessor>)"
       R"(</technique_common></source><vertices id="v"><input semantic="POSITION" source="#p"/>)"
       R"(</vertices><triangles count="1000000000"><input semantic="VERTEX" source="#v" )"
       R"(offset="0"/><p>0 1 2</p></triangles></mesh></geometry></library_geometries>)"
       R"(<library_visual_scenes><visual_scene id="s"><node><instance_geometry url="#g"/>)"
       R"(</node></visual_scene></library_visual_scenes><scene><instance_visual_scene )"
       R"(url="#s"/></scene></COLLADA>)"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    std::string p = write(c.name, c.text);
    auto r = rvr::load_scene(p);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().kind, rvr::ErrorKind::BadInput);
    EXPECT_NE(r.error().message.find("declares more data than it holds"), std::string::npos)
        << r.error().message;
  }
  // Refused before the memory was touched: the whole test process (each test runs in its own)
  // stayed far below the 3.6 GB the OFF file's vertex array alone would be.
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  EXPECT_LT(usage.ru_maxrss, 512L * 1024) << "peak RSS in KiB";
}

// Assimp 5.2's Collada reader dereferences null on a <float_array> without its `count`
// attribute that an accessor reads from (found by fuzzing, tests/fuzz/regressions/mesh). The
// import runs in a child process, so its crash is this file's error, not rvr's crash.
TEST_F(ModelFiles, ImporterCrashIsAnErrorNotACrash) {
  std::string p = write(
      "crash.dae",
      R"(<?xml version="1.0"?><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" )"
      R"(version="1.4.1"><library_geometries><geometry id="g"><mesh><source id="p">)"
      R"(<float_array id="pa">0 0 0 1 0 0 0 1 0</float_array><technique_common>)"
      R"(<accessor source="#pa" count="3" stride="3"><param name="X" type="float"/>)"
      R"(<param name="Y" type="float"/><param name="Z" type="float"/></accessor>)"
      R"(</technique_common></source><vertices id="v"><input semantic="POSITION" source="#p"/>)"
      R"(</vertices><triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/>)"
      R"(<p>0 1 2</p></triangles></mesh></geometry></library_geometries>)"
      R"(<library_visual_scenes><visual_scene id="s"><node><instance_geometry url="#g"/>)"
      R"(</node></visual_scene></library_visual_scenes><scene><instance_visual_scene )"
      R"(url="#s"/></scene></COLLADA>)");
  for (bool as_object : {false, true}) {
    SCOPED_TRACE(as_object ? "mesh object" : "model file");
    rvr::Expected<rvr::Scene> r =
        as_object ? rvr::parse_scene(R"({"camera":{"eye":[3,3,3],"target":[0,0,0],"up":[0,1,0]},)"
                                     R"("objects":[{"type":"mesh","file":"crash.dae"}]})",
                                     "inline.json", fs::path(p).parent_path().string())
                  : rvr::load_scene(p);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().kind, rvr::ErrorKind::BadInput);
    EXPECT_NE(r.error().message.find("crash.dae"), std::string::npos) << r.error().message;
    // (signal 11 here; under ASan its report ends the child with exit status 1)
    EXPECT_NE(r.error().message.find(": the importer crashed ("), std::string::npos)
        << r.error().message;
  }
}

TEST_F(ModelFiles, ModelContentIsRecognisedWhateverTheExtension) {
  // A PLY named .dat: Assimp picks its reader by content, and so does rvr.
  std::string p = write("scan.dat", corpus::blender_ply_cube(10, 10, 10));
  auto s = rvr::load_scene(p);
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(s->triangle_count(), 12u);
}

// The normals of the cube written by corpus::ascii_stl_cube_with_stated_normals as rvr should
// shade it: each facet whose stated normal contradicts the winding with the cube's outward
// normal, the others with their stated normal, normalised.
void expect_stl_normals_honest(const rvr::TriangleMesh& mesh) {
  const auto tris = corpus::cube_triangles();
  ASSERT_EQ(mesh.triangles.size(), tris.size());
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  // Each loaded triangle is the cube triangle with the same corners, in the same order.
  size_t matched = 0;
  for (const glm::uvec3& lt : mesh.triangles) {
    for (size_t t = 0; t < tris.size(); ++t) {
      bool same = true;
      for (int k = 0; k < 3; ++k) {
        auto c = corpus::cube_vertex(tris[t][k]);
        same = same && mesh.positions[lt[k]] == glm::vec3(c[0], c[1], c[2]);
      }
      if (!same) continue;
      ++matched;
      SCOPED_TRACE("facet " + std::to_string(t));
      auto out = corpus::cube_outward_normal(tris[t]);
      auto stated = corpus::stated_facet_normal(t);
      glm::vec3 want = corpus::facet_normal_kind(t) == 'k'
                           ? glm::normalize(glm::vec3(stated[0], stated[1], stated[2]))
                           : glm::vec3(out[0], out[1], out[2]);
      for (int k = 0; k < 3; ++k) expect_near3(mesh.normals[lt[k]], want, 1e-6f);
    }
  }
  EXPECT_EQ(matched, tris.size());
}

// STL facet normals against the winding: facets 0-2 state a tilted outward normal reversed, 3-4 a
// zero normal, the rest an outward normal tilted by 0.25 (corpus::stated_facet_normal). Assimp
// hands every stated normal on as it is (the oracle, checked first); rvr shades the five that
// contradict the winding with their geometric normal (e1 x e2 of the file's vertices, the
// cube's outward normal) and keeps the seven that agree, normalised; the warning counts both
// kinds. A zero-area facet is dropped, with its own warning.
TEST_F(ModelFiles, StlFacetNormalsThatContradictTheWindingAreReplaced) {
  std::string p = write("stated.stl", corpus::ascii_stl_cube_with_stated_normals(true));
  const auto tris = corpus::cube_triangles();
  {
    Assimp::Importer importer;
    const aiScene* ai = importer.ReadFile(p, 0);
    ASSERT_TRUE(ai && ai->mNumMeshes == 1 && ai->mMeshes[0]->mNormals);
    ASSERT_EQ(ai->mMeshes[0]->mNumFaces, tris.size() + 1);
    for (size_t t = 0; t < tris.size(); ++t) {
      auto want = corpus::stated_facet_normal(t);
      const aiVector3D& got = ai->mMeshes[0]->mNormals[ai->mMeshes[0]->mFaces[t].mIndices[0]];
      expect_near3({got.x, got.y, got.z}, {want[0], want[1], want[2]}, 0.0f);
    }
  }
  rvr::Expected<rvr::Scene> loaded = rvr::load_scene(p);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  const rvr::Scene& s = *loaded;
  ASSERT_EQ(s.objects.size(), 1u);
  const rvr::TriangleMesh& mesh = s.objects[0].mesh;
  ASSERT_EQ(mesh.triangles.size(), tris.size());
  expect_stl_normals_honest(mesh);
  std::string all;
  for (const std::string& w : s.warnings) all += w + "\n";
  EXPECT_NE(all.find(p + ": 5 facets have normals that contradict the winding (3 pointing "
                         "against it, 2 zero or non-finite)"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find(p + ": dropped 1 degenerate triangle"), std::string::npos) << all;
}

// The same STL file as a mesh object of a scene file: with `smooth: true` (the file's normals
// kept) the facets that contradict the winding are shaded with their geometric normal and the
// scene carries the warning, naming the object; with `smooth: false` no stated normal is used,
// so there is nothing to replace and no such warning.
TEST_F(ModelFiles, StlFacetNormalsAreCheckedAsAMeshObjectOfASceneFile) {
  write("stated.stl", corpus::ascii_stl_cube_with_stated_normals(false));
  auto scene_with = [&](const char* smooth) {
    return rvr::parse_scene(R"({"camera":{"eye":[3,3,3],"target":[0,0,0],"up":[0,1,0]},)"
                            R"("objects":[{"name":"part","type":"mesh","file":"stated.stl",)"
                            R"("smooth":)" +
                                std::string(smooth) + "}]}",
                            "t.json", dir_.string());
  };
  rvr::Expected<rvr::Scene> smooth = scene_with("true");
  ASSERT_TRUE(smooth.ok()) << smooth.error().message;
  ASSERT_EQ(smooth->objects.size(), 1u);
  expect_stl_normals_honest(smooth->objects[0].mesh);
  ASSERT_EQ(smooth->warnings.size(), 1u);
  EXPECT_EQ(smooth->warnings[0],
            "objects[0] (part): 5 facets have normals that contradict the winding (3 pointing "
            "against it, 2 zero or non-finite): shaded with the facets' geometric normals");
  rvr::Expected<rvr::Scene> flat = scene_with("false");
  ASSERT_TRUE(flat.ok()) << flat.error().message;
  EXPECT_TRUE(flat->objects.at(0).mesh.normals.empty());
  EXPECT_TRUE(flat->warnings.empty()) << flat->warnings.front();
}

// A file with a camera (and a light) and no geometry: Assimp's Collada reader makes a
// placeholder skeleton mesh of its nodes and flags the scene incomplete (the oracle: Assimp on
// its own returns triangles); its glTF reader makes no mesh. Either is refused as bad input
// saying what the file holds, as a model file and as a mesh object of a scene file.
TEST_F(ModelFiles, FileWithOnlyCamerasOrLightsHasNoTriangles) {
  struct Case {
    std::string name, text, holds;
    bool placeholder;
  };
  for (const Case& c :
       {Case{"camera.dae", corpus::dae_camera_only(false), "1 camera", true},
        Case{"lit.dae", corpus::dae_camera_only(true), "1 camera and 1 light", true},
        Case{"camera.gltf", corpus::gltf_camera_only(), "1 camera", false}}) {
    SCOPED_TRACE(c.name);
    std::string p = write(c.name, c.text);
    {
      Assimp::Importer importer;
      const aiScene* ai = importer.ReadFile(p, aiProcess_Triangulate);
      ASSERT_TRUE(ai) << importer.GetErrorString();
      EXPECT_TRUE(ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE);
      EXPECT_EQ(assimp_triangles(p) > 0, c.placeholder);
    }
    auto r = rvr::load_scene(p);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().kind, rvr::ErrorKind::BadInput);
    EXPECT_EQ(r.error().message,
              p + ": objects: no triangles (the file holds only " + c.holds + ")");
    for (const char* material : {"", R"(, "material": "from_file")"}) {
      auto o = rvr::parse_scene(R"({"camera":{"eye":[3,3,3],"target":[0,0,0],"up":[0,1,0]},)"
                                R"("objects":[{"type":"mesh","file":")" +
                                    c.name + "\"" + material + "}]}",
                                "t.json", dir_.string());
      ASSERT_FALSE(o.ok()) << material;
      EXPECT_EQ(o.error().message, "t.json: objects[0].file: '" + c.name +
                                       "': no triangles (the file holds only " + c.holds + ")");
    }
  }
}

}  // namespace
