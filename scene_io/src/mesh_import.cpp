// Reading a mesh file through Assimp, hardened (see mesh_import.h).
#include "mesh_import.h"

#include <assimp/DefaultIOSystem.h>
#include <assimp/material.h>
#include <assimp/metadata.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <glm/glm.hpp>
#include <initializer_list>
#include <iterator>
#include <map>
#include <memory>
#include <new>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "allocation_budget.h"
#include "isolated_call.h"
#include "mesh_repair.h"
#include "model_wire.h"
#include "scene_json_errors.h"
#include "scene_json_parse.h"

namespace rvr::scene_load {
namespace {

namespace fs = std::filesystem;

constexpr size_t kMaxMeshTriangles = 50'000'000;

// What Assimp's readers may hold while reading a file: kMemoryBase plus kMemoryPerByte times
// the bytes of every file they open (the model and its .mtl, .bin, ...; a file sniffed and then
// read counts twice). Measured (Assimp 5.2.5, a 180,000-triangle grid in each format): peaks of
// 0.9 (glb) to 4.4 (OBJ) bytes per byte opened, plus up to 17 MB whatever the size (OBJ's line
// buffers), so 64 leaves a margin of more than 10x. A file whose header declares more data
// than it holds asks for more, and is refused (see allocation_budget.h).
constexpr uint64_t kMemoryBase = uint64_t(256) << 20;
constexpr uint64_t kMemoryPerByte = 64;

// The CPU time of the isolated import (isolated_call.h): kCpuSeconds plus kCpuSecondsPerByte
// times the bytes of every file opened. Assimp reads OBJ, the slowest here, at about 50 MB/s
// (under ASan about 10) and post-processing takes about as long again, so 1 s per MiB is a
// margin of 5x or more; a small file that takes 3 s of CPU is a reader spinning (and a
// fuzzing run, which loads each input twice, must stay under its 10 s per input).
constexpr double kCpuSeconds = 3.0;
constexpr double kCpuSecondsPerByte = 1.0 / double(1 << 20);

std::string file_status(const fs::path& p) {
  std::error_code ec;
  fs::file_status st = fs::status(p, ec);
  if (ec) return ec.message();
  if (!fs::exists(st)) return std::strerror(ENOENT);
  if (fs::is_directory(st)) return std::strerror(EISDIR);
  if (!fs::is_regular_file(st)) return "not a regular file";
  std::FILE* f = std::fopen(p.c_str(), "rb");
  if (!f) return std::strerror(errno);
  std::fclose(f);
  return {};
}

// Assimp's file access, with a budget: some of its readers loop forever on broken files (the
// PLY reader seeks back and forth at the end of a header with no `end_header` line; found by
// fuzzing, tests/fuzz/regressions/mesh). Every read, seek and tell counts; past the budget
// the stream throws, which Assimp turns into an import error. A healthy import reads each
// file a few times over in large blocks, far below the budget.
class BudgetIOSystem : public Assimp::IOSystem {
 public:
  struct Budget {
    uint64_t operations = 0;
    uint64_t bytes_opened = 0;
    uint64_t bytes_requested = 0;
    // Reads may ask for large blocks (Assimp's line reader takes 1 MB at a time): at most
    // 64 MiB plus 16 times what was opened.
    void spend_read(size_t bytes) {
      bytes_requested += bytes;
      if (bytes_requested > (uint64_t(64) << 20) + 16 * bytes_opened) {
        throw std::runtime_error("the importer is stuck reading the file (gave up)");
      }
      spend();
    }
    void spend() {
      // 200 thousand operations (about a second of the PLY loop) plus one per 8 bytes opened:
      // Assimp's readers take whole files or megabyte blocks, so a good import stays far
      // below this.
      if (++operations > 200'000 + bytes_opened / 8) {
        throw std::runtime_error("the importer is stuck reading the file (gave up)");
      }
    }
  };

  // Each file opened raises `memory` (if any) by kMemoryPerByte times its size.
  explicit BudgetIOSystem(AllocationBudget* memory = nullptr) : memory_(memory) {}

  void forget_memory() { memory_ = nullptr; }

  bool Exists(const char* file) const override { return base_.Exists(file); }
  char getOsSeparator() const override { return base_.getOsSeparator(); }
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    budget_.spend();
    Assimp::IOStream* inner = base_.Open(file, mode);
    if (!inner) return nullptr;
    budget_.bytes_opened += inner->FileSize();
    if (memory_) memory_->raise(kMemoryPerByte * inner->FileSize());
    extend_cpu_time(kCpuSecondsPerByte * double(inner->FileSize()));
    return new Stream(inner, &budget_);
  }
  void Close(Assimp::IOStream* stream) override { delete stream; }

 private:
  class Stream : public Assimp::IOStream {
   public:
    Stream(Assimp::IOStream* inner, Budget* budget) : inner_(inner), budget_(budget) {}
    ~Stream() override { delete inner_; }
    size_t Read(void* buffer, size_t size, size_t count) override {
      budget_->spend_read(size * count);
      return inner_->Read(buffer, size, count);
    }
    size_t Write(const void* buffer, size_t size, size_t count) override {
      budget_->spend();
      return inner_->Write(buffer, size, count);
    }
    aiReturn Seek(size_t offset, aiOrigin origin) override {
      budget_->spend();
      return inner_->Seek(offset, origin);
    }
    size_t Tell() const override {
      budget_->spend();
      return inner_->Tell();
    }
    size_t FileSize() const override { return inner_->FileSize(); }
    void Flush() override { inner_->Flush(); }

   private:
    Assimp::IOStream* inner_;
    Budget* budget_;
  };

  Assimp::DefaultIOSystem base_;
  mutable Budget budget_;
  AllocationBudget* memory_;
};

// Assimp's PLY reader loops forever or reads out of bounds on some malformed headers (found by
// fuzzing; tests/fuzz/regressions/mesh), so PLY headers are checked here first: the grammar,
// the types, and (binary files) that the body is at least as long as the header says.
// Files that start with "ply" are checked whatever their extension: Assimp picks readers by
// content when the extension is unknown.
std::string ply_header_problem(const fs::path& p, bool named_ply) {
  std::FILE* f = std::fopen(p.c_str(), "rb");
  if (!f) return std::strerror(errno);
  std::string text(1 << 20, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), f));
  std::fseek(f, 0, SEEK_END);
  long file_size = std::ftell(f);
  std::fclose(f);
  if (!named_ply && text.compare(0, 3, "ply") != 0) return {};

  static const std::map<std::string, uint64_t> kTypes = {
      {"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},  {"short", 2}, {"ushort", 2},
      {"int16", 2}, {"uint16", 2},  {"int", 4},    {"uint", 4},   {"int32", 4}, {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  size_t pos = 0, line_no = 0;
  bool binary = false, have_format = false, in_element = false;
  uint64_t body_min = 0, element_count = 0;
  while (true) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) return "PLY header has no end_header line";
    std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::vector<std::string> w;
    for (size_t i = 0; i < line.size();) {
      size_t j = line.find_first_of(" \t", i);
      if (j == std::string::npos) j = line.size();
      if (j > i) w.push_back(line.substr(i, j - i));
      i = j + 1;
    }
    auto bad = [&](const char* what) {
      return fmt::format("PLY header line {}: {}", line_no, what);
    };
    if (line_no == 1) {
      if (w.size() != 1 || w[0] != "ply") return bad("the file does not start with 'ply'");
      continue;
    }
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    // Assimp skips header lines it does not know, and exporters write them: Blender puts a
    // free-text "Created by Blender ..." line after `format` without the `comment` keyword.
    // Only the lines that shape the body (format, element, property) are checked.
    static const std::set<std::string> kShaping = {"format", "element", "property", "end_header"};
    if (!kShaping.count(w[0])) continue;
    if (w[0] == "end_header") {
      if (w.size() != 1) return bad("text after end_header");
      break;
    }
    if (w[0] == "format") {
      if (have_format || w.size() != 3) return bad("bad format line");
      if (w[1] == "binary_little_endian" || w[1] == "binary_big_endian") {
        binary = true;
      } else if (w[1] != "ascii") {
        return bad("unknown format");
      }
      have_format = true;
    } else if (w[0] == "element") {
      if (w.size() != 3 || w[2].empty() || w[2].size() > 10 ||
          w[2].find_first_not_of("0123456789") != std::string::npos) {
        return bad("an element needs a name and a count");
      }
      element_count = std::stoull(w[2]);
      if (element_count > 0xFFFFFFFFull) return bad("element count too large");
      in_element = true;
    } else if (w[0] == "property") {
      if (!in_element) return bad("property before any element");
      if (w.size() == 5 && w[1] == "list") {
        if (!kTypes.count(w[2]) || !kTypes.count(w[3])) return bad("unknown property type");
        body_min += element_count * kTypes.at(w[2]);
      } else if (w.size() == 3 && kTypes.count(w[1])) {
        body_min += element_count * kTypes.at(w[1]);
      } else {
        return bad("a property needs a known type and a name");
      }
    }
  }
  if (!have_format) return "PLY header has no format line";
  if (binary && file_size >= 0 && uint64_t(file_size) - pos < body_min) {
    return fmt::format("PLY file is truncated: the header asks for at least {} bytes, {} follow",
                       body_min, uint64_t(file_size) - pos);
  }
  return {};
}

// What is wrong with a freshly read (not post-processed) Assimp scene, if anything.
std::string raw_mesh_problem(const aiScene* ai) {
  if (ai->mNumMeshes > 0 && !ai->mMeshes) return "the importer returned no mesh array";
  for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
    const aiMesh* am = ai->mMeshes[m];
    if (!am) return fmt::format("mesh {} is missing", m);
    if (am->mNumFaces > 0 && (!am->mFaces || !am->mVertices)) {
      return fmt::format("mesh {} has faces but no vertices", m);
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices == 0 || !face.mIndices) {
        return fmt::format("face {} of mesh {} has no vertices", f, m);
      }
      for (unsigned k = 0; k < face.mNumIndices; ++k) {
        if (face.mIndices[k] >= am->mNumVertices) {
          return fmt::format("face {} of mesh {} has a vertex index out of range", f, m);
        }
      }
    }
  }
  return {};
}

fs::path resolve(const std::string& file, const std::string& base_dir, const std::string& path) {
  if (file.empty()) fail(path, "must not be empty");
  if (file.find('\0') != std::string::npos) fail(path, "must not contain a NUL character");
  fs::path full = fs::path(file);
  if (full.is_relative()) full = fs::path(base_dir.empty() ? "." : base_dir) / full;
  return full;
}

// Where the JSON of a .gltf file breaks: Assimp's glTF readers refuse a file whose JSON does
// not parse without saying where ("No suitable reader found"). "JSON syntax at line L, column
// C: what" (a truncated file: where its JSON ends), or "" when the JSON parses.
std::string gltf_json_problem(const fs::path& full) {
  struct SyntaxOnly {  // nlohmann's SAX interface, keeping nothing but the first error
    bool null() { return true; }
    bool boolean(bool) { return true; }
    bool number_integer(json::number_integer_t) { return true; }
    bool number_unsigned(json::number_unsigned_t) { return true; }
    bool number_float(json::number_float_t, const json::string_t&) { return true; }
    bool string(json::string_t&) { return true; }
    bool binary(json::binary_t&) { return true; }
    bool start_object(std::size_t) { return true; }
    bool key(json::string_t&) { return true; }
    bool end_object() { return true; }
    bool start_array(std::size_t) { return true; }
    bool end_array() { return true; }
    bool parse_error(std::size_t at, const std::string&, const nlohmann::detail::exception& e) {
      position = at;
      message = e.what();
      return false;
    }
    std::size_t position = 0;
    std::string message;
  };
  std::ifstream in(full, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  SyntaxOnly sax;
  if (json::sax_parse(text, &sax, json::input_format_t::json, true, true) || sax.message.empty()) {
    return {};
  }
  const bool whitespace_only = text.find_first_not_of(" \t\r\n") == std::string::npos;
  bool token_error = false;
  const std::string what = syntax_message(sax.message, whitespace_only, &token_error);
  const size_t last = sax.position == 0 ? 0 : sax.position - 1;
  const size_t at = token_error ? token_start(text, last) : last;
  const auto [line, column] = line_column(text, at);
  const bool at_the_end = text.find_first_not_of(" \t\r\n", at) == std::string::npos;
  return fmt::format("JSON syntax at line {}, column {}{}: {}", line, column,
                     at_the_end ? ", where the file ends" : "", what);
}

[[noreturn]] void import_failed(const Assimp::Importer& importer, const std::string& file,
                                const std::string& path) {
  std::string reason = importer.GetErrorString();
  std::replace(reason.begin(), reason.end(), '\n', ' ');
  fail(path, "cannot read " + quote_path(file) + ": " +
                 (reason.empty() ? "the importer gave no reason" : reason));
}

// Reads the file with the pre-checks, validation only, and checks what the reader made.
// Assimp's readers can make broken data from broken files (faces with no indices, indices past
// the vertices) and its post-processing steps assert on that, which aborts the process (found
// by fuzzing; tests/fuzz/regressions/mesh). So: read with validation only, check what the
// reader made ourselves, then post-process (post_process below).
const aiScene* read_checked(Assimp::Importer& importer, const fs::path& full,
                            const std::string& file, const std::string& path) {
  std::string prefix = "cannot read " + quote_path(file) + ": ";
  if (std::string problem = file_status(full); !problem.empty()) fail(path, prefix + problem);
  std::string ext = full.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (std::string problem = ply_header_problem(full, ext == ".ply"); !problem.empty()) {
    fail(path, prefix + problem);
  }
  const aiScene* ai = nullptr;
  {
    AllocationBudget memory(kMemoryBase);
    auto* io = new BudgetIOSystem(&memory);
    importer.SetIOHandler(io);  // the importer owns it
    ai = importer.ReadFile(full.string(), aiProcess_ValidateDataStructure);
    io->forget_memory();  // `memory` ends here; post-processing opens no files
    if (!ai && memory.exceeded()) {
      fail(path, prefix + fmt::format("the file declares more data than it holds (reading it "
                                      "would take more than {} MiB)",
                                      memory.limit() >> 20));
    }
  }
  if (!ai && ext == ".gltf") {
    if (std::string problem = gltf_json_problem(full); !problem.empty()) {
      fail(path, prefix + problem);
    }
  }
  if (!ai) import_failed(importer, file, path);
  if (std::string problem = raw_mesh_problem(ai); !problem.empty()) {
    fail(path, quote_path(file) + ": " + problem);
  }
  return ai;
}

const aiScene* post_process(Assimp::Importer& importer, unsigned flags, const std::string& file,
                            const std::string& path) {
  const aiScene* ai = importer.ApplyPostProcessing(flags);
  if (!ai) import_failed(importer, file, path);
  size_t faces = 0, vertices = 0;
  for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
    faces += ai->mMeshes[m]->mNumFaces;
    vertices += ai->mMeshes[m]->mNumVertices;
  }
  if (faces > kMaxMeshTriangles || vertices > 3 * kMaxMeshTriangles) {
    fail(path, fmt::format("{} has {} faces, more than the limit of {} triangles", quote_path(file),
                           faces, kMaxMeshTriangles));
  }
  return ai;
}

// A vertex colour from a file: Assimp gives 0..1 (bytes divided by 255); non-finite and
// negative components become 0, components above 1 are 1.
glm::vec3 vertex_colour(const aiColor4D& c) {
  auto clean = [](float x) { return std::isfinite(x) && x > 0.0f ? std::min(x, 1.0f) : 0.0f; };
  return {clean(c.r), clean(c.g), clean(c.b)};
}

// Appends mesh m's vertices (with normals when `normals`: the file's, or zero to be repaired;
// the texture coordinates of set `uv_set` when it is >= 0 and the mesh has it; its first set
// of vertex colours when `colours` and it has them) and triangles; other faces are counted in
// `skipped`. A mesh appended to one that already holds vertices keeps uvs and colours only
// when every mesh appended has them.
void append_mesh(TriangleMesh& mesh, const aiScene* ai, unsigned m, bool normals, int uv_set,
                 bool colours, const std::string& file, const std::string& path, size_t* skipped) {
  const aiMesh* am = ai->mMeshes[m];
  if (!am->mVertices) return;
  uint32_t base = static_cast<uint32_t>(mesh.positions.size());
  const aiVector3D* uvs =
      uv_set >= 0 && uv_set < AI_MAX_NUMBER_OF_TEXTURECOORDS ? am->mTextureCoords[uv_set] : nullptr;
  const aiColor4D* cols = colours ? am->mColors[0] : nullptr;
  if (!uvs || mesh.uvs.size() != base) mesh.uvs.clear();
  if (!cols || mesh.colours.size() != base) mesh.colours.clear();
  const bool keep_uvs = uvs && mesh.uvs.size() == base;
  const bool keep_colours = cols && mesh.colours.size() == base;
  for (unsigned v = 0; v < am->mNumVertices; ++v) {
    if (keep_uvs) {
      glm::vec2 uv(uvs[v].x, uvs[v].y);
      mesh.uvs.push_back(std::isfinite(uv.x) && std::isfinite(uv.y) ? uv : glm::vec2(0.0f));
    }
    if (keep_colours) mesh.colours.push_back(vertex_colour(cols[v]));
    const aiVector3D& p = am->mVertices[v];
    glm::vec3 pos(p.x, p.y, p.z);
    if (!finite(pos)) {
      fail(path, fmt::format("{}: vertex {} of mesh {} has a non-finite coordinate",
                             quote_path(file), v, m));
    }
    mesh.positions.push_back(pos);
    if (normals) {
      glm::vec3 n(0.0f);  // missing: repaired later from the faces
      if (am->mNormals) n = glm::vec3(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z);
      mesh.normals.push_back(n);
    }
  }
  for (unsigned f = 0; f < am->mNumFaces; ++f) {
    const aiFace& face = am->mFaces[f];
    if (face.mNumIndices != 3) {
      ++*skipped;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      if (face.mIndices[k] >= am->mNumVertices) {
        fail(path, fmt::format("{}: face {} of mesh {} has a vertex index out of range",
                               quote_path(file), f, m));
      }
    }
    mesh.triangles.emplace_back(base + face.mIndices[0], base + face.mIndices[1],
                                base + face.mIndices[2]);
  }
}

// Whether the meshes of a freshly read scene are a placeholder an Assimp reader made rather
// than the file's geometry: Assimp's SkeletonMeshBuilder puts one mesh of small pyramids around
// the nodes of a file with no meshes (Collada, ASE, BVH, CSM, LWS, MD5, SMD: cameras, lights or
// a skeleton alone). Its readers then flag the scene AI_SCENE_FLAGS_INCOMPLETE (all but BVH),
// and the mesh has bones and takes the material the builder adds, "SkeletonMaterial", where the
// file has none.
bool placeholder_meshes(const aiScene* raw) {
  if (raw->mNumMeshes == 0) return false;
  if (raw->mFlags & AI_SCENE_FLAGS_INCOMPLETE) return true;
  const aiMesh* am = raw->mMeshes[0];
  if (raw->mNumMeshes != 1 || am->mNumBones == 0 || am->mMaterialIndex >= raw->mNumMaterials)
    return false;
  aiString name;
  return raw->mMaterials[am->mMaterialIndex]->Get(AI_MATKEY_NAME, name) == AI_SUCCESS &&
         std::strcmp(name.C_Str(), "SkeletonMaterial") == 0;
}

// What a freshly read scene holds besides meshes, e.g. {"1 camera", "2 lights"} (read before
// post-processing, which may drop animations).
std::vector<std::string> other_contents(const aiScene* raw) {
  std::vector<std::string> items;
  auto count = [&](size_t n, const char* one, const char* many) {
    if (n > 0) items.push_back(fmt::format("{} {}", n, n == 1 ? one : many));
  };
  count(raw->mNumCameras, "camera", "cameras");
  count(raw->mNumLights, "light", "lights");
  count(raw->mNumAnimations, "animation", "animations");
  return items;
}

// Refuses a file with no triangles of its own: "no triangles (the file holds only ...)", with
// what it holds instead (`contents`, and its point and line primitives), on `path` for a mesh
// object of a scene file, on "objects" for a model file given as the scene.
[[noreturn]] void fail_no_triangles(std::vector<std::string> contents, size_t point_line_primitives,
                                    const std::string& file, const std::string& path) {
  if (point_line_primitives > 0) {
    contents.push_back(fmt::format("{} point/line primitive{}", point_line_primitives,
                                   point_line_primitives == 1 ? "" : "s"));
  }
  std::string holds = contents.empty() ? "empty nodes" : contents[0];
  for (size_t i = 1; i < contents.size(); ++i)
    holds += (i + 1 == contents.size() ? " and " : ", ") + contents[i];
  std::string what = "no triangles (the file holds only " + holds + ")";
  if (path.empty()) fail("objects", what);
  fail(path, quote_path(file) + ": " + what);
}

// Facet normals of an STL file that contradict the facet's winding: the normal points to the
// side the vertices turn clockwise on (normal . (e1 x e2) < 0, e1 and e2 the edges from the
// first vertex), or is zero or non-finite. Such facets are shaded with their geometric normal
// (the winding's, which the STL format defines as pointing out), counted in `opposite` and
// `zero`. Assimp's STL reader gives each corner of a facet the facet's normal as written;
// degenerate facets are left alone (finish_mesh drops them).
void replace_contradicting_facet_normals(TriangleMesh& mesh, size_t* opposite, size_t* zero) {
  if (mesh.normals.size() != mesh.positions.size()) return;
  std::vector<uint32_t> uses(mesh.positions.size(), 0);
  for (const glm::uvec3& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++uses[t[k]];
  for (glm::uvec3& t : mesh.triangles) {
    const glm::vec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
    if (degenerate(a, b, c)) continue;
    const glm::vec3 n = mesh.normals[t.x];
    const glm::dvec3 g = glm::cross(glm::dvec3(b) - glm::dvec3(a), glm::dvec3(c) - glm::dvec3(a));
    if (finite(n) && glm::length(n) > 0.0f) {
      if (glm::dot(glm::dvec3(n), g) >= 0.0) continue;
      ++*opposite;
    } else {
      ++*zero;
    }
    const glm::vec3 geometric(glm::normalize(g));
    for (int k = 0; k < 3; ++k) {
      if (uses[t[k]] > 1) {  // shared with another facet: this facet gets a vertex of its own
        --uses[t[k]];
        mesh.positions.push_back(mesh.positions[t[k]]);
        mesh.normals.push_back(geometric);
        if (!mesh.uvs.empty()) mesh.uvs.push_back(mesh.uvs[t[k]]);
        if (!mesh.colours.empty()) mesh.colours.push_back(mesh.colours[t[k]]);
        t[k] = uint32_t(mesh.positions.size() - 1);
      } else {
        mesh.normals[t[k]] = geometric;
      }
    }
  }
}

// Merges vertices whose position, normal, texture coordinates and vertex colour are the same
// bits, renumbering the triangles; first occurrences keep their order. Stands in for
// aiProcess_JoinIdenticalVertices on model files: Assimp's OBJ reader makes one vertex per face
// corner, and Assimp's join (which also merges positions a few float steps apart) searches for
// near neighbours; this is one hash lookup per vertex. Geometry is the file's, bit for bit.
void weld_identical_vertices(TriangleMesh& mesh) {
  const size_t n = mesh.positions.size();
  const bool normals = mesh.normals.size() == n;
  const bool uvs = mesh.uvs.size() == n;
  const bool colours = mesh.colours.size() == n;
  using Key = std::array<uint32_t, 11>;
  auto bits_of = [&](size_t v) {
    Key b{};
    std::memcpy(b.data(), &mesh.positions[v], sizeof(glm::vec3));
    if (normals) std::memcpy(b.data() + 3, &mesh.normals[v], sizeof(glm::vec3));
    if (uvs) std::memcpy(b.data() + 6, &mesh.uvs[v], sizeof(glm::vec2));
    if (colours) std::memcpy(b.data() + 8, &mesh.colours[v], sizeof(glm::vec3));
    return b;
  };
  // Open addressing, no allocation per vertex: slots hold 1 + the input index of the first
  // vertex with those bits (0: empty), at most half full.
  size_t size = 16;
  while (size < 2 * n) size *= 2;
  std::vector<uint32_t> slot(size, 0);
  std::vector<uint32_t> remap(n);
  TriangleMesh welded;
  welded.positions.reserve(n);
  for (size_t v = 0; v < n; ++v) {
    const Key key = bits_of(v);
    uint64_t h = 1469598103934665603ull;  // FNV-1a over the words
    for (uint32_t b : key) h = (h ^ b) * 1099511628211ull;
    size_t i = size_t(h ^ (h >> 29)) & (size - 1);
    while (slot[i] != 0 && bits_of(slot[i] - 1) != key) i = (i + 1) & (size - 1);
    if (slot[i] == 0) {
      slot[i] = uint32_t(v + 1);
      remap[v] = uint32_t(welded.positions.size());
      welded.positions.push_back(mesh.positions[v]);
      if (normals) welded.normals.push_back(mesh.normals[v]);
      if (uvs) welded.uvs.push_back(mesh.uvs[v]);
      if (colours) welded.colours.push_back(mesh.colours[v]);
    } else {
      remap[v] = remap[slot[i] - 1];
    }
  }
  for (glm::uvec3& t : mesh.triangles) t = {remap[t.x], remap[t.y], remap[t.z]};
  mesh.positions = std::move(welded.positions);
  if (normals) mesh.normals = std::move(welded.normals);
  if (uvs) mesh.uvs = std::move(welded.uvs);
  if (colours) mesh.colours = std::move(welded.colours);
}

// Colours from files: negative or non-finite components become 0.
glm::vec3 file_colour(const aiColor3D& c) {
  auto clean = [](float x) { return std::isfinite(x) && x > 0.0f ? x : 0.0f; };
  return {clean(c.r), clean(c.g), clean(c.b)};
}

// The file's own image as bytes: a compressed image (mHeight 0: mWidth bytes, its format in
// achFormatHint) as it is, raw ARGB8888 texels (mWidth x mHeight, the top row first) as RGB.
EmbeddedImage embedded_image(const aiTexture& t, unsigned index) {
  EmbeddedImage image;
  image.name =
      t.mFilename.length > 0 ? t.mFilename.C_Str() : fmt::format("embedded image {}", index);
  if (!t.pcData) return image;
  if (t.mHeight == 0) {
    image.format = t.achFormatHint;
    image.bytes.assign(reinterpret_cast<const char*>(t.pcData), t.mWidth);
    return image;
  }
  image.format = "rgb8";
  image.width = int(t.mWidth);
  image.height = int(t.mHeight);
  const size_t texels = size_t(t.mWidth) * size_t(t.mHeight);
  image.bytes.resize(3 * texels);
  for (size_t i = 0; i < texels; ++i) {
    image.bytes[3 * i + 0] = char(t.pcData[i].r);
    image.bytes[3 * i + 1] = char(t.pcData[i].g);
    image.bytes[3 * i + 2] = char(t.pcData[i].b);
  }
  return image;
}

// The material of an imported mesh; empty when the file has none of its own (no material,
// Assimp's stand-in "DefaultMaterial", or the unnamed one its PLY, OFF and STL readers make)
// and no vertex colours either. A mesh with vertex colours and no material of its own (PLY,
// OFF) gets a white one, so that its base colour is its vertex colours; with a material, the
// vertex colours multiply its diffuse colour (glTF's COLOR_0 times baseColorFactor).
std::optional<Material> part_material(const aiScene* ai, const aiMesh* am) {
  const aiMaterial* mat =
      am->mMaterialIndex < ai->mNumMaterials ? ai->mMaterials[am->mMaterialIndex] : nullptr;
  aiString name;
  bool stand_in = !mat || mat->Get(AI_MATKEY_NAME, name) != AI_SUCCESS || name.length == 0 ||
                  std::strcmp(name.C_Str(), AI_DEFAULT_MATERIAL_NAME) == 0;
  if (stand_in) {
    if (!am->mColors[0]) return std::nullopt;
    Material m = default_material();
    m.diffuse = glm::vec3(1.0f);
    m.name = "vertex colours";
    return m;
  }
  Material m = default_material();
  m.name = name.length > 0 ? name.C_Str() : "material";
  aiColor3D c;
  // glTF's baseColorFactor is the base colour; older formats give a diffuse colour.
  if (mat->Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS ||
      mat->Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS) {
    m.diffuse = glm::min(file_colour(c), glm::vec3(1.0f));
  }
  if (mat->Get(AI_MATKEY_COLOR_SPECULAR, c) == AI_SUCCESS) {
    m.specular = glm::min(file_colour(c), glm::vec3(1.0f));
    float strength = 1.0f;
    if (mat->Get(AI_MATKEY_SHININESS_STRENGTH, strength) == AI_SUCCESS && std::isfinite(strength) &&
        strength >= 0.0f) {
      m.specular = glm::min(m.specular * strength, glm::vec3(1.0f));
    }
  }
  if (mat->Get(AI_MATKEY_COLOR_EMISSIVE, c) == AI_SUCCESS) m.emission = file_colour(c);
  float shininess = 0.0f;
  if (mat->Get(AI_MATKEY_SHININESS, shininess) == AI_SUCCESS && std::isfinite(shininess) &&
      shininess > 0.0f) {
    m.shininess = std::min(shininess, 1e4f);
  }
  return m;
}

TextureWrap texture_wrap(int mode) {
  switch (mode) {
    case aiTextureMapMode_Clamp:
    case aiTextureMapMode_Decal:
      return TextureWrap::ClampToEdge;
    case aiTextureMapMode_Mirror:
      return TextureWrap::MirroredRepeat;
    default:
      return TextureWrap::Repeat;
  }
}

// KHR_texture_transform from the aiUVTransform Assimp's glTF reader (5.2) makes of it, which
// is for its v-up texture coordinates: mScaling = scale, mRotation = -rotation and
// mTranslation = (s.x/2 (1 - cos r + sin r) + offset.x,
//                 s.y/2 (sin r + cos r - 1) + 1 - s.y - offset.y), solved here for offset.
UvTransform gltf_uv_transform(const aiUVTransform& t) {
  UvTransform u;
  u.scale = {t.mScaling.x, t.mScaling.y};
  u.rotation = -t.mRotation;
  const float c = std::cos(u.rotation), s = std::sin(u.rotation);
  u.offset.x = t.mTranslation.x - 0.5f * u.scale.x * (1.0f - c + s);
  u.offset.y = 0.5f * u.scale.y * (s + c - 1.0f) + 1.0f - u.scale.y - t.mTranslation.y;
  const bool finite_all = std::isfinite(u.offset.x) && std::isfinite(u.offset.y) &&
                          std::isfinite(u.rotation) && std::isfinite(u.scale.x) &&
                          std::isfinite(u.scale.y);
  return finite_all ? u : UvTransform{};
}

// The material's base-colour texture (glTF's baseColorTexture, else the diffuse texture of
// other formats) and the texture coordinate set it uses; empty without one. An embedded image
// (Assimp's "*N", or a file name an FBX file embeds) is named "*N", N its index in the
// scene's textures (and in ImportedModel::images). `gltf`: the file is glTF, whose texture
// transform Assimp gives in its own form (gltf_uv_transform); other formats' transforms are applied
// to the texture coordinates by aiProcess_TransformUVCoords.
std::optional<ModelTexture> base_colour_texture(const aiScene* ai, const aiMesh* am, bool gltf,
                                                int* uv_set) {
  const aiMaterial* mat =
      am->mMaterialIndex < ai->mNumMaterials ? ai->mMaterials[am->mMaterialIndex] : nullptr;
  if (!mat) return std::nullopt;
  aiTextureType type = aiTextureType_NONE;
  aiString file;
  for (aiTextureType t : {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE}) {
    if (mat->GetTextureCount(t) > 0 && mat->GetTexture(t, 0, &file) == AI_SUCCESS &&
        file.length > 0) {
      type = t;
      break;
    }
  }
  if (type == aiTextureType_NONE) return std::nullopt;
  ModelTexture texture;
  texture.file = file.C_Str();
  int source = 0, wrap_u = aiTextureMapMode_Wrap, wrap_v = aiTextureMapMode_Wrap;
  if (mat->Get(AI_MATKEY_UVWSRC(type, 0), source) != AI_SUCCESS || source < 0) source = 0;
  mat->Get(AI_MATKEY_MAPPINGMODE_U(type, 0), wrap_u);
  mat->Get(AI_MATKEY_MAPPINGMODE_V(type, 0), wrap_v);
  texture.wrap_u = texture_wrap(wrap_u);
  texture.wrap_v = texture_wrap(wrap_v);
  aiUVTransform transform;
  if (gltf && mat->Get(AI_MATKEY_UVTRANSFORM(type, 0), transform) == AI_SUCCESS) {
    texture.transform = gltf_uv_transform(transform);
  }
  *uv_set = source;
  auto [embedded, index] = ai->GetEmbeddedTextureAndIndex(file.C_Str());
  if (embedded && index >= 0) texture.file = "*" + std::to_string(index);
  return texture;
}

// The node's transform to world space (the product of its ancestors').
aiMatrix4x4 world_transform(const aiNode* node) {
  aiMatrix4x4 t;
  for (; node; node = node->mParent) t = node->mTransformation * t;
  return t;
}

const aiNode* find_node(const aiScene* ai, const aiString& name) {
  return ai->mRootNode ? ai->mRootNode->FindNode(name) : nullptr;
}

glm::vec3 to_glm(const aiVector3D& v) {
  return {v.x, v.y, v.z};
}

// Whether an FBX camera is an exporter's viewport camera rather than one the user placed.
// Assimp's FBX reader (5.2, FBXConverter::ConvertNodes) converts only cameras attached to
// models in the node hierarchy, so FBX 7's viewport cameras, which only GlobalSettings'
// DefaultCamera names, never arrive. What can arrive: the FBX 6 "Producer Perspective",
// "Producer Top", ... cameras and the "Camera Switcher", which exporters write as models of
// their own; and a camera whose node Assimp did not keep, which an FBX camera needs (Assimp
// puts it at its node's origin looking along +x), so without it every such camera would sit
// at the world's origin. Both are refused; a camera the user placed is kept wherever it is.
bool fbx_viewport_camera(const aiScene* ai, const aiCamera& cam) {
  const std::string name = cam.mName.C_Str();
  return name.rfind("Producer ", 0) == 0 || name == "Camera Switcher" ||
         find_node(ai, cam.mName) == nullptr;
}

// The first camera the file's author placed, in world space; empty when the file has none or
// it is unusable. `gltf`: Assimp's glTF reader stores yfov x aspect as the horizontal angle.
// `fbx`: an exporter's viewport cameras are skipped (fbx_viewport_camera).
void read_camera(const aiScene* ai, bool gltf, bool fbx, ImportedModel& model) {
  if (ai->mNumCameras == 0 || !ai->mCameras) return;
  const aiCamera* first = nullptr;
  std::vector<std::string> viewport;
  for (unsigned i = 0; i < ai->mNumCameras && !first; ++i) {
    const aiCamera* cam = ai->mCameras[i];
    if (!cam) continue;
    if (fbx && fbx_viewport_camera(ai, *cam)) {
      viewport.push_back(quote_json(cam->mName.C_Str()));
      continue;
    }
    first = cam;
  }
  if (!viewport.empty()) {
    std::string names;
    for (const std::string& n : viewport) names += (names.empty() ? "" : ", ") + n;
    model.warnings.push_back(fmt::format("ignored the exporter's viewport camera{} {}",
                                         viewport.size() == 1 ? "" : "s", names));
  }
  if (!first) return;
  const aiCamera& cam = *first;
  aiMatrix4x4 t = world_transform(find_node(ai, cam.mName));
  aiMatrix3x3 turn(t);
  // A glTF camera sits at its node's origin (the format has no other place for it); Assimp's
  // glTF reader (5.2) also copies the node's translation into mPosition, which would count it
  // twice.
  glm::vec3 eye = to_glm(t * (gltf ? aiVector3D(0.0f) : cam.mPosition));
  glm::vec3 forward = to_glm(turn * cam.mLookAt);
  glm::vec3 up = to_glm(turn * cam.mUp);
  if (!finite(eye) || !finite(forward) || !finite(up) || glm::length(forward) == 0.0f ||
      glm::length(glm::cross(forward, up)) < 1e-6f * glm::length(forward) * glm::length(up)) {
    model.warnings.push_back(
        "the file's camera is unusable (zero or parallel directions); "
        "framing the model instead");
    return;
  }
  Camera c;
  c.eye = eye;
  c.target = eye + glm::normalize(forward);
  c.up = glm::normalize(up);
  model.camera_aspect = std::isfinite(cam.mAspect) && cam.mAspect > 0.0f ? cam.mAspect : 0.0f;
  // Assimp gives the horizontal angle: half of it by its documentation, the whole of it from
  // its Collada and FBX readers, taken as the whole; its glTF reader (5.2) stores
  // yfov x aspect, undone as such.
  float aspect = model.camera_aspect > 0.0f ? model.camera_aspect : 4.0f / 3.0f;
  float fov_y = gltf ? cam.mHorizontalFOV / aspect
                     : 2.0f * std::atan(std::tan(0.5f * cam.mHorizontalFOV) / aspect);
  if (std::isfinite(fov_y) && fov_y > 1e-3f && fov_y < 3.1f) c.fov_y_deg = glm::degrees(fov_y);
  // Near and far are distances along the view direction in the camera's own units: they
  // scale as that direction does from the camera to world space (e.g. Collada's <unit>,
  // which Assimp puts in the root node's transform, as it does the positions).
  float scale = glm::length(forward) / glm::length(to_glm(cam.mLookAt));
  float near = cam.mClipPlaneNear * scale, far = cam.mClipPlaneFar * scale;
  if (std::isfinite(near) && near > 0.0f && std::isfinite(far) && far > near) {
    c.near = near;
    c.far = far;
  }
  c.focus_distance = 1.0f;
  model.camera = c;
}

// Point lights (spot lights as point lights, their cone ignored), in world space.
void read_lights(const aiScene* ai, ImportedModel& model) {
  size_t skipped = 0;
  for (unsigned i = 0; i < ai->mNumLights && ai->mLights; ++i) {
    const aiLight* l = ai->mLights[i];
    if (!l) continue;
    if (l->mType != aiLightSource_POINT && l->mType != aiLightSource_SPOT) {
      ++skipped;
      continue;
    }
    Light light;
    light.type = LightType::Point;
    light.position = to_glm(world_transform(find_node(ai, l->mName)) * l->mPosition);
    light.intensity = file_colour(l->mColorDiffuse);
    if (!finite(light.position)) continue;
    if (l->mAttenuationQuadratic == 0.0f && l->mAttenuationLinear == 0.0f) {
      model.unattenuated_lights.push_back(model.lights.size());
    }
    model.lights.push_back(light);
  }
  if (skipped > 0) {
    model.warnings.push_back(fmt::format(
        "ignored {} light{} that {} not point or spot lights (directional, area, ambient)", skipped,
        skipped == 1 ? "" : "s", skipped == 1 ? "is" : "are"));
  }
}

// The up direction the file's metadata gives (Assimp's scene metadata: UpAxis 0/1/2 for
// x/y/z and UpAxisSign +-1, which its FBX reader stores and does not apply); +y when it gives
// none or something else.
glm::vec3 metadata_up(const aiScene* ai) {
  int32_t axis = 1, sign = 1;
  if (!ai->mMetaData || !ai->mMetaData->Get("UpAxis", axis)) return {0.0f, 1.0f, 0.0f};
  if (!ai->mMetaData->Get("UpAxisSign", sign)) sign = 1;
  if (axis < 0 || axis > 2 || (sign != 1 && sign != -1)) return {0.0f, 1.0f, 0.0f};
  glm::vec3 up(0.0f);
  up[axis] = float(sign);
  return up;
}

// The length of one FBX unit in metres: GlobalSettings' UnitScaleFactor is in centimetres (1,
// centimetres, when the file does not say), which Assimp (5.2) reports in the scene's metadata
// as a float or a double and does not apply. An unusable factor (zero, negative, non-finite)
// counts as the default with a warning.
float fbx_metres_per_unit(const aiScene* ai, std::vector<std::string>& warnings) {
  double factor = 1.0;
  float as_float = 0.0f;
  if (ai->mMetaData && !ai->mMetaData->Get("UnitScaleFactor", factor)) {
    factor = ai->mMetaData->Get("UnitScaleFactor", as_float) ? double(as_float) : 1.0;
  }
  if (!std::isfinite(factor) || factor <= 0.0) {
    warnings.push_back(fmt::format(
        "the file's UnitScaleFactor ({}) is unusable; read in centimetres, the FBX default",
        factor));
    factor = 1.0;
  }
  return float(factor * 0.01);
}

// Scales the whole file (meshes, cameras, lights) by `metres_per_unit` through its root
// node's transform, as Assimp applies Collada's <unit>: positions come out in metres, and a
// camera's near and far scale with its node's transform (read_camera).
void apply_units(const aiScene* ai, float metres_per_unit) {
  if (!ai->mRootNode || metres_per_unit == 1.0f) return;
  aiMatrix4x4 scale;
  aiMatrix4x4::Scaling(aiVector3D(metres_per_unit), scale);
  ai->mRootNode->mTransformation = scale * ai->mRootNode->mTransformation;
}

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// The warning for STL facets whose normals were replaced (replace_contradicting_facet_normals);
// empty when there were none.
std::string facet_normals_warning(size_t opposite, size_t zero) {
  const size_t n = opposite + zero;
  if (n == 0) return {};
  return fmt::format(
      "{} facet{} normals that contradict the winding ({} pointing against it, {} zero or "
      "non-finite): shaded with the facets' geometric normals",
      n, n == 1 ? " has" : "s have", opposite, zero);
}

TriangleMesh import_mesh_here(const fs::path& full, const std::string& file,
                              const std::string& path, bool smooth, size_t* skipped_primitives,
                              std::vector<std::string>* warnings) {
  Assimp::Importer importer;
  const aiScene* raw = read_checked(importer, full, file, path);
  const bool placeholder = placeholder_meshes(raw);
  const std::vector<std::string> contents = other_contents(raw);
  const std::string ext = lower_extension(full);
  if (ext == ".fbx") apply_units(raw, fbx_metres_per_unit(raw, *warnings));
  unsigned flags =
      aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices;
  if (smooth) flags |= aiProcess_GenSmoothNormals;  // ignored where the file has normals
  const aiScene* ai = post_process(importer, flags, file, path);
  // Texture coordinates (the set the file's own base-colour texture uses, else the first) for
  // a textured material of the scene, and vertex colours, which multiply its diffuse colour.
  TriangleMesh mesh;
  for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
    if (placeholder) continue;
    int uv_set = 0;
    base_colour_texture(ai, ai->mMeshes[m], false, &uv_set);
    append_mesh(mesh, ai, m, smooth, uv_set, true, file, path, skipped_primitives);
  }
  if (mesh.triangles.empty()) fail_no_triangles(contents, *skipped_primitives, file, path);
  // Smooth shading keeps the file's normals: an STL file's facet normals are checked first.
  size_t opposite_normals = 0, zero_normals = 0;
  if (ext == ".stl") replace_contradicting_facet_normals(mesh, &opposite_normals, &zero_normals);
  if (std::string w = facet_normals_warning(opposite_normals, zero_normals); !w.empty()) {
    warnings->push_back(std::move(w));
  }
  return mesh;
}

ImportedModel import_model_here(const fs::path& full, const std::string& file,
                                const std::string& path) {
  Assimp::Importer importer;
  ImportedModel model;
  const aiScene* raw = read_checked(importer, full, file, path);
  const bool placeholder = placeholder_meshes(raw);
  const std::vector<std::string> contents = other_contents(raw);
  // Cameras and lights hang off nodes, whose transforms PreTransformVertices removes: read
  // them first.
  const std::string ext = lower_extension(full);
  if (ext == ".fbx") apply_units(raw, fbx_metres_per_unit(raw, model.warnings));
  read_camera(raw, ext == ".gltf" || ext == ".glb", ext == ".fbx", model);
  read_lights(raw, model);
  // Only FBX: Assimp (5.2) reports the axes of FBX alone, and applies Collada's itself.
  if (ext == ".fbx") model.up = metadata_up(raw);
  // The file's normals where it has them (smooth shading); flat faces where it has none.
  // Vertices are joined afterwards by weld_identical_vertices. The texture transforms of
  // formats other than glTF are applied to the texture coordinates by Assimp
  // (aiProcess_TransformUVCoords); glTF's are kept as the material's (base_colour_texture).
  const bool gltf = ext == ".gltf" || ext == ".glb";
  const aiScene* ai = post_process(importer,
                                   aiProcess_Triangulate | aiProcess_PreTransformVertices |
                                       (gltf ? 0u : unsigned(aiProcess_TransformUVCoords)),
                                   file, path);
  size_t opposite_normals = 0, zero_normals = 0;
  std::vector<std::string> without_uvs;
  bool embedded = false;
  const bool stl = ext == ".stl";
  for (unsigned m = 0; m < ai->mNumMeshes && !placeholder; ++m) {
    const aiMesh* am = ai->mMeshes[m];
    ModelPart part;
    part.name = am->mName.length > 0 ? am->mName.C_Str() : fmt::format("mesh{}", m);
    int uv_set = -1;
    part.texture = base_colour_texture(ai, am, gltf, &uv_set);
    append_mesh(part.mesh, ai, m, am->mNormals != nullptr, uv_set, true, file, path,
                &model.skipped_primitives);
    if (part.mesh.triangles.empty()) continue;
    if (part.texture && !part.mesh.textured()) {
      without_uvs.push_back(quote_json(part.name));
      part.texture.reset();
    }
    embedded |= part.texture && part.texture->file.rfind('*', 0) == 0;
    if (stl) replace_contradicting_facet_normals(part.mesh, &opposite_normals, &zero_normals);
    weld_identical_vertices(part.mesh);
    part.material = part_material(ai, am);
    model.parts.push_back(std::move(part));
  }
  for (unsigned i = 0; embedded && i < ai->mNumTextures && ai->mTextures; ++i) {
    model.images.push_back(ai->mTextures[i] ? embedded_image(*ai->mTextures[i], i)
                                            : EmbeddedImage{});
  }
  if (!without_uvs.empty()) {
    std::string names;
    for (const std::string& n : without_uvs) names += (names.empty() ? "" : ", ") + n;
    model.warnings.push_back(fmt::format(
        "mesh{} {} ha{} a colour texture but no texture coordinates: rendered without it",
        without_uvs.size() == 1 ? "" : "es", names, without_uvs.size() == 1 ? "s" : "ve"));
  }
  if (model.parts.empty()) fail_no_triangles(contents, model.skipped_primitives, file, path);
  if (std::string w = facet_normals_warning(opposite_normals, zero_normals); !w.empty()) {
    model.warnings.push_back(std::move(w));
  }
  return model;
}

// The child's side of an isolated import: `body`'s result then 'O' (a tag at the end, so a
// large result is not copied to make room), or its error: the JSON path, a NUL, the message,
// 'E'; 'M' out of memory; what any other exception said, 'X'.
std::string child_side(const std::function<std::string()>& body) {
  std::string out;
  char tag = 'O';
  try {
    out = body();
  } catch (const LoadError& e) {
    out = e.path;
    out.push_back('\0');
    out += e.what;
    tag = 'E';
  } catch (const std::bad_alloc&) {
    out.clear();
    tag = 'M';
  } catch (const std::exception& e) {
    out = e.what();
    tag = 'X';
  } catch (...) {
    out = "unknown exception";
    tag = 'X';
  }
  out.push_back(tag);
  return out;
}

// Runs `body` (an import of `file`) in a child process and returns what it produced, or
// throws its error here.
std::string import_isolated(const std::function<std::string()>& body, const std::string& file,
                            const std::string& path) {
  IsolatedResult r = run_isolated([&] { return child_side(body); }, kCpuSeconds);
  if (r.status != IsolatedResult::Status::Ok || r.bytes.empty()) {
    fail(path, "cannot read " + quote_path(file) + ": the importer " +
                   (r.problem.empty() ? "returned nothing" : r.problem) + " on this file");
  }
  char tag = r.bytes.back();
  r.bytes.pop_back();
  switch (tag) {
    case 'O':
      return std::move(r.bytes);
    case 'E': {
      size_t nul = r.bytes.find('\0');
      fail(r.bytes.substr(0, nul), nul == std::string::npos ? "" : r.bytes.substr(nul + 1));
    }
    case 'M':
      throw std::bad_alloc();
    default:
      throw std::runtime_error(r.bytes);
  }
}

}  // namespace

TriangleMesh import_mesh(const std::string& file, const std::string& base_dir,
                         const std::string& path, bool smooth, size_t* skipped_primitives,
                         std::vector<std::string>* warnings) {
  fs::path full = resolve(file, base_dir, path);
  std::string bytes = import_isolated(
      [&] {
        size_t skipped = 0;
        std::vector<std::string> found;
        TriangleMesh mesh = import_mesh_here(full, file, path, smooth, &skipped, &found);
        return encode(mesh, skipped, found);
      },
      file, path);
  return decode_mesh(bytes, skipped_primitives, warnings);
}

ImportedModel import_model(const std::string& file, const std::string& base_dir,
                           const std::string& path) {
  fs::path full = resolve(file, base_dir, path);
  return decode_model(
      import_isolated([&] { return encode(import_model_here(full, file, path)); }, file, path));
}

}  // namespace rvr::scene_load
