// SVG elements as text, for charts drawn inline in a page: every attribute value and tooltip
// escaped, every coordinate written the one way.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace rvr::present {

// Attributes in the order written: name and plain-text value (escaped when written).
using Attributes = std::vector<std::pair<std::string, std::string>>;

// A coordinate or length: at most two decimals, no trailing zeros ("120", "7.5", "543.27").
std::string number(double v);

// <tag attributes/>, or <tag attributes>inner</tag> when `inner` (markup) is not empty.
std::string element(const std::string& tag, const Attributes& attributes,
                    const std::string& inner = "");

// The shapes: `attributes` (class, data-*, colours) first, then the geometry.
std::string line(const Attributes& attributes, double x1, double y1, double x2, double y2);
std::string rect(const Attributes& attributes, double x, double y, double width, double height,
                 const std::string& inner = "");
std::string circle(const Attributes& attributes, double cx, double cy, double r);
// A point in SVG units.
using Point = std::pair<double, double>;
// A path of straight pieces, each through its points (an "M", then "L"s); the path's "d" after
// `attributes`.
std::string path(const Attributes& attributes, const std::vector<std::vector<Point>>& pieces,
                 const std::string& inner = "");
// Text at (x, y); `markup` is SVG text content (escape plain text first).
std::string text(const Attributes& attributes, double x, double y, const std::string& markup);

// A tooltip: <title> of plain text, the first child of the element it describes.
std::string tooltip(const std::string& plain);

}  // namespace rvr::present
