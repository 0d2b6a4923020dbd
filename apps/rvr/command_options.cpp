// The options render and compare share (see commands.h).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <glm/glm.hpp>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include "cli_exit.h"
#include "commands.h"
#include "one_of.h"
#include "rvr/core/expected.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/limits.h"
#include "rvr/core/render_option_table.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/scene_io/scene_for_render.h"
#include "rvr/scene_io/scene_loader.h"
#include "suggest.h"

namespace rvr::cli {

namespace {

// The type CLI11's help shows for an option of the table.
const char* type_name(OptionType type) {
  switch (type) {
    case OptionType::Integer:
      return "INT";
    case OptionType::Unsigned:
      return "UINT";
    case OptionType::Real:
      return "FLOAT";
    case OptionType::Flag:
    case OptionType::Choice:
      break;
  }
  return "TEXT";
}

// The table's check of a value as a CLI11 validator; a choice's error asks "did you mean".
CLI::Validator table_check(const RenderOptionSpec& spec) {
  std::vector<std::string> choices(spec.choices.begin(), spec.choices.end());
  std::string description;
  if (spec.type == OptionType::Choice) description = fmt::format("{}", fmt::join(choices, "|"));
  if (spec.type == OptionType::Integer || spec.type == OptionType::Real)
    description = fmt::format("{} in [{} - {}]", type_name(spec.type), spec.min, spec.max);
  return CLI::Validator(
      [&spec, choices](std::string& value) -> std::string {
        RenderOptions scratch;
        const Status status = set_render_option(scratch, spec, value);
        if (status) return "";
        if (spec.type == OptionType::Choice) return not_one_of(value, choices);
        return status.error().message;
      },
      description);
}

// One option of the render option table, as --kebab-name.
void add_render_option(CLI::App& cmd, CommonOptions& o, const RenderOptionSpec& spec) {
  std::optional<std::string>& text = o.render_option_text[std::string(spec.name)];
  const std::string name = cli_option_name(spec);
  const std::string help(spec.help);
  if (spec.type == OptionType::Flag) {
    cmd.add_flag_callback(
        name, [&text] { text = "on"; }, help);
    return;
  }
  cmd.add_option(name, text, help)->type_name(type_name(spec.type))->check(table_check(spec));
}

}  // namespace

void add_common_options(CLI::App& cmd, CommonOptions& o) {
  cmd.add_option("scene", o.scene, "scene file or builtin:NAME (default builtin:cornell)");
  add_render_option(cmd, o, *find_render_option("mode"));
  cmd.add_option("--width", o.width, "image width (overrides the scene)")
      ->check(CLI::Range(1, kMaxImageSize));
  cmd.add_option("--height", o.height, "image height (overrides the scene)")
      ->check(CLI::Range(1, kMaxImageSize));
  cmd.add_option("--image", o.image, "image size WxH, e.g. 800x600 (overrides the scene)")
      ->excludes(cmd.get_option("--width"))
      ->excludes(cmd.get_option("--height"));
  cmd.add_option("--camera-from", o.camera_from,
                 "X,Y,Z: look at the scene's (or model's) bounding sphere from this direction, "
                 "framing it (replaces the scene's camera)");
  cmd.add_option("--exposure", o.exposure,
                 "EV: multiply every renderer's linear colour by 2^EV after shading (replaces the "
                 "scene's, or a model file's automatic exposure)")
      ->check(CLI::Range(-kMaxExposure, kMaxExposure));
  cmd.add_option("--up", o.up,
                 "model files: the up axis of the file's coordinates, turned to +y: auto (the "
                 "file's metadata; +y where it has none) | y | z")
      ->check(one_of({"auto", "y", "z"}));
  cmd.add_option("--camera", o.camera,
                 "model files: file (the file's own camera where it frames the model) | auto "
                 "(the framing camera) | file-always (the file's own camera whatever it shows)")
      ->check(one_of({"file", "auto", "file-always"}));
  cmd.add_option("--lights", o.lights,
                 "model files: file (the file's own lights where it has them) | auto (the "
                 "default key light and ambient)")
      ->check(one_of({"file", "auto"}));
  cmd.add_option("--spp", o.spp, "samples per pixel (overrides the scene)")
      ->check(CLI::Range(1, 65536));
  for (const RenderOptionSpec& spec : render_option_table())
    if (spec.name != "mode") add_render_option(cmd, o, spec);
  cmd.add_option("--gl", o.gl,
                 "raster GL back end: osmesa | egl (default osmesa, egl when OSMesa is missing)")
      ->check(one_of(gl_backend_names()));
  cmd.add_flag("--quiet,-q", o.quiet, "no progress output");
  cmd.add_option("--max-samples", o.limits.max_samples,
                 "refuse more than N pixels x samples (default 2^30)")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--max-triangles", o.limits.max_triangles,
                 "refuse more than N triangles, tessellation included (default 50000000)")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--max-memory-mb", o.max_memory_mb,
                 "refuse renders estimated to need more MiB (default 3/4 of physical memory)")
      ->check(CLI::PositiveNumber);
}

GlBackend gl_backend(const CommonOptions& o) {
  return parse_gl_backend(o.gl).value_or(GlBackend::Default);
}

RenderMode parse_mode(const std::string& s) {
  if (s == "visibility") return RenderMode::Visibility;
  if (s == "full") return RenderMode::Full;
  return RenderMode::Local;
}

RenderOptions render_options(const CommonOptions& o, const std::string& default_mode) {
  RenderOptions r;
  check(set_render_option(r, *find_render_option("mode"), default_mode));
  for (const RenderOptionSpec& spec : render_option_table()) {
    const auto it = o.render_option_text.find(std::string(spec.name));
    if (it != o.render_option_text.end() && it->second)
      check(set_render_option(r, spec, *it->second));  // checked by CLI11 already
  }
  return r;
}

std::vector<std::string> given_render_options(const CommonOptions& o) {
  std::vector<std::string> given;
  for (const RenderOptionSpec& spec : render_option_table()) {
    const auto it = o.render_option_text.find(std::string(spec.name));
    if (it != o.render_option_text.end() && it->second) given.emplace_back(spec.name);
  }
  return given;
}

namespace {

// "X,Y,Z" as three finite numbers, not all zero.
glm::vec3 parse_direction(const std::string& text) {
  glm::vec3 d;
  char end = 0;
  if (std::sscanf(text.c_str(), " %f , %f , %f %c", &d.x, &d.y, &d.z, &end) != 3 ||
      !std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z) ||
      !(glm::length(d) > 0.0f)) {
    fail(bad_input("--camera-from: expected a direction X,Y,Z (not all zero), got '" + text + "'"));
  }
  return d;
}

// "WxH", each in [1, kMaxImageSize].
std::pair<int, int> parse_image_size(const std::string& text) {
  int w = 0, h = 0;
  char end = 0;
  if (std::sscanf(text.c_str(), " %d x %d %c", &w, &h, &end) != 2 || w < 1 || h < 1 ||
      w > kMaxImageSize || h > kMaxImageSize) {
    fail(bad_input(fmt::format("--image: expected WIDTHxHEIGHT, each 1 to {}, got '{}'",
                               kMaxImageSize, text)));
  }
  return {w, h};
}

}  // namespace

Scene load(const CommonOptions& o, const RenderOptions& options, double& load_seconds) {
  SceneRequest request;
  request.spec = o.scene;
  SceneOverrides& overrides = request.overrides;
  overrides.width = o.width;
  overrides.height = o.height;
  if (!o.image.empty()) std::tie(overrides.width, overrides.height) = parse_image_size(o.image);
  if (!o.camera_from.empty()) overrides.view_from = parse_direction(o.camera_from);
  overrides.exposure = o.exposure;
  overrides.up = o.up == "z" ? UpAxis::Z : o.up == "y" ? UpAxis::Y : UpAxis::Auto;
  overrides.camera = o.camera == "auto" ? FromFile::Auto : FromFile::File;
  overrides.judge_file_camera = o.camera != "file-always";
  overrides.lights = o.lights == "auto" ? FromFile::Auto : FromFile::File;
  request.spp = o.spp;
  request.limits = o.limits;
  request.limits.max_memory_bytes = std::min<uint64_t>(o.max_memory_mb, uint64_t(1) << 40) << 20;
  return take(load_scene_for_render(request, options, &load_seconds));
}

}  // namespace rvr::cli
