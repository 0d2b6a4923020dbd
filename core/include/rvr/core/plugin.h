// Plugins: parts of rvr built as shared objects of their own and opened on first use, so that a
// run that needs none of them starts without their libraries (OpenImageIO for images, Assimp
// for model files, Embree for the embree renderer; docs/design.md, "Start-up"). Each exports one
// function returning a table of function pointers whose first member is its interface version.
#pragma once

#include <string>

#include "rvr/core/expected.h"

namespace rvr {

// Opens `module` (a file name such as "librvr_embree.so") from the folder of the running
// executable, else from the folder of the shared object holding rvr's code (the Python module),
// else wherever the dynamic loader finds it, and returns the address of its function `symbol`.
// `what` names the plugin in errors ("the image library"), which say what was tried. The
// plugin stays loaded for the life of the process.
Expected<void*> open_plugin(const char* module, const char* symbol, const std::string& what);

// The table the plugin's function `symbol` (of type `const Table* ()`, called as such) returns,
// whose first member `abi_version` must be `abi_version` (a plugin of another build is refused).
template <class Table>
Expected<const Table*> open_plugin_table(const char* module, const char* symbol, int abi_version,
                                         const std::string& what) {
  Expected<void*> opened = open_plugin(module, symbol, what);
  if (!opened) return opened.error();
  using Get = const Table* (*)();
  const Table* table = reinterpret_cast<Get>(*opened)();
  if (!table)
    return internal_error(std::string(module) + " is not this build's " + what + " (" + symbol +
                          " gave no table)");
  if (table->abi_version != abi_version)
    return internal_error(std::string(module) + " is not this build's " + what + " (interface " +
                          std::to_string(table->abi_version) + ", expected " +
                          std::to_string(abi_version) + ")");
  return table;
}

// The folder of the shared object or executable holding rvr's code (where its plugins are
// built): the Python module's folder in Python, the executable's otherwise.
std::string rvr_code_folder();

}  // namespace rvr
