// study.json, format rvr-study/1 (docs/rvr-study-1.schema.json; fields in docs/cli.md).
#pragma once

#include <string>

#include "rvr/study/study.h"

namespace rvr::study {

constexpr const char* kStudyFormat = "rvr-study/1";

// The whole study as JSON text; non-finite numbers are null.
std::string study_json(const StudyResult& result);

}  // namespace rvr::study
