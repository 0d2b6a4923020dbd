// The C interface of rvr's light image writer module (librvr_image_writer.so): the two formats
// every run writes (PNG through libpng, OpenEXR through OpenEXR's own library), without
// OpenImageIO's ~260 shared libraries, whose loading costs about half a second per process.
// Every other format, every read and every image this writer declines go through the full
// codec module (image_codec_abi.h). Plain C types only, as there.
#pragma once

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define RVR_IMAGE_WRITER_ABI_VERSION 1

struct rvr_image_writer {
  int abi_version;  // RVR_IMAGE_WRITER_ABI_VERSION
  // 1 when write() takes an image of this extension (".png", any case), channel count,
  // channel names (null: none) and sample type, the same pixels OpenImageIO would write;
  // 0 when it must go to the full codec.
  int (*handles)(const char* ext, int channels, const char* const* names, int as_float);
  // Same contract as rvr_image_codec::write, for images handles() accepted.
  int (*write)(const char* path, int w, int h, int channels, const char* const* names, int as_float,
               const void* pixels, char* err, size_t err_size);
};

// The module's one exported symbol.
const struct rvr_image_writer* rvr_image_writer_get(void);

#ifdef __cplusplus
}
#endif
