// Reading a `mesh` object's file through Assimp, hardened against hostile files: PLY headers
// checked first, reads on a budget, the raw import checked before post-processing. Private to
// shared/src.
#pragma once

#include <cstddef>
#include <string>

#include "rvr/shared/scene.h"

namespace rvr::scene_load {

// `file` relative to `base_dir`; `path` is the JSON path for errors. Faces that are not
// triangles are counted in `skipped_primitives`.
TriangleMesh import_mesh(const std::string& file, const std::string& base_dir,
                         const std::string& path, bool smooth, size_t* skipped_primitives);

}  // namespace rvr::scene_load
