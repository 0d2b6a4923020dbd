// How a z-buffer answered an effect at a pixel (full mode): the technique, and for the
// approximations which of their known failures the pixel falls in. A tracer follows every ray
// and answers nothing here; compare reports a z-buffer's error against it class by class.
#pragma once

#include <cstddef>
#include <cstdint>

#include "rvr/core/framebuffers.h"

namespace rvr {

enum class EffectAnswer : uint8_t {
  None = 0,            // no effect at the pixel's surface (or not full mode)
  ReflectedView,       // a planar mirror's reflected view: exact up to the z-buffer's sampling
  LayerView,           // an ior-1 layer's view behind it: exact up to the z-buffer's sampling
  CubeMapReflection,   // a curved mirror's cube map: parallax, no self-reflection
  CubeMapRefraction,   // refraction through a sphere by a cube map (both interfaces): parallax
  FirstInterfaceOnly,  // refraction by a cube map bent at the first interface: the second missed
  SsrHit,              // screen-space reflection met the reflected point in the frame
  SsrOffScreen,        // its ray left the view first: shown as the background
  SsrHidden,           // its ray passed behind a surface first: shown as the background
  SsrBackground,       // its ray met nothing: the background, as the tracer's
  LeftOut,             // not rendered: the local colour at full weight
  AtLimit,             // at --max-depth: the shares dropped, as the tracer drops them
};
inline constexpr size_t kEffectAnswers = 12;

// The name metrics.json and compare give each answer ("cube_map_reflection", ...).
const char* effect_answer_name(EffectAnswer a);

// Records answer `a` at `pixel` of `fb`, sizing fb.answer (None everywhere) on first use.
void set_answer(FrameBuffers& fb, size_t pixel, EffectAnswer a);

}  // namespace rvr
