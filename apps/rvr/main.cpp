// rvr: render one scene two ways and tell the truth about the difference. This program only
// parses, calls the libraries and writes; errors come back as values and are printed here.
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

namespace {

using namespace rvr;
using Clock = std::chrono::steady_clock;

constexpr const char* kVersion = "0.1.0";

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Thrown inside this program only, to leave with an exit status from any depth.
struct Exit {
  int status;
};

[[noreturn]] void fail(const Error& e) {
  stop_active_progress();  // the error line starts a clean line, not the progress bar's
  std::fprintf(stderr, "error: %s\n", e.message.c_str());
  throw Exit{int(e.kind)};
}

template <class T>
T take(Expected<T> result) {
  if (!result) fail(result.error());
  return std::move(result).value();
}

void check(const Status& status) {
  if (!status) fail(status.error());
}

// Options shared by render and compare.
struct CommonOptions {
  std::string scene = "builtin:cornell";
  std::string mode;
  std::optional<int> width, height, spp;
  int threads = 0;
  std::string accel = "bvh";
  std::string spheres = "analytic";
  int sphere_segments = 64;
  std::string triangle_test = "mt";
  int max_depth = 5;
  uint64_t seed = 0;
  std::string gl;  // empty: osmesa, falling back to egl when OSMesa is missing
  int shadow_map_size = 1024;
  float shadow_bias = 0.01f;
  bool shadow_pcf = false;
  std::string hiz = "on";
  bool quiet = false;
  Limits limits;
  uint64_t max_memory_mb = 0;
};

void add_common_options(CLI::App& cmd, CommonOptions& o) {
  cmd.add_option("scene", o.scene, "scene file or builtin:NAME (default builtin:cornell)");
  cmd.add_option("--mode", o.mode, "visibility | local | full")
      ->check(CLI::IsMember({"visibility", "local", "full"}));
  cmd.add_option("--width", o.width, "image width (overrides the scene)")
      ->check(CLI::Range(1, 16384));
  cmd.add_option("--height", o.height, "image height (overrides the scene)")
      ->check(CLI::Range(1, 16384));
  cmd.add_option("--spp", o.spp, "samples per pixel (overrides the scene)")
      ->check(CLI::Range(1, 65536));
  cmd.add_option("--threads", o.threads, "worker threads, 0 = every core")
      ->check(CLI::Range(0, 1024));
  cmd.add_option("--accel", o.accel,
                 "tracer acceleration: bvh (wide SIMD BVH, default) | bvh2 (binary, one box at a "
                 "time) | none (every object for every ray)")
      ->check(CLI::IsMember({"bvh", "bvh2", "none"}));
  cmd.add_option("--spheres", o.spheres,
                 "tracer spheres: analytic | mesh (the raster's tessellation)")
      ->check(CLI::IsMember({"analytic", "mesh"}));
  cmd.add_option("--sphere-segments", o.sphere_segments, "sphere tessellation: longitudes")
      ->check(CLI::Range(3, 4096));
  cmd.add_option("--triangle-test", o.triangle_test,
                 "tracer ray-triangle test: mt (Moller-Trumbore) | chapter (plane, then edges)")
      ->check(CLI::IsMember({"mt", "chapter"}));
  cmd.add_option("--max-depth", o.max_depth, "recursion limit for bounce rays")
      ->check(CLI::Range(0, 64));
  cmd.add_option("--seed", o.seed, "seed of the per-pixel random streams");
  cmd.add_option("--gl", o.gl,
                 "raster GL back end: osmesa | egl (default osmesa, egl when OSMesa is missing)")
      ->check(CLI::IsMember({"osmesa", "egl"}));
  cmd.add_option("--shadow-map-size", o.shadow_map_size, "raster shadow maps: texels per side")
      ->check(CLI::Range(16, 8192));
  cmd.add_option("--shadow-bias", o.shadow_bias, "raster shadow maps: depth bias (scene units)")
      ->check(CLI::Range(0.0f, 10.0f));
  cmd.add_flag("--shadow-pcf", o.shadow_pcf, "raster shadow maps: 3x3 percentage-closer filtering");
  cmd.add_option("--hiz", o.hiz,
                 "softraster: hierarchical z, each 8x8 block's farthest depth rejecting what lies "
                 "behind it: on | off (the textbook z-buffer)")
      ->check(CLI::IsMember({"on", "off"}));
  cmd.add_flag("--quiet,-q", o.quiet, "no progress output");
  cmd.add_option("--max-samples", o.limits.max_samples,
                 "refuse more than N pixels x samples (default 2^30)")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--max-triangles", o.limits.max_triangles,
                 "refuse more than N triangles, tessellation included (default 50000000)")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--max-memory-mb", o.max_memory_mb,
                 "refuse renders estimated to need more MiB (default 3/4 of physical memory)")
      ->check(CLI::PositiveNumber);
}

GlBackend gl_backend(const CommonOptions& o) {
  if (o.gl == "osmesa") return GlBackend::OsMesa;
  if (o.gl == "egl") return GlBackend::Egl;
  return GlBackend::Default;
}

RenderMode parse_mode(const std::string& s) {
  if (s == "visibility") return RenderMode::Visibility;
  if (s == "full") return RenderMode::Full;
  return RenderMode::Local;
}

RenderOptions render_options(const CommonOptions& o, const std::string& default_mode) {
  RenderOptions r;
  r.mode = parse_mode(o.mode.empty() ? default_mode : o.mode);
  r.spheres = o.spheres == "mesh" ? SphereMode::Mesh : SphereMode::Analytic;
  r.sphere_segments = o.sphere_segments;
  r.threads = o.threads;
  r.max_depth = o.max_depth;
  r.seed = o.seed;
  r.accel = o.accel == "none"   ? AccelKind::None
            : o.accel == "bvh2" ? AccelKind::Bvh2
                                : AccelKind::Bvh;
  r.triangle_test =
      o.triangle_test == "chapter" ? TriangleTest::Chapter : TriangleTest::MollerTrumbore;
  r.shadow_map_size = o.shadow_map_size;
  r.shadow_bias = o.shadow_bias;
  r.shadow_pcf = o.shadow_pcf;
  r.hiz = o.hiz == "on";
  return r;
}

Scene load(const CommonOptions& o, const RenderOptions& options, double& load_seconds) {
  take(selected_isa());  // a bad RVR_ISA is refused before any work
  auto start = Clock::now();
  Scene scene = take(load_scene(o.scene));
  if (o.width) scene.image.width = *o.width;
  if (o.height) scene.image.height = *o.height;
  if (o.spp) scene.image.samples_per_pixel = *o.spp;
  load_seconds = seconds_since(start);
  Limits limits = o.limits;
  limits.max_memory_bytes = std::min<uint64_t>(o.max_memory_mb, uint64_t(1) << 40) << 20;
  check(check_limits(scene, options, limits));
  return scene;
}

double peak_memory_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) * 1024.0;
}

nlohmann::json finite_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

// ---------------------------------------------------------------------------------- render

struct RenderArgs {
  CommonOptions common;
  std::string renderer;
  std::string out = "render.png";
  std::vector<std::string> aovs;
  std::string stats;
};

// Refuses, before any work, an output that would overwrite one of the inputs.
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

int run_render(const RenderArgs& a) {
  std::vector<std::string> outputs{a.out, a.stats};
  const std::string base = std::filesystem::path(a.out).replace_extension().string();
  for (const std::string& aov : a.aovs)
    outputs.push_back(base + "." + aov + (aov == "cost" ? ".png" : ".exr"));
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
  double render_seconds = seconds_since(start);

  progress.begin(a.renderer, "write");
  auto write_start = Clock::now();
  check(write_image(a.out, color_image(out.buffers)));
  if (!a.aovs.empty()) check(write_aovs(a.out, out.buffers, a.aovs));
  double write_seconds = seconds_since(write_start);
  progress.stop();  // before the warnings and the summary

  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  for (const std::string& w : out.warnings)
    std::fprintf(stderr, "warning: %s: %s\n", a.renderer.c_str(), w.c_str());
  if (!a.stats.empty()) {
    nlohmann::json j;
    j["renderer"] = a.renderer;
    j["scene"] = scene.source;
    j["width"] = scene.image.width;
    j["height"] = scene.image.height;
    j["mode"] = to_string(options.mode);
    j["time"] = {{"load", load_seconds}, {"render", render_seconds}, {"write", write_seconds}};
    nlohmann::json counters = nlohmann::json::object();
    for (const auto& [k, v] : out.stats) counters[k] = finite_or_null(v);
    j["stats"] = counters;
    j["info"] = out.info;
    j["warnings"] = out.warnings;
    j["peak_memory_bytes"] = peak_memory_bytes();
    // The scene's own vertex and index data, to read peak memory against.
    double scene_bytes = 0;
    for (const Object& o : scene.objects)
      scene_bytes += double(o.mesh.positions.size() * sizeof(glm::vec3) +
                            o.mesh.normals.size() * sizeof(glm::vec3) +
                            o.mesh.triangles.size() * sizeof(glm::uvec3));
    j["scene_mesh_bytes"] = scene_bytes;
    check(write_text_file(a.stats, j.dump(2) + "\n"));
  }
  if (!a.common.quiet) {
    std::fprintf(stderr, "%s: %s %dx%d %s in %.3f s -> %s\n", a.renderer.c_str(),
                 scene.source.c_str(), scene.image.width, scene.image.height,
                 to_string(options.mode), render_seconds, a.out.c_str());
  }
  return 0;
}

// --------------------------------------------------------------------------------- compare

struct CompareArgs {
  CommonOptions common;
  std::vector<std::string> renderers{"raster", "raytrace"};
  std::string out_dir = "rvr-out";
  std::optional<double> fail_below_agreement;
};

int run_compare(const CompareArgs& a, const std::string& command_line) {
  if (a.renderers.size() < 2)
    fail(bad_input("--renderers: need at least two renderers to compare"));
  refuse_overwriting_inputs({a.common.scene},
                            {a.out_dir + "/metrics.json", a.out_dir + "/report.html"});
  TerminalProgress progress(progress_wanted(a.common.quiet));
  progress.begin("", "load");
  RenderOptions options = render_options(a.common, "local");
  double load_seconds = 0;
  Scene scene = load(a.common, options, load_seconds);
  options.progress = progress.sink();

  CompareOptions compare;
  compare.config.gl = gl_backend(a.common);
  compare.on_phase = [&](const std::string& label, const std::string& phase) {
    progress.begin(label, phase);
  };
  // Everything is computed before the first file is written.
  CompareResult result = take(compare_renderers(scene, a.renderers, options, compare));

  ReportInput report;
  report.scene = scene.source;
  report.width = scene.image.width;
  report.height = scene.image.height;
  report.mode = to_string(options.mode);
  report.command_line = command_line;
  report.out_dir = a.out_dir;
  report.metrics = result.metrics;
  report.heat_map_scale = compare.heat_map_scale;
  report.depth_diff_scale = compare.depth_diff_scale;
  for (const ComparedRenderer& c : result.renderers) {
    ReportRenderer r;
    r.name = c.name;
    r.image_file = r.name + ".png";
    r.seconds = c.seconds;
    r.warnings = c.output.warnings;
    r.stats = c.output.stats;
    r.info = c.output.info;
    r.stats["time.load"] = load_seconds;
    if (c.has_cost) {
      r.cost_file = r.name + ".cost.png";
      r.cost_scale = c.cost_scale;
      r.cost_mean = c.cost_mean;
    }
    report.renderers.push_back(r);
  }

  for (size_t i = 0; i < result.renderers.size(); ++i) {
    check(write_image(a.out_dir + "/" + report.renderers[i].image_file, result.renderers[i].image));
    if (!report.renderers[i].cost_file.empty())
      check(write_image(a.out_dir + "/" + report.renderers[i].cost_file,
                        result.renderers[i].cost_image, false));
  }
  check(write_image(a.out_dir + "/diff.png", result.diff, false));
  check(write_image(a.out_dir + "/id_mismatch.png", result.id_mismatch, false));
  check(write_image(a.out_dir + "/depth_diff.png", result.depth_diff, false));
  check(write_text_file(a.out_dir + "/metrics.json", metrics_json(report)));
  check(write_text_file(a.out_dir + "/report.html", take(report_html(report))));

  progress.stop();  // before the warnings and the table
  const ComparisonMetrics& m = report.metrics;
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  for (const ReportRenderer& r : report.renderers)
    for (const std::string& w : r.warnings)
      std::fprintf(stderr, "warning: %s: %s\n", r.name.c_str(), w.c_str());
  std::printf("%s  %dx%d  mode %s\n", scene.source.c_str(), scene.image.width, scene.image.height,
              report.mode.c_str());
  for (const ReportRenderer& r : report.renderers)
    std::printf("  %-12s %9.3f s\n", r.name.c_str(), r.seconds);
  std::printf("  %s vs %s:\n", a.renderers[0].c_str(), a.renderers[1].c_str());
  std::printf("  id agreement      %.5f  (%zu of %zu pixels differ, %zu off edges)\n",
              m.visibility.id_agreement, m.visibility.mismatched_pixels, m.visibility.pixels,
              m.visibility.mismatched_off_edge);
  std::printf("  depth rel error   max %.3g  mean %.3g\n", m.depth.max_rel_error,
              m.depth.mean_rel_error);
  std::printf("  colour            rmse %.4g  psnr %.2f dB  max %.4g  ssim %.4f\n", m.color.rmse,
              m.color.psnr_db, m.color.max_abs, m.color.ssim);
  std::printf(
      "  wrote %s/{%s.png,%s.png,diff.png,depth_diff.png,id_mismatch.png,metrics.json,"
      "report.html}\n",
      a.out_dir.c_str(), a.renderers[0].c_str(), a.renderers[1].c_str());
  if (a.fail_below_agreement && m.visibility.id_agreement < *a.fail_below_agreement) {
    std::fprintf(stderr, "id agreement %.5f is below %.5f\n", m.visibility.id_agreement,
                 *a.fail_below_agreement);
    return 1;
  }
  return 0;
}

// ------------------------------------------------------------------------------------ diff

struct DiffArgs {
  std::string a, b, out;
  std::optional<double> fail_above;
};

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

// ----------------------------------------------------------------------------- scenes/info

struct ScenesArgs {
  std::string export_name;  // --export NAME
  std::string out;          // -o FILE (default: stdout)
};

// --export: the built-in scene as an rvr-scene/1 document. Meshes other than single
// triangles have no inline form in the format: they go to PLY files next to -o FILE.
int export_scene(const ScenesArgs& a) {
  std::string name = a.export_name;
  if (name.rfind("builtin:", 0) == 0) name = name.substr(8);
  Scene scene = take(make_builtin_scene(name));
  std::filesystem::path out(a.out);
  std::string prefix = a.out.empty() ? name : out.stem().string();
  SceneDocument doc = take(write_scene(scene, prefix));
  if (a.out.empty()) {
    if (!doc.mesh_files.empty()) {
      fail(bad_input(fmt::format(
          "builtin:{}: has {} mesh{} of more than one triangle, which rvr-scene/1 reads only "
          "from mesh files: give -o FILE.json to write {} as PLY next to it",
          name, doc.mesh_files.size(), doc.mesh_files.size() == 1 ? "" : "es",
          doc.mesh_files.size() == 1 ? "it" : "them")));
    }
    std::fwrite(doc.json.data(), 1, doc.json.size(), stdout);
    return std::fflush(stdout) == 0 ? 0 : 3;
  }
  for (const SceneMeshFile& m : doc.mesh_files) {
    check(write_text_file((out.parent_path() / m.name).string(), m.bytes));
  }
  check(write_text_file(a.out, doc.json));
  return 0;
}

int run_scenes(const ScenesArgs& a) {
  if (!a.export_name.empty()) return export_scene(a);
  if (!a.out.empty()) fail(bad_input("scenes: -o needs --export NAME"));
  for (const BuiltinSceneInfo& s : builtin_scenes())
    std::printf("builtin:%-14s %s\n", s.name.c_str(), s.description.c_str());
  return 0;
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(colon + 2);
    }
  }
  return "unknown";
}

// The vector instructions the baseline code is built for; the SIMD kernels are compiled for
// several and picked at run time (shared/isa.h), as Embree picks its own.
const char* built_simd() {
#if defined(__AVX512F__)
  return "AVX-512 (512-bit)";
#elif defined(__AVX2__)
  return "AVX2 (256-bit)";
#elif defined(__AVX__)
  return "AVX (256-bit)";
#else
  return "SSE2 (128-bit)";
#endif
}

// Vector extensions the CPU reports in /proc/cpuinfo.
std::string cpu_simd() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("flags", 0) != 0) continue;
    std::string found;
    for (const char* f : {"sse4_2", "avx", "avx2", "avx512f"}) {
      if ((" " + line + " ").find(std::string(" ") + f + " ") != std::string::npos)
        found += (found.empty() ? "" : ", ") + std::string(f);
    }
    return found.empty() ? "none of SSE4.2, AVX, AVX2, AVX-512" : found;
  }
  return "unknown (no /proc/cpuinfo)";
}

int run_info(const std::string& gl_name) {
  std::printf("rvr %s\n", kVersion);
  std::printf("cpu: %s, %u hardware threads\n", cpu_model().c_str(),
              std::thread::hardware_concurrency());
  std::printf("renderers: ");
  for (const RendererInfo& r : renderers()) std::printf("%s ", r.name.c_str());
  std::printf("\n");
  std::printf("simd: baseline build %s; the CPU has %s\n", built_simd(), cpu_simd().c_str());
  std::printf("kernels: %s; compiled: sse avx2 avx512; this CPU runs:",
              describe_isa_choice().c_str());
  for (Isa isa : {Isa::Sse, Isa::Avx2, Isa::Avx512})
    if (cpu_supports(isa)) std::printf(" %s", to_string(isa));
  std::printf(" (RVR_ISA=sse|avx2|avx512 forces one)\n");
  std::printf("embree: %s\nopenimageio: %s\ntbb: %s\n", embree_version().c_str(),
              openimageio_version().c_str(), tbb_version().c_str());
  CommonOptions gl_choice;
  gl_choice.gl = gl_name;
  Expected<GlInfo> gl = query_gl_info(gl_backend(gl_choice));
  if (!gl) fail(gl.error());
  for (const std::string& w : gl->warnings) std::printf("gl warning: %s\n", w.c_str());
  std::printf("gl backend: %s\nGL_VERSION: %s\nGL_RENDERER: %s\nGL_VENDOR: %s\nGLSL: %s\n",
              gl->backend.c_str(), gl->version.c_str(), gl->renderer.c_str(), gl->vendor.c_str(),
              gl->glsl_version.c_str());
  const char* lp_threads = std::getenv("LP_NUM_THREADS");
  std::printf("llvmpipe threads: %s\n",
              lp_threads ? lp_threads : "every core (LP_NUM_THREADS not set)");
  return 0;
}

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

int run(int argc, char** argv) {
  CLI::App app{"rvr: one scene, two loop orders (z-buffer rasterization vs ray tracing)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", kVersion);

  RenderArgs render;
  CLI::App* render_cmd = app.add_subcommand("render", "render a scene with one renderer");
  add_common_options(*render_cmd, render.common);
  render_cmd->add_option("-r,--renderer", render.renderer, renderer_help())->required();
  render_cmd->add_option("-o,--output", render.out, "output image (.png, .exr)");
  render_cmd->add_option("--aov", render.aovs, "extra outputs: depth,id,normal,cost")
      ->delimiter(',')
      ->check(CLI::IsMember({"depth", "id", "normal", "cost"}));
  render_cmd->add_option("--stats", render.stats, "write counters and phase times as JSON");

  CompareArgs compare;
  CLI::App* compare_cmd = app.add_subcommand("compare", "render with two renderers and compare");
  add_common_options(*compare_cmd, compare.common);
  compare_cmd
      ->add_option(
          "-r,--renderers", compare.renderers,
          "renderers, first two compared (default raster,raytrace): " + renderer_name_list())
      ->delimiter(',');
  compare_cmd->add_option("-o,--output", compare.out_dir, "output folder (default rvr-out)");
  compare_cmd
      ->add_option("--fail-below-agreement", compare.fail_below_agreement,
                   "exit 1 when the id agreement is below F")
      ->check(CLI::Range(0.0, 1.0));

  DiffArgs diff;
  CLI::App* diff_cmd = app.add_subcommand("diff", "compare two image files, like idiff");
  diff_cmd->add_option("image_a", diff.a, "first image")->required();
  diff_cmd->add_option("image_b", diff.b, "second image")->required();
  diff_cmd->add_option("-o,--output", diff.out, "heat map of the difference (.png)");
  diff_cmd->add_option("--fail-above", diff.fail_above, "exit 1 when the RMSE is above this");

  ScenesArgs scenes;
  CLI::App* scenes_cmd =
      app.add_subcommand("scenes", "list the built-in scenes, or write one as rvr-scene/1 JSON");
  scenes_cmd->add_option("--export", scenes.export_name,
                         "write built-in scene NAME (e.g. cornell, tessphere:2000) as JSON");
  scenes_cmd->add_option("-o,--output", scenes.out,
                         "with --export: write FILE (and its meshes as FILE-stem.meshI.ply "
                         "beside it) instead of stdout");
  CLI::App* info_cmd = app.add_subcommand("info", "versions and machine facts for bug reports");
  std::string info_gl;
  info_cmd->add_option("--gl", info_gl, "GL back end to describe: osmesa | egl (default as render)")
      ->check(CLI::IsMember({"osmesa", "egl"}));

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  if (render_cmd->parsed()) return run_render(render);
  if (compare_cmd->parsed()) return run_compare(compare, join_args(argc, argv));
  if (diff_cmd->parsed()) return run_diff(diff);
  if (scenes_cmd->parsed()) return run_scenes(scenes);
  if (info_cmd->parsed()) return run_info(info_gl);
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
