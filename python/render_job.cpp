#include "render_job.h"

#include <pybind11/pybind11.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "rvr/shared/timer.h"

namespace py = pybind11;

namespace rvr::python {
namespace {

// How often the waiting thread looks at Python's signals.
constexpr std::chrono::milliseconds kSignalPoll{20};

struct RenderJob {
  std::shared_ptr<const Scene> scene;
  std::unique_ptr<Renderer> renderer;
  RenderOptions options;
  RenderResultWithTime result;
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  std::thread thread;  // joined by whoever holds the job last: the caller, or the exit hook

  void run() {
    const auto start = std::chrono::steady_clock::now();
    Expected<RenderOutput> out = [&]() -> Expected<RenderOutput> {
      try {
        return renderer->render(*scene, options);
      } catch (const std::bad_alloc&) {
        return internal_error("out of memory");
      } catch (const std::exception& e) {
        return internal_error(std::string("internal: ") + e.what());
      }
    }();
    std::lock_guard lock(mutex);
    result.output = std::move(out);
    result.seconds = seconds_since(start);
    done = true;
    finished.notify_all();
  }

  // True when done within `wait`.
  bool wait_for(std::chrono::milliseconds wait) {
    std::unique_lock lock(mutex);
    return finished.wait_for(lock, wait, [&] { return done; });
  }
};

std::mutex g_abandoned_mutex;
std::vector<std::shared_ptr<RenderJob>> g_abandoned;

void abandon(std::shared_ptr<RenderJob> job) {
  std::lock_guard lock(g_abandoned_mutex);
  g_abandoned.push_back(std::move(job));
}

}  // namespace

RenderResultWithTime render_interruptibly(std::shared_ptr<const Scene> scene,
                                          std::unique_ptr<Renderer> renderer,
                                          const RenderOptions& options) {
  auto job = std::make_shared<RenderJob>();
  job->scene = std::move(scene);
  job->renderer = std::move(renderer);
  job->options = options;
  job->thread = std::thread([raw = job.get()] { raw->run(); });
  for (;;) {
    bool done = false;
    {
      py::gil_scoped_release release;
      done = job->wait_for(kSignalPoll);
    }
    if (done) break;
    if (PyErr_CheckSignals() != 0) {
      abandon(job);
      throw py::error_already_set();
    }
  }
  job->thread.join();
  return std::move(job->result);
}

void wait_for_abandoned_renders() {
  std::vector<std::shared_ptr<RenderJob>> jobs;
  {
    std::lock_guard lock(g_abandoned_mutex);
    jobs.swap(g_abandoned);
  }
  py::gil_scoped_release release;
  for (const auto& job : jobs) job->thread.join();
}

}  // namespace rvr::python
