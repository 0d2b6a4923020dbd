// Refusing an output that would overwrite an input (see commands.h).
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

void refuse_overwriting_inputs(const std::vector<std::string>& inputs,
                               const std::vector<std::string>& outputs) {
  for (const std::string& out : outputs) {
    for (const std::string& in : inputs) {
      std::error_code ec;
      if (in.rfind("builtin:", 0) == 0 || !std::filesystem::exists(out, ec)) continue;
      if (std::filesystem::equivalent(out, in, ec))
        fail(bad_input(out + ": is also an input; writing it would destroy it"));
    }
  }
}

}  // namespace rvr::cli
