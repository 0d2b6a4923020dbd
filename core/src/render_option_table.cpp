#include "rvr/core/render_option_table.h"

#include <algorithm>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <system_error>
#include <utility>

#include "rvr/core/image_sample.h"
#include "rvr/core/isa.h"
#include "rvr/core/texture.h"

namespace rvr {
namespace {

// Who reads what: the z-buffers draw, the tracers trace, the hybrids run a z-buffer for what the
// eye sees (raster's GL, softraster's own) and the tracer for everything after it.
const std::vector<std::string_view> kEveryRenderer = {"raster", "softraster", "raytrace",
                                                      "embree", "hybrid",     "hybrid_soft"};
const std::vector<std::string_view> kZBuffers = {"raster", "softraster"};
const std::vector<std::string_view> kTracersAndHybrids = {"raytrace", "embree", "hybrid",
                                                          "hybrid_soft"};

template <class Number>
std::string number_text(Number value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

std::string choice_text(const std::vector<std::string_view>& choices, size_t index) {
  return std::string(choices.at(index));
}

const std::vector<std::string_view> kModes = {"visibility", "local", "full"};
const std::vector<std::string_view> kAccels = {"bvh", "bvh2", "none"};
const std::vector<std::string_view> kSpheres = {"analytic", "mesh"};
const std::vector<std::string_view> kTriangleTests = {"mt", "chapter"};
const std::vector<std::string_view> kTextureLods = {"cones", "differentials", "none"};
const std::vector<std::string_view> kDepthFormats = {"d24", "d32f", "d32f_reversed"};
const std::vector<std::string_view> kSupersamplings = {"accumulation", "msaa"};
const std::vector<std::string_view> kZBufferDofs = {"accumulation", "blur"};
const std::vector<std::string_view> kZBufferReflections = {"cube_map", "ssr"};
const std::vector<std::string_view> kOnOff = {"on", "off"};

// Each entry's store and show convert between the table's values and RenderOptions' members;
// a choice's index is its enumerator's value (the choices are listed in enumerator order).
using O = RenderOptions;
using U = unsigned long long;

// What every renderer reads, or all but the one that hands it to someone else.
std::vector<RenderOptionSpec> general_options() {
  return {
      {.name = "mode",
       .type = OptionType::Choice,
       .choices = kModes,
       .help = "visibility | local | full",
       .readers = kEveryRenderer,
       .store = [](O& o, U i, double) { o.mode = RenderMode(i); },
       .show = [](const O& o) { return choice_text(kModes, size_t(o.mode)); }},
      {.name = "threads",
       .type = OptionType::Integer,
       .min = 0,
       .max = 1024,
       .help = "worker threads, 0 = every core",
       // raster: llvmpipe has threads of its own (LP_NUM_THREADS).
       .readers = {"softraster", "raytrace", "embree", "hybrid", "hybrid_soft"},
       .store = [](O& o, U v, double) { o.threads = int(v); },
       .show = [](const O& o) { return std::to_string(o.threads); }},
  };
}

// The tracers' (and so the hybrids', after their z-buffer's primary hits).
std::vector<RenderOptionSpec> tracer_options() {
  return {
      {.name = "accel",
       .type = OptionType::Choice,
       .choices = kAccels,
       .help = "tracer acceleration: bvh (wide SIMD BVH, default) | bvh2 (binary, one box at a "
               "time) | none (every object for every ray)",
       .readers = {"raytrace", "hybrid", "hybrid_soft"},  // embree is its own
       .store = [](O& o, U i, double) { o.accel = AccelKind(i); },
       .show = [](const O& o) { return choice_text(kAccels, size_t(o.accel)); }},
      {.name = "spheres",
       .type = OptionType::Choice,
       .choices = kSpheres,
       .help = "spheres and discs: analytic | mesh (the z-buffers' tessellation, traced as "
               "triangles, its facets named alike in the primitive ids)",
       .readers = kEveryRenderer,
       .store = [](O& o, U i, double) { o.spheres = SphereMode(i); },
       .show = [](const O& o) { return choice_text(kSpheres, size_t(o.spheres)); }},
      {.name = "sphere_segments",
       .type = OptionType::Integer,
       .min = 3,
       .max = 4096,
       .help = "sphere tessellation: longitudes",
       .readers = kEveryRenderer,
       .store = [](O& o, U v, double) { o.sphere_segments = int(v); },
       .show = [](const O& o) { return std::to_string(o.sphere_segments); }},
      {.name = "triangle_test",
       .type = OptionType::Choice,
       .choices = kTriangleTests,
       .help = "tracer ray-triangle test: mt (Moller-Trumbore) | chapter (plane, then edges)",
       .readers = {"raytrace", "hybrid", "hybrid_soft"},  // Embree has its own test
       .store = [](O& o, U i, double) { o.triangle_test = TriangleTest(i); },
       .show = [](const O& o) { return choice_text(kTriangleTests, size_t(o.triangle_test)); }},
      {.name = "texture_lod",
       .type = OptionType::Choice,
       .choices = kTextureLods,
       .help = "tracers' texture level of detail: cones (ray cones, default) | differentials "
               "(ray differentials) | none (level 0, bilinear)",
       .readers = kTracersAndHybrids,
       .store = [](O& o, U i, double) { o.texture_lod = TextureLod(i); },
       .show = [](const O& o) { return choice_text(kTextureLods, size_t(o.texture_lod)); }},
      {.name = "max_depth",
       .type = OptionType::Integer,
       .min = 0,
       .max = 64,
       .help = "recursion limit for bounce rays (and the z-buffers' planar mirror views)",
       .readers = {"raytrace", "embree", "hybrid", "hybrid_soft", "raster", "softraster"},
       .store = [](O& o, U v, double) { o.max_depth = int(v); },
       .show = [](const O& o) { return std::to_string(o.max_depth); }},
      {.name = "seed",
       .type = OptionType::Unsigned,
       .help = "seed of the per-pixel random streams",
       .readers = kTracersAndHybrids,
       .store = [](O& o, U v, double) { o.seed = v; },
       .show = [](const O& o) { return std::to_string(o.seed); }},
  };
}

// The z-buffers' (the hybrids' for what their z-buffer does: visibility, no shadow maps).
std::vector<RenderOptionSpec> zbuffer_options() {
  return {
      {.name = "shadow_map_size",
       .type = OptionType::Integer,
       .min = 16,
       .max = 8192,
       .help = "raster shadow maps: texels per side",
       .readers = kZBuffers,
       .store = [](O& o, U v, double) { o.shadow_map_size = int(v); },
       .show = [](const O& o) { return std::to_string(o.shadow_map_size); }},
      {.name = "cube_map_size",
       .type = OptionType::Integer,
       .min = 0,
       .max = 4096,
       .help = "z-buffers' curved mirrors and refraction: texels per side of each object's cube "
               "environment map (0: not rendered, local colour only)",
       .readers = kZBuffers,
       .store = [](O& o, U v, double) { o.cube_map_size = int(v); },
       .show = [](const O& o) { return std::to_string(o.cube_map_size); }},
      {.name = "shadow_bias",
       .type = OptionType::Real,
       .min = 0,
       .max = 10,
       .help = "raster shadow maps: depth bias (scene units)",
       .readers = kZBuffers,
       .store = [](O& o, U, double v) { o.shadow_bias = float(v); },
       .show = [](const O& o) { return number_text(o.shadow_bias); }},
      {.name = "shadow_pcf",
       .type = OptionType::Flag,
       .help = "raster shadow maps: 3x3 percentage-closer filtering",
       .readers = kZBuffers,
       .store = [](O& o, U v, double) { o.shadow_pcf = v != 0; },
       .show = [](const O& o) { return std::string(o.shadow_pcf ? "on" : "off"); }},
      {.name = "hiz",
       .type = OptionType::Choice,
       .choices = kOnOff,
       .help = "softraster: hierarchical z, each 8x8 block's farthest depth rejecting what lies "
               "behind it: on | off (the textbook z-buffer)",
       .readers = {"softraster", "hybrid_soft"},
       .store = [](O& o, U i, double) { o.hiz = i == 0; },
       .show = [](const O& o) { return choice_text(kOnOff, o.hiz ? 0 : 1); }},
      {.name = "depth_format",
       .type = OptionType::Choice,
       .choices = kDepthFormats,
       .help = "rasterizers' z-buffer: d24 | d32f | d32f_reversed (default: the most precise "
               "the renderer has)",
       .readers = {"raster", "softraster", "hybrid", "hybrid_soft"},
       .store = [](O& o, U i, double) { o.depth_format = DepthFormat(i); },
       .show =
           [](const O& o) {
             return o.depth_format ? choice_text(kDepthFormats, size_t(*o.depth_format))
                                   : std::string();
           }},
      {.name = "supersampling",
       .type = OptionType::Choice,
       .choices = kSupersamplings,
       .help = "raster with samples_per_pixel > 1: accumulation (a pass per sample of the "
               "tracer's set, lens included: default) | msaa (one multisampled pass, pinhole)",
       .readers = {"raster"},
       .store = [](O& o, U i, double) { o.supersampling = Supersampling(i); },
       .show = [](const O& o) { return choice_text(kSupersamplings, size_t(o.supersampling)); }},
      {.name = "zbuffer_dof",
       .type = OptionType::Choice,
       .choices = kZBufferDofs,
       .help = "z-buffers' depth of field: accumulation (a pass per lens sample: default) | blur "
               "(one pinhole pass blurred by each pixel's circle of confusion)",
       .readers = kZBuffers,
       .store = [](O& o, U i, double) { o.zbuffer_dof = ZBufferDof(i); },
       .show = [](const O& o) { return choice_text(kZBufferDofs, size_t(o.zbuffer_dof)); }},
      {.name = "zbuffer_reflection",
       .type = OptionType::Choice,
       .choices = kZBufferReflections,
       .help = "z-buffers' curved mirrors: cube_map (a cube environment map per mirror: "
               "default) | ssr (screen-space reflections over the camera's frame)",
       .readers = kZBuffers,
       .store = [](O& o, U i, double) { o.zbuffer_reflection = ZBufferReflection(i); },
       .show =
           [](const O& o) {
             return choice_text(kZBufferReflections, size_t(o.zbuffer_reflection));
           }},
  };
}

std::vector<RenderOptionSpec> make_table() {
  std::vector<RenderOptionSpec> table = general_options();
  for (auto part : {tracer_options, zbuffer_options})
    for (RenderOptionSpec& spec : part()) table.push_back(std::move(spec));
  return table;
}

std::string range_error(const RenderOptionSpec& spec, std::string_view got) {
  return "must be " + number_text(spec.min) + " to " + number_text(spec.max) + ", got " +
         std::string(got);
}

// 'text', for messages.
std::string quoted(std::string_view text) {
  std::string q(1, '\'');
  q.append(text);
  q += '\'';
  return q;
}

std::optional<unsigned long long> parse_flag(std::string_view text) {
  if (text == "true" || text == "on" || text == "1") return 1;
  if (text == "false" || text == "off" || text == "0") return 0;
  return std::nullopt;
}

template <class T>
std::optional<T> parse_whole(std::string_view text) {
  T value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

}  // namespace

const std::vector<RenderOptionSpec>& render_option_table() {
  static const std::vector<RenderOptionSpec> table = make_table();
  return table;
}

const RenderOptionSpec* find_render_option(std::string_view name) {
  for (const RenderOptionSpec& spec : render_option_table())
    if (spec.name == name) return &spec;
  return nullptr;
}

std::string cli_option_name(const RenderOptionSpec& spec) {
  std::string name = "--" + std::string(spec.name);
  std::replace(name.begin(), name.end(), '_', '-');
  return name;
}

std::string default_text(const RenderOptionSpec& spec) {
  return spec.show(RenderOptions{});
}

Status set_render_option(RenderOptions& options, const RenderOptionSpec& spec,
                         std::string_view text) {
  switch (spec.type) {
    case OptionType::Integer: {
      const std::optional<long long> v = parse_whole<long long>(text);
      if (!v) return bad_input("expected a whole number, got " + quoted(text));
      if (double(*v) < spec.min || double(*v) > spec.max) return bad_input(range_error(spec, text));
      spec.store(options, static_cast<unsigned long long>(*v), 0);
      break;
    }
    case OptionType::Unsigned: {
      const std::optional<unsigned long long> v = parse_whole<unsigned long long>(text);
      if (!v) return bad_input("expected a whole number >= 0, got " + quoted(text));
      spec.store(options, *v, 0);
      break;
    }
    case OptionType::Real: {
      double v = 0;
      const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), v);
      if (error != std::errc() || end != text.data() + text.size())
        return bad_input("expected a number, got " + quoted(text));
      if (!(v >= spec.min && v <= spec.max)) return bad_input(range_error(spec, text));
      spec.store(options, 0, v);
      break;
    }
    case OptionType::Flag: {
      const std::optional<unsigned long long> v = parse_flag(text);
      if (!v) return bad_input("expected on or off, got " + quoted(text));
      spec.store(options, *v, 0);
      break;
    }
    case OptionType::Choice: {
      const auto it = std::find(spec.choices.begin(), spec.choices.end(), text);
      if (it == spec.choices.end()) {
        std::string known;
        for (std::string_view c : spec.choices)
          known += (known.empty() ? "" : ", ") + std::string(c);
        return bad_input(quoted(text) + " is not one of " + known);
      }
      spec.store(options, static_cast<unsigned long long>(it - spec.choices.begin()), 0);
      break;
    }
  }
  return ok_status();
}

bool reads_option(const RenderOptionSpec& spec, std::string_view renderer) {
  return std::find(spec.readers.begin(), spec.readers.end(), renderer) != spec.readers.end();
}

std::vector<std::string> unread_option_warnings(const std::vector<std::string>& given,
                                                std::string_view renderer, bool cli_names) {
  std::vector<std::string> warnings;
  for (const RenderOptionSpec& spec : render_option_table()) {
    if (std::find(given.begin(), given.end(), spec.name) == given.end()) continue;
    if (reads_option(spec, renderer)) continue;
    warnings.push_back("option " + (cli_names ? cli_option_name(spec) : std::string(spec.name)) +
                       " is not read by " + std::string(renderer));
  }
  return warnings;
}

}  // namespace rvr
