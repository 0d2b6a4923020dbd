// The C interface of rvr's image codec module (librvr_image_codec.so): OpenImageIO behind a
// table of plain functions, so that the rvr binaries do not link OpenImageIO and its ~260
// shared libraries. Runs that read or write no image (rvr --version, rvr scenes, every
// bad-input error) start without them; image_codec/src/image_codec_loader.cpp loads the module on
// the first image read or write. Plain C types only: the module and its host need not agree
// on any C++ type.
#pragma once

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define RVR_IMAGE_CODEC_ABI_VERSION 2

struct rvr_image_reader;  // an open input file

struct rvr_image_codec {
  int abi_version;                       // RVR_IMAGE_CODEC_ABI_VERSION
  const char* (*library_version)(void);  // OpenImageIO's version string
  // Writes w x h x channels pixels, rows top-down: floats when as_float (linear), else bytes
  // (display-referred). names: `channels` channel names or null. The format comes from the
  // path's extension. Returns 1, or 0 with a one-line reason in err.
  int (*write)(const char* path, int w, int h, int channels, const char* const* names, int as_float,
               const void* pixels, char* err, size_t err_size);
  // Opens a file of any format the library reads; its size and channel count. Null on failure,
  // with the reason in err.
  struct rvr_image_reader* (*open)(const char* path, int* w, int* h, int* channels, char* err,
                                   size_t err_size);
  // Channel c's name into out (always terminated); returns its full length.
  size_t (*channel_name)(struct rvr_image_reader* r, int c, char* out, size_t out_size);
  // All pixels as floats, w * h * channels values, rows top-down. Returns 1, or 0 with err.
  int (*read)(struct rvr_image_reader* r, float* pixels, char* err, size_t err_size);
  void (*close)(struct rvr_image_reader* r);
};

// The module's one exported symbol.
const struct rvr_image_codec* rvr_image_codec_get(void);

#ifdef __cplusplus
}
#endif
