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
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "arguments.h"
#include "bindings.h"
#include "errors.h"
#include "render_kwargs.h"
#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/study/renderer_frames.h"
#include "rvr/study/run_study.h"
#include "rvr/study/study.h"
#include "rvr/study/study_json.h"
#include "stub_docs.h"
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

// The command line's option names in the study library's messages, as rvr.study's keywords.
constexpr std::pair<const char*, const char*> kKeywords[] = {
    {"--renderers", "renderers"}, {"--budget", "budget"},
    {"--width", "width"},         {"--repetitions", "repetitions"},
    {"--processes", "sessions"},  {"--noise-threshold", "noise_threshold"},
};

// A study error as rvr.study reports it: a message that starts with an option's name names
// the keyword instead.
Error with_keywords(Error e) {
  for (const auto& [option, keyword] : kKeywords) {
    const std::string prefix = std::string(option) + ":";
    if (e.message.rfind(prefix, 0) == 0) {
      e.message = keyword + e.message.substr(std::string(option).size());
      break;
    }
  }
  return e;
}

py::object run(const py::object& scenes, const py::object& renderers, int width,
               const std::string& mode, double budget, int repetitions, int sessions,
               double noise_threshold, uint64_t seed, bool check_predictions) {
  study::StudyRequest request;
  request.scenes = names_of("scenes", scenes);
  request.renderers = study_renderers(names_of("renderers", renderers));
  request.width = width;
  request.mode = render_settings(mode, 0, py::kwargs()).options.mode;
  request.budget_seconds = budget;
  request.repetitions = repetitions;
  request.sessions = sessions;
  request.noise_threshold = noise_threshold;
  request.seed = seed;
  request.check_predictions = check_predictions;
  Expected<study::StudyResult> ran = run_interruptibly(request);
  if (!ran) raise(with_keywords(ran.error()));
  study::StudyResult result = std::move(ran).value();
  result.machine = machine_info(RVR_VERSION);
  result.command = "rvr.study()";
  return py::module_::import("json").attr("loads")(study::study_json(result));
}

}  // namespace

void bind_study(py::module_& m) {
  m.def("study", &run, py::arg("scenes") = py::make_tuple("builtin:tessphere", "builtin:soup"),
        py::kw_only(), py::arg("renderers") = py::tuple(), py::arg("width") = 1024,
        py::arg("mode") = "local", py::arg("budget") = 300.0, py::arg("repetitions") = 5,
        py::arg("sessions") = 3, py::arg("noise_threshold") = 0.03, py::arg("seed") = uint64_t(1),
        py::arg("check_predictions") = true, docs::study);
}

}  // namespace rvr::python
