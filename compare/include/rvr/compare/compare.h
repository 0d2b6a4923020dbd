// How two renders of one scene differ: visibility (ids), depth and colour.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "rvr/compare/effect_errors.h"
#include "rvr/compare/mismatch_classes.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/image_codec/image_io.h"

namespace rvr {

struct VisibilityMetrics {
  size_t pixels = 0;
  double id_agreement = 1.0;  // fraction of pixels with the same object AND primitive id
  size_t mismatched_pixels = 0;
  // Pixels that show a hit in a, in b, in either; covered_fraction = covered_pixels / pixels.
  size_t covered_a = 0, covered_b = 0, covered_pixels = 0;
  double covered_fraction = 0.0;
  // The fraction of covered pixels whose ids agree; 0 when nothing is covered: agreement on
  // background alone says nothing about visibility.
  double covered_agreement = 0.0;
  MismatchCounts classes;  // every mismatched pixel in one class (mismatch_classes.h)
};

// Why a pixel's depths differ by more than kDepthOutlierThreshold (docs/cli.md).
enum class DepthOutlierCause {
  // On an object's outline (its 3x3 neighbourhood holds another object or the background in
  // either image): a facet seen edge-on there changes depth by more than the threshold within
  // the z-buffer's sub-pixel vertex snapping (1/256 px in llvmpipe), so a pixel centre a hair
  // outside one facet in exact arithmetic is drawn on it, and the tracer hits its neighbour.
  // Both are the same object (and, for a tessellated sphere, the same primitive).
  Silhouette,
  // On an analytic sphere, away from its outline, by no more than the z-buffer's polygon of it
  // can differ from the sphere along that pixel's ray: the polygon lies between the sphere
  // and the largest ball inside it, so its depth lies between where the ray enters the two
  // (or leaves the sphere, for a ray that misses the ball). Only with
  // MismatchContext::polygon_sphere_segments > 0; expected, not a disagreement.
  AnalyticSphere,
  // Anything else: a real disagreement.
  Elsewhere,
};
// "silhouette", "analytic_sphere", "elsewhere"
const char* to_string(DepthOutlierCause cause);

inline constexpr double kDepthOutlierThreshold = 1e-3;

struct DepthOutlier {
  int x = 0, y = 0;
  uint32_t object = 0;
  double rel_error = 0.0;
  float depth_a = 0.0f, depth_b = 0.0f;
  DepthOutlierCause cause = DepthOutlierCause::Elsewhere;
};

struct DepthMetrics {  // over pixels whose ids agree and are not background
  double max_rel_error = 0.0;
  double mean_rel_error = 0.0;
  // Nearest-rank percentiles: the smallest error that 99% (99.9%) of those pixels do not exceed.
  double p99_rel_error = 0.0;
  double p999_rel_error = 0.0;
  // Pixels whose error is above kDepthOutlierThreshold, by cause; the worst are listed.
  size_t outliers = 0;
  size_t outliers_at_silhouettes = 0;
  size_t outliers_on_analytic_spheres = 0;
  size_t outliers_elsewhere = 0;
  std::vector<DepthOutlier> worst_outliers;  // by error, largest first; at most kMaxListed
  static constexpr size_t kMaxListed = 100;
};

struct ColourMetrics {  // linear RGB, peak value 1 for PSNR and SSIM
  double rmse = 0.0;
  double psnr_db = 0.0;  // +inf when identical
  double max_abs = 0.0;
  double ssim = 1.0;  // luminance, 11x11 Gaussian window (sigma 1.5)
};

// The texture level of detail each renderer sampled at (FrameBuffers::lod), over the pixels
// textured in both (a finite lod in each): |lod_a - lod_b| in mip levels.
struct LodMetrics {
  size_t pixels = 0;  // textured in both; 0: nothing to compare (the values below are 0)
  double mean_abs = 0.0;
  double p99_abs = 0.0;
};

struct ComparisonMetrics {
  VisibilityMetrics visibility;
  DepthMetrics depth;
  ColourMetrics colour;
  LodMetrics lod;
  // The colour error where each effect acts (effect_errors.h), masks read from the frame of
  // `effects_mask_from` (one of the two renderers' names); set by compare_renderers.
  std::vector<EffectError> effects;
  std::string effects_mask_from;
  // The renderer of the pair whose z-buffer answers (FrameBuffers::answer) split each effect's
  // mask (EffectError::answers); "" when neither frame holds answers. Set by compare_renderers.
  std::string answers_from;
};

LodMetrics lod_metrics(const FrameBuffers& a, const FrameBuffers& b);

// Both buffers must have the same size. The context gives the mismatch classes their geometry
// and depth resolutions; without it they use the id-boundary rule (see MismatchContext).
ComparisonMetrics compare_buffers(const FrameBuffers& a, const FrameBuffers& b,
                                  const MismatchContext& context = {});

// A pixel whose (object, primitive) id differs from one of its 4 neighbours.
std::vector<bool> id_boundaries(const FrameBuffers& fb);

// Thresholds of an image diff, with OpenImageIO idiff's meanings and defaults. A pixel "fails"
// (or "warns") when any of its channels differs by more than `fail` (`warn`); the verdict is
// PASS when no pixel fails (whatever the warnings, as idiff 2.4 with -allowfailures 0), else
// FAILURE when more than `fail_percent` % of the pixels fail or the largest channel difference
// is above `hard_fail`, else WARNING when more than `warn_percent` % warn or the largest
// difference is above `hard_warn`, else PASS. Thresholds are single precision, as idiff's are,
// so a difference is compared with the float nearest the value given.
struct DiffThresholds {
  float fail = 1e-6f;
  float fail_percent = 0.0f;
  float hard_fail = std::numeric_limits<float>::max();
  float warn = 1e-6f;
  float warn_percent = 0.0f;
  float hard_warn = std::numeric_limits<float>::max();
};

// Statistics of the difference of two images, like idiff: errors are per channel; mean and RMS
// over every channel of every pixel; the maximum is the first channel (in pixel order) with the
// largest difference. Two NaNs (or two infinities) in one channel are no difference; a NaN or
// infinity against anything else is a difference of +inf.
struct ImageDiff {
  double mean_abs = 0.0;
  double rmse = 0.0;
  double psnr_db = 0.0;  // 20 log10(1 / rmse), peak 1; +inf when identical
  double max_abs = 0.0;
  int max_x = 0, max_y = 0, max_channel = 0;
  size_t pixels = 0;       // width x height
  size_t warn_pixels = 0;  // pixels with a channel differing by more than the warn threshold
  size_t fail_pixels = 0;  // ... by more than the fail threshold
};
// Errors (exit 2) when sizes or channel counts differ.
Expected<ImageDiff> diff_images(const Image& a, const Image& b,
                                const DiffThresholds& thresholds = {});

enum class DiffVerdict { Pass, Warning, Failure };
const char* to_string(DiffVerdict verdict);  // "PASS", "WARNING", "FAILURE"
// The verdict of a diff made with `thresholds` (see DiffThresholds).
DiffVerdict diff_verdict(const ImageDiff& diff, const DiffThresholds& thresholds);

// Colour heat map of the per-pixel max channel difference, scaled so `scale` maps to the top of
// the colour map ("inferno").
Image diff_heat_map(const Image& a, const Image& b, float scale);

// Pixels whose object id differs in red over a grey version of a's colour.
Image id_mismatch_image(const FrameBuffers& a, const FrameBuffers& b);

// The relative view-depth difference |dA - dB| / max(dA, dB) of every pixel that both render
// as a hit (whatever the ids), display referred. It spans decades, so the colour map is
// logarithmic: inferno of log10(rel / low) / log10(high / low), clamped, so 0 and anything up
// to `low` is black and `high` or more is yellow-white. Pixels that are background in both
// are kDepthDiffBackground; background in one and a hit in the other, kDepthDiffHitVsBackground
// (colours the inferno map never takes). Pixels without a counterpart (sizes differ) count as
// hit vs background.
struct DepthDiffScale {
  float low = 1e-6f;
  float high = 1e-1f;
};
inline constexpr float kDepthDiffBackground[3] = {0.5f, 0.5f, 0.5f};       // mid grey
inline constexpr float kDepthDiffHitVsBackground[3] = {0.0f, 1.0f, 1.0f};  // cyan
Image depth_diff_image(const FrameBuffers& a, const FrameBuffers& b, DepthDiffScale scale = {});

}  // namespace rvr
