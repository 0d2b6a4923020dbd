// How two renders of one scene differ: visibility (ids), depth and colour. Everything here is
// O(pixels): the SSIM window is separable and runs over a rolling buffer of rows.
#include "rvr/compare/compare.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <glm/glm.hpp>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "rvr/core/camera.h"
#include "rvr/core/check.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/srgb.h"
#include "rvr/core/tessellate.h"
#include "ssim.h"

namespace rvr {

namespace detail {
// Defined in image_io.cpp: OpenImageIO's "inferno" map of values / scale, sRGB-encoded.
Image inferno_display(std::span<const float> values, int width, int height, float scale);
}  // namespace detail

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The (object, primitive) id of a pixel; every background pixel has the same key whatever
// primitive id a renderer left there.
inline uint64_t id_key(const FrameBuffers& fb, size_t i) {
  uint32_t obj = fb.object_id[i];
  uint32_t prim = obj == kNoId ? kNoId : fb.primitive_id[i];
  return (uint64_t(obj) << 32) | prim;
}

bool ids_sized(const FrameBuffers& fb) {
  return fb.width >= 0 && fb.height >= 0 && fb.object_id.size() == fb.pixel_count() &&
         fb.primitive_id.size() == fb.pixel_count();
}

// |da - db| / max(|da|, |db|) of a pixel both renders hit; unequal infinite or NaN depth on a
// hit is as wrong as a depth can be (1).
double relative_depth_error(double da, double db) {
  if (da == db) return 0.0;
  if (!std::isfinite(da) || !std::isfinite(db)) return 1.0;
  double denom = std::max(std::fabs(da), std::fabs(db));
  return denom > 0 ? std::fabs(da - db) / denom : 0.0;
}

double psnr_of(double rmse) {
  return rmse > 0.0 ? 20.0 * std::log10(1.0 / rmse) : kInf;
}

// The nearest-rank percentile `p` (0 < p <= 1) of `values`, which it reorders.
double percentile(std::vector<double>& values, double p) {
  RVR_CHECK(p > 0.0 && p <= 1.0, "a nearest-rank percentile lies in (0, 1]: ", p);
  if (values.empty()) return 0.0;
  const size_t rank = size_t(std::ceil(p * double(values.size())));
  const size_t at = std::min(values.size(), std::max<size_t>(rank, 1)) - 1;
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(at), values.end());
  return values[at];
}

// Whether the 3x3 neighbourhood of pixel (x, y) holds another object, or the background, in
// either image: the object's outline.
bool on_outline(const FrameBuffers& a, const FrameBuffers& b, int x, int y) {
  const uint32_t object = a.object_id[a.index(x, y)];
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int xx = x + dx, yy = y + dy;
      if (xx < 0 || yy < 0 || xx >= a.width || yy >= a.height) continue;
      const size_t j = a.index(xx, yy);
      if (a.object_id[j] != object || b.object_id[j] != object) return true;
    }
  return false;
}

}  // namespace

namespace {

// The covered pixels (a hit in either image) and the agreement over them.
VisibilityMetrics with_coverage(VisibilityMetrics v, const FrameBuffers& a, const FrameBuffers& b) {
  for (size_t i = 0; i < a.pixel_count(); ++i) {
    const bool hit_a = a.object_id[i] != kNoId, hit_b = b.object_id[i] != kNoId;
    v.covered_a += hit_a;
    v.covered_b += hit_b;
    v.covered_pixels += hit_a || hit_b;
  }
  v.covered_fraction = v.pixels ? double(v.covered_pixels) / double(v.pixels) : 0.0;
  // Every mismatch is covered: background against background is never one.
  v.covered_agreement =
      v.covered_pixels ? double(v.covered_pixels - v.mismatched_pixels) / double(v.covered_pixels)
                       : 0.0;
  return v;
}

}  // namespace

const char* to_string(DepthOutlierCause cause) {
  switch (cause) {
    case DepthOutlierCause::Silhouette:
      return "silhouette";
    case DepthOutlierCause::AnalyticSphere:
      return "analytic_sphere";
    case DepthOutlierCause::Elsewhere:
      return "elsewhere";
  }
  return "elsewhere";
}

namespace {

// Where along a pixel's ray an analytic sphere and the z-buffer's polygon of it can be seen.
// tessellate_sphere puts every vertex on the sphere, so the polygon (convex) lies inside the
// sphere and contains the ball whose radius is the distance from the centre to the nearest
// facet plane. A ray that enters the sphere at t_s enters the polygon at some t_p between t_s
// and where it enters that inner ball (or, when it misses the ball, where it leaves the
// sphere): T. A tracer sees t_s, a z-buffer t_p; both lie in [t_s, T]. Rays are the pixel
// centres', with unit component along the view axis, so t is view depth.
class SpherePolygons {
 public:
  SpherePolygons(const Scene& scene, int segments, int width, int height)
      : scene_(scene), segments_(segments), inner_(scene.objects.size(), -1.0) {
    const CameraFrame f = make_camera_frame(scene.camera, width, height);
    eye_ = f.eye;
    forward_ = f.forward;
    right_ = f.right;
    up_ = f.up;
    tan_half_fov_y_ = f.tan_half_fov_y;
    aspect_ = f.aspect;
    width_ = width;
    height_ = height;
  }

  // [t_s, T] of `object` at pixel (x, y); nullopt when the object is not an analytic sphere
  // or the pixel's ray misses it.
  std::optional<std::pair<double, double>> seen_between(uint32_t object, int x, int y) {
    if (object >= scene_.objects.size() || scene_.objects[object].type != ObjectType::Sphere)
      return std::nullopt;
    const Sphere& s = scene_.objects[object].sphere;
    const glm::dvec3 d = direction(x + 0.5, y + 0.5);
    const std::optional<std::pair<double, double>> outer = span(d, s.center, s.radius);
    if (!outer || !(outer->first > 0.0)) return std::nullopt;
    const std::optional<std::pair<double, double>> ball = span(d, s.center, inner_radius(object));
    return std::pair{outer->first, ball ? ball->first : outer->second};
  }

 private:
  glm::dvec3 direction(double px, double py) const {
    const double ndc_x = 2.0 * px / double(width_) - 1.0;
    const double ndc_y = 1.0 - 2.0 * py / double(height_);
    return forward_ + right_ * (ndc_x * tan_half_fov_y_ * aspect_) +
           up_ * (ndc_y * tan_half_fov_y_);
  }
  // Where the ray eye + t d enters and leaves the ball; nullopt when it misses it.
  std::optional<std::pair<double, double>> span(const glm::dvec3& d, const glm::vec3& centre,
                                                double radius) const {
    const glm::dvec3 oc = eye_ - glm::dvec3(centre);
    const double a = glm::dot(d, d), b = glm::dot(d, oc), c = glm::dot(oc, oc) - radius * radius;
    const double disc = b * b - a * c;
    if (!(disc >= 0.0)) return std::nullopt;
    const double root = std::sqrt(disc);
    return std::pair{(-b - root) / a, (-b + root) / a};
  }
  // The distance from the sphere's centre to the nearest plane of its polygon's facets.
  double inner_radius(uint32_t object) {
    if (inner_[object] >= 0.0) return inner_[object];
    const Sphere& s = scene_.objects[object].sphere;
    const TriangleMesh mesh = tessellate_sphere(s, segments_);
    double inner = s.radius;
    for (const glm::uvec3& t : mesh.triangles) {
      const glm::dvec3 p0(mesh.positions[t.x]), p1(mesh.positions[t.y]), p2(mesh.positions[t.z]);
      const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
      const double len = glm::length(n);
      if (len > 0.0)
        inner = std::min(inner, std::fabs(glm::dot(n, p0 - glm::dvec3(s.center))) / len);
    }
    return inner_[object] = inner;
  }

  const Scene& scene_;
  int segments_;
  std::vector<double> inner_;  // per object, -1 until computed
  glm::dvec3 eye_{0.0}, forward_{0.0}, right_{0.0}, up_{0.0};
  double tan_half_fov_y_ = 1.0, aspect_ = 1.0;
  int width_ = 1, height_ = 1;
};

// Depth statistics of the pixels whose ids agree and are not background.
DepthMetrics depth_metrics(const FrameBuffers& a, const FrameBuffers& b,
                           const MismatchContext& context) {
  std::optional<SpherePolygons> polygons;
  double near = 0.0, far = 0.0;
  if (context.scene && context.polygon_sphere_segments > 0) {
    polygons.emplace(*context.scene, context.polygon_sphere_segments, a.width, a.height);
    near = context.scene->camera.near;
    far = context.scene->camera.far > near ? context.scene->camera.far : 2.0 * near;
  }
  DepthMetrics m;
  std::vector<double> errors;
  errors.reserve(a.pixel_count());
  double sum = 0.0;
  std::vector<DepthOutlier>& listed = m.worst_outliers;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const size_t i = a.index(x, y);
      if (id_key(a, i) != id_key(b, i) || a.object_id[i] == kNoId) continue;
      const double rel = relative_depth_error(a.depth[i], b.depth[i]);
      errors.push_back(rel);
      sum += rel;
      m.max_rel_error = std::max(m.max_rel_error, rel);
      if (!(rel > kDepthOutlierThreshold)) continue;
      DepthOutlierCause cause = DepthOutlierCause::Elsewhere;
      if (on_outline(a, b, x, y)) {
        cause = DepthOutlierCause::Silhouette;
      } else if (polygons) {
        const auto seen = polygons->seen_between(a.object_id[i], x, y);
        // Each depth within its store's resolution of [t_s, T].
        auto within = [&](double depth, DepthStore store) {
          const double res = depth_resolution(store, std::max(depth, near), near, far);
          return seen && depth >= seen->first - res && depth <= seen->second + res;
        };
        if (within(a.depth[i], context.store_a) && within(b.depth[i], context.store_b))
          cause = DepthOutlierCause::AnalyticSphere;
      }
      ++m.outliers;
      ++(cause == DepthOutlierCause::Silhouette       ? m.outliers_at_silhouettes
         : cause == DepthOutlierCause::AnalyticSphere ? m.outliers_on_analytic_spheres
                                                      : m.outliers_elsewhere);
      listed.push_back({x, y, a.object_id[i], rel, a.depth[i], b.depth[i], cause});
      if (listed.size() > 2 * DepthMetrics::kMaxListed) {  // keep the list bounded
        std::sort(listed.begin(), listed.end(), [](const DepthOutlier& p, const DepthOutlier& q) {
          return p.rel_error > q.rel_error;
        });
        listed.resize(DepthMetrics::kMaxListed);
      }
    }
  std::stable_sort(listed.begin(), listed.end(), [](const DepthOutlier& p, const DepthOutlier& q) {
    return p.rel_error > q.rel_error;
  });
  if (listed.size() > DepthMetrics::kMaxListed) listed.resize(DepthMetrics::kMaxListed);
  m.mean_rel_error = errors.empty() ? 0.0 : sum / double(errors.size());
  m.p99_rel_error = percentile(errors, 0.99);
  m.p999_rel_error = percentile(errors, 0.999);
  return m;
}

}  // namespace

LodMetrics lod_metrics(const FrameBuffers& a, const FrameBuffers& b) {
  LodMetrics m;
  const size_t n = a.pixel_count();
  if (a.lod.size() != n || b.lod.size() != n || b.pixel_count() != n) return m;
  std::vector<double> errors;
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(a.lod[i]) || !std::isfinite(b.lod[i])) continue;
    const double d = std::abs(double(a.lod[i]) - double(b.lod[i]));
    errors.push_back(d);
    sum += d;
  }
  m.pixels = errors.size();
  m.mean_abs = errors.empty() ? 0.0 : sum / double(errors.size());
  m.p99_abs = percentile(errors, 0.99);
  return m;
}

std::vector<bool> id_boundaries(const FrameBuffers& fb) {
  const int w = fb.width, h = fb.height;
  std::vector<bool> edge(ids_sized(fb) ? fb.pixel_count() : 0, false);
  if (edge.empty()) return edge;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      size_t i = fb.index(x, y);
      uint64_t k = id_key(fb, i);
      edge[i] = (x > 0 && id_key(fb, i - 1) != k) || (x + 1 < w && id_key(fb, i + 1) != k) ||
                (y > 0 && id_key(fb, i - w) != k) || (y + 1 < h && id_key(fb, i + w) != k);
    }
  return edge;
}

ComparisonMetrics compare_buffers(const FrameBuffers& a, const FrameBuffers& b,
                                  const MismatchContext& context) {
  ComparisonMetrics m;
  const size_t n = a.pixel_count();
  m.visibility.pixels = n;
  const bool same_size = a.width == b.width && a.height == b.height && ids_sized(a) &&
                         ids_sized(b) && a.depth.size() == n && b.depth.size() == n &&
                         a.colour.size() == n && b.colour.size() == n;
  if (!same_size) {
    // The caller broke the contract; report total disagreement rather than reading out of range.
    m.visibility.id_agreement = 0.0;
    m.visibility.mismatched_pixels = n;
    m.visibility.classes.coverage = n;
    m.depth.max_rel_error = m.depth.mean_rel_error = 1.0;
    m.depth.p99_rel_error = m.depth.p999_rel_error = 1.0;
    m.colour = ColourMetrics{1.0, 0.0, 1.0, 0.0};
    return m;
  }
  if (n == 0) {
    m.colour.psnr_db = kInf;
    return m;
  }
  const int w = a.width, h = a.height;

  // Visibility: pixels whose (object, primitive) ids differ, each in one class
  // (mismatch_classes.h).
  size_t mismatched = 0;
  for (size_t i = 0; i < n; ++i) mismatched += id_key(a, i) != id_key(b, i);
  m.visibility.mismatched_pixels = mismatched;
  m.visibility.id_agreement = double(n - mismatched) / double(n);
  m.visibility = with_coverage(m.visibility, a, b);
  m.visibility.classes = count_classes(classify_mismatches(a, b, context));
  m.depth = depth_metrics(a, b, context);
  m.lod = lod_metrics(a, b);

  // Colour, linear values, peak 1.
  double sq = 0.0, max_abs = 0.0;
  std::vector<float> ya(n), yb(n);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      double d = std::fabs(double(a.colour[i][c]) - double(b.colour[i][c]));
      if (std::isnan(d)) d = 1.0;  // a NaN colour is an error of at least full scale
      sq += d * d;
      max_abs = std::max(max_abs, d);
    }
    ya[i] = luminance(a.colour[i]);
    yb[i] = luminance(b.colour[i]);
  }
  m.colour.rmse = std::sqrt(sq / (3.0 * double(n)));
  m.colour.psnr_db = psnr_of(m.colour.rmse);
  m.colour.max_abs = max_abs;
  m.colour.ssim = mean_ssim(ssim_map(ya, yb, w, h), w);
  return m;
}

Expected<ImageDiff> diff_images(const Image& a, const Image& b, const DiffThresholds& thresholds) {
  try {
    if (a.width != b.width || a.height != b.height)
      return bad_input("images differ in size: " + std::to_string(a.width) + "x" +
                       std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                       std::to_string(b.height));
    if (a.channels != b.channels)
      return bad_input("images differ in channel count: " + std::to_string(a.channels) + " vs " +
                       std::to_string(b.channels));
    const size_t pixels = size_t(a.width) * a.height;
    const size_t channels = size_t(a.channels);
    const size_t count = pixels * channels;
    if (a.pixels.size() != count || b.pixels.size() != count)
      return internal_error("image pixel buffers do not match their size");
    ImageDiff d;
    d.pixels = pixels;
    if (count == 0) {
      d.psnr_db = kInf;
      return d;
    }
    const double warn = thresholds.warn, fail = thresholds.fail;
    double sum = 0.0, sq = 0.0;
    size_t worst = 0;
    for (size_t p = 0; p < pixels; ++p) {
      bool warned = false, failed = false;
      for (size_t c = 0; c < channels; ++c) {
        const size_t i = p * channels + c;
        const double va = a.pixels[i], vb = b.pixels[i];
        double e;
        if (std::isfinite(va) && std::isfinite(vb)) {
          e = std::fabs(va - vb);
        } else {
          const bool same = std::isnan(va) == std::isnan(vb) && std::isinf(va) == std::isinf(vb);
          e = same ? 0.0 : kInf;
        }
        sum += e;
        sq += e * e;
        if (e > d.max_abs) {
          d.max_abs = e;
          worst = i;
        }
        if (!warned && e > warn) {
          warned = true;
          ++d.warn_pixels;
        }
        if (!failed && e > fail) {
          failed = true;
          ++d.fail_pixels;
        }
      }
    }
    d.mean_abs = sum / double(count);
    d.rmse = std::sqrt(sq / double(count));
    d.psnr_db = psnr_of(d.rmse);
    d.max_channel = int(worst % channels);
    size_t pixel = worst / channels;
    d.max_x = int(pixel % size_t(a.width));
    d.max_y = int(pixel / size_t(a.width));
    return d;
  } catch (const std::exception& e) {
    return internal_error(std::string("image diff failed: ") + e.what());
  }
}

const char* to_string(DiffVerdict verdict) {
  switch (verdict) {
    case DiffVerdict::Pass:
      return "PASS";
    case DiffVerdict::Warning:
      return "WARNING";
    case DiffVerdict::Failure:
      return "FAILURE";
  }
  return "FAILURE";
}

DiffVerdict diff_verdict(const ImageDiff& diff, const DiffThresholds& t) {
  // A 0x0 image counts as one pixel, so the allowed fraction is never of nothing.
  const double pixels = double(std::max<size_t>(diff.pixels, 1));
  // No failing pixel passes, whatever the warnings (idiff's -allowfailures, default 0).
  if (diff.fail_pixels == 0) return DiffVerdict::Pass;
  if (double(diff.fail_pixels) > double(t.fail_percent) / 100.0 * pixels ||
      diff.max_abs > double(t.hard_fail))
    return DiffVerdict::Failure;
  if (double(diff.warn_pixels) > double(t.warn_percent) / 100.0 * pixels ||
      diff.max_abs > double(t.hard_warn))
    return DiffVerdict::Warning;
  return DiffVerdict::Pass;
}

Image diff_heat_map(const Image& a, const Image& b, float scale) {
  const int w = a.width, h = a.height;
  const int channels = std::min(a.channels, b.channels);
  for (const Image* image : {&a, &b})
    RVR_DCHECK(image->pixels.size() == size_t(std::max(image->width, 0)) *
                                           size_t(std::max(image->height, 0)) *
                                           size_t(std::max(image->channels, 0)),
               "an image's pixels fill its size: ", image->pixels.size(), " for ", image->width,
               "x", image->height, "x", image->channels);
  std::vector<float> v(size_t(std::max(w, 0)) * std::max(h, 0), 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float e = 0.0f;
      if (x >= b.width || y >= b.height || a.channels != b.channels) {
        e = std::numeric_limits<float>::infinity();  // no counterpart: top of the map
      } else {
        for (int c = 0; c < channels; ++c) {
          float d = std::fabs(a.at(x, y, c) - b.at(x, y, c));
          if (!(d <= e)) e = std::isnan(d) ? std::numeric_limits<float>::infinity() : d;
        }
      }
      // scale <= 0: any difference at all is at the top of the map.
      v[size_t(y) * w + x] = scale > 0.0f ? e / scale : (e > 0.0f ? 1.0f : 0.0f);
    }
  if (v.empty()) return Image{w, h, 3, {"R", "G", "B"}, {}};
  return detail::inferno_display(v, w, h, 1.0f);
}

Image id_mismatch_image(const FrameBuffers& a, const FrameBuffers& b) {
  Image img;
  img.width = a.width;
  img.height = a.height;
  img.channels = 3;
  img.channel_names = {"R", "G", "B"};
  const size_t n = a.pixel_count();
  img.pixels.assign(n * 3, 0.0f);
  const bool comparable = a.width == b.width && a.height == b.height && a.object_id.size() == n &&
                          b.object_id.size() == n;
  for (size_t i = 0; i < n; ++i) {
    float* p = &img.pixels[3 * i];
    if (!comparable || a.object_id[i] != b.object_id[i]) {
      p[0] = 1.0f;  // pure red, display referred
      continue;
    }
    // Display-referred grey: the sRGB encoding of a's linear luminance.
    float g = i < a.colour.size() ? srgb_encode(luminance(a.colour[i])) : 0.0f;
    p[0] = p[1] = p[2] = g;
  }
  return img;
}

Image depth_diff_image(const FrameBuffers& a, const FrameBuffers& b, DepthDiffScale scale) {
  const int w = std::max(a.width, 0), h = std::max(a.height, 0);
  const size_t n = size_t(w) * h;
  if (n == 0) return Image{a.width, a.height, 3, {"R", "G", "B"}, {}};
  const bool a_sized = a.object_id.size() == n && a.depth.size() == n;
  const bool b_sized = b.object_id.size() == b.pixel_count() && b.depth.size() == b.pixel_count();
  // A bad scale (low <= 0, high <= low) still gives a picture: one decade above low.
  const double low = scale.low > 0.0f ? scale.low : 1e-6;
  const double high = scale.high > low ? double(scale.high) : low * 10.0;
  const double decades = std::log10(high / low);

  enum class Kind : uint8_t { Both, Background, HitVsBackground };
  std::vector<Kind> kind(n, Kind::Both);
  std::vector<float> v(n, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const bool has_b = b_sized && x < b.width && y < b.height;
      const size_t j = has_b ? b.index(x, y) : 0;
      const bool hit_a = a_sized && a.object_id[i] != kNoId;
      const bool hit_b = has_b && b.object_id[j] != kNoId;
      if (!has_b || !a_sized || hit_a != hit_b) {
        kind[i] = Kind::HitVsBackground;
      } else if (!hit_a) {
        kind[i] = Kind::Background;
      } else {
        const double rel = relative_depth_error(a.depth[i], b.depth[j]);
        v[i] = rel > low ? float(std::log10(rel / low) / decades) : 0.0f;
      }
    }
  Image img = detail::inferno_display(v, w, h, 1.0f);
  for (size_t i = 0; i < n; ++i) {
    if (kind[i] == Kind::Both) continue;
    const float* c = kind[i] == Kind::Background ? kDepthDiffBackground : kDepthDiffHitVsBackground;
    std::copy(c, c + 3, &img.pixels[3 * i]);
  }
  return img;
}

}  // namespace rvr
