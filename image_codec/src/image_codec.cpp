// OpenImageIO behind rvr_image_codec's C table (see image_codec_abi.h). No codec is written by
// hand: the library picks the format from the extension. Exceptions never cross the C boundary.
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/oiioversion.h>
#include <OpenImageIO/typedesc.h>

#include <cstring>
#include <exception>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "rvr/image_codec/image_codec_abi.h"

namespace {

void set_error(char* err, size_t size, std::string reason) {
  if (!err || size == 0) return;
  const auto nl = reason.find('\n');
  if (nl != std::string::npos) reason.resize(nl);
  if (reason.empty()) reason = "unknown error";
  std::strncpy(err, reason.c_str(), size - 1);
  err[size - 1] = '\0';
}

const char* library_version() {
  return OIIO_VERSION_STRING;
}

int write(const char* path, int w, int h, int channels, const char* const* names, int as_float,
          const void* pixels, char* err, size_t err_size) {
  try {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) {
      std::string reason = OIIO::geterror();
      if (reason.empty()) reason = "no image format for this extension";
      set_error(err, err_size, reason);
      return 0;
    }
    OIIO::ImageSpec spec(w, h, channels, as_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    if (names) {
      spec.channelnames.assign(names, names + channels);
      // A lone "Z" channel is depth to OpenImageIO; do not let it take it for alpha.
      spec.alpha_channel = -1;
      for (int c = 0; c < channels; ++c) {
        if (spec.channelnames[size_t(c)] == "A") spec.alpha_channel = c;
        if (spec.channelnames[size_t(c)] == "Z") spec.z_channel = c;
      }
    }
    // 8-bit files hold display (sRGB-encoded) values; float files linear ones.
    spec.attribute("oiio:ColorSpace", as_float ? "Linear" : "sRGB");
    if (!out->open(path, spec)) {
      set_error(err, err_size, out->geterror());
      return 0;
    }
    bool ok = out->write_image(as_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8, pixels);
    std::string reason = ok ? "" : out->geterror();
    if (!out->close() && ok) {
      ok = false;
      reason = out->geterror();
    }
    if (!ok) set_error(err, err_size, reason);
    return ok ? 1 : 0;
  } catch (const std::exception& e) {
    set_error(err, err_size, e.what());
    return 0;
  }
}

}  // namespace

struct rvr_image_reader {
  std::unique_ptr<OIIO::ImageInput> in;
};

namespace {

rvr_image_reader* open(const char* path, int* w, int* h, int* channels, char* err,
                       size_t err_size) {
  try {
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
      set_error(err, err_size, OIIO::geterror());
      return nullptr;
    }
    const OIIO::ImageSpec& spec = in->spec();
    *w = spec.width;
    *h = spec.height;
    *channels = spec.nchannels;
    return new rvr_image_reader{std::move(in)};
  } catch (const std::exception& e) {
    set_error(err, err_size, e.what());
    return nullptr;
  }
}

size_t channel_name(rvr_image_reader* r, int c, char* out, size_t out_size) {
  const std::vector<std::string>& names = r->in->spec().channelnames;
  const std::string name = c >= 0 && size_t(c) < names.size() ? names[size_t(c)] : "";
  if (out_size > 0) {
    std::strncpy(out, name.c_str(), out_size - 1);
    out[out_size - 1] = '\0';
  }
  return name.size();
}

int read(rvr_image_reader* r, float* pixels, char* err, size_t err_size) {
  try {
    const int channels = r->in->spec().nchannels;
    if (!r->in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels)) {
      set_error(err, err_size, r->in->geterror());
      return 0;
    }
    return 1;
  } catch (const std::exception& e) {
    set_error(err, err_size, e.what());
    return 0;
  }
}

void close(rvr_image_reader* r) {
  if (!r) return;
  try {
    r->in->close();
  } catch (...) {
  }
  delete r;
}

const rvr_image_codec kCodec = {
    RVR_IMAGE_CODEC_ABI_VERSION, library_version, write, open, channel_name, read, close};

}  // namespace

extern "C" __attribute__((visibility("default"))) const rvr_image_codec* rvr_image_codec_get() {
  return &kCodec;
}
