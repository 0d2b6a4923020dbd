#include "rvr/core/render_option_table.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <optional>
#include <system_error>

#include "rvr/core/texture.h"

namespace rvr {
namespace {

// Who reads what: the z-buffers draw, the tracers trace, the hybrids run a z-buffer for what the
// eye sees (raster's GL, softraster's own) and the tracer for everything after it.
const std::vector<std::string_view> kEveryRenderer = {"raster",  "softraster", "raytrace",
                                                      "embree",  "hybrid",     "hybrid_soft"};
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
const std::vector<std::string_view> kOnOff = {"on", "off"};

// Each entry's store and show convert between the table's values and RenderOptions' members;
// a choice's index is its enumerator's value (the choices are listed in enumerator order).
std::vector<RenderOptionSpec> make_table() {
  using O = RenderOptions;
  using U = unsigned long long;
  return {
      {"mode", OptionType::Choice, 0, 0, kModes, "visibility | local | full", kEveryRenderer,
       [](O& o, U i, double) { o.mode = RenderMode(i); },
       [](const O& o) { return choice_text(kModes, size_t(o.mode)); }},
      {"threads", OptionType::Integer, 0, 1024, {}, "worker threads, 0 = every core",
       {"softraster", "raytrace", "embree", "hybrid", "hybrid_soft"},
       [](O& o, U v, double) { o.threads = int(v); },
       [](const O& o) { return std::to_string(o.threads); }},
      {"accel", OptionType::Choice, 0, 0, kAccels,
       "tracer acceleration: bvh (wide SIMD BVH, default) | bvh2 (binary, one box at a time) | "
       "none (every object for every ray)",
       {"raytrace", "hybrid", "hybrid_soft"}, [](O& o, U i, double) { o.accel = AccelKind(i); },
       [](const O& o) { return choice_text(kAccels, size_t(o.accel)); }},
      {"spheres", OptionType::Choice, 0, 0, kSpheres,
       "spheres: analytic | mesh (the z-buffers' tessellation, traced as triangles, its facets "
       "named alike in the primitive ids)",
       kEveryRenderer,
       [](O& o, U i, double) { o.spheres = SphereMode(i); },
       [](const O& o) { return choice_text(kSpheres, size_t(o.spheres)); }},
      {"sphere_segments", OptionType::Integer, 3, 4096, {}, "sphere tessellation: longitudes",
       kEveryRenderer, [](O& o, U v, double) { o.sphere_segments = int(v); },
       [](const O& o) { return std::to_string(o.sphere_segments); }},
      {"triangle_test", OptionType::Choice, 0, 0, kTriangleTests,
       "tracer ray-triangle test: mt (Moller-Trumbore) | chapter (plane, then edges)",
       {"raytrace", "hybrid", "hybrid_soft"},
       [](O& o, U i, double) { o.triangle_test = TriangleTest(i); },
       [](const O& o) { return choice_text(kTriangleTests, size_t(o.triangle_test)); }},
      {"texture_lod", OptionType::Choice, 0, 0, kTextureLods,
       "tracers' texture level of detail: cones (ray cones, default) | differentials (ray "
       "differentials) | none (level 0, bilinear)",
       kTracersAndHybrids, [](O& o, U i, double) { o.texture_lod = TextureLod(i); },
       [](const O& o) { return choice_text(kTextureLods, size_t(o.texture_lod)); }},
      {"max_depth", OptionType::Integer, 0, 64, {}, "recursion limit for bounce rays",
       kTracersAndHybrids, [](O& o, U v, double) { o.max_depth = int(v); },
       [](const O& o) { return std::to_string(o.max_depth); }},
      {"seed", OptionType::Unsigned, 0, 0, {}, "seed of the per-pixel random streams",
       kTracersAndHybrids, [](O& o, U v, double) { o.seed = v; },
       [](const O& o) { return std::to_string(o.seed); }},
      {"shadow_map_size", OptionType::Integer, 16, 8192, {}, "raster shadow maps: texels per side",
       kZBuffers, [](O& o, U v, double) { o.shadow_map_size = int(v); },
       [](const O& o) { return std::to_string(o.shadow_map_size); }},
      {"shadow_bias", OptionType::Real, 0, 10, {}, "raster shadow maps: depth bias (scene units)",
       kZBuffers, [](O& o, U, double v) { o.shadow_bias = float(v); },
       [](const O& o) { return number_text(o.shadow_bias); }},
      {"shadow_pcf", OptionType::Flag, 0, 0, {},
       "raster shadow maps: 3x3 percentage-closer filtering", kZBuffers,
       [](O& o, U v, double) { o.shadow_pcf = v != 0; },
       [](const O& o) { return std::string(o.shadow_pcf ? "on" : "off"); }},
      {"hiz", OptionType::Choice, 0, 0, kOnOff,
       "softraster: hierarchical z, each 8x8 block's farthest depth rejecting what lies behind "
       "it: on | off (the textbook z-buffer)",
       {"softraster", "hybrid_soft"}, [](O& o, U i, double) { o.hiz = i == 0; },
       [](const O& o) { return choice_text(kOnOff, o.hiz ? 0 : 1); }},
      {"depth_format", OptionType::Choice, 0, 0, kDepthFormats,
       "rasterizers' z-buffer: d24 | d32f | d32f_reversed (default: the most precise the "
       "renderer has)",
       {"raster", "softraster", "hybrid", "hybrid_soft"},
       [](O& o, U i, double) { o.depth_format = DepthFormat(i); },
       [](const O& o) {
         return o.depth_format ? choice_text(kDepthFormats, size_t(*o.depth_format))
                               : std::string();
       }},
  };
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
      if (double(*v) < spec.min || double(*v) > spec.max)
        return bad_input(range_error(spec, text));
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
        for (std::string_view c : spec.choices) known += (known.empty() ? "" : ", ") + std::string(c);
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
