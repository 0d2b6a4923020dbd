// Every stat a renderer reports in RenderOutput::stats, declared once (as pbrt-v4 declares a
// statistic once with STAT_COUNTER): its name, what kind of number it is, its unit, which
// renderers report it and what it measures. How a stat is written (stat_kind), the `--stats`
// and metrics.json documents, and docs/cli.md's table of stats ("Every stat") all come from
// this table; tests/test_stats.cpp fails when a renderer reports a stat the table lacks or
// when docs/cli.md's table is not stats_markdown_table()'s.
#pragma once

#include <span>
#include <string>
#include <string_view>

namespace rvr {

// Counts (rays, nodes, tests, fragments, pixels, triangles, bytes: whole numbers, written as
// integers), the seconds of a phase, and ratios, averages or costs (written as numbers).
enum class StatKind { Count, Seconds, Ratio };

struct StatDeclaration {
  std::string_view name;  // flat, with dots: "rays.primary"
  StatKind kind;
  std::string_view unit;         // what one unit of it is: "rays", "s", "fragments per pixel"
  std::string_view reported_by;  // the renderers that report it, in docs/cli.md's words
  std::string_view measures;     // one sentence for the docs
};

// Every declared stat, in docs/cli.md's order.
std::span<const StatDeclaration> stat_declarations();

// The declaration of `name`; a hybrid's copy of its z-buffer's stats ("zbuffer." + name) is
// declared as the name is. Null for a name never declared.
const StatDeclaration* find_stat(std::string_view name);

// What kind of number `name` is (a count where it is not declared: an undeclared stat is a
// test failure, not a reason to drop a value).
StatKind stat_kind(std::string_view name);

// docs/cli.md's table of every stat, as Markdown rows under a header.
std::string stats_markdown_table();

}  // namespace rvr
