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

}  // namespace rvr
