// Texture paths resolved as modelling tools resolve them (texture_paths.h).
#include "texture_paths.h"

#include <stddef.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <deque>
#include <filesystem>
#include <initializer_list>
#include <system_error>
#include <utility>
#include <vector>

namespace rvr::scene_load {
namespace {

namespace fs = std::filesystem;

bool is_file(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// "C:/..." or "//server/...": a path only Windows can follow.
bool windows_absolute(const std::string& p) {
  return (p.size() >= 2 && std::isalpha(static_cast<unsigned char>(p[0])) && p[1] == ':') ||
         p.rfind("//", 0) == 0;
}

// The folder's entries, sorted by name (the file system's order is not fixed).
std::vector<fs::path> entries(const fs::path& folder, size_t* budget) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (*budget == 0) break;
    --*budget;
    out.push_back(it->path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// `relative` below `folder` with every name matched regardless of case (exact matches first).
fs::path match_case_insensitively(const fs::path& folder, const fs::path& relative) {
  fs::path at = folder;
  size_t budget = kSearchEntries;
  for (const fs::path& part : relative) {
    const std::string name = part.string();
    if (name.empty() || name == ".") continue;
    if (name == "..") {
      at /= name;
      continue;
    }
    if (fs::exists(at / part)) {
      at /= part;
      continue;
    }
    fs::path found;
    for (const fs::path& e : entries(at, &budget)) {
      if (lower(e.filename().string()) == lower(name)) {
        found = e;
        break;
      }
    }
    if (found.empty()) return {};
    at = found;
  }
  return is_file(at) ? at : fs::path();
}

// A file named `name` under `folder`, at most kSearchDepth folders down, breadth first (the
// shallowest wins); a name of the same case before one that differs in case. The folder `skip`
// (already searched) is not entered.
fs::path search_by_name(const fs::path& folder, const std::string& name,
                        const fs::path& skip = {}) {
  size_t budget = kSearchEntries;
  fs::path other_case;  // the first name that differs only in case, and its depth
  int other_depth = 0;
  std::deque<std::pair<fs::path, int>> queue{{folder, 0}};
  while (!queue.empty()) {
    auto [at, depth] = queue.front();
    queue.pop_front();
    if (!other_case.empty() && depth > other_depth) break;
    for (const fs::path& e : entries(at, &budget)) {
      std::error_code ec;
      if (fs::is_directory(e, ec)) {
        if (depth < kSearchDepth && e != skip) queue.emplace_back(e, depth + 1);
      } else if (is_file(e)) {
        if (e.filename().string() == name) return e;
        if (other_case.empty() && lower(e.filename().string()) == lower(name)) {
          other_case = e;
          other_depth = depth;
        }
      }
    }
  }
  return other_case;
}

// `p` with its URI escapes (%20 for a space, as glTF exporters write file names) decoded;
// empty when it has none or a malformed one.
std::string percent_decoded(const std::string& p) {
  if (p.find('%') == std::string::npos) return {};
  std::string out;
  for (size_t i = 0; i < p.size(); ++i) {
    if (p[i] != '%') {
      out += p[i];
      continue;
    }
    if (i + 2 >= p.size() || !std::isxdigit(static_cast<unsigned char>(p[i + 1])) ||
        !std::isxdigit(static_cast<unsigned char>(p[i + 2]))) {
      return {};
    }
    out += static_cast<char>(std::stoi(p.substr(i + 1, 2), nullptr, 16));
    i += 2;
  }
  return out.find('\0') == std::string::npos ? out : std::string();
}

// The path as written, then with each name matched regardless of case. A path from the root
// that is not there is read from `base` too: Windows exporters write \..\maps\x.png (from the
// root of the drive, which is "/../maps/x.png" here) for a path from the model's folder.
fs::path find_as_written(const std::string& p, const fs::path& base) {
  if (windows_absolute(p)) return {};
  fs::path written = fs::path(p).is_absolute() ? fs::path(p) : base / p;
  if (is_file(written)) return written;
  if (fs::path(p).is_relative()) return match_case_insensitively(base, fs::path(p));
  const size_t first = p.find_first_not_of('/');
  if (first == std::string::npos) return {};
  const std::string from_base = p.substr(first);
  if (is_file(base / from_base)) return base / from_base;
  return match_case_insensitively(base, fs::path(from_base));
}

// `folder` absolute, normalised and without a trailing separator ("" when it cannot be made
// absolute).
fs::path normal_folder(const std::string& folder) {
  std::error_code ec;
  fs::path p = fs::absolute(folder.empty() ? fs::path(".") : fs::path(folder), ec);
  if (ec) return {};
  p = p.lexically_normal();
  return p.has_filename() || p == p.root_path() ? p : p.parent_path();
}

}  // namespace

std::string texture_search_parent(const std::string& folder) {
  const fs::path base = normal_folder(folder);
  const fs::path parent = base.parent_path();
  return base.empty() || parent == base ? std::string() : parent.string();
}

std::string find_texture_file(const std::string& named, const std::string& folder) {
  std::string p = named;
  std::replace(p.begin(), p.end(), '\\', '/');
  if (p.rfind("file://", 0) == 0) p = p.substr(7);
  if (p.empty() || p.find('\0') != std::string::npos) return {};
  const fs::path base = folder.empty() ? fs::path(".") : fs::path(folder);
  const std::string decoded = percent_decoded(p);
  for (const std::string& candidate : {p, decoded}) {
    if (candidate.empty()) continue;
    const fs::path found = find_as_written(candidate, base);
    if (!found.empty()) return found.string();
  }
  const std::string parent = texture_search_parent(folder);
  for (const bool in_parent : {false, true}) {
    if (in_parent && parent.empty()) break;
    for (const std::string& candidate : {p, decoded}) {
      const std::string name = fs::path(candidate).filename().string();
      if (candidate.empty() || name.empty() || name == "." || name == "..") continue;
      const fs::path found = in_parent ? search_by_name(parent, name, normal_folder(folder))
                                       : search_by_name(base, name);
      if (!found.empty()) return found.string();
    }
  }
  return {};
}

}  // namespace rvr::scene_load
