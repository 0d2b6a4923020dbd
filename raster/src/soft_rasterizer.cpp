#include "rvr/raster/soft_rasterizer.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "rvr/shared/camera.h"
#include "rvr/shared/shading.h"
#include "rvr/shared/tessellate.h"

namespace rvr {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

constexpr int kTile = 64;
// Sub-pixel precision of the edge functions: finer than GL's usual 8 bits, so that snapping
// an edge-on sliver (a sphere's silhouette) rarely makes it cover a centre it does not.
constexpr int kSubBits = 12;
constexpr int64_t kSub = int64_t(1) << kSubBits;
// Guard-band clipping keeps screen coordinates within +-(2^15 + 2^14) pixels, i.e. 28-bit
// fixed point, so edge functions (products of 29-bit differences) never overflow int64.
constexpr double kGuardPixels = double(1 << 16);
constexpr int kMaxImageSide = 1 << 15;

// What shading needs per object; tessellated shapes point into SoftRasterizer-owned meshes.
struct DrawObject {
  const TriangleMesh* mesh = nullptr;
  const Material* material = nullptr;
  bool smooth = false;
  bool use_primitive_id = false;
};

// A screen-space triangle after clipping. One input triangle gives up to a few of these.
struct SetupTriangle {
  std::array<int64_t, 3> x, y;   // fixed point, oriented so the edge functions are >= 0 inside
  std::array<bool, 3> top_left;  // edge i runs from vertex i to vertex i+1
  // q_j(p) = q0[j] + qa[j]*(px - ox) + qb[j]*(py - oy) = (barycentric j of the ORIGINAL
  // triangle) / w: linear in screen space, so sum_j q_j = 1/w = 1/view depth, and q_j/sum is
  // the perspective-correct barycentric. From the unsnapped vertices, in double: P must be
  // exact where 1/|L - P|^2 is steep (surfaces next to a light).
  std::array<double, 3> q0, qa, qb;
  double ox = 0, oy = 0;
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // pixel bounding box, inclusive, on screen
  uint32_t object = 0, primitive = 0;

  double inv_w(double px, double py, std::array<double, 3>& q) const {
    double s = 0;
    for (int j = 0; j < 3; ++j) {
      // Clamped: a sliver may cover a centre just outside itself (snapping); it is then seen
      // at its nearest edge point instead of extrapolating depth.
      q[j] = std::max(0.0, q0[j] + qa[j] * (px - ox) + qb[j] * (py - oy));
      s += q[j];
    }
    return s;
  }
};

struct ClipVertex {
  glm::dvec4 c;  // clip space
  glm::dvec3 b;  // barycentric in the original triangle
};

// Clip-space planes as dot(plane, c) >= 0.
using Polygon = std::vector<ClipVertex>;

void clip_polygon(const Polygon& in, const glm::dvec4& plane, Polygon& out) {
  out.clear();
  for (size_t i = 0; i < in.size(); ++i) {
    const ClipVertex& a = in[i];
    const ClipVertex& b = in[(i + 1) % in.size()];
    double da = glm::dot(plane, a.c), db = glm::dot(plane, b.c);
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) {
      double t = da / (da - db);
      out.push_back({a.c + t * (b.c - a.c), a.b + t * (b.b - a.b)});
    }
  }
}

struct Setup {
  int width, height;
  glm::dmat4 view_projection;
  std::vector<SetupTriangle> triangles;
  size_t clipped = 0;  // input triangles culled or clipped
  Polygon poly, scratch;

  void add(const std::array<glm::vec3, 3>& p, uint32_t object, uint32_t primitive) {
    Polygon& v = poly;
    v.resize(3);
    for (int i = 0; i < 3; ++i) {
      v[i].c = view_projection * glm::dvec4(glm::dvec3(p[i]), 1.0);
      v[i].b = glm::dvec3(0.0);
      v[i].b[i] = 1.0;
    }
    // Trivial reject against the view frustum; then clip only where a plane is crossed.
    const double gx = kGuardPixels / width, gy = kGuardPixels / height;
    const glm::dvec4 frustum[6] = {{1, 0, 0, 1},  {-1, 0, 0, 1}, {0, 1, 0, 1},
                                   {0, -1, 0, 1}, {0, 0, 1, 1},  {0, 0, -1, 1}};
    for (const glm::dvec4& f : frustum) {
      if (glm::dot(f, v[0].c) < 0 && glm::dot(f, v[1].c) < 0 && glm::dot(f, v[2].c) < 0) {
        ++clipped;
        return;
      }
    }
    // Near first: afterwards w >= near > 0, so the guard planes (scaled by w) are well defined.
    const glm::dvec4 planes[5] = {
        {0, 0, 1, 1}, {1, 0, 0, gx}, {-1, 0, 0, gx}, {0, 1, 0, gy}, {0, -1, 0, gy}};
    bool was_clipped = false;
    for (const glm::dvec4& plane : planes) {
      bool outside = false;
      for (const ClipVertex& c : v) outside |= glm::dot(plane, c.c) < 0;
      if (!outside) continue;
      was_clipped = true;
      clip_polygon(v, plane, scratch);
      std::swap(v, scratch);
      if (v.size() < 3) break;
    }
    clipped += was_clipped ? 1 : 0;
    // A convex polygon as a fan: the inner diagonals are shared edges, drawn once by the rule.
    for (size_t i = 1; i + 1 < v.size(); ++i) emit(v[0], v[i], v[i + 1], object, primitive);
  }

  void emit(const ClipVertex& a, const ClipVertex& b, const ClipVertex& c, uint32_t object,
            uint32_t primitive) {
    const ClipVertex* cv[3] = {&a, &b, &c};
    SetupTriangle t;
    std::array<double, 3> sx, sy;
    for (int i = 0; i < 3; ++i) {
      const glm::dvec4& k = cv[i]->c;
      // Viewport with y flipped: row 0 is the top.
      sx[i] = (k.x / k.w * 0.5 + 0.5) * width;
      sy[i] = (0.5 - k.y / k.w * 0.5) * height;
      t.x[i] = std::llround(sx[i] * double(kSub));
      t.y[i] = std::llround(sy[i] * double(kSub));
    }
    int64_t area = (t.x[1] - t.x[0]) * (t.y[2] - t.y[0]) - (t.y[1] - t.y[0]) * (t.x[2] - t.x[0]);
    if (area == 0) return;  // covers no pixel centre
    if (area < 0) {         // two-sided: either winding, oriented here
      std::swap(cv[1], cv[2]);
      std::swap(sx[1], sx[2]);
      std::swap(sy[1], sy[2]);
      std::swap(t.x[1], t.x[2]);
      std::swap(t.y[1], t.y[2]);
    }
    int64_t min_x = std::min({t.x[0], t.x[1], t.x[2]}), max_x = std::max({t.x[0], t.x[1], t.x[2]});
    int64_t min_y = std::min({t.y[0], t.y[1], t.y[2]}), max_y = std::max({t.y[0], t.y[1], t.y[2]});
    t.x0 = int(std::max<int64_t>(0, min_x >> kSubBits));
    t.y0 = int(std::max<int64_t>(0, min_y >> kSubBits));
    t.x1 = int(std::min<int64_t>(width - 1, max_x >> kSubBits));
    t.y1 = int(std::min<int64_t>(height - 1, max_y >> kSubBits));
    if (t.x0 > t.x1 || t.y0 > t.y1) return;
    for (int i = 0; i < 3; ++i) {
      int64_t dx = t.x[(i + 1) % 3] - t.x[i], dy = t.y[(i + 1) % 3] - t.y[i];
      // y points down: with positive area, top edges run right and left edges run up.
      t.top_left[i] = (dy == 0 && dx > 0) || dy < 0;
    }
    double dx1 = sx[1] - sx[0], dy1 = sy[1] - sy[0], dx2 = sx[2] - sx[0], dy2 = sy[2] - sy[0];
    double det = dx1 * dy2 - dx2 * dy1;
    if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return;
    t.ox = sx[0];
    t.oy = sy[0];
    for (int j = 0; j < 3; ++j) {
      double f0 = cv[0]->b[j] / cv[0]->c.w, f1 = cv[1]->b[j] / cv[1]->c.w,
             f2 = cv[2]->b[j] / cv[2]->c.w;
      t.q0[j] = f0;
      t.qa[j] = ((f1 - f0) * dy2 - (f2 - f0) * dy1) / det;
      t.qb[j] = ((f2 - f0) * dx1 - (f1 - f0) * dx2) / det;
    }
    t.object = object;
    t.primitive = primitive;
    triangles.push_back(t);
  }
};

struct TileCounters {
  uint64_t generated = 0;
};

// Rasterizes one tile: every binned triangle in submission order, strict-less depth test, so
// the result does not depend on which thread runs which tile.
void raster_tile(int tx, int ty, const std::vector<uint32_t>& bin,
                 const std::vector<SetupTriangle>& tris, double near_plane, double far_plane,
                 FrameBuffers& fb, std::vector<uint32_t>& visible, TileCounters& counters) {
  const int ox = tx * kTile, oy = ty * kTile;
  const int tw = std::min(kTile, fb.width - ox), th = std::min(kTile, fb.height - oy);
  std::array<double, kTile * kTile> zbuf;
  std::array<uint32_t, kTile * kTile> ids;
  std::array<uint32_t, kTile * kTile> cost;
  zbuf.fill(std::numeric_limits<double>::infinity());
  ids.fill(kNoId);
  cost.fill(0);
  uint64_t generated = 0;
  std::array<double, 3> q;
  for (uint32_t index : bin) {
    const SetupTriangle& t = tris[index];
    const int x0 = std::max(t.x0, ox), x1 = std::min(t.x1, ox + tw - 1);
    const int y0 = std::max(t.y0, oy), y1 = std::min(t.y1, oy + th - 1);
    if (x0 > x1 || y0 > y1) continue;
    // E_i(p) = (x[i+1]-x[i])*(py-y[i]) - (y[i+1]-y[i])*(px-x[i]) at pixel centres, in
    // sub-pixel units; a non-top-left edge needs E > 0, i.e. E - 1 >= 0 in integers.
    const int64_t px0 = int64_t(x0) * kSub + kSub / 2, py0 = int64_t(y0) * kSub + kSub / 2;
    int64_t row[3], step_x[3], step_y[3];
    for (int i = 0; i < 3; ++i) {
      const int n = (i + 1) % 3;
      const int64_t dx = t.x[n] - t.x[i], dy = t.y[n] - t.y[i];
      row[i] = dx * (py0 - t.y[i]) - dy * (px0 - t.x[i]) - (t.top_left[i] ? 0 : 1);
      step_x[i] = -dy * kSub;
      step_y[i] = dx * kSub;
    }
    for (int y = y0; y <= y1; ++y) {
      int64_t e0 = row[0], e1 = row[1], e2 = row[2];
      for (int x = x0; x <= x1; ++x) {
        if ((e0 | e1 | e2) >= 0) {
          const size_t i = size_t(y - oy) * kTile + size_t(x - ox);
          ++cost[i];
          ++generated;
          const double depth = 1.0 / t.inv_w(x + 0.5, y + 0.5, q);
          // The depth range clips what lies beyond far (and rounding just inside near).
          if (depth < zbuf[i] && depth >= near_plane && depth <= far_plane) {
            zbuf[i] = depth;
            ids[i] = index;
          }
        }
        e0 += step_x[0];
        e1 += step_x[1];
        e2 += step_x[2];
      }
      for (int i = 0; i < 3; ++i) row[i] += step_y[i];
    }
  }
  for (int y = 0; y < th; ++y) {
    for (int x = 0; x < tw; ++x) {
      const size_t i = size_t(y) * kTile + size_t(x);
      const size_t o = fb.index(ox + x, oy + y);
      fb.depth[o] = ids[i] == kNoId ? std::numeric_limits<float>::infinity() : float(zbuf[i]);
      fb.cost[o] = float(cost[i]);
      visible[o] = ids[i];
    }
  }
  counters.generated = generated;
}

std::string object_label(const Object& o, size_t index) {
  return o.name.empty() ? fmt::format("csg#{}", index) : o.name;
}

Expected<RenderOutput> render_impl(const Scene& scene, const RenderOptions& options) {
  const int w = scene.image.width, h = scene.image.height;
  if (w < 1 || h < 1) return bad_input(fmt::format("image size {}x{} is empty", w, h));
  if (w > kMaxImageSide || h > kMaxImageSide)
    return bad_input(fmt::format("image size {}x{}: softraster draws at most {} pixels a side", w,
                                 h, kMaxImageSide));
  RenderOutput out;
  ProgressSink* const progress = options.progress;
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);

  // --- setup: objects to triangles, transform, clip, bin (in submission order)
  auto t = Clock::now();
  std::vector<TriangleMesh> tessellated;  // sphere and plane meshes, alive until shading ends
  tessellated.reserve(scene.objects.size());
  std::vector<DrawObject> objects(scene.objects.size());
  std::vector<std::string> skipped_csg;
  bool mirror = false, transparency = false;
  const Material fallback = default_material();
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const Object& o = scene.objects[i];
    DrawObject& d = objects[i];
    if (o.material < scene.materials.size()) {
      d.material = &scene.materials[o.material];
    } else if (scene.materials.empty()) {
      d.material = &fallback;  // a hand-made scene with no material list: the built-in grey
    } else {
      return bad_input(
          fmt::format("object '{}': material index {} out of range", o.name, o.material));
    }
    switch (o.type) {
      case ObjectType::Triangles:
        d.mesh = &o.mesh;
        d.use_primitive_id = true;
        break;
      case ObjectType::Sphere:
        tessellated.push_back(tessellate_sphere(o.sphere, options.sphere_segments));
        d.mesh = &tessellated.back();
        break;
      case ObjectType::Plane:
        tessellated.push_back(tessellate_plane(o.plane));
        d.mesh = &tessellated.back();
        break;
      case ObjectType::Csg:
        skipped_csg.push_back(object_label(o, i));
        continue;
    }
    const TriangleMesh& m = *d.mesh;
    d.smooth = m.smooth();
    if (m.smooth() && m.normals.size() != m.positions.size())
      return bad_input(fmt::format("object '{}': {} normals for {} positions", o.name,
                                   m.normals.size(), m.positions.size()));
    for (const glm::uvec3& tri : m.triangles)
      if (std::max({tri.x, tri.y, tri.z}) >= m.positions.size())
        return bad_input(fmt::format("object '{}': triangle index out of range ({} positions)",
                                     o.name, m.positions.size()));
    mirror |= d.material->mirror > 0.0f;
    transparency |= d.material->transparency > 0.0f;
  }

  // Setup in parallel over fixed chunks of the submission order, each chunk transforming,
  // clipping and binning its own triangles; chunks are joined in order, so the triangle list and
  // every bin come out exactly as a serial pass would make them, whatever the thread count.
  const glm::dmat4 view_projection =
      glm::dmat4(projection_matrix(scene.camera, w, h)) * glm::dmat4(view_matrix(scene.camera));
  struct Submitted {
    uint32_t object, primitive;
  };
  std::vector<Submitted> order;
  for (size_t i = 0; i < objects.size(); ++i)
    if (const TriangleMesh* m = objects[i].mesh)
      for (size_t k = 0; k < m->triangles.size(); ++k) order.push_back({uint32_t(i), uint32_t(k)});
  const size_t submitted = order.size();
  const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
  const size_t tile_count = size_t(tiles_x) * size_t(tiles_y);
  constexpr size_t kChunk = 8192;
  const size_t chunk_count = (order.size() + kChunk - 1) / kChunk;
  std::vector<Setup> chunks(chunk_count, Setup{w, h, view_projection, {}, 0, {}, {}});
  std::vector<std::vector<std::vector<uint32_t>>> chunk_bins(chunk_count);
  if (progress) progress->begin("setup", submitted, "triangles");
  arena.execute([&] {
    tbb::parallel_for(size_t(0), chunk_count, [&](size_t c) {
      Setup& setup = chunks[c];
      const size_t end = std::min(order.size(), (c + 1) * kChunk);
      setup.triangles.reserve(end - c * kChunk);
      for (size_t j = c * kChunk; j < end; ++j) {
        const TriangleMesh& m = *objects[order[j].object].mesh;
        const glm::uvec3& tri = m.triangles[order[j].primitive];
        setup.add({m.positions[tri.x], m.positions[tri.y], m.positions[tri.z]}, order[j].object,
                  order[j].primitive);
      }
      auto& bins = chunk_bins[c];
      bins.resize(tile_count);
      for (size_t i = 0; i < setup.triangles.size(); ++i) {
        const SetupTriangle& st = setup.triangles[i];
        for (int ty = st.y0 / kTile; ty <= st.y1 / kTile; ++ty)
          for (int tx = st.x0 / kTile; tx <= st.x1 / kTile; ++tx)
            bins[size_t(ty) * size_t(tiles_x) + size_t(tx)].push_back(uint32_t(i));
      }
      if (progress) progress->advance(end - c * kChunk);
    });
  });
  // Joining the chunks: mostly allocation and copies, so time only.
  if (progress) progress->begin("bin");
  // Offsets of each chunk's triangles in the joined list.
  std::vector<uint32_t> first(chunk_count + 1, 0);
  size_t clipped = 0;
  for (size_t c = 0; c < chunk_count; ++c) {
    first[c + 1] = first[c] + uint32_t(chunks[c].triangles.size());
    clipped += chunks[c].clipped;
  }
  std::vector<SetupTriangle> tris(first[chunk_count]);
  std::vector<std::vector<uint32_t>> bins(tile_count);
  arena.execute([&] {
    tbb::parallel_for(size_t(0), chunk_count, [&](size_t c) {
      std::copy(chunks[c].triangles.begin(), chunks[c].triangles.end(), tris.begin() + first[c]);
    });
    tbb::parallel_for(size_t(0), tile_count, [&](size_t b) {
      size_t n = 0;
      for (size_t c = 0; c < chunk_count; ++c) n += chunk_bins[c][b].size();
      bins[b].reserve(n);
      for (size_t c = 0; c < chunk_count; ++c)
        for (uint32_t i : chunk_bins[c][b]) bins[b].push_back(first[c] + i);
    });
  });
  out.stats["time.setup"] = seconds_since(t);

  // --- raster: tiles in parallel, each independent of the others
  t = Clock::now();
  FrameBuffers& fb = out.buffers;
  fb.reset(w, h, scene.image.background);
  std::vector<uint32_t> visible(fb.pixel_count(), kNoId);
  std::vector<TileCounters> counters(bins.size());
  const double near_plane = scene.camera.near, far_plane = scene.camera.far;
  // The fraction in tiles, the speed in fragments (a tile's cost is its fragments).
  if (progress) progress->begin("raster", bins.size(), "tiles", "fragments");
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, bins.size()),
                      [&](const tbb::blocked_range<size_t>& r) {
                        uint64_t fragments = 0;
                        for (size_t b = r.begin(); b != r.end(); ++b) {
                          raster_tile(int(b % size_t(tiles_x)), int(b / size_t(tiles_x)), bins[b],
                                      tris, near_plane, far_plane, fb, visible, counters[b]);
                          fragments += counters[b].generated;
                        }
                        if (progress) progress->advance(r.size(), fragments);
                      });
  });
  out.stats["time.raster"] = seconds_since(t);

  // --- shade: deferred, each visible pixel once
  t = Clock::now();
  const std::vector<LightSample> samples = options.mode == RenderMode::Visibility
                                               ? std::vector<LightSample>{}
                                               : light_samples(scene.lights);
  const glm::vec3 eye = scene.camera.eye;
  if (progress) progress->begin("shade", uint64_t(w) * uint64_t(h), "pixels");
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
      std::array<double, 3> q;
      for (int y = r.begin(); y != r.end(); ++y) {
        for (int x = 0; x < w; ++x) {
          const size_t o = fb.index(x, y);
          if (visible[o] == kNoId) continue;
          const SetupTriangle& s = tris[visible[o]];
          const DrawObject& d = objects[s.object];
          const double inv_w = s.inv_w(x + 0.5, y + 0.5, q);
          const glm::vec3 b(float(q[0] / inv_w), float(q[1] / inv_w), float(q[2] / inv_w));
          const glm::uvec3& tri = d.mesh->triangles[s.primitive];
          const glm::vec3 &p0 = d.mesh->positions[tri.x], &p1 = d.mesh->positions[tri.y],
                          &p2 = d.mesh->positions[tri.z];
          const glm::vec3 P = b.x * p0 + b.y * p1 + b.z * p2;
          const glm::vec3 g = glm::normalize(glm::cross(p1 - p0, p2 - p0));
          const glm::vec3 shading =
              d.smooth ? glm::normalize(b.x * d.mesh->normals[tri.x] +
                                        b.y * d.mesh->normals[tri.y] + b.z * d.mesh->normals[tri.z])
                       : g;
          const glm::vec3 V = glm::normalize(eye - P);
          const glm::vec3 N = face_viewer(shading, g, V);
          fb.object_id[o] = s.object;
          fb.primitive_id[o] = d.use_primitive_id ? s.primitive : 0u;
          fb.normal[o] = N;
          if (options.mode != RenderMode::Visibility)
            fb.color[o] = shade_local(*d.material, P, N, V, scene.ambient, samples);
        }
      }
      if (progress) progress->advance(uint64_t(r.size()) * uint64_t(w));
    });
  });
  out.stats["time.shade"] = seconds_since(t);

  uint64_t generated = 0, covered = 0;
  for (const TileCounters& c : counters) generated += c.generated;
  for (uint32_t v : visible) covered += v != kNoId ? 1 : 0;
  out.stats["triangles.submitted"] = double(submitted);
  out.stats["triangles.clipped"] = double(clipped);
  out.stats["triangles.setup"] = double(tris.size());
  out.stats["fragments.generated"] = double(generated);
  out.stats["fragments.shaded"] = double(covered);
  out.stats["pixels.covered"] = double(covered);
  out.stats["overdraw"] = covered > 0 ? double(generated) / double(covered) : 0.0;

  if (!skipped_csg.empty()) {
    std::string names;
    for (const std::string& s : skipped_csg) names += (names.empty() ? "" : ", ") + s;
    out.warnings.push_back(fmt::format("csg objects have no z-buffer form: skipped {} ({})",
                                       skipped_csg.size(), names));
  }
  if (options.mode == RenderMode::Full) {
    if (!scene.lights.empty())
      out.warnings.push_back("shadows not rendered by softraster (no shadow maps yet)");
    if (mirror) out.warnings.push_back("mirror reflection not rendered by softraster");
    if (transparency) out.warnings.push_back("transparency not rendered by softraster");
    if (scene.camera.aperture_radius > 0.0f)
      out.warnings.push_back("depth of field (aperture) not rendered by softraster: pinhole");
  }
  if (scene.image.samples_per_pixel > 1)
    out.warnings.push_back(
        fmt::format("softraster: {} samples per pixel requested; multisampling is not "
                    "implemented, rendered 1",
                    scene.image.samples_per_pixel));
  return out;
}

}  // namespace

Expected<RenderOutput> SoftRasterizer::render(const Scene& scene, const RenderOptions& options) {
  try {
    return render_impl(scene, options);
  } catch (const std::bad_alloc&) {
    return internal_error(fmt::format("out of memory rendering {}x{} with {} objects",
                                      scene.image.width, scene.image.height, scene.objects.size()));
  }
}

}  // namespace rvr
