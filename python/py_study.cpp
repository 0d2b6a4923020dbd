// rvr.study: `rvr study`'s sweep, fits and conclusions, returned as the study.json document.
// The study runs on a thread of its own; Ctrl-C sets the study's own cancel hook (polled between
// frames), the thread is joined and KeyboardInterrupt raised.
#include <Python.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // IWYU pragma: keep (type casters for std containers)
#include <stdint.h>

#include <array>
#include <atomic>
#include <chrono>
#include <exception>
#include <functional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "bindings.h"
#include "errors.h"
#include "render_kwargs.h"
#include "rvr/shared/expected.h"
#include "rvr/shared/renderer.h"
#include "rvr/study/renderer_frames.h"
#include "rvr/study/run_study.h"
#include "rvr/study/study.h"
#include "rvr/study/study_json.h"
#include "study_setup.h"

namespace py = pybind11;

namespace rvr::python {
namespace {

constexpr std::chrono::milliseconds kSignalPoll{20};

// Runs the study on a worker thread while this one (the GIL released) watches for signals.
// Throws error_already_set when one raised, after the study has stopped.
Expected<study::StudyResult> run_interruptibly(const study::StudyRequest& request) {
  std::atomic<bool> cancelled{false}, done{false};
  study::StudyHooks hooks;
  hooks.start_session = study::in_process_sessions(request);
  hooks.cancelled = [&] { return cancelled.load(); };
  Expected<study::StudyResult> result = internal_error("study not run");
  std::thread worker([&] {
    try {
      result = study::run_study(request, hooks);
    } catch (const std::exception& e) {
      result = internal_error(std::string("internal: ") + e.what());
    }
    done.store(true);
  });
  bool interrupted = false;
  while (!done.load()) {
    {
      py::gil_scoped_release release;
      std::this_thread::sleep_for(kSignalPoll);
    }
    if (!interrupted && PyErr_CheckSignals() != 0) {
      interrupted = true;
      cancelled.store(true);
    }
  }
  worker.join();
  if (interrupted) throw py::error_already_set();
  return result;
}

py::object run(const std::vector<std::string>& scenes, const std::vector<std::string>& renderers,
               int width, const std::string& mode, double budget, int repetitions, int sessions,
               double noise_threshold, uint64_t seed, bool check_predictions) {
  study::StudyRequest request;
  request.scenes = scenes;
  request.renderers = study_renderers(renderers);
  request.width = width;
  request.mode = render_settings(mode, 0, py::kwargs()).options.mode;
  request.budget_seconds = budget;
  request.repetitions = repetitions;
  request.sessions = sessions;
  request.noise_threshold = noise_threshold;
  request.seed = seed;
  request.check_predictions = check_predictions;
  study::StudyResult result = take(run_interruptibly(request));
  result.machine = machine_info(RVR_VERSION);
  result.command = "rvr.study()";
  return py::module_::import("json").attr("loads")(study::study_json(result));
}

}  // namespace

void bind_study(py::module_& m) {
  m.def("study", &run,
        py::arg("scenes") = std::vector<std::string>{"builtin:tessphere", "builtin:soup"},
        py::kw_only(), py::arg("renderers") = std::vector<std::string>{}, py::arg("width") = 1024,
        py::arg("mode") = "local", py::arg("budget") = 300.0, py::arg("repetitions") = 5,
        py::arg("sessions") = 3, py::arg("noise_threshold") = 0.03, py::arg("seed") = uint64_t(1),
        py::arg("check_predictions") = true,
        "Runs `rvr study` (docs/cli.md): the scene families swept within BUDGET seconds, one "
        "renderer per loop order plus RENDERERS, cost models fitted, crossovers found. Returns "
        "the study.json document as a dict; its 'points' is a list of records for "
        "pandas.DataFrame. Each point is measured in SESSIONS fresh preparations of its scene "
        "in this process (the command line starts a process for each). Ctrl-C stops the sweep "
        "and raises KeyboardInterrupt.");
}

}  // namespace rvr::python
