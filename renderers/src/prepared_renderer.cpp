#include "rvr/renderers/prepared_renderer.h"

#include <memory>
#include <type_traits>
#include <utility>

#include "rvr/core/scene.h"
#include "rvr/renderers/registry.h"

namespace rvr {

namespace {

// For renderers with nothing to build beforehand: every frame is a whole render.
class RenderAfresh : public PreparedRenderer {
 public:
  RenderAfresh(std::unique_ptr<Renderer> renderer, const Scene& scene, const RenderOptions& options)
      : renderer_(std::move(renderer)), scene_(scene), options_(options) {}
  Expected<RenderOutput> render() override { return renderer_->render(scene_, options_); }

 private:
  std::unique_ptr<Renderer> renderer_;
  const Scene& scene_;
  const RenderOptions options_;
};

}  // namespace

Expected<std::unique_ptr<PreparedRenderer>> prepare_renderer(const RendererChoice& choice,
                                                             const Scene& scene,
                                                             RendererConfig config,
                                                             RenderOptions options) {
  choice.apply(config, options);
  if (choice.info->prepare) return choice.info->prepare(scene, config, options);
  RVR_TRY_ASSIGN(renderer, choice.info->create(config));
  return std::unique_ptr<PreparedRenderer>(
      std::make_unique<RenderAfresh>(std::move(renderer).value(), scene, options));
}

}  // namespace rvr
