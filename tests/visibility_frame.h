// What a z-buffer's visibility-mode frame must hold: depth, ids and cost only, held against the
// same renderer's local-mode frame of the scene and against the id rules on their own.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "rvr/core/renderer.h"
#include "same_bytes.h"

namespace rvr::test {

// `visibility` and `no_cost` are visibility-mode frames of `scene` (with and without the cost
// AOV), `local` a local-mode one, all from the same renderer. Depth, object and primitive ids and
// cost are local's bytes (shading does not change what is visible); colour is the background
// and normal +0 everywhere; without the cost AOV the cost is +0 and nothing else changes. The
// ids also follow the rules by themselves: background pixels have no ids and infinite depth;
// a triangle mesh's primitive id is one of its triangles, every other object's is 0.
inline void expect_visibility_frame(const Scene& scene, const FrameBuffers& local,
                                    const FrameBuffers& visibility, const FrameBuffers& no_cost,
                                    const std::string& label) {
  ASSERT_EQ(visibility.pixel_count(), size_t(scene.image.width) * size_t(scene.image.height));
  EXPECT_TRUE(same_bytes(visibility.depth, local.depth)) << label;
  EXPECT_TRUE(same_bytes(visibility.object_id, local.object_id)) << label;
  EXPECT_TRUE(same_bytes(visibility.primitive_id, local.primitive_id)) << label;
  EXPECT_TRUE(same_bytes(visibility.cost, local.cost)) << label;

  size_t covered = 0, non_zero_cost = 0, background = 0, zero_normal = 0, zero_cost = 0;
  size_t broken = 0;         // pixels whose ids or depth break the rules
  std::string first_broken;  // the first of them, and how
  auto rule = [&](bool holds, size_t i, const char* what) {
    if (holds) return;
    if (broken++ == 0) first_broken = "pixel " + std::to_string(i) + ": " + what;
  };
  for (size_t i = 0; i < visibility.pixel_count(); ++i) {
    background +=
        std::memcmp(&visibility.colour[i], &scene.image.background, sizeof(glm::vec3)) == 0;
    const glm::vec3 zero(0.0f);
    zero_normal += std::memcmp(&visibility.normal[i], &zero, sizeof(glm::vec3)) == 0;
    const float no_work = 0.0f;
    zero_cost += std::memcmp(&no_cost.cost[i], &no_work, sizeof(float)) == 0;
    non_zero_cost += visibility.cost[i] > 0.0f;
    const uint32_t id = visibility.object_id[i];
    if (id == kNoId) {
      rule(visibility.primitive_id[i] == kNoId, i, "background with a primitive id");
      rule(visibility.depth[i] == std::numeric_limits<float>::infinity(), i,
           "background with a finite depth");
      continue;
    }
    ++covered;
    rule(std::isfinite(visibility.depth[i]), i, "an object at infinite depth");
    if (id >= scene.objects.size()) {
      rule(false, i, "no such object");
      continue;
    }
    const Object& o = scene.objects[id];
    if (o.type == ObjectType::Triangles)
      rule(visibility.primitive_id[i] < o.mesh.triangles.size(), i, "no such triangle");
    else
      rule(visibility.primitive_id[i] == 0, i, "a primitive id other than 0 on a shape");
  }
  EXPECT_EQ(broken, 0u) << label << ": " << first_broken;
  EXPECT_GT(covered, visibility.pixel_count() / 10) << label;  // there is something to see
  EXPECT_GE(non_zero_cost, covered) << label;
  EXPECT_EQ(background, visibility.pixel_count()) << label << ": colour is not the background";
  EXPECT_EQ(zero_normal, visibility.pixel_count()) << label << ": normal is not 0";
  EXPECT_EQ(zero_cost, visibility.pixel_count()) << label << " without the cost AOV";

  EXPECT_TRUE(same_bytes(no_cost.depth, visibility.depth)) << label;
  EXPECT_TRUE(same_bytes(no_cost.object_id, visibility.object_id)) << label;
  EXPECT_TRUE(same_bytes(no_cost.primitive_id, visibility.primitive_id)) << label;
  EXPECT_TRUE(same_bytes(no_cost.colour, visibility.colour)) << label;
  EXPECT_TRUE(same_bytes(no_cost.normal, visibility.normal)) << label;
}

// The same frame drawn with the cost AOV (`with`) and without it (`without`): every other
// buffer the same bytes, the cost +0 everywhere without, and work counted with.
inline void expect_only_the_cost_left_out(const FrameBuffers& with, const FrameBuffers& without,
                                          const std::string& what) {
  EXPECT_TRUE(same_bytes(with.colour, without.colour)) << what;
  EXPECT_TRUE(same_bytes(with.normal, without.normal)) << what;
  EXPECT_TRUE(same_bytes(with.depth, without.depth)) << what;
  EXPECT_TRUE(same_bytes(with.object_id, without.object_id)) << what;
  EXPECT_TRUE(same_bytes(with.primitive_id, without.primitive_id)) << what;
  for (float c : without.cost)
    if (std::signbit(c) || c != 0.0f) {
      ADD_FAILURE() << what << ": cost " << c << " without the cost AOV";
      break;
    }
  bool counted = false;
  for (float c : with.cost) counted = counted || c > 0.0f;
  EXPECT_TRUE(counted) << what << ": no work counted with the cost AOV";
}

}  // namespace rvr::test
