// rvr_image_writer's C table (see image_writer_abi.h): PNG through libpng and OpenEXR through
// OpenEXR's own library, the pixels OpenImageIO writes for the same call (image_codec.cpp):
// 8-bit grey or RGB PNG with the sRGB chunk; 32-bit float EXR, ZIP-compressed, one channel per
// name. Anything else (alpha, which OpenImageIO un-premultiplies in PNG; unnamed EXR channels)
// is declined and goes to OpenImageIO. Exceptions and libpng's longjmp never cross the C
// boundary.
#include <ImfCompression.h>
#include <ImfPixelType.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfThreading.h>
#include <png.h>
#include <strings.h>

#include <algorithm>
#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <exception>
#include <set>
#include <string>
#include <thread>
#include <utility>

#include "rvr/image_codec/image_writer_abi.h"

namespace {

void set_error(char* err, size_t size, const char* reason) {
  if (!err || size == 0) return;
  std::strncpy(err, reason && *reason ? reason : "unknown error", size - 1);
  err[size - 1] = '\0';
}

bool has_channel(const char* const* names, int channels, const char* name) {
  if (!names) return false;
  for (int c = 0; c < channels; ++c)
    if (names[c] && std::strcmp(names[c], name) == 0) return true;
  return false;
}

int handles(const char* ext, int channels, const char* const* names, int as_float) {
  if (!ext) return 0;
  if (::strcasecmp(ext, ".png") == 0)
    return !as_float && (channels == 1 || channels == 3) && !has_channel(names, channels, "A");
  if (::strcasecmp(ext, ".exr") == 0) {
    if (!as_float || channels <= 0 || !names) return 0;
    std::set<std::string> seen;
    for (int c = 0; c < channels; ++c)
      if (!names[c] || !*names[c] || !seen.insert(names[c]).second) return 0;
    return 1;
  }
  return 0;
}

// libpng reports errors through a callback that must not return: it records the message and
// jumps back to write_png's setjmp.
struct PngFailure {
  std::jmp_buf jump;
  char message[256] = {};
};

[[noreturn]] void png_failed(png_structp png, png_const_charp message) {
  auto* failure = static_cast<PngFailure*>(png_get_error_ptr(png));
  std::snprintf(failure->message, sizeof(failure->message), "%s", message);
  std::longjmp(failure->jump, 1);
}

void png_warned(png_structp, png_const_charp) {}

// Only plain data lives across setjmp: libpng's longjmp skips destructors.
int write_png(const char* path, int w, int h, int channels, const unsigned char* pixels, char* err,
              size_t err_size) {
  std::FILE* file = std::fopen(path, "wb");
  if (!file) {
    set_error(err, err_size, std::strerror(errno));
    return 0;
  }
  PngFailure failure;
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, &failure, png_failed, png_warned);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, nullptr);
    std::fclose(file);
    set_error(err, err_size, "out of memory");
    return 0;
  }
  if (setjmp(failure.jump)) {
    png_destroy_write_struct(&png, &info);
    std::fclose(file);
    set_error(err, err_size, failure.message);
    return 0;
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, png_uint_32(w), png_uint_32(h), 8,
               channels == 1 ? PNG_COLOR_TYPE_GRAY : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // The bytes are sRGB-encoded (display referred), as OpenImageIO tags them.
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_ABSOLUTE);
  // No row filter and zlib level 2: on rendered images (large flat areas) the files are as small
  // as with OpenImageIO's default (adaptive filters, level 6) for much less compression work.
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
  png_set_compression_level(png, 2);
  png_write_info(png, info);
  const size_t stride = size_t(w) * size_t(channels);
  for (int y = 0; y < h; ++y) png_write_row(png, pixels + size_t(y) * stride);
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  const bool flushed = std::fflush(file) == 0;
  const int saved = errno;
  if (std::fclose(file) != 0 || !flushed) {
    set_error(err, err_size, std::strerror(flushed ? errno : saved));
    return 0;
  }
  return 1;
}

int write_exr(const char* path, int w, int h, int channels, const char* const* names,
              const float* pixels, char* err, size_t err_size) {
  try {
    // OpenEXR compresses blocks of scan lines on its global thread pool, which has no threads
    // unless asked for: one per core, as OpenImageIO gives it.
    static const bool threaded = [] {
      Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency())));
      return true;
    }();
    (void)threaded;
    Imf::Header header(w, h);
    header.compression() = Imf::ZIP_COMPRESSION;  // OpenImageIO's default for EXR
    Imf::FrameBuffer frame;
    const size_t x_stride = sizeof(float) * size_t(channels);
    const size_t y_stride = x_stride * size_t(w);
    for (int c = 0; c < channels; ++c) {
      header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
      // OpenEXR's slices take a non-const base pointer but only read from it when writing.
      char* base = reinterpret_cast<char*>(const_cast<float*>(pixels + c));
      frame.insert(names[c], Imf::Slice(Imf::FLOAT, base, x_stride, y_stride));
    }
    Imf::OutputFile file(path, header);
    file.setFrameBuffer(frame);
    file.writePixels(h);
    return 1;
  } catch (const std::exception& e) {
    set_error(err, err_size, e.what());
    return 0;
  }
}

int write(const char* path, int w, int h, int channels, const char* const* names, int as_float,
          const void* pixels, char* err, size_t err_size) {
  const char* dot = path ? std::strrchr(path, '.') : nullptr;
  if (!dot || !handles(dot, channels, names, as_float) || w <= 0 || h <= 0) {
    set_error(err, err_size, "not an image this writer takes");
    return 0;
  }
  if (::strcasecmp(dot, ".png") == 0)
    return write_png(path, w, h, channels, static_cast<const unsigned char*>(pixels), err,
                     err_size);
  return write_exr(path, w, h, channels, names, static_cast<const float*>(pixels), err, err_size);
}

const rvr_image_writer kWriter = {RVR_IMAGE_WRITER_ABI_VERSION, handles, write};

}  // namespace

extern "C" __attribute__((visibility("default"))) const rvr_image_writer* rvr_image_writer_get() {
  return &kWriter;
}
