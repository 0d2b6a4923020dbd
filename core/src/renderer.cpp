#include "rvr/core/renderer.h"

#include <initializer_list>
#include <optional>
#include <string>

namespace rvr {

const char* to_string(RenderMode mode) {
  switch (mode) {
    case RenderMode::Visibility:
      return "visibility";
    case RenderMode::Local:
      return "local";
    case RenderMode::Full:
      return "full";
  }
  return "?";
}

const char* to_string(AccelKind accel) {
  switch (accel) {
    case AccelKind::Bvh:
      return "bvh";
    case AccelKind::Bvh2:
      return "bvh2";
    case AccelKind::None:
      return "none";
    case AccelKind::Embree:
      return "embree";
  }
  return "?";
}

const char* to_string(DepthFormat format) {
  switch (format) {
    case DepthFormat::D24:
      return "d24";
    case DepthFormat::D32F:
      return "d32f";
    case DepthFormat::D32FReversed:
      return "d32f_reversed";
  }
  return "?";
}

std::optional<DepthFormat> parse_depth_format(const std::string& name) {
  for (DepthFormat f : {DepthFormat::D24, DepthFormat::D32F, DepthFormat::D32FReversed})
    if (name == to_string(f)) return f;
  return std::nullopt;
}

}  // namespace rvr
