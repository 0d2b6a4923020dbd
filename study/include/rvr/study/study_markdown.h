// study.md: the conclusions as sentences generated from the numbers of a study.
#pragma once

#include <string>

#include "rvr/study/study.h"

namespace rvr::study {

// 2.1×10^6 for large and small numbers, 3 significant digits between 0.01 and 10^4.
std::string format_number(double v);

std::string study_markdown(const StudyResult& result);

}  // namespace rvr::study
