// Reading JSON text for the scene loader (see scene_json_parse.h).
#include "scene_json_parse.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>

namespace rvr::scene_load {
namespace {

constexpr int kMaxJsonDepth = 512;

}  // namespace

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
  } else if (size_t colon = msg.find(']'); colon != std::string::npos) {
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

}  // namespace rvr::scene_load
