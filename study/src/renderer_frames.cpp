// FrameSource over the renderer table (see renderer_frames.h).
#include "rvr/study/renderer_frames.h"

#include <algorithm>
#include <chrono>
#include <initializer_list>
#include <map>
#include <optional>
#include <utility>
#include <variant>

#include "rvr/compare/effect_errors.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/renderers/prepared_renderer.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/scene_loader.h"
#include "rvr/study/grid_of_copies.h"
#include "rvr/study/measurement.h"

namespace rvr::study {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Triangles the z-buffers draw for a mesh-only scene; the family's N for any other.
double axis_value_of(const Scene& scene, const Family& family, size_t n) {
  if (family.axis != "triangles") return double(n);
  double triangles = 0;
  for (const Object& o : scene.objects) triangles += double(o.mesh.triangles.size());
  return triangles;
}

// The tracer whose frame each renderer's effect errors are measured against.
constexpr const char* kEffectReference = "raytrace";

class RendererFrames : public FrameSource {
 public:
  RendererFrames(std::unique_ptr<Scene> scene, double axis)
      : scene_(std::move(scene)), axis_(axis) {}

  // Renderer `name` prepared and its first frame rendered; in full mode that frame is kept
  // until measure_effect_errors.
  Status add(const std::string& name, const RenderOptions& options) {
    RVR_TRY_ASSIGN(choice, find_renderer_choice(name));
    const auto start = std::chrono::steady_clock::now();
    RVR_TRY_ASSIGN(p, prepare_renderer(*choice, *scene_, {}, options));
    prepare_seconds_.push_back(seconds_since(start));
    prepared_.push_back(std::move(*p));
    // The first frame (thread start, first touch of the frame buffers) is not timed; its
    // counters are every frame's.
    RVR_TRY_ASSIGN(first, prepared_.back()->render());
    std::map<std::string, double> work;
    for (const auto& [stat, value] : first->stats)
      if (is_work_counter(stat)) work[stat] = value;
    counters_.push_back(std::move(work));
    names_.push_back(name);
    if (options.mode == RenderMode::Full) first_frames_.push_back(std::move(first->buffers));
    return ok_status();
  }

  // Each renderer's error in each effect's mask against the reference tracer's first frame
  // (when the study holds it); the first frames are released.
  void measure_effect_errors(RenderMode mode) {
    effect_errors_.assign(names_.size(), {});
    auto ref = std::find(names_.begin(), names_.end(), kEffectReference);
    if (mode == RenderMode::Full && ref != names_.end()) {
      const FrameBuffers& reference = first_frames_.at(size_t(ref - names_.begin()));
      for (size_t i = 0; i < names_.size(); ++i) {
        if (names_[i] == kEffectReference) continue;
        for (const EffectError& e :
             rvr::effect_errors(*scene_, mode, reference, reference, first_frames_[i]))
          effect_errors_[i].push_back({e.effect, double(e.pixels), e.rmse, e.psnr_db, e.ssim});
      }
    }
    first_frames_.clear();
  }

  double axis_value() const override { return axis_; }
  double pixels() const override { return double(scene_->image.width) * scene_->image.height; }
  double prepare_seconds(size_t index) const override { return prepare_seconds_.at(index); }
  std::map<std::string, double> counters(size_t index) const override {
    return counters_.at(index);
  }

  std::vector<PointEffectError> effect_errors(size_t index) const override {
    return effect_errors_.at(index);
  }

  Expected<FrameTime> time_frame(size_t index) override {
    const auto start = std::chrono::steady_clock::now();
    Expected<RenderOutput> out = prepared_.at(index)->render();
    FrameTime t;
    t.seconds = seconds_since(start);
    if (!out) return out.error();
    for (const auto& [stat, phase] :
         {std::pair{"time.zbuffer", "zbuffer"}, {"time.trace", "trace"}})
      if (auto it = out->stats.find(stat); it != out->stats.end()) t.phases[phase] = it->second;
    return t;
  }

 private:
  std::unique_ptr<Scene> scene_;  // before prepared_: they hold references to it
  double axis_;
  std::vector<std::unique_ptr<PreparedRenderer>> prepared_;
  std::vector<double> prepare_seconds_;
  std::vector<std::map<std::string, double>> counters_;
  std::vector<std::string> names_;
  std::vector<FrameBuffers> first_frames_;  // full mode, until measure_effect_errors
  std::vector<std::vector<PointEffectError>> effect_errors_;
};

class InProcessSession : public Session {
 public:
  InProcessSession(std::vector<std::string> renderers, RenderMode mode)
      : renderers_(std::move(renderers)), mode_(mode) {}
  std::string kind() const override { return "preparation"; }
  Expected<std::unique_ptr<FrameSource>> prepare(const Family& family, size_t n,
                                                 int width) override {
    return prepare_frames(renderers_, mode_, family, n, width);
  }

 private:
  std::vector<std::string> renderers_;
  RenderMode mode_;
};

}  // namespace

Expected<Scene> family_scene(const Family& family, size_t n, int width) {
  if (family.source.empty()) {
    RVR_TRY_ASSIGN(scene, make_builtin_scene(family.name + ":" + std::to_string(n)));
    scene->image.width = width;
    scene->image.height = width * 3 / 4;
    return scene;
  }
  SceneOverrides size;
  size.width = width;
  size.height = width * 3 / 4;
  RVR_TRY_ASSIGN(base, load_scene(family.source, size));
  return grid_of_copies(*base, n);
}

bool is_work_counter(const std::string& stat) {
  // Times and memory, at the top or under a prefix ("zbuffer.time.raster"), are not work; nor
  // are ratios of counts (fills, overdraw), which the counts themselves give.
  for (const char* part : {"time.", "memory.", "fill", "overdraw"})
    if (stat.rfind(part, 0) == 0 || stat.find(std::string(".") + part) != std::string::npos)
      return false;
  return true;
}

Expected<std::unique_ptr<FrameSource>> prepare_frames(const std::vector<std::string>& renderers,
                                                      RenderMode mode, const Family& family,
                                                      size_t n, int width) {
  RVR_TRY_ASSIGN(scene, family_scene(family, n, width));
  double axis = axis_value_of(*scene, family, n);
  auto frames = std::make_unique<RendererFrames>(std::make_unique<Scene>(std::move(*scene)), axis);
  RenderOptions options;
  options.mode = mode;
  for (const std::string& name : renderers) RVR_TRY(frames->add(name, options));
  frames->measure_effect_errors(mode);
  return std::unique_ptr<FrameSource>(std::move(frames));
}

StartSession in_process_sessions(const StudyRequest& request) {
  return
      [renderers = request.renderers, mode = request.mode]() -> Expected<std::unique_ptr<Session>> {
        return std::unique_ptr<Session>(std::make_unique<InProcessSession>(renderers, mode));
      };
}

}  // namespace rvr::study
