// Shared by the fuzz harnesses and the regression test: feeding one input to the scene loader
// exactly as the CLI does (load_scene on a file path), from a private scratch folder.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "rvr/scene_io/scene_loader.h"

namespace rvr::fuzz {

// A scratch folder (in /dev/shm when there is one: fuzzing writes a file per input) with a
// `models` link to the repository's scenes/models, so scenes copied from scenes/ find their
// meshes. One per process.
inline const std::filesystem::path& scratch_dir(const char* models_dir) {
  static const std::filesystem::path dir = [models_dir] {
    namespace fs = std::filesystem;
    fs::path base = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    fs::path d = base / ("rvr-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(d);
    std::error_code ec;
    fs::create_directory_symlink(models_dir, d / "models", ec);
    // Removed at a normal exit (a crash leaves it for inspection).
    static const std::string* const keep = new std::string(d.string());
    std::atexit([] {
      std::error_code ignored;
      fs::remove_all(*keep, ignored);
    });
    return d;
  }();
  return dir;
}

inline void write_file(const std::filesystem::path& p, const uint8_t* data, size_t size) {
  std::FILE* f = std::fopen(p.c_str(), "wb");
  if (!f) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
}

// The loader must return a scene or an error, never crash, hang or throw. An error must be
// bad input (exit status 2 in the CLI), one line, starting with the file's name. Returns
// what the loader returned; a broken promise aborts (so the fuzzer reports it).
inline Expected<Scene> check_loaded(const std::filesystem::path& p, Expected<Scene> s) {
  if (!s.ok()) {
    const Error& e = s.error();
    bool well_formed = e.kind == ErrorKind::BadInput && e.message.rfind(p.string(), 0) == 0 &&
                       e.message.find('\n') == std::string::npos;
    if (!well_formed) {
      std::fprintf(stderr, "malformed loader error (kind %d): %s\n", static_cast<int>(e.kind),
                   e.message.c_str());
      std::abort();
    }
  }
  return s;
}

inline Expected<Scene> load_scene_text(const std::filesystem::path& dir, const uint8_t* data,
                                       size_t size) {
  std::filesystem::path p = dir / "scene.json";
  write_file(p, data, size);
  return check_loaded(p, load_scene(p.string()));
}

// Mesh mode: the first byte picks the file's extension (the importer chooses its reader by
// it) and whether `smooth` is set; the rest is the mesh file, loaded as the scene itself (a
// model file: its materials, camera and lights read too) and referenced by a small scene,
// whose result is returned.
inline constexpr const char* kMeshExtensions[] = {"obj", "ply", "gltf", "3ds",
                                                  "stl", "off", "glb",  "dae"};

inline Expected<Scene> load_mesh_bytes(const std::filesystem::path& dir, const uint8_t* data,
                                       size_t size) {
  if (size < 1) return bad_input("empty input");
  constexpr size_t n = sizeof kMeshExtensions / sizeof kMeshExtensions[0];
  std::string ext = kMeshExtensions[data[0] % n];
  bool smooth = (data[0] / n) % 2 == 1;
  std::string name = "mesh." + ext;
  write_file(dir / name, data + 1, size - 1);
  check_loaded(dir / name, load_scene((dir / name).string()));
  std::string scene = std::string(R"({"camera": {"eye": [0, 0, 5], "target": [0, 0, 0],)") +
                      R"( "up": [0, 1, 0]}, "objects": [{"type": "mesh", "file": ")" + name +
                      R"(", "smooth": )" + (smooth ? "true" : "false") + "}]}";
  return load_scene_text(dir, reinterpret_cast<const uint8_t*>(scene.data()), scene.size());
}

}  // namespace rvr::fuzz
