// softraster's back end: the z-buffer of the whole frame, kept across the chunks of triangles
// streamed through it, and the loop that draws a tile's share of a chunk. Each tile is 8x8
// blocks; a triangle's blocks are classified from the edge functions at their corners (outside,
// partly or fully covered: a full block draws every pixel without an edge test), and hi-z keeps
// the farthest depth of every block, so that a triangle behind everything drawn in a block (or
// in all of its blocks) is not rasterized there at all.
#pragma once

#include <stddef.h>

#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <vector>

#include "rvr/core/check.h"
#include "rvr/core/framebuffers.h"
#include "soft/fill_kernel.h"
#include "soft/setup_triangle.h"

namespace rvr::soft {

constexpr int kTile = 64;
constexpr int kBlock = 8;

struct TileCounters {
  uint64_t generated = 0;           // fragments: covered pixel centres that were depth-tested
  uint64_t blocks_rejected = 0;     // 8x8 blocks hi-z skipped (a triangle's, one by one)
  uint64_t triangles_rejected = 0;  // triangles hi-z skipped in a whole tile at once
  uint64_t blocks_full = 0;         // blocks drawn without edge tests
};

// What a target keeps per pixel besides its depth: what the passes that read it need, no more
// written per fragment.
struct TargetArrays {
  bool ids = true;           // object and primitive ids (false: depth alone, a shadow map)
  bool barycentrics = true;  // the visible triangle's, for shading
  bool fragments = true;     // fragments generated per pixel, for the cost AOV
  bool operator==(const TargetArrays&) const = default;
};
inline constexpr TargetArrays kDepthOnly{false, false, false};

class DepthTarget {
 public:
  // `arrays`: what it keeps besides depth (barycentrics and fragments only with ids).
  // `kernels`: the per-pixel loop of the instruction set chosen for this render.
  DepthTarget(int width, int height, double near_plane, double far_plane, bool hiz,
              const FillKernels& kernels, TargetArrays arrays = {});
  // Back to nothing drawn, for the next pass through the same target.
  void clear();
  // Re-dimensioned to width x height (the same planes, hi-z and kernels) and cleared, keeping
  // its arrays' memory: passes of changing sizes through one target allocate once.
  void resize(int width, int height);
  // What the depth test compares from now on (fill_kernel.h: kDepthExact, kDepthD24, ...).
  void set_depth_format(int format) {
    depth_format_ = format;
    fill_target_.depth_format = format;
  }
  // Whether this target was made with these arguments (and can be cleared instead of rebuilt).
  bool same_setup(int width, int height, double near_plane, double far_plane, bool hiz,
                  const FillKernels& kernels, TargetArrays arrays) const {
    return width == width_ && height == height_ && near_plane == near_ && far_plane == far_ &&
           hiz == hiz_ && &kernels == kernels_ && arrays == arrays_;
  }
  const TargetArrays& arrays() const { return arrays_; }

  int width() const { return width_; }
  int height() const { return height_; }
  int tiles_x() const { return tiles_x_; }
  int tiles_y() const { return tiles_y_; }
  // The kernels of the instruction set chosen for this render (setup uses them too).
  const FillKernels& kernels() const { return *kernels_; }

  // Draws the triangles bin[0..count) into tile (tx, ty), in that order; an entry is
  // sub-chunk << kLocalBits | index in that sub-chunk's triangles. Tiles are independent: any
  // thread may draw any tile, and the bytes do not change.
  static constexpr uint32_t kLocalBits = 20;
  void draw_tile(int tx, int ty, const SetupTriangles* sub_chunks, const uint32_t* bin,
                 size_t count, TileCounters& counters);

  // What the frame ended with, per pixel.
  bool covered(size_t i) const {
    return !arrays_.ids ? depth_[i] != std::numeric_limits<double>::infinity()
                        : object_[i] != 0xFFFFFFFFu;
  }
  // How many pixels are covered: the frame less its blocks' counts of empty pixels, which every
  // draw keeps (a pixel leaves its block's count when first drawn), so no pixel is read.
  size_t covered_pixels() const;
  double depth(size_t i) const { return depth_[i]; }
  uint32_t object(size_t i) const { return object_[i]; }
  uint32_t primitive(size_t i) const { return primitive_[i]; }
  // Perspective-correct barycentrics of the visible triangle at the pixel centre (kept).
  glm::vec3 barycentric(size_t i) const {
    RVR_DCHECK(arrays_.barycentrics, "a target without barycentrics");
    return {bary_[3 * i], bary_[3 * i + 1], bary_[3 * i + 2]};
  }
  // Work at pixel (x, y): fragments generated, plus each hi-z rejection of its block as 1/64
  // (fragments kept).
  float cost(int x, int y) const {
    RVR_DCHECK(arrays_.fragments, "a target without fragment counts");
    return float(fragments_[size_t(y) * size_t(width_) + size_t(x)]) +
           float(block_rejects_[block_index(x, y)]) / float(kBlock * kBlock);
  }
  // cost(x, y) of the whole row y into out[0, width): the same floats, the block's rejection
  // term computed once per block instead of once per pixel.
  void cost_row(int y, float* out) const {
    RVR_DCHECK(arrays_.fragments, "a target without fragment counts");
    const uint32_t* fragments = fragments_.data() + size_t(y) * size_t(width_);
    const uint32_t* rejects = block_rejects_.data() + size_t(y / kBlock) * size_t(blocks_x_);
    for (int x0 = 0; x0 < width_; x0 += kBlock) {
      const int block_x = x0 / kBlock;
      const float reject = float(rejects[block_x]) / float(kBlock * kBlock);
      const int x1 = x0 + kBlock < width_ ? x0 + kBlock : width_;
      for (int x = x0; x < x1; ++x) out[x] = float(fragments[x]) + reject;
    }
  }
  // A surface found after every draw into the target (a CSG solid's, csg_pass.h) written at
  // pixel i over what was drawn there (a depth-only target: its depth alone). The blocks' hi-z
  // bounds are not updated: nothing is drawn into the target after it. Pixels of one block may be
  // set from different threads.
  void set_surface(size_t i, double depth, uint32_t object, uint32_t primitive,
                   const glm::vec3& barycentric) {
    if (depth_[i] == std::numeric_limits<double>::infinity()) leave_empty_count(i);
    depth_[i] = depth;
    if (!arrays_.ids) return;
    object_[i] = object;
    primitive_[i] = primitive;
    if (!arrays_.barycentrics) return;
    bary_[3 * i] = barycentric.x;
    bary_[3 * i + 1] = barycentric.y;
    bary_[3 * i + 2] = barycentric.z;
  }
  // Fragments drawn at pixel i outside this target (a CSG solid's leaf passes), counted in its
  // cost.
  void add_fragments(size_t i, uint32_t fragments) {
    if (arrays_.fragments) fragments_[i] += fragments;
  }
  double near_plane() const { return near_; }
  double far_plane() const { return far_; }
  // The per-pixel arrays above, row-major, for passes that walk whole rows.
  const double* depths() const { return depth_.data(); }
  const uint32_t* objects() const { return object_.data(); }
  const uint32_t* primitives() const { return primitive_.data(); }
  const float* barycentrics() const { return bary_.data(); }
  // This frame's object and primitive ids, swapped into `object` and `primitive` instead of
  // copied, for a caller that reads them after the next draw: the target has none until its next
  // clear(), which sizes its own again (from the recycled pixel memory).
  void give_ids(PixelVector<uint32_t>& object, PixelVector<uint32_t>& primitive);
  size_t bytes() const;

 private:
  void draw(const SetupTriangle& t, int x0, int y0, int x1, int y1, TileCounters& counters);
  size_t block_index(int x, int y) const {
    return size_t(y / kBlock) * size_t(blocks_x_) + size_t(x / kBlock);
  }
  void update_block_max(int bx, int by);
  // Pixel i, drawn for the first time outside the kernels, leaves its block's empty count.
  void leave_empty_count(size_t i);

  int width_, height_, tiles_x_, tiles_y_, blocks_x_, blocks_y_;
  double near_, far_;
  bool hiz_;
  TargetArrays arrays_;
  int depth_format_ = kDepthExact;
  const FillKernels* kernels_;
  FillTarget fill_target_;     // pointers into the arrays below, for the kernels
  PixelVector<double> depth_;  // +inf until drawn
  PixelVector<uint32_t> object_, primitive_, fragments_;
  PixelVector<float> bary_;
  std::vector<double> block_max_;        // farthest depth in each block (+inf: not all drawn)
  std::vector<uint32_t> block_rejects_;  // hi-z rejections per block
  std::vector<uint16_t> block_empty_;    // pixels of each block nothing has been drawn in
};

}  // namespace rvr::soft
