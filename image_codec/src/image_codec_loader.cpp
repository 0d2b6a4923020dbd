#include "image_codec_loader.h"

#include <memory>
#include <variant>

#include "rvr/core/plugin.h"

namespace rvr {

Expected<const rvr_image_codec*> image_codec() {
  static const Expected<const rvr_image_codec*> loaded =
      open_plugin_table<rvr_image_codec>("librvr_image_codec.so", "rvr_image_codec_get",
                                         RVR_IMAGE_CODEC_ABI_VERSION, "the image library");
  return loaded;
}

Expected<const rvr_image_writer*> image_writer() {
  static const Expected<const rvr_image_writer*> loaded =
      open_plugin_table<rvr_image_writer>("librvr_image_writer.so", "rvr_image_writer_get",
                                          RVR_IMAGE_WRITER_ABI_VERSION, "the image library");
  return loaded;
}

}  // namespace rvr
