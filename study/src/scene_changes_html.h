// study.html's table of what each renderer builds per scene and the frames per scene change
// that pay for it (scene_changes.h). Private to the study library.
#pragma once

#include <string>

#include "rvr/study/study.h"

namespace rvr::study {

// One family's table: each renderer's preparation at each N at the full image size, and k* of
// every z-buffer against every renderer that builds; "" when nothing was measured.
std::string builds_html(const StudyResult& r, const std::string& scene);

}  // namespace rvr::study
