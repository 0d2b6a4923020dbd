// What the commands of rvr share: the options of render and compare, the arguments of each
// command and its entry point. Private to apps/rvr.
#pragma once

#include <CLI/CLI.hpp>
#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rvr/compare/compare.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/limits.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/timer.h"

namespace rvr::cli {

using Clock = std::chrono::steady_clock;

constexpr const char* kVersion = "0.1.0";

// Options shared by render and compare.
struct CommonOptions {
  std::string scene = "builtin:cornell";
  std::optional<int> width, height, spp;
  std::string image;              // --image WxH
  std::string camera_from;        // --camera-from X,Y,Z
  std::optional<float> exposure;  // --exposure EV
  std::string up = "auto";        // --up auto | y | z (model files)
  std::string camera = "file";    // --camera file | auto | file-always (model files)
  std::string lights = "file";    // --lights file | auto (model files)
  std::string gl;                 // empty: osmesa, falling back to egl when OSMesa is missing
  // The options of the render option table (rvr/core/render_option_table.h) by snake_case
  // name: the text typed, unset when not given (RenderOptions' default then holds).
  std::map<std::string, std::optional<std::string>> render_option_text;
  bool quiet = false;
  Limits limits;
  uint64_t max_memory_mb = 0;
};

void add_common_options(CLI::App& cmd, CommonOptions& o);
GlBackend gl_backend(const CommonOptions& o);
RenderMode parse_mode(const std::string& s);
RenderOptions render_options(const CommonOptions& o, const std::string& default_mode);
// The render options the user gave (snake_case names, in the table's order).
std::vector<std::string> given_render_options(const CommonOptions& o);
Scene load(const CommonOptions& o, const RenderOptions& options, double& load_seconds);

// Refuses, before any work, an output file that names a folder (an existing one, or a name
// ending in '/') or that would overwrite one of the inputs.
void refuse_overwriting_inputs(const std::vector<std::string>& inputs,
                               const std::vector<std::string>& outputs);

struct RenderArgs {
  CommonOptions common;
  std::string renderer;
  std::string out = "render.png";
  std::vector<std::string> aovs;
  std::string stats;
};

int run_render(const RenderArgs& a);

struct CompareArgs {
  CommonOptions common;
  std::vector<std::string> renderers{"raster", "raytrace"};
  std::string out_dir = "rvr-out";
  std::optional<double> fail_below_agreement;
  std::vector<std::string> fail_on;  // mismatch classes: edge, depth_precision, ...
};

int run_compare(const CompareArgs& a, const std::string& command_line);

struct DiffArgs {
  std::string a, b, out;
  std::optional<double> fail_above;  // FAILURE also when the RMS error is above this
  DiffThresholds thresholds;         // idiff's --fail, --failpercent, --hardfail, --warn...
};

int run_diff(const DiffArgs& d);

struct ScenesArgs {
  std::string export_name;   // --export NAME
  std::string out;           // -o FILE (default: stdout)
  bool copy_assets = false;  // --copy-assets: texture files copied beside FILE
};

int run_scenes(const ScenesArgs& a);

int run_info(const std::string& gl_name);

struct StudyArgs {
  std::vector<std::string> scenes{"builtin:tessphere", "builtin:soup"};
  std::vector<std::string> renderers;  // -r: added to one renderer per loop order
  int width = 1024;
  std::string mode = "local";
  double budget = 300;
  int repetitions = 5;
  int processes = 3;              // --processes: runs per point, each in a fresh process
  double noise_threshold = 0.03;  // --noise-threshold
  uint64_t seed = 1;
  std::string shard;               // --shard I/N
  std::vector<std::string> merge;  // --merge DIR...: study folders to pool instead of a sweep
  std::string out_dir;
  bool quiet = false;
};

void add_study_command(CLI::App& app, StudyArgs& a, CLI::App*& cmd);
int run_study(const StudyArgs& a, const std::string& command_line);

// `rvr study-worker`: a study's session process (study_processes.h); not for users, hidden.
struct StudyWorkerArgs {
  std::vector<std::string> renderers;
  std::string mode = "local";
};
void add_study_worker_command(CLI::App& app, StudyWorkerArgs& a, CLI::App*& cmd);

}  // namespace rvr::cli
