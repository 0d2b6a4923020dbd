// Leaving with an error's exit status (see cli_exit.h).
#include "cli_exit.h"

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

[[noreturn]] void fail(const Error& e) {
  stop_active_progress();  // the error line starts a clean line, not the progress bar's
  std::fprintf(stderr, "error: %s\n", e.message.c_str());
  throw Exit{int(e.kind)};
}

void check(const Status& status) {
  if (!status) fail(status.error());
}

}  // namespace rvr::cli
