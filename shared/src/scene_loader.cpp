// Loading and validating rvr-scene/1 files (see docs/scene-format.md).
//
// Errors are reported as "FILE: json.path: what is wrong" or, for JSON syntax,
// "FILE:LINE:COL: JSON syntax: what". Internally the reader throws a LoadError and the public
// functions turn it (and anything else, e.g. std::bad_alloc) into an rvr::Error: no exception
// escapes.
//
// Decisions the format's key table leaves open (all documented in docs/scene-format.md):
// - `transform` is accepted on every object type. On `mesh` and `triangle` it is a full affine
//   map (normals by the inverse transpose). On the analytic shapes (`sphere`, `plane`, `csg`)
//   it moves centres/points and turns normals; the scale must then be uniform in magnitude
//   (|sx| = |sy| = |sz|), since a sphere would otherwise become an ellipsoid and a square a
//   rectangle, which the model cannot express. A plane's square keeps the in-plane
//   orientation given by plane_axes(normal) (a rotation about the normal has no effect).
// - A `triangle` object whose triangle is degenerate (zero area) is an error; in a `mesh`,
//   degenerate triangles are dropped with a warning, and a mesh left with none is an error.
// - Duplicate keys in a JSON object are an error (the last one would silently win).
// - Limits against hostile input: JSON nesting <= 512, csg nesting <= 64, light samples per
//   side <= 64, samples per pixel <= 4096, meshes <= 50 million triangles.
#include "rvr/shared/scene_loader.h"

#include <assimp/DefaultIOSystem.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <algorithm>
#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <map>
#include <new>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <unordered_set>

namespace rvr {
namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

constexpr int kMaxJsonDepth = 512;
constexpr size_t kMaxSceneFileBytes = size_t(256) << 20;
constexpr int kMaxCsgDepth = 64;
constexpr int kMaxImageSize = 16384;
constexpr int kMaxSamplesPerPixel = 4096;
constexpr int kMaxLightSamples = 64;
constexpr size_t kMaxMeshTriangles = 50'000'000;
constexpr const char* kFormat = "rvr-scene/1";

// ------------------------------------------------------------------------------------------
// Internal error values (thrown inside the loader, caught by the public functions).

struct LoadError {
  std::string path;  // JSON path, e.g. "objects[3].radius"
  std::string what;
};

struct SyntaxError {
  size_t offset;  // byte offset into the text
  std::string what;
};

[[noreturn]] void fail(std::string path, std::string what) {
  throw LoadError{std::move(path), std::move(what)};
}

// ------------------------------------------------------------------------------------------
// Formatting helpers.

std::string fmt_num(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{}", v);
}

std::string quote_json(const std::string& s) {
  // 'text', JSON-escaped inside, cut short so a hostile string cannot flood the message.
  std::string shown = s.size() > 60 ? s.substr(0, 57) + "..." : s;
  std::string q = json(shown).dump(-1, ' ', false, json::error_handler_t::replace);
  q.front() = q.back() = '\'';
  return q;
}

// What a JSON value is, for "must be X, got Y" messages.
std::string describe(const json& v) {
  switch (v.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::boolean:
      return v.get<bool>() ? "true" : "false";
    case json::value_t::string:
      return "string " + quote_json(v.get_ref<const std::string&>());
    case json::value_t::number_integer:
      return fmt::format("number {}", v.get<int64_t>());
    case json::value_t::number_unsigned:
      return fmt::format("number {}", v.get<uint64_t>());
    case json::value_t::number_float:
      return "number " + fmt_num(v.get<double>());
    case json::value_t::array:
      return fmt::format("array of {}", v.size());
    case json::value_t::object:
      return "object";
    default:
      return v.type_name();
  }
}

bool is_identifier(const std::string& s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

std::string key_path(const std::string& parent, const std::string& key) {
  std::string k = is_identifier(key) ? key : "[" + quote_json(key) + "]";
  if (parent.empty()) return k;
  return is_identifier(key) ? parent + "." + k : parent + k;
}

std::string index_path(const std::string& parent, size_t i) {
  return fmt::format("{}[{}]", parent, i);
}

std::string where(const std::string& path) {
  return path.empty() ? "top level" : path;
}

// Edit distance counting a swap of two neighbouring letters as one edit (optimal string
// alignment), case-insensitive.
size_t edit_distance(const std::string& a, const std::string& b) {
  auto same = [](char x, char y) {
    return std::tolower(static_cast<unsigned char>(x)) ==
           std::tolower(static_cast<unsigned char>(y));
  };
  const size_t w = b.size() + 1;
  std::vector<size_t> d((a.size() + 1) * w);
  for (size_t i = 0; i <= a.size(); ++i) d[i * w] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t cost = same(a[i - 1], b[j - 1]) ? 0 : 1;
      size_t best =
          std::min({d[(i - 1) * w + j] + 1, d[i * w + j - 1] + 1, d[(i - 1) * w + j - 1] + cost});
      if (i > 1 && j > 1 && same(a[i - 1], b[j - 2]) && same(a[i - 2], b[j - 1])) {
        best = std::min(best, d[(i - 2) * w + j - 2] + 1);
      }
      d[i * w + j] = best;
    }
  }
  return d[a.size() * w + b.size()];
}

// The closest allowed word, if it is close enough to be a likely typo.
std::string suggestion(const std::string& word, const std::vector<std::string>& allowed) {
  if (word.size() > 64) return {};
  std::string best;
  size_t best_d = std::numeric_limits<size_t>::max();
  for (const std::string& a : allowed) {
    size_t d = edit_distance(word, a);
    if (d < best_d) best_d = d, best = a;
  }
  size_t limit = std::max<size_t>(1, std::min(word.size(), best.size()) / 3);
  return best_d <= limit ? best : std::string();
}

std::string join(const std::vector<std::string>& words, const char* sep = ", ") {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : sep) + w;
  return out;
}

// ------------------------------------------------------------------------------------------
// JSON syntax: depth pre-scan, SAX parse with duplicate-key detection, readable messages.

// Line and column (1-based; the column counts UTF-8 code points) of a byte offset.
std::pair<size_t, size_t> line_column(const std::string& text, size_t offset) {
  offset = std::min(offset, text.size());
  size_t line = 1, line_start = 0;
  for (size_t i = 0; i < offset; ++i) {
    if (text[i] == '\n') ++line, line_start = i + 1;
  }
  size_t column = 1;
  for (size_t i = line_start; i < offset; ++i) {
    if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80) ++column;
  }
  return {line, column};
}

// nlohmann reports where it stopped reading, i.e. the end of the offending token. Strings
// cannot span lines in JSON, so the token's start is found by tokenising its line.
size_t token_start(const std::string& text, size_t last) {
  if (last >= text.size()) return text.size();
  if (text[last] == '\n') return last;
  size_t line_start = text.rfind('\n', last);
  size_t i = line_start == std::string::npos ? 0 : line_start + 1;
  auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  auto is_punct = [](char c) { return std::strchr("{}[]:,", c) != nullptr && c != '\0'; };
  while (i <= last) {
    if (is_space(text[i])) {
      ++i;
      continue;
    }
    size_t start = i;
    if (text[i] == '"') {
      for (++i; i < text.size() && text[i] != '\n'; ++i) {
        if (text[i] == '\\') {
          ++i;
        } else if (text[i] == '"') {
          ++i;
          break;
        }
      }
    } else if (is_punct(text[i])) {
      ++i;
    } else {
      while (i < text.size() && text[i] != '\n' && text[i] != '"' && !is_space(text[i]) &&
             !is_punct(text[i])) {
        ++i;
      }
    }
    if (last < i) return start;
  }
  return last;
}

// nlohmann's parser does not recurse, but later consumers of the tree might: refuse absurd
// nesting before parsing.
void check_nesting(const std::string& text) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) {
        throw SyntaxError{i, fmt::format("nesting deeper than {}", kMaxJsonDepth)};
      }
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

std::string token_name(const std::string& t) {
  if (t == "string literal") return "a string";
  if (t == "number literal") return "a number";
  if (t == "true literal") return "'true'";
  if (t == "false literal") return "'false'";
  if (t == "null literal") return "'null'";
  return t;
}

// Turns "[json.exception.parse_error.101] parse error at line 1, column 8: syntax error while
// parsing object - unexpected number literal; expected '}'" into "expected ',' or '}', got a
// number".
std::string syntax_message(const std::string& raw, bool whitespace_only, bool* token_error) {
  *token_error = false;
  std::string msg = raw;
  std::string context;
  static const std::string kMarker = "syntax error while parsing ";
  if (size_t p = msg.find(kMarker); p != std::string::npos) {
    msg = msg.substr(p + kMarker.size());
    if (size_t dash = msg.find(" - "); dash != std::string::npos) {
      context = msg.substr(0, dash);
      msg = msg.substr(dash + 3);
    }
  } else if (size_t colon = msg.find("]"); colon != std::string::npos) {
    msg = msg.substr(colon + 2);
  }
  if (msg.rfind("unexpected ", 0) == 0) {
    std::string got = msg.substr(11), expected;
    if (size_t semi = got.find("; expected "); semi != std::string::npos) {
      expected = got.substr(semi + 11);
      got = got.substr(0, semi);
    }
    if (context == "object" && expected == "'}'") expected = "',' or '}'";
    if (context == "array" && expected == "']'") expected = "',' or ']'";
    if (expected == "'[', '{', or a literal") expected = "a value";
    if (expected == "string literal") expected = "a quoted key";
    if (got == "end of input") {
      if (whitespace_only) return "unexpected end of input (the file is empty)";
      return "unexpected end of input" + (expected.empty() ? "" : " (expected " + expected + ")");
    }
    *token_error = true;
    std::string out = "expected " + expected + ", got " + token_name(got);
    if ((got == "'}'" || got == "']'") &&
        (context == "object key" || (context == "value" && expected == "a value"))) {
      out += " (trailing comma?)";
    }
    return out;
  }
  // Lexer errors: drop nlohmann's "last read" echo, the position says where.
  bool trailing = msg.find("; expected end of input") != std::string::npos;
  if (size_t lr = msg.find("; last read: "); lr != std::string::npos) msg = msg.substr(0, lr);
  if (trailing) return "unexpected text after the end of the JSON value";
  return msg;
}

// A SAX handler that builds the DOM through nlohmann's own DOM builder, tracking the JSON
// path so that duplicate keys and number overflow can be reported by path, and recording the
// order of the material names (the DOM's std::map sorts them).
class SceneSax {
 public:
  using Dom = nlohmann::detail::json_sax_dom_parser<json>;

  explicit SceneSax(json& root) : dom_(root, false) {}

  bool null() { return value(dom_.null()); }
  bool boolean(bool v) { return value(dom_.boolean(v)); }
  bool number_integer(json::number_integer_t v) { return value(dom_.number_integer(v)); }
  bool number_unsigned(json::number_unsigned_t v) { return value(dom_.number_unsigned(v)); }
  bool number_float(json::number_float_t v, const json::string_t& s) {
    return value(dom_.number_float(v, s));
  }
  bool string(json::string_t& v) { return value(dom_.string(v)); }
  bool binary(json::binary_t& v) { return value(dom_.binary(v)); }
  bool start_object(std::size_t n) {
    frames_.push_back(Frame{true, {}, 0, {}});
    return dom_.start_object(n);
  }
  bool key(json::string_t& k) {
    Frame& top = frames_.back();
    top.key = k;
    if (!top.keys.insert(k).second) {
      duplicate_path_ = current_path();
      return false;
    }
    if (frames_.size() == 2 && frames_[0].is_object && frames_[0].key == "materials") {
      material_order.push_back(k);
    }
    return dom_.key(k);
  }
  bool end_object() {
    frames_.pop_back();
    return value(dom_.end_object());
  }
  bool start_array(std::size_t n) {
    frames_.push_back(Frame{false, {}, 0, {}});
    return dom_.start_array(n);
  }
  bool end_array() {
    frames_.pop_back();
    return value(dom_.end_array());
  }
  bool parse_error(std::size_t position, const std::string& /*last_token*/,
                   const nlohmann::detail::exception& ex) {
    error_position_ = position;
    error_id_ = ex.id;
    error_message_ = ex.what();
    error_path_ = current_path();
    return false;
  }

  // Throws the error the parse ended with, if any.
  void raise(const std::string& text, bool parsed) const {
    if (!duplicate_path_.empty()) fail(duplicate_path_, "duplicate key");
    if (error_id_ == 406) {  // number overflow: report it like any non-finite number
      std::string literal = error_message_;
      if (size_t q = literal.find('\''); q != std::string::npos) {
        literal = literal.substr(q + 1);
        if (!literal.empty() && literal.back() == '\'') literal.pop_back();
      }
      fail(error_path_, "must be a finite number, got " + literal + " (overflows)");
    }
    if (error_id_ >= 0) {
      bool whitespace_only = text.find_first_not_of(" \t\r\n") == std::string::npos;
      bool token_error = false;
      std::string what = syntax_message(error_message_, whitespace_only, &token_error);
      size_t last = error_position_ == 0 ? 0 : error_position_ - 1;
      size_t at = token_error ? token_start(text, last) : last;
      throw SyntaxError{at, what};
    }
    if (!parsed) throw SyntaxError{0, "could not be parsed"};
  }

  std::vector<std::string> material_order;

 private:
  struct Frame {
    bool is_object;
    std::string key;  // object: the key being read
    size_t index;     // array: the element being read
    std::unordered_set<std::string> keys;
  };

  bool value(bool keep_going) {
    if (!frames_.empty() && !frames_.back().is_object) ++frames_.back().index;
    return keep_going;
  }

  std::string current_path() const {
    std::string p;
    for (const Frame& f : frames_) p = f.is_object ? key_path(p, f.key) : index_path(p, f.index);
    return p;
  }

  Dom dom_;
  std::vector<Frame> frames_;
  std::string duplicate_path_;
  int error_id_ = -1;
  size_t error_position_ = 0;
  std::string error_message_;
  std::string error_path_;
};

// ------------------------------------------------------------------------------------------
// Typed access with validation.

const json* find(const json& obj, const char* key) {
  auto it = obj.find(key);
  return it == obj.end() ? nullptr : &*it;
}

const json& require(const json& obj, const std::string& path, const char* key,
                    const std::string& hint = {}) {
  const json* v = find(obj, key);
  if (!v) fail(key_path(path, key), "is required" + (hint.empty() ? "" : " (" + hint + ")"));
  return *v;
}

void check_object(const json& v, const std::string& path) {
  if (!v.is_object()) fail(where(path), "must be an object, got " + describe(v));
}

void check_keys(const json& obj, const std::string& path, const std::vector<std::string>& allowed,
                const std::string& context = {}) {
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

enum class Bound { Open, Closed };

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
            const std::string& note = {}) {
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

glm::vec3 vec3(const json& v, const std::string& path, const char* what = "3 numbers") {
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

// ------------------------------------------------------------------------------------------
// Transforms.

struct Transform {
  bool identity = true;
  glm::dvec3 scale{1.0};
  glm::dmat4 matrix{1.0};
  glm::dmat3 normal_matrix{1.0};

  bool uniform() const {
    double s = std::abs(scale.x);
    return std::abs(scale.y) == s && std::abs(scale.z) == s;
  }
  glm::dvec3 point(const glm::dvec3& p) const { return glm::dvec3(matrix * glm::dvec4(p, 1.0)); }
  glm::dvec3 normal(const glm::dvec3& n) const { return normal_matrix * n; }
};

Transform parse_transform(const json& v, const std::string& path) {
  check_object(v, path);
  check_keys(v, path, {"scale", "rotate_deg", "translate"});
  Transform t;
  glm::dvec3 rotate{0.0}, translate{0.0};
  if (const json* s = find(v, "scale")) {
    std::string p = key_path(path, "scale");
    if (s->is_number()) {
      t.scale = glm::dvec3(real(*s, p));
      if (t.scale.x == 0.0) fail(p, "must be non-zero, got 0");
    } else if (s->is_array()) {
      t.scale = glm::dvec3(vec3(*s, p));
      for (int i = 0; i < 3; ++i) {
        if (t.scale[i] == 0.0) fail(index_path(p, i), "must be non-zero, got 0");
      }
    } else {
      fail(p, "must be a number or an array of 3 numbers, got " + describe(*s));
    }
  }
  if (const json* r = find(v, "rotate_deg")) rotate = vec3(*r, key_path(path, "rotate_deg"));
  if (const json* tr = find(v, "translate")) translate = vec3(*tr, key_path(path, "translate"));

  glm::dmat4 m = glm::translate(glm::dmat4(1.0), translate);
  m = glm::rotate(m, glm::radians(rotate.z), glm::dvec3(0, 0, 1));
  m = glm::rotate(m, glm::radians(rotate.y), glm::dvec3(0, 1, 0));
  m = glm::rotate(m, glm::radians(rotate.x), glm::dvec3(1, 0, 0));
  m = glm::scale(m, t.scale);
  t.matrix = m;
  t.normal_matrix = glm::transpose(glm::inverse(glm::dmat3(m)));
  t.identity =
      t.scale == glm::dvec3(1.0) && rotate == glm::dvec3(0.0) && translate == glm::dvec3(0.0);
  return t;
}

glm::vec3 to_float(const glm::dvec3& v, const std::string& path, const std::string& what) {
  glm::vec3 f(v);
  if (!std::isfinite(f.x) || !std::isfinite(f.y) || !std::isfinite(f.z)) {
    fail(path, what + " is out of range for 32-bit floats after the transform");
  }
  return f;
}

// ------------------------------------------------------------------------------------------
// Meshes.

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Twice the area, and whether the triangle is too thin to have a usable normal in floats.
bool degenerate(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  glm::vec3 nf = glm::cross(b - a, c - a);
  float lf = glm::length(nf);
  if (!(lf > 0.0f) || !std::isfinite(lf)) return true;
  glm::dvec3 e1 = glm::dvec3(b) - glm::dvec3(a), e2 = glm::dvec3(c) - glm::dvec3(a),
             e3 = glm::dvec3(c) - glm::dvec3(b);
  double longest = std::max({glm::dot(e1, e1), glm::dot(e2, e2), glm::dot(e3, e3)});
  return glm::length(glm::cross(e1, e2)) <= 1e-10 * longest;
}

// Applies the transform, drops degenerate triangles (counted in `dropped`) and repairs vertex
// normals that are zero or non-finite.
void finish_mesh(TriangleMesh& mesh, const Transform& t, const std::string& path, size_t* dropped,
                 size_t* repaired_normals) {
  if (!t.identity) {
    for (glm::vec3& p : mesh.positions) p = to_float(t.point(glm::dvec3(p)), path, "a vertex");
  }
  std::vector<char> bad_normal(mesh.normals.size(), 0);
  for (size_t i = 0; i < mesh.normals.size(); ++i) {
    glm::dvec3 n = t.normal(glm::dvec3(mesh.normals[i]));
    double len = glm::length(n);
    if (!std::isfinite(len) || len < 1e-20) {
      bad_normal[i] = 1;
      continue;
    }
    mesh.normals[i] = glm::vec3(n / len);
    if (!finite(mesh.normals[i])) bad_normal[i] = 1;
  }
  std::vector<glm::uvec3> kept;
  kept.reserve(mesh.triangles.size());
  for (const glm::uvec3& tri : mesh.triangles) {
    if (tri.x == tri.y || tri.y == tri.z || tri.x == tri.z ||
        degenerate(mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z])) {
      ++*dropped;
      continue;
    }
    kept.push_back(tri);
  }
  mesh.triangles = std::move(kept);
  mesh.triangles.shrink_to_fit();
  if (std::find(bad_normal.begin(), bad_normal.end(), 1) == bad_normal.end()) return;
  for (const glm::uvec3& tri : mesh.triangles) {
    glm::vec3 face = glm::normalize(glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x],
                                               mesh.positions[tri.z] - mesh.positions[tri.x]));
    for (int k = 0; k < 3; ++k) {
      if (bad_normal[tri[k]] == 1 && finite(face)) {
        mesh.normals[tri[k]] = face;
        bad_normal[tri[k]] = 2;
        ++*repaired_normals;
      }
    }
  }
  for (size_t i = 0; i < bad_normal.size(); ++i) {
    if (bad_normal[i] == 1) mesh.normals[i] = glm::vec3(0.0f, 0.0f, 1.0f);  // unused vertex
  }
}

std::string file_status(const fs::path& p) {
  std::error_code ec;
  fs::file_status st = fs::status(p, ec);
  if (ec) return ec.message();
  if (!fs::exists(st)) return std::strerror(ENOENT);
  if (fs::is_directory(st)) return std::strerror(EISDIR);
  if (!fs::is_regular_file(st)) return "not a regular file";
  std::FILE* f = std::fopen(p.c_str(), "rb");
  if (!f) return std::strerror(errno);
  std::fclose(f);
  return {};
}

// Assimp's file access, with a budget: some of its readers loop forever on broken files (the
// PLY reader seeks back and forth at the end of a header with no `end_header` line; found by
// fuzzing, tests/fuzz/regressions/mesh). Every read, seek and tell counts; past the budget
// the stream throws, which Assimp turns into an import error. A healthy import reads each
// file a few times over in large blocks, far below the budget.
class BudgetIOSystem : public Assimp::IOSystem {
 public:
  struct Budget {
    uint64_t operations = 0;
    uint64_t bytes_opened = 0;
    uint64_t bytes_requested = 0;
    // Reads may ask for large blocks (Assimp's line reader takes 1 MB at a time): at most
    // 64 MiB plus 16 times what was opened.
    void spend_read(size_t bytes) {
      bytes_requested += bytes;
      if (bytes_requested > (uint64_t(64) << 20) + 16 * bytes_opened) {
        throw std::runtime_error("the importer is stuck reading the file (gave up)");
      }
      spend();
    }
    void spend() {
      // 200 thousand operations (about a second of the PLY loop) plus one per 8 bytes opened:
      // Assimp's readers take whole files or megabyte blocks, so a good import stays far
      // below this.
      if (++operations > 200'000 + bytes_opened / 8) {
        throw std::runtime_error("the importer is stuck reading the file (gave up)");
      }
    }
  };

  bool Exists(const char* file) const override { return base_.Exists(file); }
  char getOsSeparator() const override { return base_.getOsSeparator(); }
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    budget_.spend();
    Assimp::IOStream* inner = base_.Open(file, mode);
    if (!inner) return nullptr;
    budget_.bytes_opened += inner->FileSize();
    return new Stream(inner, &budget_);
  }
  void Close(Assimp::IOStream* stream) override { delete stream; }

 private:
  class Stream : public Assimp::IOStream {
   public:
    Stream(Assimp::IOStream* inner, Budget* budget) : inner_(inner), budget_(budget) {}
    ~Stream() override { delete inner_; }
    size_t Read(void* buffer, size_t size, size_t count) override {
      budget_->spend_read(size * count);
      return inner_->Read(buffer, size, count);
    }
    size_t Write(const void* buffer, size_t size, size_t count) override {
      budget_->spend();
      return inner_->Write(buffer, size, count);
    }
    aiReturn Seek(size_t offset, aiOrigin origin) override {
      budget_->spend();
      return inner_->Seek(offset, origin);
    }
    size_t Tell() const override {
      budget_->spend();
      return inner_->Tell();
    }
    size_t FileSize() const override { return inner_->FileSize(); }
    void Flush() override { inner_->Flush(); }

   private:
    Assimp::IOStream* inner_;
    Budget* budget_;
  };

  Assimp::DefaultIOSystem base_;
  mutable Budget budget_;
};

// Assimp's PLY reader loops forever or reads out of bounds on some malformed headers (found by
// fuzzing; tests/fuzz/regressions/mesh), so PLY headers are checked here first: the grammar,
// the types, and (binary files) that the body is at least as long as the header says.
// Files that start with "ply" are checked whatever their extension: Assimp picks readers by
// content when the extension is unknown.
std::string ply_header_problem(const fs::path& p, bool named_ply) {
  std::FILE* f = std::fopen(p.c_str(), "rb");
  if (!f) return std::strerror(errno);
  std::string text(1 << 20, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), f));
  std::fseek(f, 0, SEEK_END);
  long file_size = std::ftell(f);
  std::fclose(f);
  if (!named_ply && text.compare(0, 3, "ply") != 0) return {};

  static const std::map<std::string, uint64_t> kTypes = {
      {"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},  {"short", 2}, {"ushort", 2},
      {"int16", 2}, {"uint16", 2},  {"int", 4},    {"uint", 4},   {"int32", 4}, {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  size_t pos = 0, line_no = 0;
  bool binary = false, have_format = false, in_element = false;
  uint64_t body_min = 0, element_count = 0;
  while (true) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) return "PLY header has no end_header line";
    std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::vector<std::string> w;
    for (size_t i = 0; i < line.size();) {
      size_t j = line.find_first_of(" \t", i);
      if (j == std::string::npos) j = line.size();
      if (j > i) w.push_back(line.substr(i, j - i));
      i = j + 1;
    }
    auto bad = [&](const char* what) {
      return fmt::format("PLY header line {}: {}", line_no, what);
    };
    if (line_no == 1) {
      if (w.size() != 1 || w[0] != "ply") return bad("the file does not start with 'ply'");
      continue;
    }
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      if (w.size() != 1) return bad("text after end_header");
      break;
    }
    if (w[0] == "format") {
      if (have_format || w.size() != 3 || w[2] != "1.0") return bad("bad format line");
      if (w[1] == "binary_little_endian" || w[1] == "binary_big_endian") {
        binary = true;
      } else if (w[1] != "ascii") {
        return bad("unknown format");
      }
      have_format = true;
    } else if (w[0] == "element") {
      if (w.size() != 3 || w[2].empty() || w[2].size() > 10 ||
          w[2].find_first_not_of("0123456789") != std::string::npos) {
        return bad("an element needs a name and a count");
      }
      element_count = std::stoull(w[2]);
      if (element_count > 0xFFFFFFFFull) return bad("element count too large");
      in_element = true;
    } else if (w[0] == "property") {
      if (!in_element) return bad("property before any element");
      if (w.size() == 5 && w[1] == "list") {
        if (!kTypes.count(w[2]) || !kTypes.count(w[3])) return bad("unknown property type");
        body_min += element_count * kTypes.at(w[2]);
      } else if (w.size() == 3 && kTypes.count(w[1])) {
        body_min += element_count * kTypes.at(w[1]);
      } else {
        return bad("a property needs a known type and a name");
      }
    } else {
      return bad("unknown keyword");
    }
  }
  if (!have_format) return "PLY header has no format line";
  if (binary && file_size >= 0 && uint64_t(file_size) - pos < body_min) {
    return fmt::format("PLY file is truncated: the header asks for at least {} bytes, {} follow",
                       body_min, uint64_t(file_size) - pos);
  }
  return {};
}

// What is wrong with a freshly read (not post-processed) Assimp scene, if anything.
std::string raw_mesh_problem(const aiScene* ai) {
  if (ai->mNumMeshes > 0 && !ai->mMeshes) return "the importer returned no mesh array";
  for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
    const aiMesh* am = ai->mMeshes[m];
    if (!am) return fmt::format("mesh {} is missing", m);
    if (am->mNumFaces > 0 && (!am->mFaces || !am->mVertices)) {
      return fmt::format("mesh {} has faces but no vertices", m);
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices == 0 || !face.mIndices) {
        return fmt::format("face {} of mesh {} has no vertices", f, m);
      }
      for (unsigned k = 0; k < face.mNumIndices; ++k) {
        if (face.mIndices[k] >= am->mNumVertices) {
          return fmt::format("face {} of mesh {} has a vertex index out of range", f, m);
        }
      }
    }
  }
  return {};
}

TriangleMesh import_mesh(const std::string& file, const std::string& base_dir,
                         const std::string& path, bool smooth, size_t* skipped_primitives) {
  if (file.empty()) fail(path, "must not be empty");
  if (file.find('\0') != std::string::npos) fail(path, "must not contain a NUL character");
  fs::path full = fs::path(file);
  if (full.is_relative()) full = fs::path(base_dir.empty() ? "." : base_dir) / full;
  std::string prefix = "cannot read " + quote_json(file) + ": ";
  if (std::string problem = file_status(full); !problem.empty()) fail(path, prefix + problem);

  std::string ext = full.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (std::string problem = ply_header_problem(full, ext == ".ply"); !problem.empty()) {
    fail(path, prefix + problem);
  }

  Assimp::Importer importer;
  importer.SetIOHandler(new BudgetIOSystem);  // the importer owns it
  // Two stages. Assimp's readers can make broken data from broken files (faces with no
  // indices, indices past the vertices) and its post-processing steps assert on that, which
  // aborts the process (found by fuzzing; tests/fuzz/regressions/mesh). So: read with
  // validation only, check what the reader made ourselves, then post-process.
  const aiScene* ai = importer.ReadFile(full.string(), aiProcess_ValidateDataStructure);
  auto import_failed = [&] {
    std::string reason = importer.GetErrorString();
    std::replace(reason.begin(), reason.end(), '\n', ' ');
    fail(path, prefix + (reason.empty() ? "the importer gave no reason" : reason));
  };
  if (!ai) import_failed();
  if (std::string problem = raw_mesh_problem(ai); !problem.empty()) {
    fail(path, quote_json(file) + ": " + problem);
  }
  unsigned flags =
      aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices;
  if (smooth) flags |= aiProcess_GenSmoothNormals;  // ignored where the file has normals
  ai = importer.ApplyPostProcessing(flags);
  if (!ai) import_failed();

  size_t faces = 0, vertices = 0;
  for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
    faces += ai->mMeshes[m]->mNumFaces;
    vertices += ai->mMeshes[m]->mNumVertices;
  }
  if (faces > kMaxMeshTriangles || vertices > 3 * kMaxMeshTriangles) {
    fail(path, fmt::format("{} has {} faces, more than the limit of {} triangles", quote_json(file),
                           faces, kMaxMeshTriangles));
  }

  TriangleMesh mesh;
  mesh.positions.reserve(vertices);
  mesh.triangles.reserve(faces);
  if (smooth) mesh.normals.reserve(vertices);
  for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
    const aiMesh* am = ai->mMeshes[m];
    if (!am->mVertices) continue;
    uint32_t base = static_cast<uint32_t>(mesh.positions.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      glm::vec3 pos(p.x, p.y, p.z);
      if (!finite(pos)) {
        fail(path, fmt::format("{}: vertex {} of mesh {} has a non-finite coordinate",
                               quote_json(file), v, m));
      }
      mesh.positions.push_back(pos);
      if (smooth) {
        glm::vec3 n(0.0f);  // missing: repaired below from the faces
        if (am->mNormals) n = glm::vec3(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z);
        mesh.normals.push_back(n);
      }
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) {
        ++*skipped_primitives;
        continue;
      }
      for (int k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= am->mNumVertices) {
          fail(path, fmt::format("{}: face {} of mesh {} has a vertex index out of range",
                                 quote_json(file), f, m));
        }
      }
      mesh.triangles.emplace_back(base + face.mIndices[0], base + face.mIndices[1],
                                  base + face.mIndices[2]);
    }
  }
  if (mesh.triangles.empty()) fail(path, quote_json(file) + " contains no triangles");
  return mesh;
}

// ------------------------------------------------------------------------------------------
// The scene reader.

class Reader {
 public:
  Reader(Scene& scene, std::string base_dir, std::vector<std::string> material_order)
      : scene_(scene), base_dir_(std::move(base_dir)), material_order_(std::move(material_order)) {}

  void read(const json& root) {
    check_object(root, "");
    check_keys(root, "",
               {"format", "image", "camera", "ambient", "materials", "lights", "objects"});
    if (const json* f = find(root, "format")) {
      const std::string& s = string(*f, "format");
      if (s != kFormat) {
        fail("format", fmt::format("must be '{}', got {}", kFormat, quote_json(s)));
      }
    }
    if (const json* image = find(root, "image")) read_image(*image);
    read_camera(require(root, "", "camera", "eye, target and up at least"));
    if (const json* a = find(root, "ambient")) scene_.ambient = colour(*a, "ambient");
    scene_.materials.clear();
    scene_.materials.push_back(default_material());
    if (const json* m = find(root, "materials")) read_materials(*m);
    if (const json* l = find(root, "lights")) read_lights(*l);
    if (const json* o = find(root, "objects")) read_objects(*o);
  }

 private:
  void read_image(const json& v) {
    const std::string path = "image";
    check_object(v, path);
    check_keys(v, path, {"width", "height", "background", "samples_per_pixel"});
    ImageSettings& im = scene_.image;
    if (const json* w = find(v, "width")) im.width = integer(*w, "image.width", 1, kMaxImageSize);
    if (const json* h = find(v, "height")) {
      im.height = integer(*h, "image.height", 1, kMaxImageSize);
    }
    if (const json* b = find(v, "background")) im.background = colour(*b, "image.background");
    if (const json* s = find(v, "samples_per_pixel")) {
      im.samples_per_pixel = integer(*s, "image.samples_per_pixel", 1, kMaxSamplesPerPixel,
                                     " (capped at " + std::to_string(kMaxSamplesPerPixel) + ")");
    }
  }

  void read_camera(const json& v) {
    const std::string path = "camera";
    check_object(v, path);
    check_keys(
        v, path,
        {"eye", "target", "up", "fov_y_deg", "near", "far", "aperture_radius", "focus_distance"});
    Camera& c = scene_.camera;
    c.eye = vec3(require(v, path, "eye"), "camera.eye");
    c.target = vec3(require(v, path, "target"), "camera.target");
    c.up = vec3(require(v, path, "up"), "camera.up");
    glm::dvec3 view = glm::dvec3(c.target) - glm::dvec3(c.eye);
    if (glm::length(view) == 0.0) {
      fail("camera.target", "must differ from camera.eye (both are " + vec_text(c.eye) + ")");
    }
    glm::vec3 view_f = c.target - c.eye;
    float view_len = glm::length(view_f);
    if (!std::isfinite(view_len) || !(view_len > 0.0f) || !finite(glm::normalize(view_f))) {
      fail("camera.target", "is too far from or too close to camera.eye for 32-bit floats");
    }
    glm::dvec3 up(c.up);
    if (glm::length(up) == 0.0) fail("camera.up", "must be non-zero");
    double sine = glm::length(glm::cross(glm::normalize(view), glm::normalize(up)));
    if (!(sine > 1e-6)) {
      fail("camera.up", "must not be parallel to target - eye, got up " + vec_text(c.up) +
                            " and target - eye " + vec_text(view_f));
    }
    // Only its direction matters; unit length keeps float camera maths away from underflow.
    c.up = glm::vec3(glm::normalize(up));
    if (const json* f = find(v, "fov_y_deg")) {
      c.fov_y_deg = real(*f, "camera.fov_y_deg");
      if (!(c.fov_y_deg > 0.0f && c.fov_y_deg < 180.0f)) {
        fail("camera.fov_y_deg", "must be in (0, 180), got " + fmt_num(f->get<double>()));
      }
    }
    if (const json* n = find(v, "near")) c.near = real_at_least(*n, "camera.near", 0, Bound::Open);
    if (const json* f = find(v, "far")) c.far = real(*f, "camera.far");
    if (!(c.far > c.near)) {
      fail("camera.far",
           fmt::format("must be > camera.near ({}), got {}", fmt_num(c.near), fmt_num(c.far)));
    }
    if (const json* a = find(v, "aperture_radius")) {
      c.aperture_radius = real_at_least(*a, "camera.aperture_radius", 0, Bound::Closed);
    }
    if (const json* f = find(v, "focus_distance")) {
      c.focus_distance = real_at_least(*f, "camera.focus_distance", 0, Bound::Open);
    } else {
      c.focus_distance = view_len;
    }
  }

  void read_materials(const json& v) {
    const std::string path = "materials";
    check_object(v, path);
    // File order (recorded while parsing); the DOM's own order is alphabetical.
    std::vector<std::string> names = material_order_;
    if (names.size() != v.size()) {
      names.clear();
      for (const auto& [name, m] : v.items()) names.push_back(name);
    }
    for (const std::string& name : names) {
      std::string p = key_path(path, name);
      if (name.empty()) fail(path, "material names must not be empty");
      scene_.materials.push_back(read_material(v.at(name), p, name));
      material_index_[name] = static_cast<uint32_t>(scene_.materials.size() - 1);
    }
  }

  Material read_material(const json& v, const std::string& path, const std::string& name) {
    check_object(v, path);
    check_keys(v, path,
               {"diffuse", "specular", "emission", "shininess", "mirror", "transparency", "ior"});
    Material m;
    m.name = name;
    if (const json* d = find(v, "diffuse")) m.diffuse = colour(*d, key_path(path, "diffuse"));
    if (const json* s = find(v, "specular")) m.specular = colour(*s, key_path(path, "specular"));
    if (const json* e = find(v, "emission")) m.emission = colour(*e, key_path(path, "emission"));
    if (const json* s = find(v, "shininess")) {
      m.shininess = real_at_least(*s, key_path(path, "shininess"), 0, Bound::Closed);
    }
    if (const json* r = find(v, "mirror")) m.mirror = real_in_unit(*r, key_path(path, "mirror"));
    if (const json* t = find(v, "transparency")) {
      m.transparency = real_in_unit(*t, key_path(path, "transparency"));
    }
    if (double(m.mirror) + double(m.transparency) > 1.0 + 1e-6) {
      fail(path, fmt::format("mirror + transparency must be <= 1, got {} + {}",
                             fmt_num(find(v, "mirror")->get<double>()),
                             fmt_num(find(v, "transparency")->get<double>())));
    }
    if (const json* i = find(v, "ior")) {
      m.ior = real_at_least(*i, key_path(path, "ior"), 1, Bound::Closed);
    }
    return m;
  }

  void read_lights(const json& v) {
    if (!v.is_array()) fail("lights", "must be an array, got " + describe(v));
    for (size_t i = 0; i < v.size(); ++i) scene_.lights.push_back(read_light(v[i], i));
  }

  Light read_light(const json& v, size_t index) {
    std::string path = index_path("lights", index);
    check_object(v, path);
    std::string tp = key_path(path, "type");
    const std::string& type = string(require(v, path, "type", "\"point\" or \"area\""), tp);
    Light l;
    if (type == "point") {
      check_keys(v, path, {"type", "position", "intensity"}, "a point light");
      l.type = LightType::Point;
      l.position = vec3(require(v, path, "position"), key_path(path, "position"));
      l.intensity = colour(require(v, path, "intensity"), key_path(path, "intensity"));
    } else if (type == "area") {
      check_keys(v, path, {"type", "corner", "edge_u", "edge_v", "intensity", "samples"},
                 "an area light");
      l.type = LightType::Area;
      l.corner = vec3(require(v, path, "corner"), key_path(path, "corner"));
      l.edge_u = vec3(require(v, path, "edge_u"), key_path(path, "edge_u"));
      l.edge_v = vec3(require(v, path, "edge_v"), key_path(path, "edge_v"));
      l.intensity = colour(require(v, path, "intensity"), key_path(path, "intensity"));
      if (const json* s = find(v, "samples")) {
        l.samples =
            integer(*s, key_path(path, "samples"), 1, kMaxLightSamples,
                    " (samples per side, capped at " + std::to_string(kMaxLightSamples) + ")");
      }
      glm::dvec3 u(l.edge_u), w(l.edge_v);
      if (glm::length(u) == 0.0) fail(key_path(path, "edge_u"), "must be non-zero");
      if (glm::length(w) == 0.0) fail(key_path(path, "edge_v"), "must be non-zero");
      if (!(glm::length(glm::cross(glm::normalize(u), glm::normalize(w))) > 1e-6)) {
        fail(key_path(path, "edge_v"), "is parallel to edge_u (the light would have zero area)");
      }
    } else {
      std::string s = suggestion(type, {"point", "area"});
      fail(tp, "unknown light type " + quote_json(type) +
                   (s.empty() ? "" : " (did you mean '" + s + "'?)") +
                   "; expected \"point\" or \"area\"");
    }
    return l;
  }

  void read_objects(const json& v) {
    if (!v.is_array()) fail("objects", "must be an array, got " + describe(v));
    for (size_t i = 0; i < v.size(); ++i) scene_.objects.push_back(read_object(v[i], i));
  }

  Object read_object(const json& v, size_t index) {
    static const std::vector<std::string> kTypes = {"sphere", "plane", "triangle", "mesh", "csg"};
    std::string path = index_path("objects", index);
    check_object(v, path);
    std::string tp = key_path(path, "type");
    const std::string& type = string(require(v, path, "type", "one of " + join(kTypes)), tp);
    std::vector<std::string> keys = {"name", "type", "material", "transform"};
    if (type == "sphere") {
      keys.insert(keys.end(), {"center", "radius"});
    } else if (type == "plane") {
      keys.insert(keys.end(), {"point", "normal", "half_size"});
    } else if (type == "triangle") {
      keys.insert(keys.end(), {"vertices"});
    } else if (type == "mesh") {
      keys.insert(keys.end(), {"file", "smooth"});
    } else if (type == "csg") {
      keys.insert(keys.end(), {"op", "a", "b"});
    } else {
      std::string s = suggestion(type, kTypes);
      fail(tp, "unknown object type " + quote_json(type) +
                   (s.empty() ? "" : " (did you mean '" + s + "'?)") + "; expected one of " +
                   join(kTypes));
    }
    check_keys(v, path, keys, "a " + type);

    Object o;
    o.name = type + "#" + std::to_string(index);
    if (const json* n = find(v, "name")) o.name = string(*n, key_path(path, "name"));
    if (const json* m = find(v, "material")) {
      std::string mp = key_path(path, "material");
      const std::string& name = string(*m, mp);
      auto it = material_index_.find(name);
      if (it == material_index_.end()) {
        std::vector<std::string> known;
        for (const auto& [k, idx] : material_index_) known.push_back(k);
        std::string s = suggestion(name, known);
        fail(mp, "unknown material " + quote_json(name) +
                     (s.empty() ? "" : " (did you mean '" + s + "'?)"));
      }
      o.material = it->second;
    }
    Transform t;
    if (const json* tr = find(v, "transform"))
      t = parse_transform(*tr, key_path(path, "transform"));
    std::string label = path + " (" + o.name + ")";

    if (type == "sphere") {
      o.type = ObjectType::Sphere;
      o.sphere = read_sphere(v, path);
      o.sphere = transform_sphere(o.sphere, t, path);
    } else if (type == "plane") {
      o.type = ObjectType::Plane;
      o.plane = read_plane(v, path, t);
    } else if (type == "triangle") {
      o.type = ObjectType::Triangles;
      std::string vp = key_path(path, "vertices");
      const json& verts = require(v, path, "vertices");
      if (!verts.is_array() || verts.size() != 3) {
        fail(vp, "must be an array of 3 vertices, got " + describe(verts));
      }
      for (size_t k = 0; k < 3; ++k) o.mesh.positions.push_back(vec3(verts[k], index_path(vp, k)));
      o.mesh.triangles.emplace_back(0, 1, 2);
      size_t dropped = 0, repaired = 0;
      finish_mesh(o.mesh, t, path, &dropped, &repaired);
      if (dropped > 0) fail(vp, "the triangle is degenerate (zero area)");
    } else if (type == "mesh") {
      o.type = ObjectType::Triangles;
      std::string fp = key_path(path, "file");
      const std::string& file = string(require(v, path, "file"), fp);
      bool smooth = false;
      if (const json* s = find(v, "smooth")) smooth = boolean(*s, key_path(path, "smooth"));
      size_t skipped = 0, dropped = 0, repaired = 0;
      o.mesh = import_mesh(file, base_dir_, fp, smooth, &skipped);
      size_t total = o.mesh.triangles.size();
      finish_mesh(o.mesh, t, path, &dropped, &repaired);
      if (o.mesh.triangles.empty()) {
        fail(fp, fmt::format("{}: all {} triangles are degenerate (zero area)", quote_json(file),
                             total));
      }
      if (skipped > 0) {
        scene_.warnings.push_back(
            fmt::format("{}: ignored {} point/line primitives", label, skipped));
      }
      if (dropped > 0) {
        scene_.warnings.push_back(fmt::format("{}: dropped {} degenerate triangle{}", label,
                                              dropped, dropped == 1 ? "" : "s"));
      }
      if (repaired > 0) {
        scene_.warnings.push_back(
            fmt::format("{}: replaced {} zero or non-finite vertex normal{} by face normals", label,
                        repaired, repaired == 1 ? "" : "s"));
      }
    } else {  // csg
      o.type = ObjectType::Csg;
      o.csg = read_csg_inner(v, path, 1, t);
    }
    return o;
  }

  static Sphere read_sphere(const json& v, const std::string& path) {
    Sphere s;
    s.center = vec3(require(v, path, "center"), key_path(path, "center"));
    s.radius = real_at_least(require(v, path, "radius"), key_path(path, "radius"), 0, Bound::Open);
    return s;
  }

  static void require_uniform(const Transform& t, const std::string& path, const char* what) {
    if (!t.uniform()) {
      fail(path + ".transform.scale",
           fmt::format("{} needs a uniform scale (one number, or three of equal magnitude), got "
                       "[{}, {}, {}]",
                       what, fmt_num(t.scale.x), fmt_num(t.scale.y), fmt_num(t.scale.z)));
    }
  }

  static Sphere transform_sphere(Sphere s, const Transform& t, const std::string& path) {
    if (t.identity) return s;
    require_uniform(t, path, "a sphere");
    s.center = to_float(t.point(glm::dvec3(s.center)), path, "the centre");
    double r = double(s.radius) * std::abs(t.scale.x);
    if (!(float(r) > 0.0f) || !std::isfinite(float(r))) {
      fail(path + ".transform.scale", "makes the radius leave the 32-bit float range");
    }
    s.radius = float(r);
    return s;
  }

  static Plane read_plane(const json& v, const std::string& path, const Transform& t) {
    Plane p;
    p.point = vec3(require(v, path, "point"), key_path(path, "point"));
    std::string np = key_path(path, "normal");
    glm::dvec3 n(vec3(require(v, path, "normal"), np));
    if (glm::length(n) == 0.0) fail(np, "must be non-zero");
    if (const json* h = find(v, "half_size")) {
      p.half_size = real_at_least(*h, key_path(path, "half_size"), 0, Bound::Open);
    }
    if (!t.identity) {
      require_uniform(t, path, "a plane");
      p.point = to_float(t.point(glm::dvec3(p.point)), path, "the point");
      n = t.normal(n);
      double h = double(p.half_size) * std::abs(t.scale.x);
      if (!(float(h) > 0.0f) || !std::isfinite(float(h))) {
        fail(path + ".transform.scale", "makes half_size leave the 32-bit float range");
      }
      p.half_size = float(h);
    }
    p.normal = glm::vec3(glm::normalize(n));
    if (!finite(p.normal) || glm::length(p.normal) == 0.0f) fail(np, "cannot be normalised");
    return p;
  }

  // The csg object itself (depth 1) or a nested child; leaves are spheres.
  std::shared_ptr<const CsgNode> read_csg_inner(const json& v, const std::string& path, int depth,
                                                const Transform& t) {
    if (depth > kMaxCsgDepth) {
      fail(path, fmt::format("csg tree nested deeper than {} levels", kMaxCsgDepth));
    }
    auto node = std::make_shared<CsgNode>();
    node->is_leaf = false;
    std::string op_path = key_path(path, "op");
    const std::string& op =
        string(require(v, path, "op", "union, intersection or difference"), op_path);
    if (op == "union") {
      node->op = CsgOp::Union;
    } else if (op == "intersection") {
      node->op = CsgOp::Intersection;
    } else if (op == "difference") {
      node->op = CsgOp::Difference;
    } else {
      std::string s = suggestion(op, {"union", "intersection", "difference"});
      fail(op_path, "unknown csg op " + quote_json(op) +
                        (s.empty() ? "" : " (did you mean '" + s + "'?)") +
                        "; expected union, intersection or difference");
    }
    node->a = read_csg_child(require(v, path, "a"), key_path(path, "a"), depth + 1, t);
    node->b = read_csg_child(require(v, path, "b"), key_path(path, "b"), depth + 1, t);
    return node;
  }

  std::shared_ptr<const CsgNode> read_csg_child(const json& v, const std::string& path, int depth,
                                                const Transform& t) {
    check_object(v, path);
    if (depth > kMaxCsgDepth) {
      fail(path, fmt::format("csg tree nested deeper than {} levels", kMaxCsgDepth));
    }
    std::string kind;
    if (const json* type = find(v, "type")) {
      kind = string(*type, key_path(path, "type"));
      if (kind != "sphere" && kind != "csg") {
        fail(key_path(path, "type"),
             "must be 'sphere' or 'csg' inside a csg tree, got " + quote_json(kind));
      }
    } else {
      kind = find(v, "op") ? "csg" : "sphere";
    }
    for (const char* k : {"material", "name", "transform"}) {
      if (find(v, k)) {
        fail(path, std::string("'") + k +
                       "' is not allowed inside a csg tree (set it on the csg object)");
      }
    }
    if (kind == "sphere") {
      check_keys(v, path, {"type", "center", "radius"}, "a csg sphere");
      auto leaf = std::make_shared<CsgNode>();
      leaf->is_leaf = true;
      leaf->sphere = transform_sphere(read_sphere(v, path), t, path);
      return leaf;
    }
    check_keys(v, path, {"type", "op", "a", "b"}, "a csg node");
    return read_csg_inner(v, path, depth, t);
  }

  Scene& scene_;
  std::string base_dir_;
  std::vector<std::string> material_order_;
  std::map<std::string, uint32_t> material_index_;
};

Expected<Scene> parse_scene_impl(const std::string& text, const std::string& source,
                                 const std::string& base_dir) {
  try {
    check_nesting(text);
    json root;
    SceneSax sax(root);
    bool parsed = json::sax_parse(text, &sax, json::input_format_t::json, true, false);
    sax.raise(text, parsed);
    Scene scene;
    scene.source = source;
    Reader reader(scene, base_dir, std::move(sax.material_order));
    reader.read(root);
    return scene;
  } catch (const SyntaxError& e) {
    auto [line, column] = line_column(text, e.offset);
    return bad_input(fmt::format("{}:{}:{}: JSON syntax: {}", source, line, column, e.what));
  } catch (const LoadError& e) {
    return bad_input(fmt::format("{}: {}: {}", source, where(e.path), e.what));
  } catch (const std::bad_alloc&) {
    return internal_error(source + ": out of memory while loading the scene");
  } catch (const std::exception& e) {
    return internal_error(source + ": internal error while loading the scene: " + e.what());
  } catch (...) {
    return internal_error(source + ": internal error while loading the scene");
  }
}

}  // namespace

Expected<Scene> parse_scene(const std::string& json_text, const std::string& source,
                            const std::string& base_dir) {
  return parse_scene_impl(json_text, source, base_dir);
}

Expected<Scene> load_scene_file(const std::string& path) {
  try {
    std::error_code ec;
    if (fs::is_directory(path, ec))
      return bad_input(path + ": cannot read: " + std::strerror(EISDIR));
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return bad_input(path + ": cannot read: " + std::strerror(errno));
    std::string text;
    char buffer[1 << 16];
    size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) {
      text.append(buffer, n);
      if (text.size() > kMaxSceneFileBytes) {  // also ends endless inputs such as /dev/zero
        std::fclose(f);
        return bad_input(
            fmt::format("{}: the scene file is over {} MiB (meshes belong in mesh "
                        "files)",
                        path, kMaxSceneFileBytes >> 20));
      }
    }
    int read_error = std::ferror(f) ? errno : 0;
    std::fclose(f);
    if (read_error) return bad_input(path + ": cannot read: " + std::strerror(read_error));
    std::string base_dir = fs::path(path).parent_path().string();
    return parse_scene_impl(text, path, base_dir.empty() ? "." : base_dir);
  } catch (const std::bad_alloc&) {
    return internal_error(path + ": out of memory while reading the scene");
  } catch (const std::exception& e) {
    return internal_error(path + ": internal error while reading the scene: " + e.what());
  } catch (...) {
    return internal_error(path + ": internal error while reading the scene");
  }
}

Expected<Scene> load_scene(const std::string& spec) {
  static const std::string kBuiltin = "builtin:";
  if (spec.rfind(kBuiltin, 0) != 0) return load_scene_file(spec);
  try {
    Expected<Scene> scene = make_builtin_scene(spec.substr(kBuiltin.size()));
    if (scene.ok() && scene->source.empty()) scene->source = spec;
    return scene;
  } catch (const std::bad_alloc&) {
    return internal_error(spec + ": out of memory while building the scene");
  } catch (const std::exception& e) {
    return internal_error(spec + ": internal error while building the scene: " + e.what());
  } catch (...) {
    return internal_error(spec + ": internal error while building the scene");
  }
}

}  // namespace rvr
