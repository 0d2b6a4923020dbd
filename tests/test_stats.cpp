// The declaration of every stat (rvr/core/stats.h) against what the renderers report and what
// docs/cli.md says: a stat a renderer reports but the table lacks, a declared stat no renderer
// reports any more, and a docs table that is not the declaration's fail here.
#include <gtest/gtest.h>
#include <stddef.h>

#include <fstream>
#include <initializer_list>
#include <map>
#include <memory>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/stats.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/scene_loader.h"

namespace rvr {
namespace {

TEST(StatsTable, NamesAreUniqueAndEachHasItsWords) {
  std::set<std::string> names;
  for (const StatDeclaration& s : stat_declarations()) {
    EXPECT_TRUE(names.insert(std::string(s.name)).second) << s.name << " declared twice";
    EXPECT_FALSE(s.unit.empty()) << s.name;
    EXPECT_FALSE(s.reported_by.empty()) << s.name;
    EXPECT_FALSE(s.measures.empty()) << s.name;
    EXPECT_EQ(s.name.find(' '), std::string::npos) << s.name;
  }
}

// A hybrid reports its z-buffer's stats under "zbuffer." + name, and raster's own
// "zbuffer.depth_bits" keeps its name under a hybrid as "zbuffer.zbuffer.depth_bits".
TEST(StatsTable, AZbufferCopyIsWhatItsNameIs) {
  ASSERT_NE(find_stat("time.setup"), nullptr);
  EXPECT_EQ(find_stat("zbuffer.time.setup"), find_stat("time.setup"));
  EXPECT_EQ(stat_kind("zbuffer.overdraw"), StatKind::Ratio);
  EXPECT_EQ(stat_kind("zbuffer.time.raster"), StatKind::Seconds);
  EXPECT_EQ(stat_kind("zbuffer.fragments.generated"), StatKind::Count);
  ASSERT_NE(find_stat("zbuffer.zbuffer.depth_bits"), nullptr);
  EXPECT_EQ(find_stat("zbuffer.zbuffer.depth_bits")->name, "zbuffer.depth_bits");
  EXPECT_EQ(find_stat("rays.none"), nullptr);
  EXPECT_EQ(find_stat("zbuffer."), nullptr);
  EXPECT_EQ(find_stat(""), nullptr);
}

// Every renderer and variant in every mode, on a scene with lights, mirrors and glass, on one
// with several samples per pixel (the hybrids' accumulation passes) and on one with a flat
// mirror (the z-buffers' reflected views), on one with CSG solids and on one with a pane of
// ior 1 (the views behind layers): each stat reported is declared, and each declared stat is
// reported by some renderer.
TEST(StatsTable, EveryStatReportedIsDeclaredAndEveryDeclaredOneReported) {
  std::set<std::string> reported;
  for (const char* scene_name : {"cornell", "dof", "discs", "csg", "glass"}) {
    Scene scene = make_builtin_scene(scene_name).value();
    scene.image.width = 32;
    scene.image.height = 24;
    for (const RendererChoice& choice : renderer_choices())
      for (RenderMode mode : {RenderMode::Visibility, RenderMode::Local, RenderMode::Full}) {
        RendererConfig config;
        RenderOptions options;
        options.mode = mode;
        options.cube_map_size = 16;  // the stats are the same at any size; small faces are quick
        choice.apply(config, options);
        Expected<std::unique_ptr<Renderer>> renderer = make_renderer(choice.info->name, config);
        ASSERT_TRUE(renderer.ok()) << choice.name << ": " << renderer.error().message;
        Expected<RenderOutput> out = (*renderer)->render(scene, options);
        ASSERT_TRUE(out.ok()) << choice.name << ": " << out.error().message;
        for (const auto& [name, value] : out->stats) {
          EXPECT_NE(find_stat(name), nullptr)
              << choice.name << " " << to_string(mode) << " reports '" << name
              << "', which core/src/stats.cpp does not declare";
          if (const StatDeclaration* s = find_stat(name)) reported.insert(std::string(s->name));
        }
      }
  }
  // The z-buffers' techniques an option chooses (not variants): depth of field by blur, and
  // screen-space reflections.
  auto add_technique = [&](const char* scene_name, const char* technique,
                           void (*choose)(RenderOptions&)) {
    Scene scene = make_builtin_scene(scene_name).value();
    scene.image.width = 32;
    scene.image.height = 24;
    for (const char* zbuffer : {"raster", "softraster"}) {
      RenderOptions options;
      options.mode = RenderMode::Full;
      options.cube_map_size = 16;
      choose(options);
      Expected<std::unique_ptr<Renderer>> renderer = make_renderer(zbuffer, RendererConfig{});
      ASSERT_TRUE(renderer.ok()) << zbuffer;
      Expected<RenderOutput> out = (*renderer)->render(scene, options);
      ASSERT_TRUE(out.ok()) << zbuffer << ": " << out.error().message;
      for (const auto& [name, value] : out->stats) {
        EXPECT_NE(find_stat(name), nullptr)
            << zbuffer << " with " << technique << " reports '" << name << "'";
        if (const StatDeclaration* s = find_stat(name)) reported.insert(std::string(s->name));
      }
    }
  };
  add_technique("dof", "a blur", [](RenderOptions& o) { o.zbuffer_dof = ZBufferDof::Blur; });
  add_technique("cornell", "screen-space reflections",
                [](RenderOptions& o) { o.zbuffer_reflection = ZBufferReflection::Ssr; });
  for (const StatDeclaration& s : stat_declarations())
    EXPECT_TRUE(reported.count(std::string(s.name)))
        << "'" << s.name << "' is declared, but no renderer reported it";
}

// metrics.json's schema tells seconds and ratios from counts by name: every declared
// seconds stat is a "time." one, and its pattern of ratios names the declared ratios.
TEST(StatsTable, TheMetricsSchemaKnowsTheDeclaredKinds) {
  std::string ratios;
  for (const StatDeclaration& s : stat_declarations()) {
    if (s.kind == StatKind::Seconds) {
      EXPECT_EQ(s.name.substr(0, 5), "time.") << s.name;
    }
    if (s.kind != StatKind::Ratio) continue;
    if (!ratios.empty()) ratios += "|";
    for (char c : s.name) ratios += c == '.' ? std::string("\\\\.") : std::string(1, c);
  }
  std::ifstream in(std::string(RVR_SOURCE_DIR) + "/docs/rvr-metrics-2.schema.json");
  ASSERT_TRUE(in) << "docs/rvr-metrics-2.schema.json";
  std::stringstream text;
  text << in.rdbuf();
  const std::string pattern = "\"^(zbuffer\\\\.)*(" + ratios + ")$\"";
  EXPECT_NE(text.str().find(pattern), std::string::npos)
      << "docs/rvr-metrics-2.schema.json has no pattern " << pattern;
}

// docs/cli.md's table of stats, between its two markers, is the declaration's table.
TEST(StatsTable, DocsShowTheDeclaration) {
  std::ifstream in(std::string(RVR_SOURCE_DIR) + "/docs/cli.md");
  ASSERT_TRUE(in) << "docs/cli.md";
  std::stringstream text;
  text << in.rdbuf();
  const std::string doc = text.str();
  const std::string begin = "<!-- stats table: core/src/stats.cpp -->\n";
  const std::string end = "<!-- end of the stats table -->\n";
  const size_t from = doc.find(begin);
  ASSERT_NE(from, std::string::npos) << "docs/cli.md has no '" << begin << "' marker";
  const size_t to = doc.find(end, from);
  ASSERT_NE(to, std::string::npos) << "docs/cli.md has no '" << end << "' marker";
  EXPECT_EQ(doc.substr(from + begin.size(), to - from - begin.size()), stats_markdown_table())
      << "paste the table this test prints as its expected value into docs/cli.md";
}

}  // namespace
}  // namespace rvr
