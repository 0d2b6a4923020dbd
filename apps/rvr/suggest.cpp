// "Did you mean" for the command line (see suggest.h).
#include "suggest.h"

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

namespace rvr::cli {

namespace {

std::string without_dashes(const std::string& s) {
  const size_t start = s.find_first_not_of('-');
  return start == std::string::npos ? std::string() : s.substr(start);
}

}  // namespace

size_t edit_distance(const std::string& a, const std::string& b) {
  // One row of the dynamic-programming table at a time: row[j] is the distance between the
  // first i characters of a and the first j of b.
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];  // the distance for (i - 1, j - 1)
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({above + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string nearest(const std::string& typed, const std::vector<std::string>& candidates) {
  const std::string word = without_dashes(typed);
  const size_t allowed = std::clamp<size_t>(word.size() / 3, 1, 3);
  std::string best;
  size_t best_distance = allowed + 1;
  for (const std::string& c : candidates) {
    const size_t d = edit_distance(word, without_dashes(c));
    if (d < best_distance && d < word.size()) {  // a typo keeps some of the word
      best = c;
      best_distance = d;
    }
  }
  return best;
}

std::string not_one_of(const std::string& value, const std::vector<std::string>& names) {
  std::string message = "'" + value + "' is not one of ";
  for (size_t i = 0; i < names.size(); ++i) message += (i ? ", " : "") + names[i];
  if (const std::string near = nearest(value, names); !near.empty())
    message += ": did you mean '" + near + "'?";
  return message;
}

}  // namespace rvr::cli
