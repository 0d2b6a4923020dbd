// The study's sessions as worker processes (apps/rvr/study_processes.h): a step still running
// at the budget's end is stopped, the worker killed and reaped, and the session says so with
// ErrorKind::OutOfTime; a step within the budget is untouched by the clock.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <thread>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/study/run_study.h"
#include "rvr/study/sweep_plan.h"
#include "study_processes.h"

namespace rvr {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A clock that runs out `seconds` after it is made.
std::function<double()> budget_of(double seconds) {
  const Clock::time_point start = Clock::now();
  return [=] { return seconds - seconds_since(start); };
}

// An executable that takes the worker's arguments and never answers.
std::string silent_worker() {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("rvr-silent-worker-" + std::to_string(getpid()));
  std::ofstream(path) << "#!/bin/sh\nexec sleep 60\n";
  chmod(path.c_str(), 0755);
  return path.string();
}

// The pid in "study: the worker process PID was stopped at the budget's end".
pid_t pid_in(const std::string& message) {
  const size_t at = message.find("process ");
  return at == std::string::npos ? 0 : pid_t(std::atol(message.c_str() + at + 8));
}

TEST(StudyProcesses, AWorkerStillBusyAtTheBudgetsEndIsStoppedAndReaped) {
  const std::string worker = silent_worker();
  Expected<study::Family> family = study::find_family("builtin:tessphere");
  ASSERT_TRUE(family.ok());
  Expected<std::unique_ptr<study::Session>> session =
      cli::process_sessions(worker, {"softraster"}, RenderMode::Local)();
  ASSERT_TRUE(session.ok()) << session.error().message;
  (*session)->stop_steps_when_out_of_time(budget_of(0.3));
  const Clock::time_point start = Clock::now();
  Expected<std::unique_ptr<study::FrameSource>> frames = (*session)->prepare(*family, 100, 64);
  const double waited = seconds_since(start);
  ASSERT_FALSE(frames.ok());
  EXPECT_EQ(frames.error().kind, ErrorKind::OutOfTime) << frames.error().message;
  // The worker sleeps for 60 s: the answer was given up at the budget's end, not awaited.
  EXPECT_GE(waited, 0.29);
  EXPECT_LT(waited, 10.0);
  // Every step after fails at once, and the session ends without waiting for the worker.
  Expected<std::unique_ptr<study::FrameSource>> again = (*session)->prepare(*family, 100, 64);
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.error().kind, ErrorKind::OutOfTime);
  const pid_t pid = pid_in(frames.error().message);
  ASSERT_GT(pid, 0) << frames.error().message;
  const Clock::time_point closing = Clock::now();
  session->reset();
  EXPECT_LT(seconds_since(closing), 1.0);
  // It is reaped in the background: gone (not even a zombie) within seconds.
  while (::kill(pid, 0) == 0 && seconds_since(closing) < 10)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(::kill(pid, 0), -1) << "worker " << pid << " still there";
  EXPECT_EQ(errno, ESRCH);
  std::filesystem::remove(worker);
}

// The real worker: a preparation of a million triangles (seconds of mesh, BVH and first frames)
// stopped a tenth of a second in; with time to spare, a small scene is prepared and timed.
TEST(StudyProcesses, TheRealWorkerIsStoppedInAPreparationAndUntouchedWithinTheBudget) {
  Expected<study::Family> family = study::find_family("builtin:tessphere");
  ASSERT_TRUE(family.ok());
  const study::StartSession start_session =
      cli::process_sessions(RVR_BINARY, {"softraster", "raytrace"}, RenderMode::Local);
  {
    Expected<std::unique_ptr<study::Session>> session = start_session();
    ASSERT_TRUE(session.ok()) << session.error().message;
    (*session)->stop_steps_when_out_of_time(budget_of(0.1));
    Expected<std::unique_ptr<study::FrameSource>> frames =
        (*session)->prepare(*family, 1000000, 1024);
    ASSERT_FALSE(frames.ok());
    EXPECT_EQ(frames.error().kind, ErrorKind::OutOfTime) << frames.error().message;
  }
  Expected<std::unique_ptr<study::Session>> session = start_session();
  ASSERT_TRUE(session.ok()) << session.error().message;
  (*session)->stop_steps_when_out_of_time(budget_of(600));
  Expected<std::unique_ptr<study::FrameSource>> frames = (*session)->prepare(*family, 100, 64);
  ASSERT_TRUE(frames.ok()) << frames.error().message;
  for (size_t renderer : {0u, 1u}) {
    Expected<study::FrameTime> t = (*frames)->time_frame(renderer);
    ASSERT_TRUE(t.ok()) << t.error().message;
    EXPECT_GT(t->seconds, 0);
  }
}

}  // namespace
}  // namespace rvr
