// How an analytic shape states its keys in the scene format (docs/scene-format.md), once: each
// shape's scene_fields(self, field) calls field(SceneField, member) for every key, in the order
// they are written, and the scene reader, the scene writer and the test that holds the format's
// documentation and schema to them all go through that one list.
#pragma once

namespace rvr {

// What a key holds, which fixes how it is read, checked and transformed:
//   Point      a position; a transform moves it.
//   Direction  a non-zero vector, normalised when read; a transform turns it (inverse
//              transpose).
//   Length     a number > 0; a transform, whose scale must then be uniform, multiplies it.
enum class SceneFieldKind { Point, Direction, Length };

struct SceneField {
  const char* key;  // the JSON key
  SceneFieldKind kind;
  const char* what;      // how messages name it ("the centre", "half_size")
  bool required = true;  // an optional key keeps the member's default when absent
};

}  // namespace rvr
