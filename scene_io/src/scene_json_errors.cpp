// The scene loader's error values and message parts (see scene_json_errors.h).
#include "scene_json_errors.h"

#include <fmt/format.h>
#include <stdint.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <utility>

namespace rvr::scene_load {

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

std::string quote_path(const std::string& path) {
  // JSON's escaping makes the bytes valid UTF-8 (U+FFFD for the others); reading the string
  // back undoes every escape, and only control characters are escaped again.
  std::string shown = path.size() > kPathMax ? path.substr(0, kPathMax) + "..." : path;
  const std::string valid =
      json::parse(json(shown).dump(-1, ' ', false, json::error_handler_t::replace))
          .get<std::string>();
  std::string q = "'";
  for (const char c : valid) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n') {
      q += "\\n";
    } else if (c == '\t') {
      q += "\\t";
    } else if (c == '\r') {
      q += "\\r";
    } else if (u < 0x20 || u == 0x7f) {
      q += fmt::format("\\u{:04x}", u);
    } else {
      q += c;
    }
  }
  return q + "'";
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
  // Appended, not "[" + temporary: out of line, that trips GCC 12's false -Wrestrict (its bug
  // 105651).
  std::string k = is_identifier(key) ? key : std::string("[").append(quote_json(key)).append("]");
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

std::string join(const std::vector<std::string>& words, const char* sep) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : sep) + w;
  return out;
}

}  // namespace rvr::scene_load
