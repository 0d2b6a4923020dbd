// The few lines of script report.html carries inline. Private to apps/rvr.
#pragma once

namespace rvr::report {

// Flip / slider between the first two renders: the top image is clipped from the left.
extern const char* const kScript;

}  // namespace rvr::report
