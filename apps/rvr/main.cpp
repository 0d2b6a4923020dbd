// rvr: render one scene two ways and tell the truth about the difference. This program only
// parses, calls the libraries and writes; errors come back as values and are printed here.
#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <exception>
#include <initializer_list>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_exit.h"
#include "commands.h"
#include "one_of.h"
#include "rvr/compare/compare.h"
#include "rvr/core/expected.h"
#include "rvr/core/gl_backend.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/renderers/registry.h"
#include "study_processes.h"
#include "suggest.h"
#include "terminal_progress.h"

namespace {

using namespace rvr;
using namespace rvr::cli;

// -r's help: each renderer of the table on a line, with its loop order and what it is.
std::string renderer_help() {
  std::string help = "one of:";
  for (const RendererInfo& r : renderers()) {
    help += fmt::format("\n  {:<12}[{}] {}", r.name, short_name(r.order), r.description);
  }
  return help;
}

std::string join_args(int argc, char** argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) {
    std::string arg = argv[i];
    bool quote = arg.find_first_of(" \t\"'$") != std::string::npos || arg.empty();
    s += (i ? " " : "") + (quote ? "'" + arg + "'" : arg);
  }
  return s;
}

// The names of `cmd`'s options as they are typed ("--long", "-s").
std::vector<std::string> option_names(const CLI::App& cmd) {
  std::vector<std::string> names;
  for (const CLI::Option* o : cmd.get_options()) {
    for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
    for (const std::string& n : o->get_snames()) names.push_back("-" + n);
  }
  return names;
}

// The names of `cmd`'s listed subcommands, in the order they were added (not the hidden ones,
// group "": study-worker is rvr study's, not the user's).
std::vector<std::string> subcommand_names(const CLI::App& cmd) {
  std::vector<std::string> names;
  for (const CLI::App* sub : cmd.get_subcommands([](const CLI::App*) { return true; }))
    if (!sub->get_group().empty()) names.push_back(sub->get_name());
  return names;
}

// The first word that `cmd` or a subcommand chosen under it did not take, as an error line
// naming the nearest known option or subcommand; "" when every word was taken. CLI11 parses
// on past an unknown word (and may then fail on a consequence of it, e.g. a required option
// the typo was meant to be), so this is the error to show first.
std::string unknown_word_message(const CLI::App& cmd, const std::string& where) {
  const std::vector<std::string> left = cmd.remaining();
  if (!left.empty()) {
    std::string word = left.front();
    const bool is_option = word.size() > 1 && word[0] == '-';
    if (is_option) word = word.substr(0, word.find('='));  // "--name=value": the name
    const std::vector<std::string> known = is_option ? option_names(cmd) : subcommand_names(cmd);
    if (!is_option && known.empty()) return fmt::format("{}unexpected argument '{}'", where, word);
    std::string message =
        fmt::format("{}unknown {} '{}'", where, is_option ? "option" : "command", word);
    if (std::string near = nearest(word, known); !near.empty())
      return message + fmt::format(": did you mean '{}'?", near);
    if (is_option)
      return message +
             fmt::format(" (see 'rvr {}--help')", where.empty() ? "" : cmd.get_name() + " ");
    return message + fmt::format(" (commands: {})", fmt::join(known, ", "));
  }
  for (const CLI::App* sub : cmd.get_subcommands()) {
    std::string message = unknown_word_message(*sub, sub->get_name() + ": ");
    if (!message.empty()) return message;
  }
  return "";
}

int run(int argc, char** argv) {
  CLI::App app{"rvr: one scene, two loop orders (z-buffer rasterization vs ray tracing)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", kVersion);

  RenderArgs render;
  CLI::App* render_cmd = app.add_subcommand("render", "render a scene with one renderer");
  add_common_options(*render_cmd, render.common);
  std::vector<std::string> renderer_names;
  for (const RendererInfo& r : renderers()) renderer_names.push_back(r.name);
  render_cmd->add_option("-r,--renderer", render.renderer, renderer_help())
      ->required()
      ->check(one_of(renderer_names));
  render_cmd->add_option("-o,--output", render.out, "output image (.png, .exr)");
  render_cmd->add_option("--aov", render.aovs, "extra outputs: depth,id,normal,cost,lod")
      ->delimiter(',')
      ->check(one_of({"depth", "id", "normal", "cost", "lod"}));
  render_cmd->add_option("--stats", render.stats, "write counters and phase times as JSON");

  CompareArgs compare;
  CLI::App* compare_cmd = app.add_subcommand("compare", "render with two renderers and compare");
  add_common_options(*compare_cmd, compare.common);
  compare_cmd
      ->add_option(
          "-r,--renderers", compare.renderers,
          "renderers, every pair compared (default raster,raytrace): " + renderer_name_list())
      ->delimiter(',')
      ->check(one_of(renderer_names));
  compare_cmd->add_option("-o,--output", compare.out_dir, "output folder (default rvr-out)");
  compare_cmd
      ->add_option("--fail-below-agreement", compare.fail_below_agreement,
                   "exit 1 when a pair's id agreement is below F, or nothing is visible")
      ->check(CLI::Range(0.0, 1.0));
  compare_cmd
      ->add_option("--fail-on", compare.fail_on,
                   "exit 1 when a pair has a mismatch of one of these classes: "
                   "edge,depth_precision,occlusion,coverage")
      ->delimiter(',')
      ->check(one_of({"edge", "depth_precision", "occlusion", "coverage"}));

  DiffArgs diff;
  CLI::App* diff_cmd = app.add_subcommand("diff", "compare two image files, like idiff");
  diff_cmd->add_option("image_a", diff.a, "first image")->required();
  diff_cmd->add_option("image_b", diff.b, "second image")->required();
  diff_cmd->add_option("-o,--output", diff.out, "heat map of the difference (.png)");
  diff_cmd->add_option("--fail", diff.thresholds.fail,
                       "a pixel fails when a channel differs by more than this (default 1e-6)");
  diff_cmd->add_option("--failpercent", diff.thresholds.fail_percent,
                       "FAILURE only when more than this % of the pixels fail (default 0)");
  diff_cmd->add_option("--hardfail", diff.thresholds.hard_fail,
                       "FAILURE when any channel differs by more than this (default inf)");
  diff_cmd->add_option("--warn", diff.thresholds.warn,
                       "a pixel warns when a channel differs by more than this (default 1e-6)");
  diff_cmd->add_option("--warnpercent", diff.thresholds.warn_percent,
                       "WARNING only when more than this % of the pixels warn (default 0)");
  diff_cmd->add_option("--hardwarn", diff.thresholds.hard_warn,
                       "WARNING when any channel differs by more than this (default inf)");
  diff_cmd->add_option("--fail-above", diff.fail_above, "FAILURE also when the RMSE is above this");

  ScenesArgs scenes;
  CLI::App* scenes_cmd =
      app.add_subcommand("scenes", "list the built-in scenes, or write one as rvr-scene/1 JSON");
  scenes_cmd->add_option("--export", scenes.export_name,
                         "write built-in scene NAME (e.g. cornell, tessphere:2000), or the scene "
                         "built from a model FILE, as JSON");
  scenes_cmd->add_option("-o,--output", scenes.out,
                         "with --export: write FILE (and its meshes as FILE-stem.meshI.ply "
                         "beside it) instead of stdout");
  scenes_cmd->add_flag("--copy-assets", scenes.copy_assets,
                       "with -o: copy the texture files from outside FILE's folder beside it "
                       "(FILE-stem.textureI.EXT), so that the folder can move");
  CLI::App* info_cmd = app.add_subcommand("info", "versions and machine facts for bug reports");
  std::string info_gl;
  info_cmd->add_option("--gl", info_gl, "GL back end to describe: osmesa | egl (default as render)")
      ->check(one_of(gl_backend_names()));

  StudyArgs study;
  CLI::App* study_cmd = nullptr;
  add_study_command(app, study, study_cmd);
  StudyWorkerArgs study_worker;
  CLI::App* study_worker_cmd = nullptr;
  add_study_worker_command(app, study_worker, study_worker_cmd);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    const std::string unknown = unknown_word_message(app, "");
    std::fprintf(stderr, "error: %s\n", unknown.empty() ? e.what() : unknown.c_str());
    return 2;
  }
  if (render_cmd->parsed()) return run_render(render);
  if (compare_cmd->parsed()) return run_compare(compare, join_args(argc, argv));
  if (diff_cmd->parsed()) return run_diff(diff);
  if (scenes_cmd->parsed()) return run_scenes(scenes);
  if (info_cmd->parsed()) return run_info(info_gl);
  if (study_cmd->parsed()) return run_study(study, join_args(argc, argv));
  if (study_worker_cmd->parsed())
    return run_study_worker(study_worker.renderers, parse_mode(study_worker.mode));
  return 2;
}

}  // namespace

// Ctrl-C (or a kill): stop at once, delete the file being written, if any (finished files are
// complete, having been renamed into place), and exit 130 as shells expect.
extern "C" void on_interrupt(int signal_number) {
  rvr::remove_unfinished_output();
  // One write, so that the progress line is erased and the message begins at column 0.
  const char message[] = "\r\x1b[Kerror: interrupted\n";
  const size_t skip = rvr::progress_line_on_screen() ? 0 : 4;  // no erase without a line
  ssize_t ignored = ::write(2, message + skip, sizeof(message) - 1 - skip);
  (void)ignored;
  ::_exit(128 + signal_number);
}

int main(int argc, char** argv) {
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaction(s, &action, nullptr);
  try {
    return run(argc, argv);
  } catch (const Exit& e) {
    return e.status;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "error: out of memory\n");
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: internal: %s\n", e.what());
    return 3;
  }
}
