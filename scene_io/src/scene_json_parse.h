// Reading JSON text for the scene loader: a depth pre-scan, a SAX parse that catches duplicate
// keys and number overflow by path, and syntax errors as line, column and a readable message.
// Private to scene_io/src.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "scene_json_errors.h"

namespace rvr::scene_load {

// Line and column (1-based; the column counts UTF-8 code points) of a byte offset.
std::pair<size_t, size_t> line_column(const std::string& text, size_t offset);
// The start of the token that ends at `last` (nlohmann reports the end).
size_t token_start(const std::string& text, size_t last);
// Throws a SyntaxError for absurd nesting, before parsing.
void check_nesting(const std::string& text);
std::string token_name(const std::string& t);
// nlohmann's parse error message in plain words ("expected ',' or '}', got a number").
std::string syntax_message(const std::string& raw, bool whitespace_only, bool* token_error);

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

}  // namespace rvr::scene_load
