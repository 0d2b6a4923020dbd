#include "render_job.h"

#include <Python.h>
#include <pybind11/pybind11.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <new>
#include <string>
#include <thread>
#include <utility>

#include "rvr/core/progress.h"
#include "rvr/core/timer.h"

namespace py = pybind11;

namespace rvr::python {
namespace {

// How often the waiting thread looks at Python's signals.
constexpr std::chrono::milliseconds kSignalPoll{20};

std::atomic<int> g_running{0};

struct RenderJob {
  std::shared_ptr<const Scene> scene;
  std::unique_ptr<Renderer> renderer;
  RenderOptions options;
  ProgressSink own_sink;  // cancelled on a signal when the caller gave none
  RenderResultWithTime result;
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;

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

// The render thread, joined (without the GIL) however the caller leaves.
class RenderThread {
 public:
  explicit RenderThread(RenderJob& job) : thread_([&job] { job.run(); }) { ++g_running; }
  RenderThread(const RenderThread&) = delete;
  RenderThread& operator=(const RenderThread&) = delete;
  ~RenderThread() {
    py::gil_scoped_release release;
    thread_.join();
    --g_running;
  }

 private:
  std::thread thread_;
};

}  // namespace

RenderResultWithTime render_interruptibly(std::shared_ptr<const Scene> scene,
                                          std::unique_ptr<Renderer> renderer,
                                          const RenderOptions& options) {
  RenderJob job;
  job.scene = std::move(scene);
  job.renderer = std::move(renderer);
  job.options = options;
  if (!job.options.progress) job.options.progress = &job.own_sink;
  {
    RenderThread thread(job);
    for (;;) {
      bool done = false;
      {
        py::gil_scoped_release release;
        done = job.wait_for(kSignalPoll);
      }
      if (done) break;
      if (PyErr_CheckSignals() != 0) {
        // The exception is pending; the render stops at its next tile, and the thread's
        // destructor waits for it before the exception leaves.
        job.options.progress->cancel();
        throw py::error_already_set();
      }
    }
  }
  return std::move(job.result);
}

int running_renders() {
  return g_running.load();
}

}  // namespace rvr::python
