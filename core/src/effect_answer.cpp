#include "rvr/core/effect_answer.h"

namespace rvr {

const char* effect_answer_name(EffectAnswer a) {
  switch (a) {
    case EffectAnswer::None:
      return "none";
    case EffectAnswer::ReflectedView:
      return "reflected_view";
    case EffectAnswer::LayerView:
      return "layer_view";
    case EffectAnswer::CubeMapReflection:
      return "cube_map_reflection";
    case EffectAnswer::CubeMapRefraction:
      return "cube_map_refraction";
    case EffectAnswer::FirstInterfaceOnly:
      return "first_interface_only";
    case EffectAnswer::SsrHit:
      return "ssr_hit";
    case EffectAnswer::SsrOffScreen:
      return "ssr_off_screen";
    case EffectAnswer::SsrHidden:
      return "ssr_hidden";
    case EffectAnswer::SsrBackground:
      return "ssr_background";
    case EffectAnswer::LeftOut:
      return "left_out";
    case EffectAnswer::AtLimit:
      return "at_limit";
  }
  return "none";
}

void set_answer(FrameBuffers& fb, size_t pixel, EffectAnswer a) {
  if (fb.answer.size() != fb.pixel_count()) fb.answer.assign(fb.pixel_count(), 0);
  fb.answer[pixel] = uint8_t(a);
}

}  // namespace rvr
