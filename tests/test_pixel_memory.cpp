// Frame memory recycled between frames (rvr/core/pixel_memory.h): a released block comes back
// for the next request of its size and alignment, the pool stays within its limit, and every
// renderer writes every pixel of every buffer, so what a recycled block held before (here:
// poison) never reaches an image.
#include <gtest/gtest.h>

#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/pixel_memory.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/scene_loader.h"
#include "same_bytes.h"

using namespace rvr;

TEST(PixelMemory, AReleasedFrameBlockComesBackForTheSameSizeOnly) {
  const size_t bytes = size_t(3) << 20;
  void* a = acquire_pixel_memory(bytes);
  std::memset(a, 0x5A, bytes);
  release_pixel_memory(a, bytes);
  void* other = acquire_pixel_memory(bytes + 4096);  // another size: not that block
  EXPECT_NE(other, a);
  void* again = acquire_pixel_memory(bytes);
  EXPECT_EQ(again, a);
  release_pixel_memory(other, bytes + 4096);
  release_pixel_memory(again, bytes);
}

TEST(PixelMemory, AlignmentIsHonouredWhenABlockIsRecycled) {
  const size_t bytes = size_t(4) << 20, page = size_t(2) << 20;
  // Blocks of the same size at 64 bytes released first: a 2 MiB-aligned request must not take
  // them unless they happen to be aligned so.
  std::vector<void*> small;
  for (int i = 0; i < 4; ++i) small.push_back(acquire_pixel_memory(bytes, 64));
  for (void* p : small) release_pixel_memory(p, bytes, 64);
  void* huge = acquire_pixel_memory(bytes, page);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(huge) % page, 0u);
  release_pixel_memory(huge, bytes, page);
  void* again = acquire_pixel_memory(bytes, page);
  EXPECT_EQ(again, huge);
  release_pixel_memory(again, bytes, page);
  for (void*& p : small) {
    p = acquire_pixel_memory(bytes, 64);
    EXPECT_EQ(reinterpret_cast<uintptr_t>(p) % 64, 0u);
  }
  for (void* p : small) release_pixel_memory(p, bytes, 64);
}

TEST(PixelMemory, ThePoolNeverHoldsMoreThanItsLimit) {
  // Untouched blocks: address space only, no pages.
  const size_t bytes = kRecycleLimitBytes / 4;
  std::vector<void*> blocks;
  for (int i = 0; i < 6; ++i) blocks.push_back(acquire_pixel_memory(bytes));
  for (void* p : blocks) {
    release_pixel_memory(p, bytes);
    EXPECT_LE(recycled_pixel_bytes(), kRecycleLimitBytes);
  }
  EXPECT_GE(recycled_pixel_bytes(), 4 * bytes);  // the newest four are kept
}

namespace {

// The VmFlags line of the mapping of /proc/self/smaps that holds address p ("" if none does).
std::string vm_flags_at(const void* p) {
  std::ifstream smaps("/proc/self/smaps");
  const uintptr_t a = reinterpret_cast<uintptr_t>(p);
  bool inside = false;
  for (std::string line; std::getline(smaps, line);) {
    uintptr_t begin = 0, end = 0;
    if (std::sscanf(line.c_str(), "%" SCNxPTR "-%" SCNxPTR " ", &begin, &end) == 2 &&
        line.find(':') > line.find(' ')) {  // a mapping's header, not a "Key: value" line
      inside = a >= begin && a < end;
      continue;
    }
    if (inside && line.rfind("VmFlags:", 0) == 0) return line;
  }
  return "";
}

}  // namespace

// Frame memory is asked for transparent huge pages, for every renderer's buffers alike: the
// whole 2 MiB pages inside a fresh block carry the kernel's "hg" flag (MADV_HUGEPAGE).
TEST(PixelMemory, AFreshFrameBlockIsAskedForHugePages) {
  if (!std::ifstream("/proc/self/smaps") ||
      !std::ifstream("/sys/kernel/mm/transparent_hugepage/enabled"))
    GTEST_SKIP() << "this system has no transparent huge pages to ask for";
  const size_t bytes = size_t(9) << 20;
  void* p = acquire_pixel_memory(bytes);
  const uintptr_t huge = kHugePageBytes;
  const void* inner =
      reinterpret_cast<const void*>((reinterpret_cast<uintptr_t>(p) + huge - 1) & ~(huge - 1));
  const std::string flags = vm_flags_at(inner);
  EXPECT_NE(flags, "") << "no mapping holds the block";
  EXPECT_NE((flags + " ").find(" hg "), std::string::npos) << flags;
  release_pixel_memory(p, bytes);
}

namespace {

// Puts blocks of every size a w x h frame's buffers take (4, 8 and 12 bytes a pixel, and three
// floats a pixel for barycentrics) into the pool, filled with `byte`.
void poison_frame_memory(size_t pixels, unsigned char byte) {
  std::vector<std::pair<void*, size_t>> blocks;
  for (size_t per_pixel : {4, 8, 12})
    for (int copies = 0; copies < 4; ++copies) {
      const size_t bytes = pixels * per_pixel;
      void* p = acquire_pixel_memory(bytes);
      std::memset(p, byte, bytes);
      blocks.push_back({p, bytes});
    }
  for (auto [p, bytes] : blocks) release_pixel_memory(p, bytes);
}

using rvr::test::same_bytes;

}  // namespace

// A renderer that skipped a pixel of a buffer would show what the recycled block held: the two
// frames, made over memory filled with 0x00 and with 0xFF, would differ there.
TEST(PixelMemory, EveryRendererWritesEveryPixelOfRecycledBuffers) {
  Scene scene = make_builtin_scene("spheres").value();
  scene.image.width = 520;  // >= 1 MiB per 4-byte buffer: recycled; not a multiple of a tile
  scene.image.height = 510;
  const size_t pixels = size_t(scene.image.width) * size_t(scene.image.height);
  ASSERT_GE(pixels * 4, kRecycledBytes);
  for (const RendererChoice& c : renderer_choices()) {
    if (c.variant && c.variant->of == VariantOf::GlContext) continue;  // EGL: its own label
    // Visibility mode with and without the cost AOV: z-buffers fill colour, normal (and cost)
    // without shading.
    for (auto [mode, cost_aov] :
         {std::pair{RenderMode::Visibility, true}, std::pair{RenderMode::Visibility, false},
          std::pair{RenderMode::Local, true}, std::pair{RenderMode::Full, true}}) {
      RendererConfig config{GlBackend::OsMesa};
      RenderOptions options;
      options.mode = mode;
      options.cost_aov = cost_aov;
      options.shadow_map_size = 128;
      c.apply(config, options);
      std::unique_ptr<Renderer> renderer = c.info->create(config).value();
      poison_frame_memory(pixels, 0x00);
      const RenderOutput zeros = renderer->render(scene, options).value();
      poison_frame_memory(pixels, 0xFF);
      const RenderOutput ones = renderer->render(scene, options).value();
      const FrameBuffers &a = zeros.buffers, &b = ones.buffers;
      const std::string label =
          c.name + " " + to_string(mode) + (cost_aov ? "" : " without the cost AOV");
      EXPECT_TRUE(same_bytes(a.colour, b.colour)) << label;
      EXPECT_TRUE(same_bytes(a.depth, b.depth)) << label;
      EXPECT_TRUE(same_bytes(a.object_id, b.object_id)) << label;
      EXPECT_TRUE(same_bytes(a.primitive_id, b.primitive_id)) << label;
      EXPECT_TRUE(same_bytes(a.normal, b.normal)) << label;
      EXPECT_TRUE(same_bytes(a.cost, b.cost)) << label;
    }
  }
}
