// SVG elements (see svg.h).
#include "rvr/present/svg.h"

#include <fmt/format.h>
#include <stddef.h>

#include <initializer_list>
#include <memory>

#include "rvr/present/html_escape.h"

namespace rvr::present {

std::string number(double v) {
  std::string s = fmt::format("{:.2f}", v);
  while (s.back() == '0') s.pop_back();
  if (s.back() == '.') s.pop_back();
  return s == "-0" ? "0" : s;
}

std::string element(const std::string& tag, const Attributes& attributes,
                    const std::string& inner) {
  std::string o = "<" + tag;
  for (const auto& [name, value] : attributes) o += " " + name + "=\"" + escape_html(value) + "\"";
  return inner.empty() ? o + "/>" : o + ">" + inner + "</" + tag + ">";
}

namespace {

Attributes with(Attributes first, std::initializer_list<std::pair<const char*, double>> geometry) {
  for (const auto& [name, value] : geometry) first.emplace_back(name, number(value));
  return first;
}

}  // namespace

std::string line(const Attributes& attributes, double x1, double y1, double x2, double y2) {
  return element("line", with(attributes, {{"x1", x1}, {"x2", x2}, {"y1", y1}, {"y2", y2}}));
}

std::string rect(const Attributes& attributes, double x, double y, double width, double height,
                 const std::string& inner) {
  return element(
      "rect", with(attributes, {{"x", x}, {"y", y}, {"width", width}, {"height", height}}), inner);
}

std::string circle(const Attributes& attributes, double cx, double cy, double r) {
  return element("circle", with(attributes, {{"cx", cx}, {"cy", cy}, {"r", r}}));
}

std::string path(const Attributes& attributes, const std::vector<std::vector<Point>>& pieces,
                 const std::string& inner) {
  std::string d;
  for (const std::vector<Point>& piece : pieces)
    for (size_t i = 0; i < piece.size(); ++i) {
      if (!d.empty()) d += ' ';
      d += i == 0 ? 'M' : 'L';
      d += number(piece[i].first);
      d += ',';
      d += number(piece[i].second);
    }
  Attributes all = attributes;
  all.emplace_back("d", d);
  return element("path", all, inner);
}

std::string text(const Attributes& attributes, double x, double y, const std::string& markup) {
  return element("text", with(attributes, {{"x", x}, {"y", y}}), markup);
}

std::string tooltip(const std::string& plain) {
  return "<title>" + escape_html(plain) + "</title>";
}

}  // namespace rvr::present
