// The render option table (rvr/core/render_option_table.h): its checks refuse exactly what lies
// outside each range or list, its readers are the renderers that read the option (a renderer it
// does not name renders the same image whatever the option's value), and docs/cli.md's rows say
// what the table says.
#include <gtest/gtest.h>
#include <stddef.h>

#include <algorithm>
#include <fstream>
#include <initializer_list>
#include <memory>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/render_option_table.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/scene_loader.h"
#include "same_bytes.h"

namespace rvr {
namespace {

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

TEST(RenderOptionTable, NamesAreSnakeCaseAndUnique) {
  std::set<std::string_view> names;
  for (const RenderOptionSpec& spec : render_option_table()) {
    EXPECT_TRUE(names.insert(spec.name).second) << spec.name;
    EXPECT_TRUE(std::all_of(spec.name.begin(), spec.name.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || c == '_';
    })) << spec.name;
    EXPECT_FALSE(spec.help.empty()) << spec.name;
    EXPECT_EQ(find_render_option(spec.name), &spec);
  }
  EXPECT_EQ(cli_option_name(*find_render_option("shadow_map_size")), "--shadow-map-size");
  EXPECT_EQ(find_render_option("no_such_option"), nullptr);
}

// A range takes both its ends and refuses the whole numbers just outside them, with the
// message the command line and the Python module print after the option's name.
TEST(RenderOptionTable, RangesTakeTheirEndsAndRefuseBeyond) {
  for (const RenderOptionSpec& spec : render_option_table()) {
    if (spec.type != OptionType::Integer) continue;
    for (double end : {spec.min, spec.max}) {
      RenderOptions o;
      ASSERT_TRUE(set_render_option(o, spec, number(end))) << spec.name;
      EXPECT_EQ(spec.show(o), number(end)) << spec.name;
    }
    const std::string range = "must be " + number(spec.min) + " to " + number(spec.max);
    for (double outside : {spec.min - 1, spec.max + 1}) {
      RenderOptions o;
      const Status s = set_render_option(o, spec, number(outside));
      ASSERT_FALSE(s) << spec.name << " " << outside;
      EXPECT_EQ(s.error().message, range + ", got " + number(outside));
      EXPECT_EQ(spec.show(o), default_text(spec)) << "a refused value is not stored";
    }
    RenderOptions o;
    EXPECT_FALSE(set_render_option(o, spec, "12x")) << spec.name;
  }
  const RenderOptionSpec& bias = *find_render_option("shadow_bias");
  RenderOptions o;
  EXPECT_TRUE(set_render_option(o, bias, "10"));
  EXPECT_EQ(o.shadow_bias, 10.0f);
  EXPECT_EQ(set_render_option(o, bias, "10.5").error().message, "must be 0 to 10, got 10.5");
  EXPECT_FALSE(set_render_option(o, bias, "nan"));
  EXPECT_FALSE(set_render_option(o, bias, "-0.5"));
  EXPECT_TRUE(set_render_option(o, *find_render_option("seed"), "18446744073709551615"));
  EXPECT_EQ(o.seed, 18446744073709551615ull);
}

// Every choice is stored as the value show() names back; a name not in the list is refused.
TEST(RenderOptionTable, ChoicesRoundTrip) {
  for (const RenderOptionSpec& spec : render_option_table()) {
    if (spec.type != OptionType::Choice) continue;
    for (std::string_view choice : spec.choices) {
      RenderOptions o;
      ASSERT_TRUE(set_render_option(o, spec, choice)) << spec.name << " " << choice;
      EXPECT_EQ(spec.show(o), choice) << spec.name;
    }
    RenderOptions o;
    EXPECT_EQ(set_render_option(o, spec, "zzzz").error().message.rfind("'zzzz' is not one of ", 0),
              0u);
  }
  RenderOptions o;
  ASSERT_TRUE(set_render_option(o, *find_render_option("accel"), "none"));
  EXPECT_EQ(o.accel, AccelKind::None);
  ASSERT_TRUE(set_render_option(o, *find_render_option("hiz"), "off"));
  EXPECT_FALSE(o.hiz);
  ASSERT_TRUE(set_render_option(o, *find_render_option("depth_format"), "d32f_reversed"));
  EXPECT_EQ(o.depth_format, DepthFormat::D32FReversed);
  ASSERT_TRUE(set_render_option(o, *find_render_option("shadow_pcf"), "on"));
  EXPECT_TRUE(o.shadow_pcf);
}

TEST(RenderOptionTable, ReadersAreRenderers) {
  std::set<std::string> names;
  for (const RendererInfo& r : renderers()) names.insert(r.name);
  for (const RenderOptionSpec& spec : render_option_table())
    for (std::string_view reader : spec.readers)
      EXPECT_TRUE(names.count(std::string(reader))) << spec.name << ": " << reader;
  EXPECT_EQ(unread_option_warnings({"shadow_map_size", "accel"}, "raytrace", true),
            std::vector<std::string>{"option --shadow-map-size is not read by raytrace"});
  EXPECT_EQ(unread_option_warnings({"accel"}, "softraster", false),
            std::vector<std::string>{"option accel is not read by softraster"});
}

// A value other than the default: the first other choice, the range's other end, on.
std::string other_value(const RenderOptionSpec& spec) {
  const std::string standard = default_text(spec);
  switch (spec.type) {
    case OptionType::Choice:
      for (std::string_view c : spec.choices)
        if (c != standard) return std::string(c);
      break;
    case OptionType::Integer:
      return number(standard == number(spec.min) ? spec.max : spec.min);
    case OptionType::Real:
      return number(spec.max);
    case OptionType::Unsigned:
      return "12345";
    case OptionType::Flag:
      return "on";
  }
  return standard;
}

using rvr::test::same_bytes;

// text in Markdown code quotes. (Built by append: g++ 12 warns -Wrestrict, wrongly, on
// "`" + std::string&& once inlined.)
std::string quoted_code(const std::string& text) {
  std::string out = "`";
  out.append(text).append("`");
  return out;
}

bool same_image(const FrameBuffers& a, const FrameBuffers& b) {
  return same_bytes(a.colour, b.colour) && same_bytes(a.depth, b.depth) &&
         same_bytes(a.object_id, b.object_id) && same_bytes(a.primitive_id, b.primitive_id) &&
         same_bytes(a.normal, b.normal) && same_bytes(a.lod, b.lod);
}

// What the table says a renderer does not read changes nothing it renders: every buffer but the
// cost (work, which threads may split differently) is byte for byte the default's.
TEST(RenderOptionTable, ARendererTheTableDoesNotNameIgnoresTheOption) {
  for (const char* scene_name : {"spheres", "textured", "glass"}) {
    Scene scene = make_builtin_scene(scene_name).value();
    scene.image.width = 40;
    scene.image.height = 30;
    for (const RendererInfo& info : renderers()) {
      Expected<std::unique_ptr<Renderer>> renderer = make_renderer(info.name, RendererConfig{});
      if (!renderer) continue;  // e.g. embree where Embree is not installed
      RenderOptions standard;
      standard.mode = RenderMode::Full;
      standard.threads = 2;
      standard.cube_map_size = 32;  // glass's faces at a fraction of the default's cost
      const FrameBuffers expected = (*renderer)->render(scene, standard).value().buffers;
      for (const RenderOptionSpec& spec : render_option_table()) {
        if (reads_option(spec, info.name) || spec.name == "mode") continue;
        RenderOptions changed = standard;
        ASSERT_TRUE(set_render_option(changed, spec, other_value(spec)));
        const FrameBuffers got = (*renderer)->render(scene, changed).value().buffers;
        EXPECT_TRUE(same_image(got, expected))
            << info.name << " renders " << scene_name << " differently with " << spec.name << " "
            << other_value(spec) << ": the table says it does not read it";
      }
    }
  }
}

// docs/cli.md's row of every option: its name, choices (`--accel bvh\|bvh2\|none`), range
// ("16 … 8192") and default are the table's. Rows of options outside the table are the scene
// overrides and limits the command line handles itself.
TEST(RenderOptionTable, DocsRowsSayWhatTheTableSays) {
  std::ifstream in(std::string(RVR_SOURCE_DIR) + "/docs/cli.md");
  ASSERT_TRUE(in) << "docs/cli.md";
  std::stringstream text;
  text << in.rdbuf();
  const std::string doc = text.str();
  const size_t from = doc.find("## Options shared by `render` and `compare`");
  ASSERT_NE(from, std::string::npos);
  const size_t to = doc.find("\n## ", from + 1);
  std::istringstream section(doc.substr(from, to - from));
  std::set<std::string> documented;
  for (std::string line; std::getline(section, line);) {
    if (line.rfind("| `--", 0) != 0) continue;
    // | `--name VALUES` | default | meaning |
    const size_t name_end = line.find_first_of(" `", 5);
    const std::string name = line.substr(5, name_end - 5);
    documented.insert(name);
    const size_t cell_end = line.find("` |");
    const std::string values = line.substr(name_end, cell_end - name_end);
    const size_t default_end = line.find(" |", cell_end + 3);
    const std::string standard = line.substr(cell_end + 4, default_end - cell_end - 4);
    const std::string meaning = line.substr(default_end + 3);
    std::string snake = name;
    std::replace(snake.begin(), snake.end(), '-', '_');
    const RenderOptionSpec* spec = find_render_option(snake);
    if (!spec) {
      static const std::set<std::string> cli_only = {
          "width",    "image", "camera-from", "camera",      "lights",        "up",
          "exposure", "spp",   "gl",          "max-samples", "max-triangles", "max-memory-mb"};
      EXPECT_TRUE(cli_only.count(name))
          << "docs/cli.md documents --" << name << ", which the render option table lacks";
      continue;
    }
    SCOPED_TRACE(line);
    if (spec->type == OptionType::Choice) {
      std::string choices;
      for (std::string_view c : spec->choices)
        choices += (choices.empty() ? " " : "\\|") + std::string(c);
      EXPECT_EQ(values, choices) << "--" << name << "'s choices";
    }
    if (spec->type == OptionType::Integer || spec->type == OptionType::Real) {
      EXPECT_NE(meaning.find(number(spec->min) + " … " + number(spec->max)), std::string::npos)
          << "--" << name << "'s range";
    }
    const std::string expected_default = spec->name == "mode" ? "`full` (render), `local` (compare)"
                                         : default_text(*spec).empty() ? "the most precise"
                                         : spec->type == OptionType::Choice
                                             ? quoted_code(default_text(*spec))
                                             : default_text(*spec);
    EXPECT_EQ(standard, expected_default) << "--" << name << "'s default";
  }
  for (const RenderOptionSpec& spec : render_option_table()) {
    std::string kebab = cli_option_name(spec).substr(2);
    EXPECT_TRUE(documented.count(kebab)) << "docs/cli.md has no row for --" << kebab;
  }
}

}  // namespace
}  // namespace rvr
