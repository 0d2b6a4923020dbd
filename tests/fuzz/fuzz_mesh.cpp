// libFuzzer harness: arbitrary bytes as a mesh file (first byte: format and `smooth`), loaded
// through a one-object scene by load_scene(), i.e. through the Assimp import path.
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path& dir = rvr::fuzz::scratch_dir(RVR_SOURCE_DIR "/scenes/models");
  rvr::fuzz::load_mesh_bytes(dir, data, size);
  return 0;
}
