// study.html: the study as one self-contained page (inline CSS and SVG, nothing fetched, no
// script): per scene family a log-log chart of frame time against the swept axis with each
// renderer's measured points, their spread and its fitted model, the crossovers marked with
// their intervals; charts against the pixel count where a scene was measured at several; the
// models, the crossovers as sentences, the machine and the notes.
#pragma once

#include <string>

#include "rvr/study/study.h"

namespace rvr::study {

std::string study_html(const StudyResult& result);

}  // namespace rvr::study
