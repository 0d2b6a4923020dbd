// libFuzzer harness: arbitrary bytes as a scene file, through load_scene() like the CLI.
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path& dir = rvr::fuzz::scratch_dir(RVR_SOURCE_DIR "/scenes/models");
  rvr::fuzz::load_scene_text(dir, data, size);
  return 0;
}
