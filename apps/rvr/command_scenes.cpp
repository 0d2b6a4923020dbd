// rvr scenes: the built-in scenes, listed or exported as scene files.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

#include "cli_exit.h"
#include "commands.h"
#include "rvr/core/expected.h"
#include "rvr/core/scene.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/scene_io/scene_loader.h"
#include "rvr/scene_io/scene_writer.h"

namespace rvr::cli {

namespace {

// --export: the built-in scene, or the scene built from a model file (or read from a scene
// file), as an rvr-scene/1 document. Meshes other than single triangles have no inline form in
// the format: they go to PLY files next to -o FILE.
int export_scene(const ScenesArgs& a) {
  if (a.copy_assets && a.out.empty()) fail(bad_input("scenes: --copy-assets needs -o FILE.json"));
  std::string name = a.export_name;
  const bool builtin_prefix = name.rfind("builtin:", 0) == 0;
  if (builtin_prefix) name = name.substr(8);
  // A name that is no regular file is a built-in scene unless it reads as a path: a folder in
  // it, or a dot in its name (a file extension; built-in names and their ":N" have none). A
  // path that names nothing is reported as missing, not as an unknown built-in scene.
  const bool reads_as_path = name.find('/') != std::string::npos ||
                             name.substr(0, name.find(':')).find('.') != std::string::npos;
  std::error_code ec;
  const bool is_file =
      !builtin_prefix && (std::filesystem::is_regular_file(a.export_name, ec) ||
                          (reads_as_path && std::filesystem::exists(a.export_name, ec)));
  if (!builtin_prefix && !is_file && reads_as_path)
    fail(bad_input(a.export_name + ": no such file"));
  refuse_overwriting_inputs(
      is_file ? std::vector<std::string>{a.export_name} : std::vector<std::string>{}, {a.out});
  Scene scene = is_file ? take(load_scene(a.export_name)) : take(make_builtin_scene(name));
  if (is_file) name = std::filesystem::path(a.export_name).stem().string();
  std::filesystem::path out(a.out);
  std::string prefix = a.out.empty() ? name : out.stem().string();
  std::string folder = out.parent_path().string();
  SceneDocument doc =
      take(write_scene(scene, prefix, folder.empty() ? "." : folder, a.copy_assets));
  if (a.out.empty()) {
    if (!doc.texture_files.empty()) {
      fail(bad_input(fmt::format(
          "{}: has {} texture{} held in memory only (embedded in the model or built in): give "
          "-o FILE.json to write {} as EXR next to it",
          is_file ? a.export_name : "builtin:" + name, doc.texture_files.size(),
          doc.texture_files.size() == 1 ? "" : "s",
          doc.texture_files.size() == 1 ? "it" : "them")));
    }
    if (!doc.mesh_files.empty()) {
      fail(bad_input(fmt::format(
          "{}: has {} mesh{} of more than one triangle, which rvr-scene/1 reads only "
          "from mesh files: give -o FILE.json to write {} as PLY next to it",
          is_file ? a.export_name : "builtin:" + name, doc.mesh_files.size(),
          doc.mesh_files.size() == 1 ? "" : "es", doc.mesh_files.size() == 1 ? "it" : "them")));
    }
    std::fwrite(doc.json.data(), 1, doc.json.size(), stdout);
    return std::fflush(stdout) == 0 ? 0 : 3;
  }
  for (const SceneMeshFile& m : doc.mesh_files) {
    check(write_text_file((out.parent_path() / m.name).string(), m.bytes));
  }
  for (const SceneTextureFile& t : doc.texture_files) {
    check(write_image((out.parent_path() / t.name).string(), t.image));
  }
  for (const SceneCopiedFile& c : doc.copied_files) {
    std::ifstream in(c.source, std::ios::binary);
    if (!in) fail(bad_input("cannot read '" + c.source + "' to copy it beside " + a.out));
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    check(write_text_file((out.parent_path() / c.name).string(), bytes));
  }
  check(write_text_file(a.out, doc.json));
  return 0;
}

}  // namespace

int run_scenes(const ScenesArgs& a) {
  if (!a.export_name.empty()) return export_scene(a);
  if (!a.out.empty()) fail(bad_input("scenes: -o needs --export NAME"));
  if (a.copy_assets) fail(bad_input("scenes: --copy-assets needs --export NAME -o FILE.json"));
  for (const BuiltinSceneInfo& s : builtin_scenes())
    std::printf("builtin:%-14s %s\n", s.name.c_str(), s.description.c_str());
  return 0;
}

}  // namespace rvr::cli
