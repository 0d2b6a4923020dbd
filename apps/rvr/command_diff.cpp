// rvr diff: two image files compared.
#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "cli_exit.h"
#include "commands.h"
#include "report.h"
#include "rvr/raster/gl_rasterizer.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/renderers/compare_renderers.h"
#include "rvr/renderers/registry.h"
#include "rvr/shared/compare.h"
#include "rvr/shared/image_io.h"
#include "rvr/shared/isa.h"
#include "rvr/shared/limits.h"
#include "rvr/shared/scene_loader.h"
#include "rvr/shared/scene_writer.h"
#include "terminal_progress.h"

namespace rvr::cli {

int run_diff(const DiffArgs& d) {
  if (!d.out.empty()) refuse_overwriting_inputs({d.a, d.b}, {d.out});
  Image a = take(read_image(d.a));
  Image b = take(read_image(d.b));
  ImageDiff diff = take(diff_images(a, b));
  if (!d.out.empty()) check(write_image(d.out, diff_heat_map(a, b, 0.1f), false));
  std::printf("Comparing \"%s\" and \"%s\"\n", d.a.c_str(), d.b.c_str());
  std::printf("  Mean error = %.6g\n  RMS error = %.6g\n  Peak SNR = %.6g\n", diff.mean_abs,
              diff.rmse, diff.psnr_db);
  std::printf("  Max error  = %.6g @ (%d, %d, channel %d)\n", diff.max_abs, diff.max_x, diff.max_y,
              diff.max_channel);
  if (d.fail_above && diff.rmse > *d.fail_above) {
    std::printf("FAILURE: RMSE %.6g above %.6g\n", diff.rmse, *d.fail_above);
    return 1;
  }
  std::printf("PASS\n");
  return 0;
}

}  // namespace rvr::cli
