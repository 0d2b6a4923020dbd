// The scene loader's error values and the parts of its messages: JSON paths ("objects[3].radius"),
// quoted values, "did you mean" suggestions. Private to scene_io/src.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace rvr::scene_load {

using json = nlohmann::json;

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

// Thrown inside the loader; the public functions turn it into an rvr::Error.
[[noreturn]] void fail(std::string path, std::string what);

std::string fmt_num(double v);
// 'text', JSON-escaped inside, cut short after 60 bytes with "..." so that a hostile string
// cannot flood the message: for values read from a file.
std::string quote_json(const std::string& s);
// 'path' whole, as the file system spells it: backslashes stay single, control characters are
// escaped (\n, \u001b) and bytes that are no UTF-8 become U+FFFD. Cut only past kPathMax bytes,
// longer than any path Linux opens.
std::string quote_path(const std::string& path);
constexpr size_t kPathMax = 4096;
// What a JSON value is, for "must be X, got Y" messages.
std::string describe(const json& v);
bool is_identifier(const std::string& s);
std::string key_path(const std::string& parent, const std::string& key);
std::string index_path(const std::string& parent, size_t i);
std::string where(const std::string& path);
// Edit distance counting a swap of two neighbouring letters as one edit (optimal string
// alignment), case-insensitive.
size_t edit_distance(const std::string& a, const std::string& b);
// The closest allowed word, if it is close enough to be a likely typo.
std::string suggestion(const std::string& word, const std::vector<std::string>& allowed);
std::string join(const std::vector<std::string>& words, const char* sep = ", ");

}  // namespace rvr::scene_load
