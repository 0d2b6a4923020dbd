// The counted-work models, the counts' scaling and the claims checked on counts as study.md and
// study.html say them (counted_work.h). Private to the study library.
#pragma once

#include <string>
#include <vector>

#include "rvr/study/study.h"

namespace rvr::study {

// One sentence per work model: its terms with their intervals, its quality, what was left out.
std::vector<std::string> work_model_sentences(const StudyResult& r);

// One sentence per claim checked on counts, with what the numbers say about it.
std::vector<std::string> count_claim_sentences(const StudyResult& r);

// The counts' scaling of one family as a table: a row per renderer and count, the log-log slope
// against N and against the pixel count at each N of the pixel sweep.
struct CountTable {
  std::string scene;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};
std::vector<CountTable> count_tables(const StudyResult& r);

// The three as study.md sections and as study.html sections; empty when the study has none.
std::string counted_work_markdown(const StudyResult& r);
std::string counted_work_html(const StudyResult& r);

}  // namespace rvr::study
