#include "soft/csg_pass.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <memory>
#include <vector>

#include "csg_leaves.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr::soft {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// What one depth pass over half a leaf left, inside the box of the pixels it covered: the depth
// (+inf where it covered nothing), and the leaf triangle and barycentrics there.
struct LeafLayer {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [x0, x1) x [y0, y1); empty when x0 == x1
  std::vector<double> depth;
  std::vector<uint32_t> triangle;
  std::vector<glm::vec3> barycentric;

  bool empty() const { return x0 >= x1 || y0 >= y1; }
  // The layer's index of pixel (x, y), or -1 outside its box.
  std::ptrdiff_t at(int x, int y) const {
    if (x < x0 || x >= x1 || y < y0 || y >= y1) return -1;
    return std::ptrdiff_t(y - y0) * (x1 - x0) + (x - x0);
  }
  double depth_at(int x, int y) const {
    const std::ptrdiff_t k = at(x, y);
    return k < 0 ? kInfinity : depth[size_t(k)];
  }
};

// The view-projection that draws `box` of a width x height view into a target of the box's
// size: clip space scaled and shifted so that the box's pixel centres are the target's, at whole
// pixel offsets (the same centres the view samples).
glm::dmat4 crop_to(const PixelBox& box, int width, int height, const glm::dmat4& view_projection) {
  const double bw = box.x1 - box.x0, bh = box.y1 - box.y0;
  glm::dmat4 crop(1.0);
  crop[0][0] = width / bw;
  crop[3][0] = (width - 2.0 * box.x0) / bw - 1.0;
  crop[1][1] = height / bh;
  crop[3][1] = 1.0 - height / bh + 2.0 * box.y0 / bh;
  return crop * view_projection;
}

// What `scratch` (drawn as `box` of the view) holds after a pass, kept as a layer over the
// pixels it covered (the box can be the whole frame, the leaf a few pixels of it);
// `triangle_of` maps the pass's primitive to the leaf's triangle in the object's mesh.
LeafLayer keep_layer(const DepthTarget& scratch, const PixelBox& box,
                     const std::vector<uint32_t>& triangle_of, uint32_t first_triangle) {
  const int w = scratch.width(), h = scratch.height();
  int x0 = w, y0 = h, x1 = 0, y1 = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (scratch.covered(size_t(y) * size_t(w) + size_t(x))) {
        x0 = std::min(x0, x);
        x1 = std::max(x1, x + 1);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y + 1);
      }
  if (x0 >= x1 || y0 >= y1) return LeafLayer{};
  LeafLayer layer;
  layer.x0 = box.x0 + x0;
  layer.y0 = box.y0 + y0;
  layer.x1 = box.x0 + x1;
  layer.y1 = box.y0 + y1;
  const size_t n = size_t(x1 - x0) * size_t(y1 - y0);
  layer.depth.assign(n, kInfinity);
  layer.triangle.assign(n, 0);
  layer.barycentric.assign(n, glm::vec3(0.0f));
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      if (!scratch.covered(i)) continue;
      const size_t k = size_t(y - y0) * size_t(x1 - x0) + size_t(x - x0);
      layer.depth[k] = scratch.depth(i);
      layer.triangle[k] = first_triangle + triangle_of[scratch.primitive(i)];
      layer.barycentric[k] = scratch.barycentric(i);
    }
  return layer;
}

// One half of a leaf drawn alone into a target of its box's size, kept as a layer.
LeafLayer draw_half(const TriangleMesh& half, const std::vector<uint32_t>& triangle_of,
                    uint32_t first_triangle, const DrawObject& object, const PixelBox& box,
                    const glm::dmat4& box_projection, const std::optional<glm::dvec4>& keep,
                    const DepthTarget& target, std::optional<DepthTarget>& scratch,
                    tbb::task_arena& arena, CsgPassResult& result) {
  result.leaf_passes++;
  if (half.triangles.empty() || box.empty()) return LeafLayer{};
  const int bw = box.x1 - box.x0, bh = box.y1 - box.y0;
  // One scratch target for every pass of the call (the same planes and kernels), resized.
  arena.execute([&] {
    if (scratch)
      scratch->resize(bw, bh);
    else
      scratch.emplace(bw, bh, target.near_plane(), target.far_plane(), /*hiz=*/false,
                      target.kernels());
  });
  DrawObject d;
  d.mesh = &half;
  d.material = object.material;
  const DrawList one = make_draw_list({d});
  const DrawResult drawn = draw_triangles(one, box_projection, *scratch, arena, nullptr, keep);
  result.drawn.clipped += drawn.clipped;
  result.drawn.set_up += drawn.set_up;
  result.drawn.peak_chunk_bytes = std::max(result.drawn.peak_chunk_bytes, drawn.peak_chunk_bytes);
  result.drawn.setup_seconds += drawn.setup_seconds;
  result.drawn.bin_seconds += drawn.bin_seconds;
  result.drawn.raster_seconds += drawn.raster_seconds;
  result.drawn.counters.generated += drawn.counters.generated;
  return keep_layer(*scratch, box, triangle_of, first_triangle);
}

// Each pixel of the leaves' boxes: the leaves' intervals from their layers (a half not seen
// there: entered before the near plane, or left past the far one), combined by the tree; its
// first boundary written into `target` where it is nearer than what the target holds.
size_t combine_leaves(uint32_t object_id, const CsgNode* root, const std::vector<LeafLayer>& front,
                      const std::vector<LeafLayer>& back, DepthTarget& target,
                      tbb::task_arena& arena) {
  const size_t leaves = front.size();
  int x0 = target.width(), y0 = target.height(), x1 = 0, y1 = 0;
  for (const std::vector<LeafLayer>* layers : {&front, &back})
    for (const LeafLayer& l : *layers)
      if (!l.empty()) {
        x0 = std::min(x0, l.x0);
        y0 = std::min(y0, l.y0);
        x1 = std::max(x1, l.x1);
        y1 = std::max(y1, l.y1);
      }
  if (x0 >= x1 || y0 >= y1) return 0;
  const size_t width = size_t(target.width());
  std::vector<size_t> row_pixels(size_t(y1 - y0), 0);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(y0, y1), [&](const tbb::blocked_range<int>& rows) {
      std::vector<CsgInterval> intervals(leaves);
      for (int y = rows.begin(); y != rows.end(); ++y)
        for (int x = x0; x < x1; ++x) {
          uint32_t fragments = 0;
          for (size_t k = 0; k < leaves; ++k) {
            const double enter = front[k].depth_at(x, y), leave = back[k].depth_at(x, y);
            fragments += uint32_t(enter < kInfinity) + uint32_t(leave < kInfinity);
            intervals[k] = pixel_interval(enter, leave, 0, 0);
          }
          if (fragments == 0) continue;
          const size_t i = size_t(y) * width + size_t(x);
          target.add_fragments(i, fragments);
          CsgBoundary b;
          if (!first_csg_boundary(root, intervals.data(), std::numeric_limits<double>::lowest(),
                                  kInfinity, b) ||
              !(b.t < target.depth(i)))
            continue;
          // The boundary is its leaf's entry (a triangle facing the eye) or its exit.
          const bool entry = b.t == intervals[b.leaf].enter;
          const LeafLayer& layer = entry ? front[b.leaf] : back[b.leaf];
          const size_t k = size_t(layer.at(x, y));
          target.set_surface(i, b.t, object_id, layer.triangle[k], layer.barycentric[k]);
          row_pixels[size_t(y - y0)]++;
        }
    });
  });
  size_t pixels = 0;
  for (size_t n : row_pixels) pixels += n;
  return pixels;
}

}  // namespace

CsgPassResult draw_csg_objects(const DrawList& list, const glm::dmat4& view_projection,
                               const glm::vec3& eye, const std::optional<glm::dvec4>& keep,
                               DepthTarget& target, tbb::task_arena& arena) {
  CsgPassResult result;
  std::optional<DepthTarget> scratch;
  for (size_t o = 0; o < list.objects.size(); ++o) {
    const DrawObject& object = list.objects[o];
    if (!object.csg || !object.mesh) continue;
    result.objects++;
    const std::vector<Sphere> leaves = csg_leaves(object.csg);
    std::vector<LeafLayer> front(leaves.size()), back(leaves.size());
    for (size_t k = 0; k < leaves.size(); ++k) {
      const uint32_t first = uint32_t(k) * object.csg_leaf_triangles;
      const CsgLeafFaces faces =
          split_by_facing(*object.mesh, first, object.csg_leaf_triangles, leaves[k].center, eye);
      const PixelBox box = leaf_box(leaves[k], view_projection, target.width(), target.height());
      const glm::dmat4 box_projection =
          box.empty() ? view_projection
                      : crop_to(box, target.width(), target.height(), view_projection);
      front[k] = draw_half(faces.front, faces.front_triangle, first, object, box, box_projection,
                           keep, target, scratch, arena, result);
      back[k] = draw_half(faces.back, faces.back_triangle, first, object, box, box_projection, keep,
                          target, scratch, arena, result);
    }
    result.pixels += combine_leaves(uint32_t(o), object.csg, front, back, target, arena);
  }
  return result;
}

}  // namespace rvr::soft
