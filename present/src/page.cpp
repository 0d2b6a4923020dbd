// The page's skeleton (see page.h).
#include "rvr/present/page.h"

#include "rvr/present/html_escape.h"
#include "rvr/present/stylesheet.h"

namespace rvr::present {

std::string page_start(const std::string& title, PageWidth width) {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>" +
         escape_html(title) + "</title>\n<style>" + kStylesheet + "</style>\n</head>\n<body>\n" +
         (width == PageWidth::Reading ? "<main class=\"reading\">\n" : "<main>\n");
}

std::string page_end(const std::string& script) {
  std::string o = "</main>\n";
  if (!script.empty()) o += "<script>" + script + "</script>\n";
  return o + "</body>\n</html>\n";
}

}  // namespace rvr::present
