// rvr study: sweeps of the built-in families timed with every loop order, the cost models
// fitted, crossovers and conclusions computed (rvr::study), written as study.json, study.md and
// study.html.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <thread>

#include "cli_exit.h"
#include "commands.h"
#include "cpu_probe.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/renderers/registry.h"
#include "rvr/shared/image_io.h"
#include "rvr/shared/isa.h"
#include "rvr/study/renderer_frames.h"
#include "rvr/study/run_study.h"
#include "rvr/study/study_html.h"
#include "rvr/study/study_json.h"
#include "rvr/study/study_markdown.h"
#include "terminal_progress.h"

namespace rvr::cli {
namespace {

study::MachineInfo machine_info() {
  study::MachineInfo m;
  m.cpu = cpu_model();
  m.threads = std::thread::hardware_concurrency();
  m.kernels = describe_isa_choice();
  m.versions = {{"rvr", kVersion},
                {"embree", embree_version()},
                {"tbb", tbb_version()},
                {"compiler", __VERSION__}};
  return m;
}

study::StudyRequest request_of(const StudyArgs& a) {
  study::StudyRequest r;
  r.scenes = a.scenes;
  r.renderers = default_study_renderers();
  for (const std::string& name : a.renderers)
    if (std::find(r.renderers.begin(), r.renderers.end(), name) == r.renderers.end())
      r.renderers.push_back(name);
  r.width = a.width;
  r.mode = parse_mode(a.mode);
  r.budget_seconds = a.budget;
  r.repetitions = a.repetitions;
  r.seed = a.seed;
  return r;
}

}  // namespace

std::vector<std::string> default_study_renderers() {
  return {"softraster", "raytrace", "hybrid_soft"};
}

void add_study_command(CLI::App& app, StudyArgs& a, CLI::App*& cmd) {
  cmd = app.add_subcommand(
      "study", "time the loop orders over swept scene sizes; fit cost models; find crossovers");
  cmd->add_option("scenes", a.scenes,
                  "families to sweep: builtin:tessphere, builtin:soup, builtin:occluders "
                  "(default: tessphere and soup; the study chooses N)");
  cmd->add_option("-r,--renderers", a.renderers,
                  "renderers added to softraster,raytrace,hybrid_soft: " + renderer_name_list())
      ->delimiter(',');
  cmd->add_option("--width", a.width, "image width, height 3/4 of it (default 1024)");
  cmd->add_option("--mode", a.mode, "visibility | local | full (default local)")
      ->check(CLI::IsMember({"visibility", "local", "full"}));
  cmd->add_option("--budget", a.budget, "seconds the sweep may take (default 300)");
  cmd->add_option("--repetitions", a.repetitions, "frames timed per renderer and point (>= 3)");
  cmd->add_option("--seed", a.seed, "seed of the interleaving order and the bootstrap");
  cmd->add_option("-o,--output", a.out_dir, "output folder: study.json, study.md, study.html")
      ->required();
  cmd->add_flag("-q,--quiet", a.quiet, "no progress line");
}

int run_study(const StudyArgs& a, const std::string& command_line) {
  take(selected_isa());  // a bad RVR_ISA is refused before any work
  study::StudyRequest request = request_of(a);
  TerminalProgress progress(progress_wanted(a.quiet));
  study::StudyHooks hooks;
  hooks.prepare = study::renderer_frames(request);
  hooks.on_progress = [&](const std::string& what) { progress.begin(what, "measure"); };
  study::StudyResult result = take(study::run_study(request, hooks));
  result.machine = machine_info();
  result.command = command_line;
  std::string markdown = study::study_markdown(result);
  check(write_text_file(a.out_dir + "/study.json", study::study_json(result)));
  check(write_text_file(a.out_dir + "/study.md", markdown));
  check(write_text_file(a.out_dir + "/study.html", study::study_html(result)));
  progress.stop();
  std::printf("%s\nwrote %s/{study.json,study.md,study.html}\n", markdown.c_str(),
              a.out_dir.c_str());
  return 0;
}

}  // namespace rvr::cli
