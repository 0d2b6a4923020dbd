// Powers of ten raised (see powers_of_ten.h).
#include "rvr/present/powers_of_ten.h"

#include <fmt/format.h>
#include <stddef.h>

#include <cctype>

#include "rvr/present/html_escape.h"

namespace rvr::present {
namespace {

// Rewrites every "10^k" (k an optional minus and digits) of already escaped text through
// `raise(k)`: the exponent as the output format writes it.
template <typename Raise>
std::string raise_powers(const std::string& text, Raise raise) {
  std::string out;
  size_t i = 0;
  while (i < text.size()) {
    size_t hat = text.find("10^", i);
    if (hat == std::string::npos) break;
    size_t end = hat + 3;
    if (end < text.size() && text[end] == '-') ++end;
    while (end < text.size() && std::isdigit(static_cast<unsigned char>(text[end]))) ++end;
    std::string k = text.substr(hat + 3, end - hat - 3);
    if (k.empty() || k == "-") {  // a caret not followed by an exponent stays as it is
      out += text.substr(i, end - i);
    } else {
      if (k[0] == '-') k = "−" + k.substr(1);  // a minus sign, not a hyphen
      out += text.substr(i, hat - i) + "10" + raise(k);
    }
    i = end;
  }
  return out + text.substr(i);
}

std::string sup(const std::string& k) {
  return "<sup>" + k + "</sup>";
}

std::string raised_tspan(const std::string& k) {
  return "<tspan class=\"exp\" dy=\"-0.45em\" font-size=\"75%\">" + k +
         "</tspan><tspan dy=\"0.45em\">&#8203;</tspan>";
}

}  // namespace

std::string html_with_powers(const std::string& s) {
  return raise_powers(escape_html(s), sup);
}

std::string decade_svg(int k) {
  return "10" + raised_tspan(k < 0 ? fmt::format("−{}", -k) : fmt::format("{}", k));
}

}  // namespace rvr::present
