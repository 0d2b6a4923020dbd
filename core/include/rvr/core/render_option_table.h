// Every render option declared once: its name, type, range or choices, help, the renderers that
// read it and where it is stored in RenderOptions. The command line's options (--kebab-name),
// the Python module's keywords (snake_name), their validation, docs/cli.md's rows (checked by
// tests/test_render_option_table.cpp) and the warning for an option the chosen renderer does not
// read all come from this table. Defaults are RenderOptions' own.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"

namespace rvr {

enum class OptionType {
  Integer,   // a whole number in [min, max]
  Unsigned,  // any 64-bit unsigned whole number (a seed)
  Real,      // a number in [min, max]
  Flag,      // on or off (true/false, on/off, 1/0)
  Choice,    // one of `choices`
};

struct RenderOptionSpec {
  // snake_case: the Python keyword; the command line's is --kebab-case.
  std::string_view name = {};
  OptionType type = OptionType::Integer;
  double min = 0, max = 0;                     // Integer, Real: the range, both ends included
  std::vector<std::string_view> choices = {};  // Choice: the names, in the order of their values
  std::string_view help = {};                  // one line
  std::vector<std::string_view> readers = {};  // the renderers (registry names) that read it
  // Stores a value the table has checked: Integer, Unsigned and Flag (0 or 1) as `integer`, Real
  // as `real`, Choice as the index into `choices`.
  void (*store)(RenderOptions& options, unsigned long long integer, double real) = nullptr;
  // The option's value in `options` as text ("" for an unset choice): RenderOptions{}'s is the
  // default.
  std::string (*show)(const RenderOptions& options) = nullptr;
};

// The table, in the order the command line's help lists the options.
const std::vector<RenderOptionSpec>& render_option_table();

// The entry named `name` (snake_case), or null.
const RenderOptionSpec* find_render_option(std::string_view name);

// "--shadow-map-size" for shadow_map_size.
std::string cli_option_name(const RenderOptionSpec& spec);

// RenderOptions{}'s value of the option as text: "1024", "0.01", "off", "bvh"; "" when unset.
std::string default_text(const RenderOptionSpec& spec);

// Checks `text` against the option's type and range or choices and stores it in `options`. The
// error names no option ("must be 16 to 8192, got 8", "'kd' is not one of bvh, bvh2, none"):
// the caller prefixes the name its user typed.
Status set_render_option(RenderOptions& options, const RenderOptionSpec& spec,
                         std::string_view text);

// Whether renderer `renderer` (a registry name) reads the option.
bool reads_option(const RenderOptionSpec& spec, std::string_view renderer);

// A warning for each option in `given` (snake_case names, as set by the user) that `renderer`
// does not read: "option --shadow-map-size is not read by raytrace" (`cli_names`), or
// "option shadow_map_size is not read by raytrace".
std::vector<std::string> unread_option_warnings(const std::vector<std::string>& given,
                                                std::string_view renderer, bool cli_names);

}  // namespace rvr
