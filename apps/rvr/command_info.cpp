// rvr info: version, CPU, SIMD, GL and the renderers.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "cli_exit.h"
#include "commands.h"
#include "cpu_probe.h"
#include "rvr/core/expected.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/isa.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/renderers/environment.h"
#include "rvr/renderers/registry.h"

namespace rvr::cli {

int run_info(const std::string& gl_name) {
  std::printf("rvr %s\n", kVersion);
  std::printf("cpu: %s, %u hardware threads\n", cpu_model().c_str(),
              std::thread::hardware_concurrency());
  std::printf("renderers: ");
  for (const RendererInfo& r : renderers()) std::printf("%s ", r.name.c_str());
  std::printf("\n");
  std::printf("simd: baseline build %s; the CPU has %s\n", built_simd(), cpu_simd().c_str());
  std::printf("kernels: %s; compiled:", describe_isa_choice().c_str());
  for (Isa isa : kAllIsas) std::printf(" %s", to_string(isa));
  std::printf("; this CPU runs:");
  for (Isa isa : kAllIsas)
    if (cpu_supports(isa)) std::printf(" %s", to_string(isa));
  std::printf(" (RVR_ISA=");
  for (Isa isa : kAllIsas) std::printf("%s%s", isa == kAllIsas[0] ? "" : "|", to_string(isa));
  std::printf(" forces one)\n");
  const TracerLibraries tracer = tracer_libraries();
  std::printf("embree: %s\nopenimageio: %s\ntbb: %s\n", tracer.embree.c_str(),
              openimageio_version().c_str(), tracer.tbb.c_str());
  CommonOptions gl_choice;
  gl_choice.gl = gl_name;
  Expected<GlInfo> gl = query_renderer_gl(gl_backend(gl_choice));
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

}  // namespace rvr::cli
