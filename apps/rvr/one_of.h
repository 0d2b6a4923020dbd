// A command-line option's value checked against its known names, as CLI::IsMember does, but
// with the suggestion mechanism (suggest.h): a typo is answered with the nearest name. Private
// to apps/rvr.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace rvr::cli {

// Accepts exactly one of `names`; otherwise the error names them all and, when one is near
// what was typed, asks "did you mean" it.
CLI::Validator one_of(std::vector<std::string> names);

}  // namespace rvr::cli
