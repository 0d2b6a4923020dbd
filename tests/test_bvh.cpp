// The BVHs must find exactly the hit the plain loop over every object finds: the wide BVH with
// every SIMD kernel this CPU can run, and the binary one. Ties at equal t go to the lowest
// primitive index in all three, so hits agree to the bit, primitive included.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <glm/glm.hpp>
#include <initializer_list>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/isa.h"
#include "rvr/core/ray.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/square.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/intersect.h"
#include "rvr/raytrace/trace_geometry.h"
#include "rvr/raytrace/wide_bvh.h"
#include "rvr/raytrace/wide_bvh_layout.h"
#include "rvr/scene_io/scene_loader.h"

using namespace rvr;

namespace {

Scene builtin(const std::string& name) {
  Expected<Scene> s = make_builtin_scene(name);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  return s.value();
}

std::vector<Isa> runnable_isas() {
  std::vector<Isa> isas;
  for (Isa isa : kAllIsas)
    if (cpu_supports(isa)) isas.push_back(isa);
  return isas;
}

// A scene with every primitive kind: triangles, spheres, squares and CSG.
Scene mixed_scene() {
  Scene s = builtin("soup:500");
  Object sphere;
  sphere.type = ObjectType::Sphere;
  sphere.sphere = {{0.5f, 0.2f, 0.1f}, 0.4f};
  s.objects.push_back(sphere);
  Object plane;
  plane.type = ObjectType::Plane;
  plane.plane = {{0, -1.2f, 0}, glm::normalize(glm::vec3(0.1f, 1, 0.2f)), 1.5f};
  s.objects.push_back(plane);
  auto leaf = [](glm::vec3 c, float r) {
    auto n = std::make_shared<CsgNode>();
    n->sphere = {c, r};
    return n;
  };
  auto diff = std::make_shared<CsgNode>();
  diff->is_leaf = false;
  diff->op = CsgOp::Difference;
  diff->a = leaf({-0.5f, 0.5f, 0}, 0.5f);
  diff->b = leaf({-0.2f, 0.7f, 0.2f}, 0.35f);
  Object csg;
  csg.type = ObjectType::Csg;
  csg.csg = diff;
  s.objects.push_back(csg);
  return s;
}

std::vector<Ray> random_rays(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> U(-1.0f, 1.0f);
  std::vector<Ray> rays;
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 o(U(rng) * 3, U(rng) * 3, U(rng) * 3);
    // Half the rays aim at the middle of the scene, half go anywhere; every 16th is a shadow
    // ray with a finite tmax.
    glm::vec3 target =
        i % 2 ? glm::vec3(U(rng), U(rng), U(rng)) : o + glm::vec3(U(rng), U(rng), U(rng));
    glm::vec3 d = target - o;
    if (glm::length(d) < 1e-3f) d = {0, 0, 1};
    rays.push_back(Ray{o, d, 0.0f, i % 16 == 3 ? 1.0f : INFINITY});
  }
  return rays;
}

bool same_bits(float a, float b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// The accelerators under test: bvh2 and the wide BVH with each kernel.
struct Accelerated {
  std::string label;
  std::unique_ptr<TraceGeometry> geometry;
};

std::vector<Accelerated> accelerated(const Scene& scene, SphereMode spheres) {
  std::vector<Accelerated> out;
  out.push_back({"bvh2", std::make_unique<TraceGeometry>(scene, spheres, 24, AccelKind::Bvh2)});
  for (Isa isa : runnable_isas())
    out.push_back({std::string("bvh/") + to_string(isa),
                   std::make_unique<TraceGeometry>(scene, spheres, 24, AccelKind::Bvh,
                                                   TriangleTest::MollerTrumbore, isa)});
  for (const Accelerated& a : out) EXPECT_EQ(a.geometry->error(), "") << a.label;
  return out;
}

// Same hit as brute force, to the bit; `what` names the ray in failure messages.
void expect_same_hit(const TraceGeometry& brute, const Accelerated& a, const Ray& ray,
                     const std::string& what) {
  HitRecord hb, ha, hu;
  TraversalCounters cb, ca;
  bool b = brute.closest(ray, hb, cb);
  bool found = a.geometry->closest(ray, ha, ca);
  ASSERT_EQ(found, b) << a.label << ": " << what;
  // The uncounted query is the same query.
  ASSERT_EQ(a.geometry->closest(ray, hu), b) << a.label << ": " << what;
  EXPECT_EQ(a.geometry->occluded(ray, ca), b) << a.label << ": " << what;
  EXPECT_EQ(a.geometry->occluded(ray), b) << a.label << ": " << what;
  if (!b) return;
  ASSERT_EQ(ha.primitive, hb.primitive) << a.label << ": " << what;
  ASSERT_TRUE(same_bits(ha.t, hb.t)) << a.label << ": " << what << " t " << ha.t << " vs " << hb.t;
  ASSERT_TRUE(same_bits(ha.u, hb.u) && same_bits(ha.v, hb.v)) << a.label << ": " << what;
  ASSERT_EQ(ha.csg_leaf, hb.csg_leaf) << a.label << ": " << what;
  ASSERT_EQ(ha.csg_flip, hb.csg_flip) << a.label << ": " << what;
  ASSERT_EQ(hu.primitive, hb.primitive) << a.label << ": " << what;
  ASSERT_TRUE(same_bits(hu.t, hb.t)) << a.label << ": " << what;
}

void expect_same_hits(const Scene& scene, SphereMode spheres, uint32_t seed) {
  TraceGeometry brute(scene, spheres, 24, AccelKind::None);
  TraceGeometry embree(scene, spheres, 24, AccelKind::Embree);
  std::vector<Accelerated> accels = accelerated(scene, spheres);
  ASSERT_EQ(embree.error(), "");
  int hits = 0, embree_edge_cases = 0, embree_occlusion_misses = 0;
  std::vector<Ray> rays = random_rays(10000, seed);
  for (size_t i = 0; i < rays.size(); ++i) {
    const Ray& ray = rays[i];
    for (const Accelerated& a : accels) {
      expect_same_hit(brute, a, ray, "ray " + std::to_string(i));
      if (::testing::Test::HasFatalFailure()) return;
    }
    HitRecord hb;
    TraversalCounters cb;
    bool b = brute.closest(ray, hb, cb);
    // Embree, the yardstick, with its own (watertight) triangle test: same hit or miss, same
    // object, same t to float precision, except on a ray through an edge; its occlusion query
    // agrees with its own closest hit, on hits and on misses.
    HitRecord he;
    TraversalCounters ce;
    bool e = embree.closest(ray, he, ce);
    embree_occlusion_misses += embree.occluded(ray, ce) != e;
    if (!b) {
      embree_edge_cases += e;
      continue;
    }
    ++hits;
    if (!e) {
      ++embree_edge_cases;
      continue;
    }
    SurfaceHit sb = brute.surface(ray, hb), se = embree.surface(ray, he);
    if (se.object != sb.object || std::abs(he.t - hb.t) > 1e-4f * std::max(1.0f, hb.t))
      ++embree_edge_cases;
  }
  EXPECT_GT(hits, 1000);
  EXPECT_LE(embree_edge_cases, 2);
  EXPECT_EQ(embree_occlusion_misses, 0);
}

// Triangles with integer corners and unit or double legs along the axes, in the three
// orientations: their edges lie on grid lines and every BVH box face on a grid plane.
Scene grid_triangles(size_t n, uint32_t seed) {
  Scene s;
  s.materials.push_back(default_material());
  Object o;
  o.type = ObjectType::Triangles;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> corner(0, 7), axis(0, 2), leg(1, 2), sign(0, 1);
  for (uint32_t i = 0; i < n; ++i) {
    glm::vec3 c(corner(rng), corner(rng), corner(rng));
    int normal = axis(rng);
    glm::vec3 a(0.0f), b(0.0f);
    a[(normal + 1) % 3] = float(leg(rng) * (sign(rng) ? 1 : -1));
    b[(normal + 2) % 3] = float(leg(rng) * (sign(rng) ? 1 : -1));
    o.mesh.positions.insert(o.mesh.positions.end(), {c, c + a, c + b});
    o.mesh.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
  }
  s.objects.push_back(o);
  return s;
}

}  // namespace

TEST(Bvh, MatchesBruteForceOnSoup) {
  expect_same_hits(builtin("soup:3000"), SphereMode::Analytic, 1);
}
TEST(Bvh, MatchesBruteForceOnTessellatedSphere) {
  expect_same_hits(builtin("tessphere:5000"), SphereMode::Analytic, 2);
}
TEST(Bvh, MatchesBruteForceOnAnalyticShapes) {
  expect_same_hits(builtin("spheres"), SphereMode::Analytic, 3);
}
TEST(Bvh, MatchesBruteForceOnSpheresAsMeshes) {
  expect_same_hits(builtin("spheres"), SphereMode::Mesh, 4);
}
TEST(Bvh, MatchesBruteForceOnMixedPrimitives) {
  expect_same_hits(mixed_scene(), SphereMode::Analytic, 5);
}
TEST(Bvh, MatchesBruteForceOnCornell) {
  expect_same_hits(builtin("cornell"), SphereMode::Analytic, 6);
}

// Rays along an axis (the other two direction components +0 or -0, every sign combination)
// from grid points: they run inside box faces and along triangle edges. A slab test computes
// 0 * inf = NaN for the faces such a ray lies in; the NaN must not reject the box.
TEST(Bvh, AxisParallelRaysOnBoxFacesFindWhatBruteForceFinds) {
  Scene scene = grid_triangles(300, 11);
  TraceGeometry brute(scene, SphereMode::Analytic, 24, AccelKind::None);
  std::vector<Accelerated> accels = accelerated(scene, SphereMode::Analytic);
  int hits = 0, rays = 0;
  for (int axis = 0; axis < 3; ++axis) {
    for (float main : {1.0f, -1.0f}) {
      for (int zero_signs = 0; zero_signs < 4; ++zero_signs) {
        glm::vec3 d(0.0f);
        d[axis] = main;
        d[(axis + 1) % 3] = zero_signs & 1 ? -0.0f : 0.0f;
        d[(axis + 2) % 3] = zero_signs & 2 ? -0.0f : 0.0f;
        // Origins on grid planes across the box, and a half step inside the cells; the
        // coordinate along the ray is outside the grid, so every triangle is ahead or behind.
        for (float p = -1.0f; p <= 10.0f; p += 0.5f) {
          for (float q = -1.0f; q <= 10.0f; q += 0.5f) {
            glm::vec3 o;
            o[axis] = main > 0 ? -2.0f : 11.0f;
            o[(axis + 1) % 3] = p;
            o[(axis + 2) % 3] = q;
            Ray ray{o, d, 0.0f, INFINITY};
            HitRecord h;
            TraversalCounters c;
            hits += brute.closest(ray, h, c);
            ++rays;
            for (const Accelerated& a : accels) {
              expect_same_hit(brute, a, ray,
                              "origin (" + std::to_string(o.x) + ", " + std::to_string(o.y) + ", " +
                                  std::to_string(o.z) + ") axis " + std::to_string(axis));
              if (HasFatalFailure()) return;
            }
          }
        }
      }
    }
  }
  EXPECT_GT(hits, rays / 4);  // most rays run along grid lines into some triangle
}

// The same rays started exactly on a BVH node's face, inside the box: the slab the ray lies in
// must not reject it, so everything in the box ahead is found.
TEST(Bvh, AxisParallelRaysStartingOnANodeFace) {
  Scene scene = grid_triangles(300, 12);
  TraceGeometry brute(scene, SphereMode::Analytic, 24, AccelKind::None);
  std::vector<Accelerated> accels = accelerated(scene, SphereMode::Analytic);
  const Bvh& bvh2 = accels[0].geometry->bvh();
  int checked = 0;
  for (size_t k = 0; k < bvh2.nodes().size(); k += 7) {
    const BvhNode& n = bvh2.nodes()[k];
    for (int face_axis = 0; face_axis < 3; ++face_axis) {
      for (int side = 0; side < 2; ++side) {
        glm::vec3 o = 0.5f * (n.lo + n.hi);
        o[face_axis] = side ? n.hi[face_axis] : n.lo[face_axis];
        for (int ray_axis = 0; ray_axis < 3; ++ray_axis) {
          if (ray_axis == face_axis) continue;
          for (float main : {1.0f, -1.0f}) {
            for (float zero : {0.0f, -0.0f}) {
              glm::vec3 d(zero);
              d[ray_axis] = main;
              // Start on the near side of the box so the box lies ahead.
              o[ray_axis] = main > 0 ? n.lo[ray_axis] : n.hi[ray_axis];
              Ray ray{o, d, 0.0f, INFINITY};
              for (const Accelerated& a : accels) {
                expect_same_hit(brute, a, ray, "node " + std::to_string(k));
                if (HasFatalFailure()) return;
              }
              ++checked;
            }
          }
        }
      }
    }
  }
  EXPECT_GT(checked, 100);
}

// The binary builder against the binned SAH written out plainly, per node: an inner node above
// the median depth splits its primitives at the split of least cost over the 16 centroid bins
// of every axis (its left child holds exactly the primitives of bins up to the split), and a
// leaf that could split is no costlier than that split. Costs as the wide BVH builds with them:
// traversal 1, leaves counted in blocks of 4, at most 8 primitives a leaf.
TEST(Bvh, EveryNodeTakesTheLeastCostBinnedSplit) {
  constexpr int kBins = 16;
  constexpr size_t kMedianDepth = 32;
  constexpr uint32_t kBlock = 4, kMaxLeaf = 8;
  constexpr float kTraversal = 1.0f;
  auto tests = [&](uint32_t n) {              // whole blocks: the division rounds up
    return float((n + kBlock - 1) / kBlock);  // NOLINT(bugprone-integer-division)
  };
  for (const char* name : {"soup:3000", "tessphere:3000"}) {
    Scene scene = builtin(name);
    TraceGeometry g(scene, SphereMode::Analytic, 1, AccelKind::Bvh2);
    std::vector<Aabb> prims(g.triangle_count());
    for (size_t i = 0; i < prims.size(); ++i) {
      const TrianglePrecomputed& t = g.triangle(uint32_t(i));
      prims[i].grow(t.v0);
      prims[i].grow(t.v0 + t.e1);
      prims[i].grow(t.v0 + t.e2);
    }
    BvhBuildOptions options;
    options.max_leaf_size = int(kMaxLeaf);
    options.leaf_block = int(kBlock);
    options.traversal_cost = kTraversal;
    const Bvh bvh = Bvh::build(prims, options);
    const std::vector<uint32_t>& order = bvh.primitive_order();
    int inner_checked = 0, leaves_checked = 0;
    // The node's primitive range [begin, end), checking its split on the way.
    std::function<std::pair<uint32_t, uint32_t>(uint32_t, size_t)> walk = [&](uint32_t index,
                                                                              size_t depth) {
      const BvhNode& node = bvh.nodes()[index];
      if (node.count > 0) {
        EXPECT_LE(node.count, kMaxLeaf);
        return std::pair<uint32_t, uint32_t>{node.offset, node.offset + node.count};
      }
      auto [begin, mid] = walk(index + 1, depth + 1);
      auto [mid2, end] = walk(node.offset, depth + 1);
      EXPECT_EQ(mid, mid2) << name << " node " << index;
      (void)mid2;
      return std::pair<uint32_t, uint32_t>{begin, end};
    };
    // The least-cost binned split of primitives order[begin, end): axis (-1: none), bin, cost.
    struct Best {
      int axis = -1, bin = 0;
      float cost = INFINITY;
    };
    auto best_split = [&](uint32_t begin, uint32_t end, std::vector<int>(&bin_of)[3]) {
      Aabb box, centroids;
      for (uint32_t k = begin; k < end; ++k) {
        const Aabb& b = prims[order[k]];
        box.grow(b);
        centroids.grow(b.lo + b.hi);
      }
      Best best;
      const float inv_area = 1.0f / std::max(box.surface_area(), 1e-30f);
      for (int a = 0; a < 3; ++a) {
        bin_of[a].assign(end - begin, 0);
        const float extent = centroids.hi[a] - centroids.lo[a];
        if (!(extent > 0.0f)) continue;
        const float scale = float(kBins) / extent;
        Aabb bin_box[kBins];
        uint32_t count[kBins] = {};
        for (uint32_t k = begin; k < end; ++k) {
          const Aabb& b = prims[order[k]];
          const int bin = std::min(kBins - 1, int(((b.lo + b.hi)[a] - centroids.lo[a]) * scale));
          bin_of[a][k - begin] = bin;
          count[bin]++;
          bin_box[bin].grow(b);
        }
        for (int split = 0; split < kBins - 1; ++split) {
          Aabb left, right;
          uint32_t n_left = 0, n_right = 0;
          for (int bin = 0; bin <= split; ++bin) left.grow(bin_box[bin]), n_left += count[bin];
          for (int bin = split + 1; bin < kBins; ++bin)
            right.grow(bin_box[bin]), n_right += count[bin];
          if (n_left == 0 || n_right == 0) continue;
          const float cost = kTraversal + inv_area * (left.surface_area() * tests(n_left) +
                                                      right.surface_area() * tests(n_right));
          if (cost < best.cost) best = {a, split, cost};
        }
      }
      return best;
    };
    std::function<void(uint32_t, size_t)> check = [&](uint32_t index, size_t depth) {
      const BvhNode& node = bvh.nodes()[index];
      std::vector<int> bin_of[3];
      if (node.count > 0) {
        if (node.count > 1 && depth < kMedianDepth) {
          const Best best = best_split(node.offset, node.offset + node.count, bin_of);
          EXPECT_FALSE(best.cost < tests(node.count))
              << name << " leaf " << index << " of " << node.count << " has a cheaper split";
          ++leaves_checked;
        }
        return;
      }
      const auto [begin, mid] = walk(index + 1, depth + 1);
      const auto [mid2, end] = walk(node.offset, depth + 1);
      (void)mid2;
      if (depth < kMedianDepth) {
        const Best best = best_split(begin, end, bin_of);
        EXPECT_EQ(int(node.axis), best.axis) << name << " node " << index;
        if (best.axis >= 0) {
          int wrong = 0;
          for (uint32_t k = begin; k < end; ++k)
            wrong += (bin_of[best.axis][k - begin] <= best.bin) != (k < mid);
          EXPECT_EQ(wrong, 0) << name << " node " << index << ": primitives on the wrong side";
        }
        ++inner_checked;
      }
      check(index + 1, depth + 1);
      check(node.offset, depth + 1);
    };
    check(0, 0);
    EXPECT_GT(inner_checked, 300) << name;
    EXPECT_GT(leaves_checked, 100) << name;
  }
}

TEST(Bvh, BinaryTreeIsSane) {
  Scene s = builtin("soup:20000");
  TraceGeometry g(s, SphereMode::Analytic, 24, AccelKind::Bvh2);
  const Bvh& bvh = g.bvh();
  EXPECT_EQ(sizeof(BvhNode), 32u);
  const BvhBuildStats& st = bvh.stats();
  EXPECT_EQ(st.primitives, 20000u);
  EXPECT_EQ(st.nodes, bvh.nodes().size());
  EXPECT_EQ(st.nodes, 2 * st.leaves - 1);  // a binary tree
  EXPECT_LT(st.max_depth, size_t(Bvh::kStackSize));
  // Every primitive sits in exactly one leaf, and leaf boxes contain their primitives.
  std::vector<int> seen(20000, 0);
  for (const BvhNode& n : bvh.nodes()) {
    if (n.count == 0) continue;
    EXPECT_LE(n.count, Bvh::kMaxLeafSize);
    for (uint32_t i = n.offset; i < n.offset + n.count; ++i) seen[bvh.primitive_order()[i]]++;
  }
  for (int c : seen) ASSERT_EQ(c, 1);
  // Leaves in the BVH hold a handful of primitives: the SAH cost per ray (in triangle tests)
  // is under 2% of testing them all.
  EXPECT_LT(st.sah_cost, 0.02 * 20000);
  // Memory target: at most 64 bytes per triangle, nodes included.
  EXPECT_LE(g.acceleration_bytes(), 64u * 20000);
  // Acceleration memory is nodes + leaf-ordered triangles + slot indices, nothing else.
  EXPECT_EQ(g.acceleration_bytes(),
            st.nodes * sizeof(BvhNode) + 20000 * (sizeof(TrianglePrecomputed) + sizeof(uint32_t)));
}

// Walks the wide tree: every triangle in exactly one lane, every child box containing all the
// triangles below it, unused lanes never hit, references in range.
TEST(WideBvh, EveryTriangleOnceAndEveryBoxContainsItsSubtree) {
  for (const char* name : {"soup:20000", "tessphere:20000"}) {
    Scene s = builtin(name);
    TraceGeometry g(s, SphereMode::Analytic, 24, AccelKind::Bvh);
    const WideBvh& w = g.wide_bvh();
    const size_t n = g.triangle_count();
    ASSERT_FALSE(w.empty());
    std::vector<int> seen(n, 0);
    size_t leaves = 0, slots = 0;
    // Returns the bounds of the triangles below `ref`.
    std::function<Aabb(uint32_t, size_t)> walk = [&](uint32_t ref, size_t depth) {
      Aabb box;
      EXPECT_LE(depth, w.stats().max_depth + 1);
      if (WideBvh::is_leaf(ref)) {
        ++leaves;
        uint32_t first = WideBvh::leaf_first_block(ref), count = WideBvh::leaf_triangles(ref);
        EXPECT_GE(count, 1u);
        EXPECT_LE(count, uint32_t(kMaxLeafTriangles));
        for (uint32_t k = 0; k < (count + 3) / 4; ++k) {
          EXPECT_LT(first + k, w.blocks().size());
          const TriangleBlock& b = w.blocks()[first + k];
          for (uint32_t lane = 0; lane < 4; ++lane) {
            uint32_t p = b.primitive[lane];
            if (4 * k + lane >= count) {
              EXPECT_EQ(p, kUnusedLane);
              EXPECT_EQ(b.e1[0][lane], 0.0f);
              EXPECT_EQ(b.e2[2][lane], 0.0f);
              continue;
            }
            EXPECT_LT(p, n);
            if (p >= n) continue;
            seen[p]++;
            glm::vec3 v0(b.v0[0][lane], b.v0[1][lane], b.v0[2][lane]);
            glm::vec3 e1(b.e1[0][lane], b.e1[1][lane], b.e1[2][lane]);
            glm::vec3 e2(b.e2[0][lane], b.e2[1][lane], b.e2[2][lane]);
            box.grow(v0);
            box.grow(v0 + e1);
            box.grow(v0 + e2);
          }
        }
        return box;
      }
      EXPECT_LT(ref, w.nodes().size());
      const WideNode& node = w.nodes()[ref];
      int used = 0;
      for (int i = 0; i < kWideBvhWidth; ++i) {
        if (node.child[i] == kEmptyTree) {
          EXPECT_EQ(node.bounds[0][i], INFINITY);
          EXPECT_EQ(node.bounds[1][i], -INFINITY);
          continue;
        }
        ++used;
        Aabb child = walk(node.child[i], depth + 1);
        for (int a = 0; a < 3; ++a) {
          EXPECT_LE(node.bounds[2 * a][i], child.lo[a]);
          EXPECT_GE(node.bounds[2 * a + 1][i], child.hi[a]);
        }
        box.grow(child);
      }
      EXPECT_GE(used, 2);
      slots += size_t(used);
      return box;
    };
    walk(w.root(), 0);
    for (size_t p = 0; p < n; ++p) ASSERT_EQ(seen[p], 1) << name << " triangle " << p;
    EXPECT_EQ(leaves, w.stats().leaves);
    EXPECT_EQ(slots, w.stats().child_slots);
    EXPECT_EQ(w.stats().nodes, w.nodes().size());
    // Collapsing fills nodes: a binary tree copied as it is would use 2 slots of 8; the nodes
    // just above the leaves have fewer children than 8, so the average is lower than 8.
    EXPECT_GT(double(slots) / double(w.nodes().size()), 4.0) << name;
    // Memory target: at most 64 bytes per triangle, nodes and leaf blocks included.
    double bytes_per_triangle = double(g.acceleration_bytes()) / double(n);
    std::printf(
        "%s: %.1f bytes per triangle, %zu nodes (%.2f of 8 slots used), %zu blocks (%.2f "
        "of 4 lanes used)\n",
        name, bytes_per_triangle, w.nodes().size(), double(slots) / double(w.nodes().size()),
        w.blocks().size(), double(n) / double(4 * w.blocks().size()));
    EXPECT_LE(bytes_per_triangle, 64.0) << name;
    RecordProperty(std::string("bytes_per_triangle_") + name, std::to_string(bytes_per_triangle));
    EXPECT_EQ(g.acceleration_bytes(),
              w.nodes().size() * sizeof(WideNode) + w.blocks().size() * sizeof(TriangleBlock));
  }
}

TEST(WideBvh, EmptyAndTinyScenes) {
  Scene s;
  s.materials.push_back(default_material());
  TraceGeometry none(s, SphereMode::Analytic, 24, AccelKind::Bvh);
  EXPECT_EQ(none.error(), "");
  HitRecord h;
  EXPECT_FALSE(none.closest(Ray{{0, 0, 1}, {0, 0, -1}, 0, INFINITY}, h));
  // One triangle: the root is a leaf.
  Object o;
  o.type = ObjectType::Triangles;
  o.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  o.mesh.triangles = {{0, 1, 2}};
  s.objects.push_back(o);
  TraceGeometry one(s, SphereMode::Analytic, 24, AccelKind::Bvh);
  EXPECT_TRUE(WideBvh::is_leaf(one.wide_bvh().root()));
  ASSERT_TRUE(one.closest(Ray{{0.25f, 0.25f, 1}, {0, 0, -1}, 0, INFINITY}, h));
  EXPECT_EQ(h.t, 1.0f);
  EXPECT_EQ(h.primitive, 0u);
  EXPECT_FALSE(one.closest(Ray{{0.25f, 0.25f, 1}, {0, 0, -1}, 0, 1.0f}, h));  // tmax excluded
  EXPECT_FALSE(one.closest(Ray{{0.25f, 0.25f, 1}, {0, 0, -1}, 1.0f, INFINITY}, h));  // tmin too
  EXPECT_FALSE(one.occluded(Ray{{0.25f, 0.25f, 1}, {0, 0, -1}, 0, 1.0f}));
  EXPECT_TRUE(one.occluded(Ray{{0.25f, 0.25f, 1}, {0, 0, -1}, 0, 1.0001f}));
}

// Embree's build reports the bytes it keeps (its memory monitor, while rtcCommitScene runs),
// which the benchmarks set beside the wide BVH's. Embree's leaves alone hold each triangle's
// vertices or edges with its ids (Triangle4v: 44 bytes a triangle, Triangle4: 56), so less
// than 40 bytes a triangle is not its BVH; its copy of the geometry (48 bytes a triangle of a
// soup) is not counted, so it stays under 100; and the bytes grow with the triangles.
TEST(EmbreeBvh, ReportsTheBytesItsBuildKeeps) {
  double per_triangle[2];
  for (int i : {0, 1}) {
    const uint32_t n = i == 0 ? 20000 : 40000;
    TraceGeometry g(builtin("soup:" + std::to_string(n)), SphereMode::Analytic, 24,
                    AccelKind::Embree);
    ASSERT_EQ(g.error(), "");
    per_triangle[i] = double(g.acceleration_bytes()) / double(n);
    EXPECT_GE(per_triangle[i], 40.0) << n << " triangles";
    EXPECT_LE(per_triangle[i], 100.0) << n << " triangles";
  }
  EXPECT_NEAR(per_triangle[1] / per_triangle[0], 1.0, 0.25);
}

TEST(Bvh, IdenticalCentroidsStillBuildABoundedTree) {
  // 5000 copies of one triangle: SAH finds nothing to split on; median splits must take over.
  Scene s;
  s.materials.push_back(default_material());
  Object o;
  o.type = ObjectType::Triangles;
  for (uint32_t i = 0; i < 5000; ++i) {
    o.mesh.positions.insert(o.mesh.positions.end(), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    o.mesh.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
  }
  s.objects.push_back(o);
  for (AccelKind accel : {AccelKind::Bvh2, AccelKind::Bvh}) {
    TraceGeometry g(s, SphereMode::Analytic, 24, accel);
    EXPECT_LT(g.bvh().stats().max_depth, size_t(Bvh::kStackSize));
    EXPECT_LT(g.wide_bvh().stats().max_depth, size_t(Bvh::kStackSize));
    HitRecord h;
    TraversalCounters c;
    ASSERT_TRUE(g.closest(Ray{{0.2f, 0.2f, 1}, {0, 0, -1}, 0, INFINITY}, h, c));
    EXPECT_FLOAT_EQ(h.t, 1.0f);
    EXPECT_EQ(h.primitive, 0u);  // all 5000 tie: the lowest index wins
  }
}

TEST(Bvh, CountsFewerTestsThanBruteForce) {
  Scene s = builtin("soup:20000");
  TraceGeometry brute(s, SphereMode::Analytic, 24, AccelKind::None);
  for (AccelKind accel : {AccelKind::Bvh2, AccelKind::Bvh}) {
    TraceGeometry bvh(s, SphereMode::Analytic, 24, accel);
    TraversalCounters cb, cn;
    for (const Ray& r : random_rays(200, 9)) {
      HitRecord h;
      bvh.closest(r, h, cb);
      brute.closest(r, h, cn);
    }
    EXPECT_EQ(cn.primitive_tests, 200u * 20000u);
    EXPECT_LT(cb.primitive_tests * 20, cn.primitive_tests);
    EXPECT_GT(cb.nodes_visited, 200u);
  }
}

// A count no ray's traversal reaches: what a packet's counter slots hold before the query.
constexpr uint64_t kStaleCount = uint64_t(1) << 60;

// Packets of primary rays (one origin, up to 64 directions) find exactly the hits single rays
// find, lane by lane, with every kernel and with Embree's rtcIntersect8/16; the per-ray counters
// add up to some work for every ray. Tiles are full or partial, aim at the scene or past it, and
// include directions with zero components (the robust single-ray path). The analytic shapes'
// tree is walked by the packet too: "spheres" and "mirror_balls" have enough spheres for inner
// nodes, where a ray that wrongly leaves the packet's walk loses its hit.
TEST(Packets, SameHitsAsSingleRays) {
  for (Scene scene : {mixed_scene(), builtin("tessphere:5000"), builtin("cornell"),
                      builtin("spheres"), builtin("mirror_balls:100")}) {
    TraceGeometry brute(scene, SphereMode::Analytic, 24, AccelKind::None);
    std::vector<Accelerated> accels = accelerated(scene, SphereMode::Analytic);
    accels.push_back({"embree", std::make_unique<TraceGeometry>(scene, SphereMode::Analytic, 24,
                                                                AccelKind::Embree)});
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> U(-1.0f, 1.0f);
    int hits = 0;
    for (int tile = 0; tile < 60; ++tile) {
      RayPacket p;
      glm::vec3 o =
          tile % 2 ? scene.camera.eye : scene.camera.eye + 0.1f * glm::vec3(U(rng), U(rng), U(rng));
      p.origin[0] = o.x;
      p.origin[1] = o.y;
      p.origin[2] = o.z;
      p.tmin = tile % 5 == 1 ? 0.5f : 0.0f;
      p.tmax = tile % 7 == 2 ? 3.5f : INFINITY;
      p.count = tile % 4 == 3 ? 1 + tile % 37 : kPacketRays;
      glm::vec3 target = scene.camera.target + 0.5f * glm::vec3(U(rng), U(rng), U(rng));
      glm::vec3 centre = target - o;
      for (int k = 0; k < p.count; ++k) {
        glm::vec3 d = centre + 0.03f * glm::length(centre) *
                                   glm::vec3(float(k % 8) - 3.5f, float(k / 8) - 3.5f, 0.0f);
        if (tile == 10 && k == 5) d = {0.0f, -0.0f, -1.0f};  // axis-parallel lane
        for (int a = 0; a < 3; ++a) p.dir[a][k] = d[a];
      }
      for (const Accelerated& a : accels) {
        // closest_packet writes every slot and reads none: what the slots held before (here a
        // hit and counts no ray could have) must not show through.
        const HitRecord stale{-1.0f, 7u, 0.25f, 0.5f, 3u, true};
        const TraversalCounters stale_work{kStaleCount, kStaleCount};
        HitRecord packet_hits[kPacketRays];
        TraversalCounters work[kPacketRays];
        std::fill_n(packet_hits, kPacketRays, stale);
        std::fill_n(work, kPacketRays, stale_work);
        a.geometry->closest_packet(p, packet_hits, work);
        HitRecord unused_hits[kPacketRays];
        std::fill_n(unused_hits, kPacketRays, stale);
        a.geometry->closest_packet(p, unused_hits, nullptr);  // the uncounted variant
        for (int k = 0; k < p.count; ++k) {
          Ray ray{o, {p.dir[0][k], p.dir[1][k], p.dir[2][k]}, p.tmin, p.tmax};
          HitRecord single;
          bool found = brute.closest(ray, single);
          const HitRecord& h = packet_hits[k];
          std::string what =
              a.label + " tile " + std::to_string(tile) + " ray " + std::to_string(k);
          ASSERT_EQ(h.primitive != kNoPrimitive, found) << what;
          ASSERT_EQ(unused_hits[k].primitive, h.primitive) << what;
          ASSERT_LT(work[k].nodes_visited, kStaleCount) << what;
          ASSERT_LT(work[k].primitive_tests, kStaleCount) << what;
          if (a.label == "embree") {  // Embree counts nothing
            EXPECT_EQ(work[k].nodes_visited + work[k].primitive_tests, 0u) << what;
          }
          if (!found) {
            const HitRecord none;
            EXPECT_TRUE(same_bits(h.t, none.t) && h.csg_leaf == none.csg_leaf &&
                        h.csg_flip == none.csg_flip)
                << what;
            continue;
          }
          hits += a.label == "bvh2";
          if (a.label == "embree") {  // its own triangle test: same object, t to float precision
            EXPECT_EQ(a.geometry->surface(ray, h).object, brute.surface(ray, single).object)
                << what;
            EXPECT_NEAR(h.t, single.t, 1e-4f * single.t) << what;
            continue;
          }
          ASSERT_EQ(h.primitive, single.primitive) << what;
          ASSERT_TRUE(same_bits(h.t, single.t) && same_bits(h.u, single.u) &&
                      same_bits(h.v, single.v))
              << what;
          ASSERT_EQ(h.csg_leaf, single.csg_leaf) << what;
          ASSERT_EQ(h.csg_flip, single.csg_flip) << what;
          EXPECT_GT(work[k].nodes_visited + work[k].primitive_tests, 0u) << what;
        }
      }
    }
    EXPECT_GT(hits, 500);
  }
}

// The hybrid's rebuild, a packet at a time: every ray names an object and primitive (the triangle
// it hits, a neighbour, one far away, a tessellated sphere, an analytic shape, ids out of range;
// in some packets every ray names one triangle), and intersect_named_packet finds what
// intersect_named finds ray by ray, to the bit, with the same counted tests, whichever kernel tests
// the named triangles eight at a time.
TEST(Packets, RebuiltHitsAreIntersectVisiblesOwn) {
  int hits = 0, misses = 0;
  for (Scene scene :
       {mixed_scene(), builtin("tessphere:5000"), builtin("cornell"), builtin("soup:3000")}) {
    for (Isa isa : {Isa::Sse, Isa::Avx2, Isa::Avx512}) {
      if (!cpu_supports(isa)) continue;
      TraceGeometry geometry(scene, SphereMode::Analytic, 24, AccelKind::Bvh,
                             TriangleTest::MollerTrumbore, isa);
      ASSERT_TRUE(geometry.error().empty());
      std::mt19937 rng(23);
      std::uniform_real_distribution<float> U(-1.0f, 1.0f);
      for (int tile = 0; tile < 40; ++tile) {
        RayPacket p;
        const glm::vec3 o = scene.camera.eye;
        for (int a = 0; a < 3; ++a) p.origin[a] = o[a];
        p.tmin = tile % 5 == 1 ? 0.5f : 0.0f;
        p.tmax = tile % 7 == 2 ? 3.5f : INFINITY;
        p.count = tile % 4 == 3 ? 1 + tile % 37 : kPacketRays;
        const glm::vec3 centre = scene.camera.target + 0.5f * glm::vec3(U(rng), U(rng), U(rng)) - o;
        uint32_t object[kPacketRays], primitive[kPacketRays];
        // Every third tile wants every ray, with the bits past the count set too: the packet's
        // count bounds the rays tested.
        uint64_t wanted = tile % 3 == 0 ? ~uint64_t(0) : 0;
        for (int k = 0; k < p.count; ++k) {
          const glm::vec3 d =
              centre + 0.02f * glm::length(centre) *
                           glm::vec3(float(k % 8) - 3.5f, float(k / 8) - 3.5f, 0.0f);
          for (int a = 0; a < 3; ++a) p.dir[a][k] = d[a];
          HitRecord h;
          Ray ray{o, d, p.tmin, p.tmax};
          object[k] = kNoId;
          primitive[k] = kNoId;
          if (geometry.closest(ray, h)) std::tie(object[k], primitive[k]) = geometry.hit_ids(h);
          switch ((k + tile) % 6) {
            case 1:  // a neighbour: shared edges, misses
              primitive[k] += 1;
              break;
            case 2:  // far away
              primitive[k] = uint32_t(rng() % 5000);
              break;
            case 3:  // any object
              object[k] = uint32_t(rng() % (scene.objects.size() + 1));
              break;
            default:
              break;
          }
          // Some unwanted, some naming nothing.
          if (object[k] != kNoId || k % 5 == 0) wanted |= uint64_t(1) << k;
        }
        if (tile % 8 == 5) {  // every ray names what the middle one hits: groups of one triangle
          wanted = p.all();
          for (int k = 0; k < p.count; ++k) {
            object[k] = object[p.count / 2];
            primitive[k] = primitive[p.count / 2];
          }
        }
        HitRecord packet_hits[kPacketRays];
        TraversalCounters work[kPacketRays];
        const uint64_t found =
            geometry.intersect_named_packet(p, object, primitive, wanted, packet_hits, work);
        EXPECT_EQ(found & ~p.all(), 0u) << "a ray past the packet's count";
        for (int k = 0; k < p.count; ++k) {
          const std::string what = std::string(to_string(isa)) + " tile " + std::to_string(tile) +
                                   " ray " + std::to_string(k);
          if (!((wanted >> k) & 1)) {
            EXPECT_FALSE((found >> k) & 1) << what;
            continue;
          }
          HitRecord single;
          TraversalCounters single_work;
          const Ray ray{o, {p.dir[0][k], p.dir[1][k], p.dir[2][k]}, p.tmin, p.tmax};
          const bool want =
              geometry.intersect_named(ray, object[k], primitive[k], single, single_work);
          ASSERT_EQ(bool((found >> k) & 1), want) << what;
          EXPECT_EQ(work[k].primitive_tests, single_work.primitive_tests) << what;
          (want ? hits : misses)++;
          if (!want) continue;
          const HitRecord& h = packet_hits[k];
          ASSERT_EQ(h.primitive, single.primitive) << what;
          ASSERT_TRUE(same_bits(h.t, single.t) && same_bits(h.u, single.u) &&
                      same_bits(h.v, single.v))
              << what;
        }
      }
    }
  }
  EXPECT_GT(hits, 2000);
  EXPECT_GT(misses, 1000);
}
