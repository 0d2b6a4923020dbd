// The pages' presentation kit (present/): escaping, the SVG elements, the charts' scales and
// ticks, and the page skeleton, against values worked out by hand.
#include <gtest/gtest.h>
#include <stddef.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "rvr/present/chart_axes.h"
#include "rvr/present/html_escape.h"
#include "rvr/present/page.h"
#include "rvr/present/powers_of_ten.h"
#include "rvr/present/svg.h"

namespace rvr::present {
namespace {

size_t occurrences(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(Present, EscapesTextAndAttributeValues) {
  EXPECT_EQ(escape_html("<a href=\"x\">R&D's</a>"),
            "&lt;a href=&quot;x&quot;&gt;R&amp;D&#39;s&lt;/a&gt;");
  const std::string svg = rect({{"data-renderer", "\"><script>"}}, 1, 2, 3, 4);
  EXPECT_EQ(svg,
            "<rect data-renderer=\"&quot;&gt;&lt;script&gt;\" x=\"1\" y=\"2\" width=\"3\" "
            "height=\"4\"/>");
  EXPECT_EQ(tooltip("a < b"), "<title>a &lt; b</title>");
}

TEST(Present, NumbersHaveAtMostTwoDecimals) {
  EXPECT_EQ(number(120), "120");
  EXPECT_EQ(number(7.5), "7.5");
  EXPECT_EQ(number(543.274), "543.27");
  EXPECT_EQ(number(-0.001), "0");
  EXPECT_EQ(number(-2.25), "-2.25");
}

TEST(Present, PathsBreakBetweenPieces) {
  EXPECT_EQ(path({{"class", "c"}}, {{{0, 1}, {2, 3}}, {{4, 5}}}),
            "<path class=\"c\" d=\"M0,1 L2,3 M4,5\"/>");
}

TEST(Present, ScalesMapTheirEndsAndMidpoints) {
  const Scale lin = Scale::linear(0, 10, 100, 300);
  EXPECT_DOUBLE_EQ(lin(0), 100);
  EXPECT_DOUBLE_EQ(lin(2.5), 150);
  EXPECT_DOUBLE_EQ(lin(10), 300);
  // A y axis drawn upwards: decades 10^-3 to 10^1 onto 400 (bottom) to 0 (top).
  const Scale log = Scale::log10(-3, 1, 400, 0);
  EXPECT_DOUBLE_EQ(log(1e-3), 400);
  EXPECT_NEAR(log(1e-1), 200, 1e-9);
  EXPECT_NEAR(log(std::sqrt(10.0)), 50, 1e-9);
}

TEST(Present, LinearTicksAreRoundSteps) {
  EXPECT_DOUBLE_EQ(nice_step(1.0), 0.2);
  EXPECT_DOUBLE_EQ(nice_step(0.146), 0.05);
  EXPECT_DOUBLE_EQ(nice_top(0.146), 0.15);
  EXPECT_DOUBLE_EQ(nice_step(12), 2.5);
  const std::vector<Tick> ticks = linear_ticks(0.146);
  ASSERT_EQ(ticks.size(), 4u);
  EXPECT_EQ(ticks[0].label, "0");
  EXPECT_EQ(ticks[3].label, "0.15");
}

TEST(Present, DecadeTicksLabelAtMostEightWithMinorsOnShortAxes) {
  // Four decades: 5 labelled, 8 minor ticks in each of the 4 decades.
  std::vector<Tick> ticks = decade_ticks(-2, 2);
  size_t labelled = 0, minor = 0;
  for (const Tick& t : ticks) {
    labelled += !t.label.empty();
    minor += t.minor;
  }
  EXPECT_EQ(labelled, 5u);
  EXPECT_EQ(minor, 32u);
  EXPECT_NE(ticks.front().label.find("−2</tspan>"), std::string::npos) << ticks.front().label;
  // Twenty decades: every third labelled (ceil(20 / 8)), no minor ticks.
  ticks = decade_ticks(0, 20);
  labelled = minor = 0;
  for (const Tick& t : ticks) {
    labelled += !t.label.empty();
    minor += t.minor;
  }
  EXPECT_EQ(ticks.size(), 21u);
  EXPECT_EQ(labelled, 7u);
  EXPECT_EQ(minor, 0u);
}

TEST(Present, TicksDrawAGridLineEachAndLabelTheLabelled) {
  const PlotArea area{100, 10, 500, 210};
  const std::string svg = x_ticks(Scale::linear(0, 4, area.left, area.right), area,
                                  {{0, "0"}, {1, ""}, {2, "2", false}, {3, "", true}});
  EXPECT_EQ(occurrences(svg, "<line class=\"gridline\""), 3u);
  EXPECT_EQ(occurrences(svg, "<line class=\"minor\" x1=\"400\""), 1u);
  EXPECT_EQ(occurrences(svg, "<text class=\"tick\""), 2u);
  EXPECT_NE(svg.find("x=\"300\" y=\"228\">2</text>"), std::string::npos) << svg;
}

TEST(Present, PowersOfTenAreRaised) {
  EXPECT_EQ(html_with_powers("2.1×10^6 < 10^-3, 10^x"),
            "2.1×10<sup>6</sup> &lt; 10<sup>−3</sup>, 10^x");
}

TEST(Present, ThePageCarriesTheStylesheetAndAnEscapedTitle) {
  const std::string page = page_start("a <b>", PageWidth::Reading) + page_end();
  EXPECT_EQ(page.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(page.find("<title>a &lt;b&gt;</title>"), std::string::npos);
  EXPECT_NE(page.find("svg.chart .gridline"), std::string::npos);
  EXPECT_NE(page.find("<main class=\"reading\">"), std::string::npos);
  EXPECT_EQ(occurrences(page, "<script>"), 0u);
  EXPECT_NE(page_end("go()").find("<script>go()</script>\n</body>"), std::string::npos);
}

TEST(Present, AChartIsNamedAndDescribedForScreenReaders) {
  const std::string open = chart_open({"c1", "timing", 880, 100, "Times", "a: 1 s"});
  EXPECT_EQ(open,
            "<svg class=\"chart timing\" id=\"c1\" viewBox=\"0 0 880 100\" role=\"img\" "
            "aria-labelledby=\"c1-title c1-desc\"><title id=\"c1-title\">Times</title><desc "
            "id=\"c1-desc\">a: 1 s</desc>");
}

}  // namespace
}  // namespace rvr::present
