// The image codec module (image_codec/: OpenImageIO behind a C table), loaded on first use.
#pragma once

#include "rvr/image_codec/image_codec_abi.h"
#include "rvr/shared/expected.h"

namespace rvr {

// The module's table, loaded once per process (thread-safe): from the folder of the running
// executable, else wherever the dynamic loader finds librvr_image_codec.so. The error names
// what was tried.
Expected<const rvr_image_codec*> image_codec();

}  // namespace rvr
