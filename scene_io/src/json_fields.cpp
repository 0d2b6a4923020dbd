// Typed access to a scene file's JSON fields (see json_fields.h).
#include "json_fields.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

namespace rvr::scene_load {

const json* find(const json& obj, const char* key) {
  auto it = obj.find(key);
  return it == obj.end() ? nullptr : &*it;
}

const json& require(const json& obj, const std::string& path, const char* key,
                    const std::string& hint) {
  const json* v = find(obj, key);
  if (!v) fail(key_path(path, key), "is required" + (hint.empty() ? "" : " (" + hint + ")"));
  return *v;
}

void check_object(const json& v, const std::string& path) {
  if (!v.is_object()) fail(where(path), "must be an object, got " + describe(v));
}

void check_keys(const json& obj, const std::string& path, const std::vector<std::string>& allowed,
                const std::string& context) {
  for (const auto& [k, v] : obj.items()) {
    (void)v;
    if (std::find(allowed.begin(), allowed.end(), k) != allowed.end()) continue;
    std::string what = "unknown key " + quote_json(k) + (context.empty() ? "" : " for " + context);
    std::string s = suggestion(k, allowed);
    if (!s.empty()) {
      what += " (did you mean '" + s + "'?)";
    } else {
      std::vector<std::string> sorted = allowed;
      std::sort(sorted.begin(), sorted.end());
      what += "; allowed: " + join(sorted);
    }
    fail(where(path), what);
  }
}

double number(const json& v, const std::string& path) {
  if (!v.is_number()) fail(path, "must be a number, got " + describe(v));
  double d = v.get<double>();
  if (!std::isfinite(d)) fail(path, "must be a finite number, got " + fmt_num(d));
  return d;
}

// A number that must also fit a 32-bit float (the model stores floats).
float real(const json& v, const std::string& path) {
  double d = number(v, path);
  if (std::abs(d) > double(std::numeric_limits<float>::max())) {
    fail(path, "is out of range for a 32-bit float, got " + fmt_num(d));
  }
  return static_cast<float>(d);
}

float real_at_least(const json& v, const std::string& path, double lo, Bound b) {
  float f = real(v, path);
  double d = v.get<double>();
  bool ok = b == Bound::Open ? (d > lo && double(f) > lo) : (d >= lo);
  if (!ok) {
    if (b == Bound::Open && d > lo)
      fail(path, "is too small for a 32-bit float, got " + fmt_num(d));
    fail(path, fmt::format("must be {} {}, got {}", b == Bound::Open ? ">" : ">=", fmt_num(lo),
                           fmt_num(d)));
  }
  return f;
}

float real_in_unit(const json& v, const std::string& path) {
  float f = real(v, path);
  if (!(f >= 0.0f && f <= 1.0f)) fail(path, "must be in 0..1, got " + fmt_num(v.get<double>()));
  return f;
}

int integer(const json& v, const std::string& path, int64_t lo, int64_t hi,
            const std::string& note) {
  std::string range = fmt::format("an integer in {}..{}", lo, hi) + note;
  if (!v.is_number()) fail(path, "must be " + range + ", got " + describe(v));
  int64_t i = 0;
  if (v.is_number_integer() && !v.is_number_unsigned()) {
    i = v.get<int64_t>();
  } else if (v.is_number_unsigned()) {
    uint64_t u = v.get<uint64_t>();
    i = u > uint64_t(hi) ? hi + 1 : int64_t(u);
  } else {
    double d = v.get<double>();
    if (!std::isfinite(d) || d != std::floor(d)) {
      fail(path, "must be " + range + ", got " + describe(v));
    }
    i = d > double(hi) ? hi + 1 : d < double(lo) ? lo - 1 : int64_t(d);
  }
  if (i < lo || i > hi) fail(path, "must be " + range + ", got " + describe(v));
  return int(i);
}

bool boolean(const json& v, const std::string& path) {
  if (!v.is_boolean()) fail(path, "must be true or false, got " + describe(v));
  return v.get<bool>();
}

const std::string& string(const json& v, const std::string& path) {
  if (!v.is_string()) fail(path, "must be a string, got " + describe(v));
  return v.get_ref<const std::string&>();
}

glm::vec3 vec3(const json& v, const std::string& path, const char* what) {
  if (!v.is_array() || v.size() != 3) {
    fail(path, std::string("must be an array of ") + what + ", got " + describe(v));
  }
  glm::vec3 out;
  for (int i = 0; i < 3; ++i) out[i] = real(v[i], index_path(path, i));
  return out;
}

glm::vec3 colour(const json& v, const std::string& path) {
  glm::vec3 c = vec3(v, path, "3 non-negative numbers (a colour)");
  for (int i = 0; i < 3; ++i) {
    if (c[i] < 0.0f) {
      fail(index_path(path, i),
           "must be >= 0 (colours are non-negative), got " + fmt_num(v[i].get<double>()));
    }
  }
  return c;
}

std::string vec_text(const glm::vec3& v) {
  return fmt::format("[{}, {}, {}]", fmt_num(v.x), fmt_num(v.y), fmt_num(v.z));
}

}  // namespace rvr::scene_load
