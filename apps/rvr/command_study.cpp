// rvr study: sweeps of the built-in families timed with every loop order, the cost models
// fitted, crossovers and conclusions computed (rvr::study), written as study.json, study.md and
// study.html; or, with --merge, studies written before pooled by machine type and concluded
// again.
#include <fmt/format.h>
#include <signal.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "cli_exit.h"
#include "commands.h"
#include "one_of.h"
#include "rvr/core/expected.h"
#include "rvr/core/isa.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/renderers/registry.h"
#include "rvr/study/memory_estimate.h"
#include "rvr/study/merge.h"
#include "rvr/study/run_study.h"
#include "rvr/study/study.h"
#include "rvr/study/study_html.h"
#include "rvr/study/study_json.h"
#include "rvr/study/study_markdown.h"
#include "rvr/study/sweep_plan.h"
#include "study_processes.h"
#include "study_setup.h"
#include "terminal_progress.h"

namespace {

// Set by the first Ctrl-C during a study's sweep.
std::atomic<bool> g_study_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");
struct sigaction g_previous_sigint {};

// The first Ctrl-C stops the sweep (the study is then concluded and written) and puts back the
// handler that was there before, so that a second stops the program as for every command.
extern "C" void on_study_interrupt(int) {
  g_study_interrupted.store(true);
  sigaction(SIGINT, &g_previous_sigint, nullptr);
}

}  // namespace

namespace rvr::cli {
namespace {

// Catches Ctrl-C for as long as it lives (the sweep); the handler before it is restored after.
class StudyInterrupt {
 public:
  StudyInterrupt() {
    g_study_interrupted.store(false);
    struct sigaction action {};
    action.sa_handler = on_study_interrupt;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, &g_previous_sigint);
  }
  ~StudyInterrupt() {
    if (!g_study_interrupted.load()) sigaction(SIGINT, &g_previous_sigint, nullptr);
  }
  StudyInterrupt(const StudyInterrupt&) = delete;
  StudyInterrupt& operator=(const StudyInterrupt&) = delete;

  bool interrupted() const { return g_study_interrupted.load(); }
};

study::StudyRequest request_of(const StudyArgs& a) {
  study::StudyRequest r;
  r.scenes = a.scenes;
  r.renderers = study_renderers(a.renderers);
  r.width = a.width;
  r.mode = parse_mode(a.mode);
  r.budget_seconds = a.budget;
  r.repetitions = a.repetitions;
  r.sessions = a.processes;
  r.noise_threshold = a.noise_threshold;
  r.seed = a.seed;
  if (!a.shard.empty()) r.shard = take(study::parse_shard(a.shard));
  return r;
}

// A study that concludes nothing says why (study.md does too) and exits 1; a shard is not meant
// to conclude on its own (its merge is), so it exits 0.
int no_conclusion_status(const study::StudyResult& result) {
  if (result.no_conclusion.empty() || result.shard) return 0;
  std::fprintf(stderr, "rvr study: no conclusion: %s\n", result.no_conclusion.c_str());
  return 1;
}

void write_study(const std::string& dir, const study::StudyResult& result,
                 const std::string& markdown) {
  check(write_text_file(dir + "/study.json", study::study_json(result)));
  check(write_text_file(dir + "/study.md", markdown));
  check(write_text_file(dir + "/study.html", study::study_html(result)));
}

// --merge: the studies in a.merge pooled by machine type; one study into a.out_dir, or one per
// machine type into its folder there and comparison.md beside them.
int run_merge(const StudyArgs& a, const std::string& command_line) {
  namespace fs = std::filesystem;
  std::vector<study::StudySource> sources;
  for (const std::string& dir : a.merge) {
    std::error_code ec;
    if (fs::equivalent(dir, a.out_dir, ec))
      fail(bad_input(fmt::format("-o: {} is one of the studies merged; write elsewhere", dir)));
    sources.push_back({dir, take(study::load_study_json(dir + "/study.json"))});
  }
  std::vector<study::MachineGroup> groups = take(study::merge_studies(sources));
  for (study::MachineGroup& g : groups) g.study.command = command_line;
  if (groups.size() == 1) {
    std::string markdown = study::study_markdown(groups[0].study);
    write_study(a.out_dir, groups[0].study, markdown);
    std::printf("%s\nwrote %s/{study.json,study.md,study.html}\n", markdown.c_str(),
                a.out_dir.c_str());
    std::fflush(stdout);
    return no_conclusion_status(groups[0].study);
  }
  for (const study::MachineGroup& g : groups)
    write_study(a.out_dir + "/" + g.slug, g.study, study::study_markdown(g.study));
  std::string comparison = study::comparison_markdown(groups);
  check(write_text_file(a.out_dir + "/comparison.md", comparison));
  std::printf("%s\nwrote %s/comparison.md and {study.json,study.md,study.html} in",
              comparison.c_str(), a.out_dir.c_str());
  for (const study::MachineGroup& g : groups) std::printf(" %s/", g.slug.c_str());
  std::printf("\n");
  return 0;
}

}  // namespace

void add_study_command(CLI::App& app, StudyArgs& a, CLI::App*& cmd) {
  cmd = app.add_subcommand(
      "study", "time the loop orders over swept scene sizes; fit cost models; find crossovers");
  cmd->add_option("scenes", a.scenes,
                  "families to sweep: builtin:tessphere, builtin:soup, builtin:effects, "
                  "builtin:occluders, or a "
                  "scene or model file grown by copies in a grid (default: tessphere and soup; "
                  "the study chooses N)");
  cmd->add_option("-r,--renderers", a.renderers,
                  "renderers added to softraster,raytrace,hybrid_soft: " + renderer_name_list())
      ->delimiter(',');
  cmd->add_option("--width", a.width, "image width, height 3/4 of it (default 1024)");
  cmd->add_option("--mode", a.mode, "visibility | local | full (default local)")
      ->check(one_of({"visibility", "local", "full"}));
  cmd->add_option("--budget", a.budget, "seconds the sweep may take (default 300)");
  cmd->add_option("--repetitions", a.repetitions,
                  "rounds timed per run: frames per renderer in each process (>= 3, default 5)");
  cmd->add_option("--processes", a.processes,
                  "runs per point, each in a fresh process (>= 3, default 3)");
  cmd->add_option("--noise-threshold", a.noise_threshold,
                  "the smallest difference called one renderer faster: a ratio of 1 + this "
                  "(default 0.03)");
  cmd->add_option("--seed", a.seed, "seed of the interleaving order and the bootstrap");
  cmd->add_flag("-q,--quiet", a.quiet, "no progress line");
  CLI::Option* shard =
      cmd->add_option("--shard", a.shard,
                      "I/N: measure only the planned points whose index is I mod N (0 <= I < N), "
                      "for --merge afterwards");
  CLI::Option* merge = cmd->add_option(
      "--merge", a.merge,
      "study folders to pool instead of sweeping: same machine type and mode pooled, others "
      "compared (comparison.md)");
  for (const char* sweep_only : {"scenes", "--renderers", "--width", "--mode", "--budget",
                                 "--repetitions", "--processes", "--noise-threshold", "--seed"})
    merge->excludes(cmd->get_option(sweep_only));
  merge->excludes(shard);
  cmd->add_option("-o,--output", a.out_dir, "output folder: study.json, study.md, study.html")
      ->required();
}

int run_study(const StudyArgs& a, const std::string& command_line) {
  if (!a.merge.empty()) return run_merge(a, command_line);
  take(selected_isa());  // a bad RVR_ISA is refused before any work
  study::StudyRequest request = request_of(a);
  TerminalProgress progress(progress_wanted(a.quiet));
  study::StudyHooks hooks;
  hooks.start_session = process_sessions(own_executable(), request.renderers, request.mode);
  hooks.probe_memory = process_memory_probes(own_executable(), request.renderers, request.mode);
  hooks.on_progress = [&](const std::string& what) { progress.begin(what, "measure"); };
  study::StudyResult result;
  {
    StudyInterrupt interrupt;
    hooks.cancelled = [&] { return interrupt.interrupted(); };
    result = take(study::run_study(request, hooks));
  }
  result.machine = machine_info(kVersion);
  result.command = command_line;
  std::string markdown = study::study_markdown(result);
  write_study(a.out_dir, result, markdown);
  progress.stop();
  std::printf("%s\nwrote %s/{study.json,study.md,study.html}\n", markdown.c_str(),
              a.out_dir.c_str());
  std::fflush(stdout);
  if (result.interrupted) {
    std::fprintf(
        stderr,
        "rvr study: interrupted; wrote %s/{study.json,study.md,study.html} from %zu points\n",
        a.out_dir.c_str(), result.points.size());
    return 130;
  }
  return no_conclusion_status(result);
}

void add_study_worker_command(CLI::App& app, StudyWorkerArgs& a, CLI::App*& cmd) {
  cmd = app.add_subcommand("study-worker", "a session process of rvr study (internal)");
  cmd->group("");  // not listed: rvr study starts it
  cmd->add_option("-r,--renderers", a.renderers)->delimiter(',')->required();
  cmd->add_option("--mode", a.mode)->check(CLI::IsMember({"visibility", "local", "full"}));
}

}  // namespace rvr::cli
