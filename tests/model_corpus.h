// Model files as real exporters write them, quirks included, written by the tests themselves
// (nothing binary in the repository): the unit cube [0,1]^3 in most formats, with a known colour
// where the format has one. Shared by test_model_import (the loader against Assimp as the
// oracle) and test_model_compare (rvr compare on bare model files).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace rvr::test {

namespace corpus {

// The unit cube: vertex v at ((v >> 2) & 1, (v >> 1) & 1, v & 1); quads counter-clockwise seen
// from outside (their normals point out).
inline std::array<float, 3> cube_vertex(int v) {
  return {float((v >> 2) & 1), float((v >> 1) & 1), float(v & 1)};
}
inline const std::array<std::array<int, 4>, 6>& cube_quads() {
  static const std::array<std::array<int, 4>, 6> q = {
      {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}}};
  return q;
}
// Each quad as the two triangles (a, b, c) and (a, c, d).
inline std::vector<std::array<int, 3>> cube_triangles() {
  std::vector<std::array<int, 3>> t;
  for (const auto& q : cube_quads()) {
    t.push_back({q[0], q[1], q[2]});
    t.push_back({q[0], q[2], q[3]});
  }
  return t;
}

inline std::string num(float x) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", double(x));
  return b;
}

inline void write_file(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

// A fixture with a fresh folder of its own per test (named after the test and the process, so
// parallel ctest runs never share one) where the test writes its model files.
class ModelDirTest : public ::testing::Test {
 protected:
  virtual const char* folder_prefix() const = 0;
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           (folder_prefix() +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
            std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& bytes) {
    write_file(dir_ / name, bytes);
    return (dir_ / name).string();
  }

  std::filesystem::path dir_;
};

template <class T>
void put(std::string& s, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  s.append(b, sizeof(T));
}

// OBJ text of the cube as quads, `usemtl` first when `material` is not empty.
inline std::string obj_cube(const std::string& header, const std::string& material,
                            const char* eol = "\n") {
  std::string s = header;
  for (int v = 0; v < 8; ++v) {
    auto p = cube_vertex(v);
    s += "v " + num(p[0]) + " " + num(p[1]) + " " + num(p[2]) + eol;
  }
  if (!material.empty()) s += "usemtl " + material + eol;
  for (const auto& q : cube_quads()) {
    s += "f";
    for (int i : q) s.append(1, ' ').append(std::to_string(i + 1));
    s += eol;
  }
  return s;
}

// The PLY header Blender 2.7x writes: a free-text "Created by Blender" line after `format`
// with no `comment` keyword; vertex colours.
inline std::string blender_ply_cube(int r, int g, int b) {
  std::string s =
      "ply\nformat ascii 1.0\nCreated by Blender 2.79 (sub 0) - www.blender.org, source file: "
      "'cube.blend'\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 6\n"
      "property list uchar uint vertex_indices\nend_header\n";
  for (int v = 0; v < 8; ++v) {
    auto p = cube_vertex(v);
    s += num(p[0]) + " " + num(p[1]) + " " + num(p[2]) + " " + std::to_string(r) + " " +
         std::to_string(g) + " " + std::to_string(b) + "\n";
  }
  for (const auto& q : cube_quads()) {
    s += "4";
    for (int i : q) s.append(1, ' ').append(std::to_string(i));
    s += "\n";
  }
  return s;
}

// Binary STL whose 80-byte header starts with "solid" (SolidWorks and others do this, which
// trips readers that decide ASCII by the first word).
inline std::string binary_stl_cube() {
  std::string s = "solid exported as binary by a CAD package";
  s.resize(80, ' ');
  auto tris = cube_triangles();
  put<uint32_t>(s, uint32_t(tris.size()));
  for (const auto& t : tris) {
    for (int k = 0; k < 3; ++k) put<float>(s, 0.0f);  // normal left to the reader
    for (int i : t)
      for (float c : cube_vertex(i)) put<float>(s, c);
    put<uint16_t>(s, 0);
  }
  return s;
}

inline std::string ascii_stl_cube() {
  std::string s = "solid cube\n";
  for (const auto& t : cube_triangles()) {
    s += "  facet normal 0 0 0\n    outer loop\n";
    for (int i : t) {
      auto p = cube_vertex(i);
      s += "      vertex " + num(p[0]) + " " + num(p[1]) + " " + num(p[2]) + "\n";
    }
    s += "    endloop\n  endfacet\n";
  }
  return s + "endsolid cube\n";
}

inline std::string off_cube_with_comments() {
  std::string s = "OFF\n# written by a mesh tool\n8 6 0\n";
  for (int v = 0; v < 8; ++v) {
    auto p = cube_vertex(v);
    s += num(p[0]) + " " + num(p[1]) + " " + num(p[2]) + "\n";
  }
  for (const auto& q : cube_quads()) {
    s += "4";
    for (int i : q) s.append(1, ' ').append(std::to_string(i));
    s += "\n";
  }
  return s;
}

// glTF 2.0 of the cube as triangles: baseColorFactor, emissiveFactor, optionally a
// perspective camera and a KHR_lights_punctual point light on nodes of their own. The buffer
// is embedded as base64 (.gltf) or is the GLB's BIN chunk.
struct GltfExtras {
  std::array<float, 4> base_colour{0.1f, 0.2f, 0.9f, 1.0f};
  std::array<float, 3> emissive{0.0f, 0.0f, 0.0f};
  bool camera = false;
  std::array<float, 3> camera_at{0.5f, 0.5f, 4.0f};  // looking down -z, y up
  float yfov = 0.7f;
  float aspect = 1.5f;
  bool light = false;
  std::array<float, 3> light_at{2.0f, 3.0f, 2.5f};
  std::array<float, 3> light_colour{1.0f, 0.9f, 0.8f};
  float light_intensity = 20.0f;
  bool texture = false;  // a baseColorTexture (an image file that need not exist)
};

inline std::string gltf_buffer() {
  std::string b;
  for (int v = 0; v < 8; ++v)
    for (float c : cube_vertex(v)) put<float>(b, c);
  for (const auto& t : cube_triangles())
    for (int i : t) put<uint16_t>(b, uint16_t(i));
  return b;  // 96 bytes of positions, 72 of indices
}

inline std::string base64(const std::string& in) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    uint32_t n = uint8_t(in[i]) << 16 | uint8_t(in[i + 1]) << 8 | uint8_t(in[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += k[(n >> s) & 63];
  }
  if (i + 1 == in.size()) {
    uint32_t n = uint8_t(in[i]) << 16;
    out += std::string{k[(n >> 18) & 63], k[(n >> 12) & 63], '=', '='};
  } else if (i + 2 == in.size()) {
    uint32_t n = uint8_t(in[i]) << 16 | uint8_t(in[i + 1]) << 8;
    out += std::string{k[(n >> 18) & 63], k[(n >> 12) & 63], k[(n >> 6) & 63], '='};
  }
  return out;
}

inline std::string gltf_json(const GltfExtras& e, bool glb) {
  auto vec = [](const auto& a) {
    std::string s = "[";
    for (size_t i = 0; i < a.size(); ++i) s.append(i ? "," : "").append(num(a[i]));
    return s + "]";
  };
  std::string buffer = gltf_buffer();
  std::string nodes = R"({"name":"cube","mesh":0})", scene_nodes = "0", extensions;
  if (e.camera) {
    nodes += R"(,{"name":"cam","camera":0,"translation":)" + vec(e.camera_at) + "}";
    scene_nodes += ",1";
  }
  if (e.light) {
    nodes += R"(,{"name":"lamp","translation":)" + vec(e.light_at) +
             R"(,"extensions":{"KHR_lights_punctual":{"light":0}}})";
    scene_nodes += e.camera ? ",2" : ",1";
    extensions = R"("extensionsUsed":["KHR_lights_punctual"],"extensions":{"KHR_lights_punctual":)"
                 R"({"lights":[{"type":"point","color":)" +
                 vec(e.light_colour) + R"(,"intensity":)" + num(e.light_intensity) + "}]}},";
  }
  std::string material = R"({"name":"paint","pbrMetallicRoughness":{"baseColorFactor":)" +
                         vec(e.base_colour) + R"(,"metallicFactor":0)" +
                         (e.texture ? R"(,"baseColorTexture":{"index":0})" : "") +
                         R"(},"emissiveFactor":)" + vec(e.emissive) + "}";
  std::string s = R"({"asset":{"version":"2.0","generator":"rvr test corpus"},)" + extensions +
                  R"("scene":0,"scenes":[{"nodes":[)" + scene_nodes + "]}],\"nodes\":[" + nodes +
                  "],";
  s += R"("meshes":[{"name":"cube","primitives":[{"attributes":{"POSITION":0},"indices":1,)"
       R"("material":0,"mode":4}]}],)";
  s += "\"materials\":[" + material + "],";
  if (e.texture) {
    s += R"("textures":[{"source":0}],"images":[{"uri":"paint.png"}],)";
  }
  if (e.camera) {
    s += R"("cameras":[{"type":"perspective","perspective":{"yfov":)" + num(e.yfov) +
         R"(,"aspectRatio":)" + num(e.aspect) + R"(,"znear":0.1,"zfar":100}}],)";
  }
  s += R"("accessors":[{"bufferView":0,"componentType":5126,"count":8,"type":"VEC3",)"
       R"("min":[0,0,0],"max":[1,1,1]},{"bufferView":1,"componentType":5123,"count":36,)"
       R"("type":"SCALAR"}],)";
  s += R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":96},)"
       R"({"buffer":0,"byteOffset":96,"byteLength":72}],)";
  s += "\"buffers\":[{\"byteLength\":" + std::to_string(buffer.size());
  if (!glb) s += ",\"uri\":\"data:application/octet-stream;base64," + base64(buffer) + "\"";
  return s + "}]}";
}

inline std::string glb(const GltfExtras& e) {
  std::string json = gltf_json(e, true), bin = gltf_buffer();
  while (json.size() % 4) json += ' ';
  while (bin.size() % 4) bin += '\0';
  std::string s = "glTF";
  put<uint32_t>(s, 2);
  put<uint32_t>(s, uint32_t(12 + 8 + json.size() + 8 + bin.size()));
  put<uint32_t>(s, uint32_t(json.size()));
  s += "JSON";
  s += json;
  put<uint32_t>(s, uint32_t(bin.size()));
  s += std::string("BIN\0", 4);
  s += bin;
  return s;
}

// 3DS (3D Studio, whose z is up) of the cube with one material of diffuse colour (r, g, b)
// bytes.
inline std::string chunk3ds(uint16_t id, const std::string& body) {
  std::string s;
  put<uint16_t>(s, id);
  put<uint32_t>(s, uint32_t(6 + body.size()));
  return s + body;
}

// `size`: the box's extent along the file's x, y and z (the unit cube by default).
inline std::string cube_3ds(uint8_t r, uint8_t g, uint8_t b,
                            const std::array<float, 3>& size = {1.0f, 1.0f, 1.0f}) {
  std::string rgb;
  put<uint8_t>(rgb, r);
  put<uint8_t>(rgb, g);
  put<uint8_t>(rgb, b);
  std::string material = chunk3ds(0xAFFF, chunk3ds(0xA000, std::string("paint\0", 6)) +
                                              chunk3ds(0xA020, chunk3ds(0x0011, rgb)));
  std::string verts;
  put<uint16_t>(verts, 8);
  for (int v = 0; v < 8; ++v) {
    auto p = cube_vertex(v);
    for (int k = 0; k < 3; ++k) put<float>(verts, p[k] * size[k]);
  }
  auto tris = cube_triangles();
  std::string faces, group = std::string("paint\0", 6);
  put<uint16_t>(faces, uint16_t(tris.size()));
  put<uint16_t>(group, uint16_t(tris.size()));
  for (size_t f = 0; f < tris.size(); ++f) {
    for (int i : tris[f]) put<uint16_t>(faces, uint16_t(i));
    put<uint16_t>(faces, 0);
    put<uint16_t>(group, uint16_t(f));
  }
  std::string mesh =
      chunk3ds(0x4100, chunk3ds(0x4110, verts) + chunk3ds(0x4120, faces + chunk3ds(0x4130, group)));
  std::string object = chunk3ds(0x4000, std::string("cube\0", 5) + mesh);
  std::string version;
  put<uint32_t>(version, 3);
  std::string editor = chunk3ds(0x3D3D, chunk3ds(0x3D3E, version) + material + object);
  return chunk3ds(0x4D4D, chunk3ds(0x0002, version) + editor);
}

// Collada 1.4 of the cube (a <polylist> of quads) with a material's diffuse colour, a
// camera and a point light with constant attenuation (the Collada default: no falloff).
struct DaeExtras {
  std::array<float, 3> diffuse{0.9f, 0.6f, 0.1f};
  std::array<float, 3> camera_at{0.5f, 0.5f, 5.0f};  // looking down -z
  float yfov_deg = 40.0f;
  float aspect = 1.5f;
  std::array<float, 3> light_at{3.0f, 4.0f, 5.0f};
  std::array<float, 3> light_colour{1.0f, 1.0f, 1.0f};
};

inline std::string dae_cube(const DaeExtras& e) {
  auto three = [](const std::array<float, 3>& a) {
    return num(a[0]) + " " + num(a[1]) + " " + num(a[2]);
  };
  std::string positions, indices;
  for (int v = 0; v < 8; ++v) {
    auto p = cube_vertex(v);
    positions += three(p) + " ";
  }
  for (const auto& q : cube_quads())
    for (int i : q) indices += std::to_string(i) + " ";
  return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><up_axis>Y_UP</up_axis></asset>
  <library_cameras><camera id="cam" name="cam"><optics><technique_common><perspective>
    <yfov>)" +
         num(e.yfov_deg) + "</yfov><aspect_ratio>" + num(e.aspect) +
         R"(</aspect_ratio><znear>0.1</znear><zfar>100</zfar>
  </perspective></technique_common></optics></camera></library_cameras>
  <library_lights><light id="lamp" name="lamp"><technique_common><point>
    <color>)" +
         three(e.light_colour) +
         R"(</color><constant_attenuation>1</constant_attenuation>
    <linear_attenuation>0</linear_attenuation><quadratic_attenuation>0</quadratic_attenuation>
  </point></technique_common></light></library_lights>
  <library_effects><effect id="paint-fx"><profile_COMMON><technique sid="common"><phong>
    <diffuse><color>)" +
         three(e.diffuse) +
         R"( 1</color></diffuse>
  </phong></technique></profile_COMMON></effect></library_effects>
  <library_materials><material id="paint" name="paint"><instance_effect url="#paint-fx"/></material></library_materials>
  <library_geometries><geometry id="cube-mesh" name="cube"><mesh>
    <source id="cube-pos"><float_array id="cube-pos-array" count="24">)" +
         positions + R"(</float_array>
      <technique_common><accessor source="#cube-pos-array" count="8" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <vertices id="cube-verts"><input semantic="POSITION" source="#cube-pos"/></vertices>
    <polylist material="paint" count="6"><input semantic="VERTEX" source="#cube-verts" offset="0"/>
      <vcount>4 4 4 4 4 4</vcount><p>)" +
         indices + R"(</p></polylist>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="scene">
    <node id="cube-node" name="cube"><instance_geometry url="#cube-mesh"><bind_material><technique_common>
      <instance_material symbol="paint" target="#paint"/></technique_common></bind_material></instance_geometry></node>
    <node id="cam-node" name="cam-node"><translate>)" +
         three(e.camera_at) + R"(</translate><instance_camera url="#cam"/></node>
    <node id="lamp-node" name="lamp-node"><translate>)" +
         three(e.light_at) + R"(</translate><instance_light url="#lamp"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
}

// The facet normal an ASCII STL file states for cube triangle t (cube_triangles()), by
// facet_normal_kind(t): 'k' outward but tilted (0.25 added on the axis after the normal's own:
// agrees with the winding, and differs from the geometric normal so that keeping it shows),
// 'r' that tilted normal reversed (contradicts the winding; reversing it again is not the
// geometric normal), 'z' zero (contradicts it too).
inline char facet_normal_kind(size_t t) {
  return t < 3 ? 'r' : t < 5 ? 'z' : 'k';
}
inline std::array<float, 3> cube_outward_normal(const std::array<int, 3>& t) {
  auto a = cube_vertex(t[0]), b = cube_vertex(t[1]), c = cube_vertex(t[2]);
  std::array<float, 3> e1{b[0] - a[0], b[1] - a[1], b[2] - a[2]},
      e2{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
          e1[0] * e2[1] - e1[1] * e2[0]};  // unit length: the cube's edges are 1 and square
}
inline std::array<float, 3> stated_facet_normal(size_t t) {
  const std::array<float, 3> n = cube_outward_normal(cube_triangles()[t]);
  std::array<float, 3> tilted = n;
  for (int k = 0; k < 3; ++k) {
    if (n[k] != 0.0f) {
      tilted[(k + 1) % 3] += 0.25f;
      break;
    }
  }
  switch (facet_normal_kind(t)) {
    case 'r':
      return {-tilted[0], -tilted[1], -tilted[2]};
    case 'z':
      return {0.0f, 0.0f, 0.0f};
    default:
      return tilted;
  }
}
// An ASCII STL of the cube with those facet normals, and (when `degenerate_facet`) a 13th
// facet of zero area (its three vertices on one line).
inline std::string ascii_stl_cube_with_stated_normals(bool degenerate_facet) {
  std::string s = "solid stated\n";
  auto tris = cube_triangles();
  for (size_t t = 0; t < tris.size(); ++t) {
    auto n = stated_facet_normal(t);
    s += "  facet normal " + num(n[0]) + " " + num(n[1]) + " " + num(n[2]) + "\n    outer loop\n";
    for (int i : tris[t]) {
      auto p = cube_vertex(i);
      s += "      vertex " + num(p[0]) + " " + num(p[1]) + " " + num(p[2]) + "\n";
    }
    s += "    endloop\n  endfacet\n";
  }
  if (degenerate_facet) {
    s += "  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 0.5 0 0\n"
         "      vertex 1 0 0\n    endloop\n  endfacet\n";
  }
  return s + "endsolid stated\n";
}

// ASCII FBX 7.4, Y up, of one triangle (0, 0, 0), (0, 0, 2s), (0, s, 0) (facing -x) and a camera
// "shot" at (-5s, 0.5s, s) looking along +x (Assimp's FBX camera convention: its node's +x),
// 40 degrees across (FieldOfView; without it Assimp reads 1 degree), with near plane 0.1s and
// far plane 100s, all in file units. `unit_scale_factor`: GlobalSettings' UnitScaleFactor
// (centimetres per file unit) as written, no such line when empty (FBX's default: 1,
// centimetres).
inline std::string fbx_triangle_and_camera(float s, const std::string& unit_scale_factor) {
  std::string unit = unit_scale_factor.empty() ? ""
                                               : "\t\tP: \"UnitScaleFactor\", \"double\", "
                                                 "\"Number\", \"\"," +
                                                     unit_scale_factor + "\n";
  return R"FBX(; FBX 7.4.0 project file
FBXHeaderExtension:  {
	FBXHeaderVersion: 1003
	FBXVersion: 7400
	Creator: "rvr test"
}
GlobalSettings:  {
	Version: 1000
	Properties70:  {
		P: "UpAxis", "int", "Integer", "",1
		P: "UpAxisSign", "int", "Integer", "",1
)FBX" + unit +
         R"FBX(	}
}
Objects:  {
	Geometry: 1000, "Geometry::tri", "Mesh" {
		Vertices: *9 {
			a: 0,0,0,0,0,)FBX" +
         num(2 * s) + ",0," + num(s) + R"FBX(,0
		}
		PolygonVertexIndex: *3 {
			a: 0,1,-3
		}
		GeometryVersion: 124
	}
	Model: 2000, "Model::tri", "Mesh" {
		Version: 232
	}
	NodeAttribute: 5000, "NodeAttribute::shot", "Camera" {
		TypeFlags: "Camera"
		Properties70:  {
			P: "FieldOfView", "FieldOfView", "", "A",40
			P: "NearPlane", "double", "Number", "",)FBX" +
         num(0.1f * s) + R"FBX(
			P: "FarPlane", "double", "Number", "",)FBX" +
         num(100.0f * s) + R"FBX(
		}
	}
	Model: 6000, "Model::shot", "Camera" {
		Version: 232
		Properties70:  {
			P: "Lcl Translation", "Lcl Translation", "", "A",)FBX" +
         num(-5.0f * s) + "," + num(0.5f * s) + "," + num(s) + R"FBX(
		}
	}
}
Connections:  {
	C: "OO",2000,0
	C: "OO",1000,2000
	C: "OO",6000,0
	C: "OO",5000,6000
}
)FBX";
}

// Collada 1.4 with a camera and no geometry (`light`: a point light too); Assimp's Collada
// reader puts a placeholder skeleton mesh around the nodes of such a file.
inline std::string dae_camera_only(bool light) {
  std::string lights =
      light ? R"(<library_lights><light id="lamp" name="lamp"><technique_common><point>
    <color>1 1 1</color></point></technique_common></light></library_lights>)"
            : "";
  std::string lamp_node =
      light ? R"(<node id="lamp-node" name="lamp-node"><translate>3 4 5</translate>
      <instance_light url="#lamp"/></node>)"
            : "";
  return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><up_axis>Y_UP</up_axis></asset>
  <library_cameras><camera id="cam" name="cam"><optics><technique_common><perspective>
    <yfov>40</yfov><aspect_ratio>1.5</aspect_ratio><znear>0.1</znear><zfar>100</zfar>
  </perspective></technique_common></optics></camera></library_cameras>
  )" + lights +
         R"(
  <library_visual_scenes><visual_scene id="scene">
    <node id="cam-node" name="cam-node"><translate>0.5 0.5 5</translate>
      <instance_camera url="#cam"/></node>
    )" + lamp_node +
         R"(
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
}

// glTF 2 with one perspective camera on one node and no meshes.
inline std::string gltf_camera_only() {
  return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"camera": 0, "translation": [0.5, 0.5, 5]}],
  "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1, "zfar": 100}}]})";
}

// Every model file of the corpus as a bare model file would come (name, bytes), each once,
// and the files they need beside them (`paint.mtl`); CorpusFile::model says which is which.
struct CorpusFile {
  std::string name, bytes;
  bool model = true;
};
inline std::vector<CorpusFile> every_file() {
  GltfExtras lit;
  lit.camera = true;
  lit.light = true;
  GltfExtras textured;
  textured.texture = true;  // on a mesh without texture coordinates: a warning
  return {{"paint.mtl", "newmtl paint\nKd 0.9 0.15 0.1\nKs 0.5 0.5 0.5\nNs 40\n", false},
          {"cube.obj", obj_cube("mtllib paint.mtl\n", "paint")},
          {"bare.obj", obj_cube("", "")},
          {"cube.ply", blender_ply_cube(250, 250, 250)},
          {"binary.stl", binary_stl_cube()},
          {"ascii.stl", ascii_stl_cube()},
          {"stated.stl", ascii_stl_cube_with_stated_normals(true)},
          {"cube.off", off_cube_with_comments()},
          {"cube.gltf", gltf_json(GltfExtras{}, false)},
          {"textured.gltf", gltf_json(textured, false)},
          {"lit.glb", glb(lit)},
          {"cube.3ds", cube_3ds(255, 255, 255)},
          {"tall.3ds", cube_3ds(200, 120, 40, {1.0f, 2.0f, 3.0f})},
          {"cube.dae", dae_cube(DaeExtras{})},
          {"cm.fbx", fbx_triangle_and_camera(100.0f, "")}};
}

}  // namespace corpus

}  // namespace rvr::test
