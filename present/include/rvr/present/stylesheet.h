// The one stylesheet of rvr's pages (report.html, study.html), carried inline by page_start
// (page.h): the page, tables, figures, legends and the charts drawn through chart_axes.h.
#pragma once

namespace rvr::present {

extern const char* const kStylesheet;

}  // namespace rvr::present
