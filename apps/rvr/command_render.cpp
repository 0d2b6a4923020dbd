// rvr render: one renderer, one image, its AOVs and --stats.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cli_exit.h"
#include "commands.h"
#include "render_stats.h"
#include "rvr/core/render_option_table.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/timer.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/renderers/registry.h"
#include "terminal_progress.h"

namespace rvr::cli {

int run_render(const RenderArgs& a) {
  const bool stats_to_stdout = a.stats == "-";  // as tools read "-": standard output
  std::vector<std::string> outputs{a.out};
  if (!stats_to_stdout && !a.stats.empty()) outputs.push_back(a.stats);
  const std::string base = std::filesystem::path(a.out).replace_extension().string();
  for (const std::string& aov : a.aovs) {
    std::string name = base;
    name.append(".").append(aov).append(aov == "cost" ? ".png" : ".exr");
    outputs.push_back(std::move(name));
  }
  if (std::count(a.aovs.begin(), a.aovs.end(), "cost")) outputs.push_back(base + ".cost.exr");
  refuse_overwriting_inputs({a.common.scene}, outputs);
  TerminalProgress progress(progress_wanted(a.common.quiet));
  progress.begin("", "load");
  RenderOptions options = render_options(a.common, "full");
  double load_seconds = 0;
  Scene scene = load(a.common, options, load_seconds);
  std::unique_ptr<Renderer> renderer = take(make_renderer(a.renderer, gl_backend(a.common)));
  options.progress = progress.sink();
  progress.begin(a.renderer, "render");
  auto start = Clock::now();
  RenderOutput out = take(renderer->render(scene, options));
  for (std::string& w : unread_option_warnings(given_render_options(a.common), a.renderer, true))
    out.warnings.push_back(std::move(w));
  double render_seconds = seconds_since(start);

  progress.begin(a.renderer, "write");
  auto write_start = Clock::now();
  check(write_image(a.out, colour_image(out.buffers)));
  if (!a.aovs.empty()) check(write_aovs(a.out, out.buffers, a.aovs));
  double write_seconds = seconds_since(write_start);
  progress.stop();  // before the warnings and the summary

  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  for (const std::string& w : out.warnings)
    std::fprintf(stderr, "warning: %s: %s\n", a.renderer.c_str(), w.c_str());
  if (!a.stats.empty()) {
    const std::string stats = render_stats_json(a.renderer, scene, options.mode,
                                                {load_seconds, render_seconds, write_seconds}, out);
    if (stats_to_stdout)
      std::fputs(stats.c_str(), stdout);
    else
      check(write_text_file(a.stats, stats));
  }
  if (!a.common.quiet) {
    std::fprintf(stderr, "%s: %s %dx%d %s in %.3f s -> %s\n", a.renderer.c_str(),
                 scene.source.c_str(), scene.image.width, scene.image.height,
                 to_string(options.mode), render_seconds, a.out.c_str());
  }
  return 0;
}

}  // namespace rvr::cli
