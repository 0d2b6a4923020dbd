// Reading a mesh file through Assimp, hardened (see mesh_import.h).
#include "mesh_import.h"

#include <assimp/DefaultIOSystem.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <algorithm>
#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "mesh_repair.h"
#include "scene_json_errors.h"

namespace rvr::scene_load {
namespace {

namespace fs = std::filesystem;

constexpr size_t kMaxMeshTriangles = 50'000'000;

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

  bool Exists(const char* file) const override { return base_.Exists(file); }
  char getOsSeparator() const override { return base_.getOsSeparator(); }
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    budget_.spend();
    Assimp::IOStream* inner = base_.Open(file, mode);
    if (!inner) return nullptr;
    budget_.bytes_opened += inner->FileSize();
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
    if (w[0] == "end_header") {
      if (w.size() != 1) return bad("text after end_header");
      break;
    }
    if (w[0] == "format") {
      if (have_format || w.size() != 3 || w[2] != "1.0") return bad("bad format line");
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
    } else {
      return bad("unknown keyword");
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

}  // namespace

TriangleMesh import_mesh(const std::string& file, const std::string& base_dir,
                         const std::string& path, bool smooth, size_t* skipped_primitives) {
  if (file.empty()) fail(path, "must not be empty");
  if (file.find('\0') != std::string::npos) fail(path, "must not contain a NUL character");
  fs::path full = fs::path(file);
  if (full.is_relative()) full = fs::path(base_dir.empty() ? "." : base_dir) / full;
  std::string prefix = "cannot read " + quote_json(file) + ": ";
  if (std::string problem = file_status(full); !problem.empty()) fail(path, prefix + problem);

  std::string ext = full.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (std::string problem = ply_header_problem(full, ext == ".ply"); !problem.empty()) {
    fail(path, prefix + problem);
  }

  Assimp::Importer importer;
  importer.SetIOHandler(new BudgetIOSystem);  // the importer owns it
  // Two stages. Assimp's readers can make broken data from broken files (faces with no
  // indices, indices past the vertices) and its post-processing steps assert on that, which
  // aborts the process (found by fuzzing; tests/fuzz/regressions/mesh). So: read with
  // validation only, check what the reader made ourselves, then post-process.
  const aiScene* ai = importer.ReadFile(full.string(), aiProcess_ValidateDataStructure);
  auto import_failed = [&] {
    std::string reason = importer.GetErrorString();
    std::replace(reason.begin(), reason.end(), '\n', ' ');
    fail(path, prefix + (reason.empty() ? "the importer gave no reason" : reason));
  };
  if (!ai) import_failed();
  if (std::string problem = raw_mesh_problem(ai); !problem.empty()) {
    fail(path, quote_json(file) + ": " + problem);
  }
  unsigned flags =
      aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices;
  if (smooth) flags |= aiProcess_GenSmoothNormals;  // ignored where the file has normals
  ai = importer.ApplyPostProcessing(flags);
  if (!ai) import_failed();

  size_t faces = 0, vertices = 0;
  for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
    faces += ai->mMeshes[m]->mNumFaces;
    vertices += ai->mMeshes[m]->mNumVertices;
  }
  if (faces > kMaxMeshTriangles || vertices > 3 * kMaxMeshTriangles) {
    fail(path, fmt::format("{} has {} faces, more than the limit of {} triangles", quote_json(file),
                           faces, kMaxMeshTriangles));
  }

  TriangleMesh mesh;
  mesh.positions.reserve(vertices);
  mesh.triangles.reserve(faces);
  if (smooth) mesh.normals.reserve(vertices);
  for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
    const aiMesh* am = ai->mMeshes[m];
    if (!am->mVertices) continue;
    uint32_t base = static_cast<uint32_t>(mesh.positions.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      glm::vec3 pos(p.x, p.y, p.z);
      if (!finite(pos)) {
        fail(path, fmt::format("{}: vertex {} of mesh {} has a non-finite coordinate",
                               quote_json(file), v, m));
      }
      mesh.positions.push_back(pos);
      if (smooth) {
        glm::vec3 n(0.0f);  // missing: repaired below from the faces
        if (am->mNormals) n = glm::vec3(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z);
        mesh.normals.push_back(n);
      }
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) {
        ++*skipped_primitives;
        continue;
      }
      for (int k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= am->mNumVertices) {
          fail(path, fmt::format("{}: face {} of mesh {} has a vertex index out of range",
                                 quote_json(file), f, m));
        }
      }
      mesh.triangles.emplace_back(base + face.mIndices[0], base + face.mIndices[1],
                                  base + face.mIndices[2]);
    }
  }
  if (mesh.triangles.empty()) fail(path, quote_json(file) + " contains no triangles");
  return mesh;
}

}  // namespace rvr::scene_load
