// Finding the image file a model or scene file names as a texture, the way modelling tools
// do: exporters write paths that only held on the machine they ran on. Private to scene_io/src.
#pragma once

#include <string>

namespace rvr::scene_load {

// The file `named` (as written: backslashes or slashes, relative or absolute, Windows drive
// letters) refers to, looked for from `folder` (the model's or scene's folder), or empty when
// there is none. In order: the path as written (relative to `folder`; a path from the root
// that is not there, as Windows exporters write \..\maps\x.png, from `folder` too); the same
// path with each name matched regardless of case; both again with URI escapes decoded (%20, as
// glTF exporters write); then, for a Windows absolute path or a path whose folders moved, the
// file's name (again exact case first) anywhere under `folder`, shallowest first and at most
// kSearchDepth folders down (textures/, Textures/, ...), and then the same under the parent of
// `folder` (a sibling folder such as ../OBJ/ of a model in FBX/).
std::string find_texture_file(const std::string& named, const std::string& folder);

// The parent folder the search by name goes on in (absolute), or "" when `folder` is the root.
std::string texture_search_parent(const std::string& folder);

// How many folders below `folder` the search by file name goes, and how many folder entries
// it looks at in all (a model in a large folder such as a home directory).
constexpr int kSearchDepth = 3;
constexpr int kSearchEntries = 20000;

}  // namespace rvr::scene_load
