// Legends and swatches (see legend.h).
#include "rvr/present/legend.h"

#include "rvr/present/html_escape.h"

namespace rvr::present {

std::string swatch(const std::string& colour) {
  return "<span class=\"sw\" style=\"background:" + escape_html(colour) + "\"></span>";
}

std::string swatch_key(const std::string& colour, const std::string& words) {
  return "<span>" + swatch(colour) + words + "</span>";
}

std::string drawing_key(const std::string& drawing, const std::string& words) {
  return "<span><svg width=\"30\" height=\"14\" aria-hidden=\"true\">" + drawing + "</svg>" +
         words + "</span>";
}

std::string custom_key(const std::string& css_class, const std::string& markup) {
  return "<span class=\"" + escape_html(css_class) + "\">" + markup + "</span>";
}

std::string legend(const std::vector<std::string>& keys) {
  std::string o = "<div class=\"legend\">";
  for (const std::string& k : keys) o += k;
  return o + "</div>";
}

}  // namespace rvr::present
