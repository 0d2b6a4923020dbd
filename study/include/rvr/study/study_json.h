// study.json, format rvr-study/2 (docs/rvr-study-2.schema.json; fields in docs/cli.md).
#pragma once

#include <string>

#include "rvr/core/expected.h"
#include "rvr/study/study.h"

namespace rvr::study {

constexpr const char* kStudyFormat = "rvr-study/2";

// The whole study as JSON text; non-finite numbers are null.
std::string study_json(const StudyResult& result);

// A study.json read back: the request's fields, the machine, the sweep's notes, the shard and
// every point with its repetitions; models, crossovers, the other conclusions and the notes
// conclude() adds are left out, for conclude() to compute again, and so are the prediction
// checks (they tested the crossovers as concluded before). Unknown keys and bad values are
// BadInput errors "PATH: json.path: what is wrong" (`path` names the text in messages).
Expected<StudyResult> read_study_json(const std::string& text, const std::string& path);

// read_study_json of the file at `path`.
Expected<StudyResult> load_study_json(const std::string& path);

}  // namespace rvr::study
