// The stylesheet report.html carries inline. Private to apps/rvr.
#pragma once

namespace rvr::report {

extern const char* const kCss;

}  // namespace rvr::report
