// The image modules (image_codec/), loaded on first use: the full codec (OpenImageIO behind a
// C table) and the light PNG/EXR writer.
#pragma once

#include "rvr/core/expected.h"
#include "rvr/image_codec/image_codec_abi.h"
#include "rvr/image_codec/image_writer_abi.h"

namespace rvr {

// The full codec's table, loaded once per process (thread-safe) by open_plugin (plugin.h): from
// the folder of the running executable or of the Python module, else wherever the dynamic
// loader finds librvr_image_codec.so. The error names what was tried.
Expected<const rvr_image_codec*> image_codec();

// The light writer's table (librvr_image_writer.so), found and loaded the same way.
Expected<const rvr_image_writer*> image_writer();

}  // namespace rvr
