// "Did you mean" for the command line: the known name nearest to what was typed, by edit
// distance. In rvr_app, for the Python module's messages too.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace rvr::cli {

// Levenshtein distance: the fewest single-character insertions, deletions and substitutions
// that turn `a` into `b`.
size_t edit_distance(const std::string& a, const std::string& b);

// The candidate nearest to `typed`, or "" when none is near enough to be a likely typo: within
// one edit per three characters of `typed` (at least one, at most three), leading dashes not
// counted, and never a candidate that shares nothing with it. Ties go to the earlier candidate.
std::string nearest(const std::string& typed, const std::vector<std::string>& candidates);

// The error of a value not among `names`: "'raytrac' is not one of raster, raytrace: did you
// mean 'raytrace'?" (the question only when one is near). The command line's option checks
// (one_of.h) and the Python module's renderer argument say it alike.
std::string not_one_of(const std::string& value, const std::vector<std::string>& names);

}  // namespace rvr::cli
