// Image files through OpenImageIO, written atomically (temporary name in the same folder, then
// rename). No codec is written by hand: OpenImageIO picks the format from the extension. It is
// reached through the image codec module, loaded on the first read or write
// (image_codec_loader.h), so runs without images never load it. PNG and EXR, which every render
// writes, go through the light writer module (libpng, OpenEXR) when it takes the image, so such
// runs do not pay for loading OpenImageIO either.
#include "rvr/image_codec/image_io.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include "image_codec_loader.h"
#include "rvr/core/check.h"
#include "rvr/core/srgb.h"
#include "rvr/image_codec/image_codec_abi.h"
#include "rvr/image_codec/image_writer_abi.h"

namespace fs = std::filesystem;

namespace rvr {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

// Formats that keep float values as they are (scene-referred, linear). Every other format gets
// 8 bits per channel, clamped, and the sRGB transfer when asked for.
bool is_float_format(const std::string& ext) {
  return ext == ".exr" || ext == ".hdr" || ext == ".pfm";
}

// A name for the temporary file beside `path` that keeps its extension, because OpenImageIO
// chooses the format by extension: "dir/.name.tmp-<pid>-<n>.ext". The counter only makes names
// unique between threads of one process; it carries no other state.
fs::path temp_path_for(const fs::path& path) {
  static std::atomic<unsigned long> counter{0};
  std::string name(1, '.');  // appended piecewise: GCC 12 warns falsely on "." + string
  name += path.stem().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  name += '-';
  name += std::to_string(counter.fetch_add(1));
  name += path.extension().string();
  return path.parent_path() / name;
}

Error write_error(const std::string& path, const std::string& reason) {
  return bad_input("cannot write '" + path + "': " + reason);
}

// `reason` with the temporary file's name replaced by the name the caller gave, since the
// temporary is how the file is written, not what was asked for: first the whole temporary path,
// then its bare file name (messages that quote only that).
std::string naming_the_target(std::string reason, const fs::path& temp, const fs::path& target) {
  const std::pair<std::string, std::string> replacements[] = {
      {temp.string(), target.string()}, {temp.filename().string(), target.filename().string()}};
  for (const auto& [from, to] : replacements) {
    if (from.empty()) continue;
    for (size_t at = reason.find(from); at != std::string::npos;
         at = reason.find(from, at + to.size()))
      reason.replace(at, from.size(), to);
  }
  return reason;
}

// Creates the parent folder of `path` when missing.
bool make_parent(const fs::path& path, std::string& reason) {
  fs::path parent = path.parent_path();
  if (parent.empty()) return true;
  std::error_code ec;
  if (fs::is_directory(parent, ec)) return true;
  fs::create_directories(parent, ec);
  if (ec) {
    reason = "cannot create folder '" + parent.string() + "': " + ec.message();
    return false;
  }
  return true;
}

// Runs `write_temp(temp)`, then renames the temporary into place; removes it on any failure.
// The temporary file being written, for remove_unfinished_output() in a signal handler: a
// fixed buffer and a lock-free flag, nothing a handler cannot touch.
char g_unfinished_path[4096];
std::atomic<bool> g_unfinished{false};

struct UnfinishedOutput {
  explicit UnfinishedOutput(const std::string& temp) {
    if (temp.size() >= sizeof(g_unfinished_path)) return;
    std::memcpy(g_unfinished_path, temp.c_str(), temp.size() + 1);
    g_unfinished.store(true);
  }
  ~UnfinishedOutput() { g_unfinished.store(false); }
};

// Errors name `path`, never the temporary.
template <class F>
Status write_atomically(const std::string& path, F&& write_temp) {
  fs::path target(path), temp;
  try {
    if (path.empty()) return write_error(path, "empty file name");
    // A folder (or a name ending in a separator, which can only be one) is never a file to
    // write: said before any folder is created.
    std::error_code is_folder;
    if (!target.has_filename() || fs::is_directory(target, is_folder))
      return write_error(path, "is a directory");
    std::string reason;
    if (!make_parent(target, reason)) return write_error(path, reason);
    temp = temp_path_for(target);
    UnfinishedOutput unfinished(temp.string());
    std::error_code ec;
    if (!write_temp(temp, reason)) {
      fs::remove(temp, ec);
      return write_error(path, naming_the_target(reason, temp, target));
    }
    fs::rename(temp, target, ec);
    if (ec) {
      std::error_code ignored;
      fs::remove(temp, ignored);
      return write_error(path, ec.message());
    }
    return ok_status();
  } catch (const std::exception& e) {
    return write_error(path, naming_the_target(e.what(), temp, target));
  }
}

std::string first_line(std::string s) {
  auto nl = s.find('\n');
  if (nl != std::string::npos) s.resize(nl);
  return s.empty() ? std::string("unknown error") : s;
}

// The light writer (PNG, EXR) when it takes this image, so that the run need not load
// OpenImageIO; null otherwise, or when RVR_IMAGE_WRITER=openimageio asks for the full library
// (to compare the two, and as a way out should the light writer misbehave).
const rvr_image_writer* light_writer_for(const std::string& ext, int channels,
                                         const std::vector<const char*>& names, bool as_float) {
  const char* choice = std::getenv("RVR_IMAGE_WRITER");
  if (choice && std::strcmp(choice, "openimageio") == 0) return nullptr;
  Expected<const rvr_image_writer*> writer = image_writer();
  if (!writer) return nullptr;  // the full codec writes it instead
  const bool takes = (*writer)->handles(ext.c_str(), channels,
                                        names.empty() ? nullptr : names.data(), as_float ? 1 : 0);
  return takes ? *writer : nullptr;
}

bool write_pixels(const fs::path& temp, const Image& image, bool linear_to_srgb,
                  std::string& reason) {
  const std::string ext = lower(fs::path(temp).extension().string());
  const bool as_float = is_float_format(ext);
  std::vector<const char*> names;
  if (image.channel_names.size() == size_t(image.channels))
    for (const std::string& n : image.channel_names) names.push_back(n.c_str());
  // 8-bit files hold display (sRGB-encoded) values either way: encoded here from linear, or
  // already display referred (heat maps).
  std::vector<uint8_t> bytes;
  if (!as_float) {
    bytes.resize(image.pixels.size());
    for (size_t i = 0; i < bytes.size(); ++i) {
      const float v = image.pixels[i];
      bytes[i] = linear_to_srgb
                     ? srgb8(v)
                     : uint8_t(std::lround((v > 0.0f ? std::min(v, 1.0f) : 0.0f) * 255.0f));
    }
  }
  const rvr_image_writer* light = light_writer_for(ext, image.channels, names, as_float);
  auto write = light ? light->write : nullptr;
  if (!write) {
    Expected<const rvr_image_codec*> codec = image_codec();
    if (!codec) {
      reason = codec.error().message;
      return false;
    }
    write = (*codec)->write;
  }
  char err[512] = {};
  const int ok = write(temp.c_str(), image.width, image.height, image.channels,
                       names.empty() ? nullptr : names.data(), as_float ? 1 : 0,
                       as_float ? static_cast<const void*>(image.pixels.data())
                                : static_cast<const void*>(bytes.data()),
                       err, sizeof(err));
  if (!ok) {
    reason = first_line(err);
    if (reason == "no image format for this extension")
      reason = "no image format for extension '" + ext + "'";
  }
  return ok != 0;
}

// OpenImageIO's "inferno" colour map: matplotlib's inferno (public domain) made linear and cut
// to 17 evenly spaced knots, linear RGB, from 0 to 1. The values are the ones OpenImageIO 2.4's
// ImageBufAlgo::color_map returns at x = k / 16, and the interpolation is its
// interpolate_linear (clamp, then v0 (1 - f) + v1 f in float), so the maps agree bit for bit
// (tested against the library). Computed here so that colour-mapped pictures (the cost AOV,
// the heat maps of compare) do not load OpenImageIO's ~260 shared libraries.
constexpr int kInfernoKnots = 17;
constexpr float kInferno[kInfernoKnots][3] = {
    {0.000113f, 0.000036f, 0.001073f}, {0.003275f, 0.002178f, 0.017634f},
    {0.015183f, 0.003697f, 0.068760f}, {0.046307f, 0.002834f, 0.130327f},
    {0.095494f, 0.005137f, 0.154432f}, {0.163601f, 0.009920f, 0.156097f},
    {0.253890f, 0.016282f, 0.143715f}, {0.367418f, 0.024893f, 0.119982f},
    {0.500495f, 0.038279f, 0.089117f}, {0.642469f, 0.061553f, 0.057555f},
    {0.776190f, 0.102517f, 0.031141f}, {0.883568f, 0.169990f, 0.012559f},
    {0.951614f, 0.271639f, 0.002704f}, {0.972636f, 0.413571f, 0.005451f},
    {0.943272f, 0.599923f, 0.035112f}, {0.884900f, 0.822282f, 0.140466f},
    {0.973729f, 0.996282f, 0.373522f}};

// Linear inferno colours of `values` / `scale`, clamped to [0, 1] (NaN to 0).
Image inferno_linear(std::span<const float> values, int width, int height, float scale) {
  RVR_CHECK(width >= 0 && height >= 0 && values.size() == size_t(width) * size_t(height),
            "one value per pixel of the ", width, "x", height, " map: ", values.size());
  Image img;
  img.width = width;
  img.height = height;
  img.channels = 3;
  img.channel_names = {"R", "G", "B"};
  img.pixels.resize(size_t(width) * height * 3);
  const float inv = scale > 0.0f ? 1.0f / scale : 0.0f;
  constexpr int kSegments = kInfernoKnots - 1;
  for (size_t i = 0; i < values.size(); ++i) {
    float v = values[i] * inv;
    v = v > 0.0f ? std::min(v, 1.0f) : 0.0f;  // NaN -> 0
    const float at = v * float(kSegments);
    const float whole = std::floor(at);
    const int k = int(whole);
    const int next = std::min(k + 1, kSegments);
    const float f = at - whole;
    for (int c = 0; c < 3; ++c)
      img.pixels[3 * i + c] = kInferno[k][c] * (1.0f - f) + kInferno[next][c] * f;
  }
  return img;
}

}  // namespace

namespace detail {
// Also used by compare.cpp (which declares it): OpenImageIO's "inferno" colour map of
// values / scale, clamped to [0, 1]. OpenImageIO's map is linear; this returns it sRGB-encoded
// (display referred, the colours matplotlib shows), to be written with linear_to_srgb = false.
Image inferno_display(std::span<const float> values, int width, int height, float scale) {
  Image img = inferno_linear(values, width, height, scale);
  for (float& v : img.pixels) v = srgb_encode(v);
  return img;
}
}  // namespace detail

Status write_image(const std::string& path, const Image& image, bool linear_to_srgb) {
  if (image.width <= 0 || image.height <= 0 || image.channels <= 0 ||
      image.pixels.size() != size_t(image.width) * image.height * image.channels)
    return write_error(path, "invalid image (" + std::to_string(image.width) + "x" +
                                 std::to_string(image.height) + "x" +
                                 std::to_string(image.channels) + ", " +
                                 std::to_string(image.pixels.size()) + " values)");
  return write_atomically(path, [&](const fs::path& temp, std::string& reason) {
    return write_pixels(temp, image, linear_to_srgb, reason);
  });
}

Expected<Image> read_image(const std::string& path) {
  try {
    auto fail = [&](const std::string& reason) {
      return bad_input("cannot read '" + path + "': " + reason);
    };
    std::error_code ec;
    if (!fs::exists(path, ec)) return fail("no such file");
    if (fs::is_directory(path, ec)) return fail("is a folder");
    RVR_TRY_ASSIGN(codec, image_codec());
    char err[512] = {};
    Image img;
    rvr_image_reader* in =
        (*codec)->open(path.c_str(), &img.width, &img.height, &img.channels, err, sizeof(err));
    if (!in) return fail(first_line(err));
    std::unique_ptr<rvr_image_reader, void (*)(rvr_image_reader*)> closer(in, (*codec)->close);
    if (img.width <= 0 || img.height <= 0 || img.channels <= 0) return fail("empty image");
    for (int c = 0; c < img.channels; ++c) {
      char name[256];
      (*codec)->channel_name(in, c, name, sizeof(name));
      img.channel_names.emplace_back(name);
    }
    img.pixels.resize(size_t(img.width) * img.height * img.channels);
    if (!(*codec)->read(in, img.pixels.data(), err, sizeof(err))) return fail(first_line(err));
    return img;
  } catch (const std::exception& e) {
    return bad_input("cannot read '" + path + "': " + e.what());
  }
}

Image colour_image(const FrameBuffers& fb) {
  Image img;
  img.width = fb.width;
  img.height = fb.height;
  img.channels = 3;
  img.channel_names = {"R", "G", "B"};
  img.pixels.resize(fb.pixel_count() * 3);
  for (size_t i = 0; i < fb.pixel_count() && i < fb.colour.size(); ++i) {
    img.pixels[3 * i + 0] = fb.colour[i].r;
    img.pixels[3 * i + 1] = fb.colour[i].g;
    img.pixels[3 * i + 2] = fb.colour[i].b;
  }
  return img;
}

namespace {

Image aov_image(const FrameBuffers& fb, std::vector<std::string> names) {
  Image img;
  img.width = fb.width;
  img.height = fb.height;
  img.channels = int(names.size());
  img.channel_names = std::move(names);
  img.pixels.assign(fb.pixel_count() * img.channels, 0.0f);
  return img;
}

float id_value(uint32_t id) {
  return id == kNoId ? -1.0f : float(id);
}

// The value at the top of OUT.cost.png's colour map: the 99th percentile of the non-zero costs
// (a few very expensive pixels would otherwise turn the rest black), at least 1.
float cost_scale(std::span<const float> cost) {
  std::vector<float> positive;
  positive.reserve(cost.size());
  for (float c : cost)
    if (c > 0.0f && std::isfinite(c)) positive.push_back(c);
  if (positive.empty()) return 1.0f;
  size_t k = std::min(positive.size() - 1, size_t(std::ceil(0.99 * double(positive.size()))) - 1);
  std::nth_element(positive.begin(), positive.begin() + k, positive.end());
  return std::max(positive[k], 1.0f);
}

}  // namespace

Image cost_image(const FrameBuffers& fb, float* scale) {
  float top = cost_scale(fb.cost);
  if (scale) *scale = top;
  return detail::inferno_display(fb.cost, fb.width, fb.height, top);
}

Status write_aovs(const std::string& out_path, const FrameBuffers& fb,
                  const std::vector<std::string>& aovs) {
  try {
    for (const auto& name : aovs)
      if (name != "depth" && name != "id" && name != "normal" && name != "cost" && name != "lod")
        return bad_input("unknown aov '" + name + "' (known: depth, id, normal, cost, lod)");
    const size_t n = fb.pixel_count();
    if (fb.depth.size() != n || fb.object_id.size() != n || fb.primitive_id.size() != n ||
        fb.normal.size() != n || fb.cost.size() != n)
      return internal_error("cannot write AOVs of '" + out_path + "': frame buffers of " +
                            std::to_string(fb.width) + "x" + std::to_string(fb.height) +
                            " are not fully sized");
    const std::string base = fs::path(out_path).replace_extension().string();

    for (const auto& name : aovs) {
      Status st = ok_status();
      if (name == "depth") {
        Image img = aov_image(fb, {"Z"});
        std::copy(fb.depth.begin(), fb.depth.end(), img.pixels.begin());
        st = write_image(base + ".depth.exr", img, false);
      } else if (name == "id") {
        Image img = aov_image(fb, {"id", "prim"});
        for (size_t i = 0; i < n; ++i) {
          img.pixels[2 * i] = id_value(fb.object_id[i]);
          img.pixels[2 * i + 1] = fb.object_id[i] == kNoId ? -1.0f : id_value(fb.primitive_id[i]);
        }
        st = write_image(base + ".id.exr", img, false);
      } else if (name == "normal") {
        Image img = aov_image(fb, {"R", "G", "B"});
        for (size_t i = 0; i < n; ++i)
          for (int c = 0; c < 3; ++c) img.pixels[3 * i + c] = fb.normal[i][c];
        st = write_image(base + ".normal.exr", img, false);
      } else if (name == "cost") {
        Image img = aov_image(fb, {"cost"});
        std::copy(fb.cost.begin(), fb.cost.end(), img.pixels.begin());
        st = write_image(base + ".cost.exr", img, false);
        if (st.ok()) {
          st = write_image(base + ".cost.png", cost_image(fb), false);
        }
      } else if (name == "lod") {
        // NaN where the visible surface is not textured (everywhere in an untextured scene).
        Image img = aov_image(fb, {"lod"});
        if (fb.lod.size() == n)
          std::copy(fb.lod.begin(), fb.lod.end(), img.pixels.begin());
        else
          std::fill(img.pixels.begin(), img.pixels.end(), std::numeric_limits<float>::quiet_NaN());
        st = write_image(base + ".lod.exr", img, false);
      }
      if (!st.ok()) return st;
    }
    return ok_status();
  } catch (const std::exception& e) {
    return internal_error("cannot write AOVs of '" + out_path + "': " + e.what());
  }
}

std::string openimageio_version() {
  Expected<const rvr_image_codec*> codec = image_codec();
  return codec ? std::string((*codec)->library_version()) : "not loaded: " + codec.error().message;
}

void remove_unfinished_output() noexcept {
  if (g_unfinished.load()) ::unlink(g_unfinished_path);
}

Status write_text_file(const std::string& path, const std::string& text) {
  return write_atomically(path, [&](const fs::path& temp, std::string& reason) {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) {
      reason = "cannot create a temporary file in '" + temp.parent_path().string() + "'";
      return false;
    }
    out.write(text.data(), std::streamsize(text.size()));
    out.close();
    if (!out) {
      reason = "write failed";
      return false;
    }
    return true;
  });
}

}  // namespace rvr
