// The skeleton of an rvr page: one self-contained HTML file, the stylesheet inline, nothing
// fetched from anywhere.
#pragma once

#include <string>

namespace rvr::present {

// How wide the page's text may run: Wide for pictures side by side (report.html), Reading for
// prose and charts one under another (study.html).
enum class PageWidth { Wide, Reading };

// From the doctype to the opening <main>: the head with `title` (plain text) and the stylesheet.
std::string page_start(const std::string& title, PageWidth width);

// From the closing </main> to the end; `script`, when not empty, inline before </body>.
std::string page_end(const std::string& script = "");

}  // namespace rvr::present
