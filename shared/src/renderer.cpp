#include "rvr/shared/renderer.h"

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

}  // namespace rvr
