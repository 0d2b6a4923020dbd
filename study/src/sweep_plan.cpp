// The sweep's grid and the cost predictions that keep it within the budget (see sweep_plan.h).
#include "rvr/study/sweep_plan.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <system_error>
#include <utility>

#include "rvr/core/check.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/scene_io/scene_loader.h"

namespace rvr::study {

namespace {

// A scene or model file as a family: copies of it, as many as hold kFileFamilyTriangles.
Expected<Family> file_family(const std::string& path) {
  RVR_TRY_ASSIGN(scene, load_scene(path));
  double per_copy = 0;
  for (const Object& o : scene->objects)
    if (o.type == ObjectType::Triangles)
      per_copy += double(o.mesh.triangle_count());
    else if (o.type == ObjectType::Sphere)
      per_copy += 1;
  if (per_copy == 0)
    return bad_input(path + ": objects: no mesh or sphere to copy for the study's sweep");
  size_t high = size_t(std::clamp(std::floor(kFileFamilyTriangles / per_copy), 4.0, 1024.0));
  return Family{std::filesystem::path(path).filename().string(), "triangles", 1, high, 9, path};
}

// A built-in triangle family from 10^2 to `high`, kPointsPerDecade log-spaced points a decade.
Family triangle_family(const std::string& name, size_t high) {
  const double decades = std::log10(double(high) / 100.0);
  return Family{name, "triangles", 100, high, int(std::lround(decades * kPointsPerDecade)) + 1, ""};
}

}  // namespace

Expected<Family> find_family(const std::string& name) {
  const bool builtin = name.rfind("builtin:", 0) == 0;
  std::string bare = builtin ? name.substr(8) : name;
  if (bare == "tessphere" || bare == "effects") return triangle_family(bare, kTessphereHigh);
  if (bare == "soup") return triangle_family(bare, kSoupHigh);
  if (bare == "occluders") return Family{"occluders", "depth", 1, 256, 9, ""};
  if (!builtin && std::filesystem::exists(name)) return file_family(name);
  return bad_input(name +
                   ": not a scene family the study sweeps (builtin:tessphere, builtin:soup, "
                   "builtin:effects, builtin:occluders, or a scene or model file; the study "
                   "chooses N)");
}

std::vector<size_t> log_spaced(size_t low, size_t high, int count) {
  RVR_CHECK(low >= 1 && low <= high, "a log-spaced range needs 1 <= low <= high: ", low, "..",
            high);
  std::vector<size_t> out;
  for (int i = 0; i < count; ++i) {
    double f = count > 1 ? double(i) / double(count - 1) : 0.0;
    size_t v = size_t(std::llround(double(low) * std::pow(double(high) / double(low), f)));
    if (out.empty() || v != out.back()) out.push_back(v);
  }
  return out;
}

std::vector<int> pixel_sweep_widths(int width) {
  std::vector<int> out;
  for (int k = 4; k >= 1; --k) {
    int w = 4 * int(std::lround(double(width) * std::pow(2.0, -0.5 * k) / 4));
    w = std::max(w, 16);
    if (w < width && (out.empty() || w != out.back())) out.push_back(w);
  }
  return out;
}

std::vector<size_t> pixel_sweep_ns(const std::vector<size_t>& all) {
  std::vector<size_t> measured;
  for (size_t n : all)
    if (n <= kPixelSweepMaxN) measured.push_back(n);
  if (measured.empty()) return {};
  const double middle = std::sqrt(double(measured.front()) * double(measured.back()));  // in log N
  size_t nearest = measured.front();
  for (size_t n : measured)
    if (std::fabs(std::log(double(n) / middle)) < std::fabs(std::log(double(nearest) / middle)))
      nearest = n;
  std::vector<size_t> out = {measured.front(), nearest, measured.back()};
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<size_t> sweep_ns(const Family& family) {
  std::vector<size_t> ns = log_spaced(family.low, family.high, family.points);
  if (family.max_n > 0) std::erase_if(ns, [&](size_t n) { return n > family.max_n; });
  return ns;
}

std::vector<PlannedPoint> planned_points(const Family& family, int width) {
  std::vector<PlannedPoint> plan;
  const std::vector<size_t> ns = sweep_ns(family);
  const std::vector<size_t> pixel_ns = pixel_sweep_ns(ns);
  const std::vector<int> widths = pixel_sweep_widths(width);
  plan.reserve(ns.size() + pixel_ns.size() * widths.size());
  for (size_t n : ns) plan.push_back({n, width});
  for (size_t n : pixel_ns)
    for (int narrower : widths) plan.push_back({n, narrower});
  return plan;
}

size_t log_midpoint(size_t low, size_t high) {
  size_t mid = size_t(std::llround(std::sqrt(double(low) * double(high))));
  return mid > low && mid < high ? mid : 0;
}

Expected<Shard> parse_shard(const std::string& text) {
  auto bad = [&](const std::string& why) {
    return bad_input(fmt::format("--shard: {}, got \"{}\"", why, text));
  };
  size_t slash = text.find('/');
  if (slash == std::string::npos) return bad("must be I/N (shard I of N, 0-based), e.g. 3/8");
  auto whole = [](const std::string& s, size_t& value) {
    const char* end = s.data() + s.size();
    auto [stop, ec] = std::from_chars(s.data(), end, value);
    return !s.empty() && ec == std::errc() && stop == end;
  };
  Shard shard;
  if (!whole(text.substr(0, slash), shard.index) || !whole(text.substr(slash + 1), shard.count))
    return bad("I and N must be whole numbers (I/N, e.g. 3/8)");
  if (shard.count < 1) return bad("N must be >= 1");
  if (shard.index >= shard.count) return bad("I must be in 0 .. N-1");
  return shard;
}

bool in_shard(size_t plan_index, const Shard& shard) {
  RVR_CHECK(shard.count >= 1 && shard.index < shard.count,
            "parse_shard gives 0 <= index < count: ", shard.index, "/", shard.count);
  return plan_index % shard.count == shard.index;
}

double CostPredictor::predict(size_t n) const {
  if (measured_.empty()) return 0;
  auto above = measured_.lower_bound(n);
  if (above != measured_.end()) return above->second;
  auto last = std::prev(measured_.end());
  double slope = 1.0;
  if (measured_.size() >= 2) {
    auto before = std::prev(last);
    slope = std::log(last->second / before->second) /
            std::log(double(last->first) / double(before->first));
    slope = std::clamp(std::isfinite(slope) ? slope : 1.0, 0.0, 1.5);
  }
  return last->second * std::pow(double(n) / double(last->first), slope);
}

}  // namespace rvr::study
