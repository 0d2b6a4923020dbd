// FrameSource over the renderer table (see renderer_frames.h).
#include "rvr/study/renderer_frames.h"

#include <stddef.h>

#include <chrono>
#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "rvr/renderers/prepared_renderer.h"
#include "rvr/renderers/registry.h"
#include "rvr/shared/expected.h"
#include "rvr/shared/renderer.h"
#include "rvr/shared/scene.h"
#include "rvr/shared/scene_loader.h"
#include "rvr/study/grid_of_copies.h"
#include "rvr/study/sweep_plan.h"

namespace rvr::study {
namespace {

// Triangles the z-buffers draw for a mesh-only scene; the family's N for any other.
double axis_value_of(const Scene& scene, const Family& family, size_t n) {
  if (family.axis != "triangles") return double(n);
  double triangles = 0;
  for (const Object& o : scene.objects) triangles += double(o.mesh.triangles.size());
  return triangles;
}

class RendererFrames : public FrameSource {
 public:
  RendererFrames(std::unique_ptr<Scene> scene, double axis)
      : scene_(std::move(scene)), axis_(axis) {}

  Status add(const std::string& name, const RenderOptions& options) {
    Expected<RendererChoice> choice = find_renderer_choice(name);
    if (!choice) return choice.error();
    Expected<std::unique_ptr<PreparedRenderer>> p = prepare_renderer(*choice, *scene_, {}, options);
    if (!p) return p.error();
    prepared_.push_back(std::move(*p));
    // The first frame (thread start, first touch of the frame buffers) is not timed.
    Expected<RenderOutput> first = prepared_.back()->render();
    if (!first) return first.error();
    return ok_status();
  }

  double axis_value() const override { return axis_; }
  double pixels() const override { return double(scene_->image.width) * scene_->image.height; }

  Expected<double> time_frame(size_t index) override {
    auto start = std::chrono::steady_clock::now();
    Expected<RenderOutput> out = prepared_[index]->render();
    auto end = std::chrono::steady_clock::now();
    if (!out) return out.error();
    last_phases_.clear();
    for (const auto& [stat, phase] :
         {std::pair{"time.zbuffer", "zbuffer"}, {"time.trace", "trace"}})
      if (auto it = out->stats.find(stat); it != out->stats.end()) last_phases_[phase] = it->second;
    return std::chrono::duration<double>(end - start).count();
  }

  std::map<std::string, double> last_phases() const override { return last_phases_; }

 private:
  std::unique_ptr<Scene> scene_;  // before prepared_: they hold references to it
  double axis_;
  std::vector<std::unique_ptr<PreparedRenderer>> prepared_;
  std::map<std::string, double> last_phases_;
};

// builtin:<family>:<n>, or n copies of the family's file, at width × width·3/4.
Expected<Scene> family_scene(const Family& family, size_t n, int width) {
  if (family.source.empty()) {
    Expected<Scene> scene = make_builtin_scene(family.name + ":" + std::to_string(n));
    if (!scene) return scene.error();
    scene->image.width = width;
    scene->image.height = width * 3 / 4;
    return scene;
  }
  SceneOverrides size;
  size.width = width;
  size.height = width * 3 / 4;
  Expected<Scene> base = load_scene(family.source, size);
  if (!base) return base.error();
  return grid_of_copies(*base, n);
}

}  // namespace

PrepareFrames renderer_frames(const StudyRequest& request) {
  return [request](const Family& family, size_t n,
                   int width) -> Expected<std::unique_ptr<FrameSource>> {
    Expected<Scene> scene = family_scene(family, n, width);
    if (!scene) return scene.error();
    double axis = axis_value_of(*scene, family, n);
    auto frames =
        std::make_unique<RendererFrames>(std::make_unique<Scene>(std::move(*scene)), axis);
    RenderOptions options;
    options.mode = request.mode;
    for (const std::string& name : request.renderers)
      if (Status s = frames->add(name, options); !s) return s.error();
    return std::unique_ptr<FrameSource>(std::move(frames));
  };
}

}  // namespace rvr::study
