// Worker processes for the study's sessions (see study_processes.h).
#include "study_processes.h"

#include <fmt/format.h>
#include <malloc.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

#include "rvr/core/expected.h"
#include "rvr/study/measurement.h"
#include "rvr/study/memory_estimate.h"
#include "rvr/study/renderer_frames.h"
#include "rvr/study/sweep_plan.h"

extern char** environ;

namespace rvr::cli {
namespace {

using nlohmann::json;

json error_json(const Error& e) {
  return {{"error", {{"kind", int(e.kind)}, {"message", e.message}}}};
}

Error error_of(const json& reply) {
  const json& e = reply.at("error");
  const int kind = e.value("kind", int(ErrorKind::Internal));
  return Error{e.value("message", std::string("study worker failed")),
               kind == int(ErrorKind::BadInput)    ? ErrorKind::BadInput
               : kind == int(ErrorKind::Cancelled) ? ErrorKind::Cancelled
                                                   : ErrorKind::Internal};
}

json family_json(const study::Family& f) {
  return {{"name", f.name}, {"axis", f.axis},     {"low", f.low},
          {"high", f.high}, {"points", f.points}, {"source", f.source}};
}

// A renderer's effect errors at one point, as the worker sends them (an identical frame's
// infinite PSNR as null).
json effect_errors_json(const std::vector<study::PointEffectError>& errors) {
  json out = json::array();
  for (const study::PointEffectError& e : errors)
    out.push_back({{"effect", e.effect},
                   {"pixels", e.pixels},
                   {"rmse", e.rmse},
                   {"psnr_db", std::isfinite(e.psnr_db) ? json(e.psnr_db) : json(nullptr)},
                   {"ssim", e.ssim}});
  return out;
}

std::vector<study::PointEffectError> effect_errors_of(const json& j) {
  std::vector<study::PointEffectError> out;
  for (const json& e : j)
    out.push_back({e.at("effect").get<std::string>(), e.at("pixels").get<double>(),
                   e.at("rmse").get<double>(),
                   e.at("psnr_db").is_null() ? std::numeric_limits<double>::infinity()
                                             : e.at("psnr_db").get<double>(),
                   e.at("ssim").get<double>()});
  return out;
}

study::Family family_of(const json& j) {
  return study::Family{j.at("name").get<std::string>(), j.at("axis").get<std::string>(),
                       j.at("low").get<size_t>(),       j.at("high").get<size_t>(),
                       j.at("points").get<int>(),       j.at("source").get<std::string>()};
}

// One worker process and the socket to it.
class Worker {
 public:
  static Expected<std::shared_ptr<Worker>> start(const std::string& executable,
                                                 const std::vector<std::string>& renderers,
                                                 RenderMode mode) {
    int fds[2];
    if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0)
      return internal_error(fmt::format("study: cannot make a socket: {}", std::strerror(errno)));
    std::string names;
    for (const std::string& r : renderers) names += (names.empty() ? "" : ",") + r;
    std::vector<std::string> args = {executable,      "study-worker", "--mode",
                                     to_string(mode), "--renderers",  names};
    std::vector<char*> argv;
    argv.reserve(args.size() + 1);
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], 0);
    posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
    pid_t pid = 0;
    const int err = posix_spawn(&pid, executable.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[1]);
    if (err != 0) {
      ::close(fds[0]);
      return internal_error(
          fmt::format("study: cannot start {} study-worker: {}", executable, std::strerror(err)));
    }
    return std::make_shared<Worker>(pid, fds[0]);
  }

  Worker(pid_t pid, int fd) : pid_(pid), fd_(fd) {}
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  // Closing the socket ends the worker's loop; one that does not end is killed. One killed at
  // the budget's end is reaped in the background: its memory's teardown is not the study's time.
  ~Worker() {
    ::close(fd_);
    if (reaped_) return;
    if (killed_) {
      std::thread([pid = pid_] { waitpid(pid, nullptr, 0); }).detach();
      return;
    }
    for (int k = 0; k < 200; ++k) {
      if (waitpid(pid_, nullptr, WNOHANG) == pid_) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ::kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }

  // The clock a reply is awaited against (Session::stop_steps_when_out_of_time).
  void stop_when_out_of_time(std::function<double()> seconds_left) {
    seconds_left_ = std::move(seconds_left);
  }

  // Sends one request and reads its one-line reply. A reply still awaited when seconds_left_
  // reads <= 0 is given up: the worker is killed, stopping the preparation or frame it runs,
  // and this call and every one after fail with ErrorKind::OutOfTime.
  Expected<json> call(const json& request) {
    if (killed_) return out_of_time();
    const std::string line = request.dump() + "\n";
    for (size_t sent = 0; sent < line.size();) {
      const ssize_t k = ::send(fd_, line.data() + sent, line.size() - sent, MSG_NOSIGNAL);
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) return lost("sending to it");
      sent += size_t(k);
    }
    std::string reply;
    while (true) {
      if (size_t end = buffer_.find('\n'); end != std::string::npos) {
        reply = buffer_.substr(0, end);
        buffer_.erase(0, end + 1);
        break;
      }
      if (!reply_in_time()) {
        ::kill(pid_, SIGKILL);
        killed_ = true;
        return out_of_time();
      }
      char chunk[4096];
      const ssize_t k = ::recv(fd_, chunk, sizeof chunk, 0);
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) return lost("reading its answer");
      buffer_.append(chunk, size_t(k));
    }
    json parsed = json::parse(reply, nullptr, false);
    if (parsed.is_discarded() || !parsed.is_object())
      return internal_error("study: a worker answered something that is not JSON: " + reply);
    if (parsed.contains("error")) return error_of(parsed);
    return parsed;
  }

 private:
  // Waits until the socket has something to read (or an error recv will tell), or until
  // seconds_left_ reads <= 0: false then. Without a clock: true at once (recv waits).
  bool reply_in_time() const {
    if (!seconds_left_) return true;
    while (true) {
      const double left = seconds_left_();
      if (!(left > 0)) return false;
      pollfd ready{fd_, POLLIN, 0};
      const int r = ::poll(&ready, 1, int(std::ceil(std::min(left, 60.0) * 1000)));
      if (r > 0 || (r < 0 && errno != EINTR)) return true;
    }
  }

  Error out_of_time() const {
    return out_of_time_error(
        fmt::format("study: the worker process {} was stopped at the budget's end", pid_));
  }

  Error lost(const char* doing) {
    int status = 0;
    std::string how = "it closed the connection";
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      reaped_ = true;
      how = WIFSIGNALED(status) ? fmt::format("it was killed by signal {}", WTERMSIG(status))
                                : fmt::format("it exited with status {}", WEXITSTATUS(status));
    }
    return internal_error(
        fmt::format("study: lost the worker process {} while {}: {}", pid_, doing, how));
  }

  pid_t pid_;
  int fd_;
  std::string buffer_;
  std::function<double()> seconds_left_;  // null: replies are awaited however long they take
  bool killed_ = false;                   // stopped at the budget's end
  bool reaped_ = false;                   // its exit status collected
};

// A scene prepared in a worker: what the worker said of it, and its frames timed there.
class ProcessFrames : public study::FrameSource {
 public:
  ProcessFrames(std::shared_ptr<Worker> worker, int id, const json& prepared)
      : worker_(std::move(worker)), id_(id) {
    axis_ = prepared.at("axis").get<double>();
    pixels_ = prepared.at("pixels").get<double>();
    prepare_ = prepared.at("prepare_seconds").get<std::vector<double>>();
    counters_ = prepared.at("counters").get<std::vector<std::map<std::string, double>>>();
    for (const json& errors : prepared.at("effect_errors"))
      effect_errors_.push_back(effect_errors_of(errors));
  }
  ProcessFrames(const ProcessFrames&) = delete;
  ProcessFrames& operator=(const ProcessFrames&) = delete;
  ~ProcessFrames() override { (void)worker_->call({{"op", "release"}, {"id", id_}}); }

  double axis_value() const override { return axis_; }
  double pixels() const override { return pixels_; }
  double prepare_seconds(size_t index) const override { return prepare_.at(index); }
  std::map<std::string, double> counters(size_t index) const override {
    return counters_.at(index);
  }
  std::vector<study::PointEffectError> effect_errors(size_t index) const override {
    return effect_errors_.at(index);
  }
  Expected<study::FrameTime> time_frame(size_t index) override {
    RVR_TRY_ASSIGN(reply, worker_->call({{"op", "frame"}, {"id", id_}, {"renderer", index}}));
    study::FrameTime t;
    t.seconds = reply->at("seconds").get<double>();
    t.phases = reply->at("phases").get<std::map<std::string, double>>();
    return t;
  }

 private:
  std::shared_ptr<Worker> worker_;
  int id_;
  double axis_ = 0, pixels_ = 0;
  std::vector<double> prepare_;
  std::vector<std::map<std::string, double>> counters_;
  std::vector<std::vector<study::PointEffectError>> effect_errors_;
};

class ProcessSession : public study::Session {
 public:
  explicit ProcessSession(std::shared_ptr<Worker> worker) : worker_(std::move(worker)) {}
  std::string kind() const override { return "process"; }
  void stop_steps_when_out_of_time(const std::function<double()>& seconds_left) override {
    worker_->stop_when_out_of_time(seconds_left);
  }
  Expected<std::unique_ptr<study::FrameSource>> prepare(const study::Family& family, size_t n,
                                                        int width) override {
    const int id = next_id_++;
    RVR_TRY_ASSIGN(reply, worker_->call({{"op", "prepare"},
                                         {"id", id},
                                         {"family", family_json(family)},
                                         {"n", n},
                                         {"width", width}}));
    return std::unique_ptr<study::FrameSource>(
        std::make_unique<ProcessFrames>(worker_, id, *reply));
  }

 private:
  std::shared_ptr<Worker> worker_;
  int next_id_ = 0;
};

// The worker's answer to one request.
json answer(const json& request, const std::vector<std::string>& renderers, RenderMode mode,
            std::map<int, std::unique_ptr<study::FrameSource>>& prepared) {
  const std::string op = request.at("op").get<std::string>();
  const int id = request.at("id").get<int>();
  // The memory a session holds at one point (memory_estimate.h): asked of a fresh worker.
  if (op == "memory") {
    Expected<study::MemoryProbe> probe =
        study::probe_memory_here(renderers, mode, family_of(request.at("family")),
                                 request.at("n").get<size_t>(), request.at("width").get<int>());
    if (!probe) return error_json(probe.error());
    return {{"probe", json::parse(study::memory_probe_json(*probe))}};
  }
  if (op == "prepare") {
    Expected<std::unique_ptr<study::FrameSource>> frames =
        study::prepare_frames(renderers, mode, family_of(request.at("family")),
                              request.at("n").get<size_t>(), request.at("width").get<int>());
    if (!frames) return error_json(frames.error());
    json prepare = json::array(), counters = json::array(), effect_errors = json::array();
    for (size_t i = 0; i < renderers.size(); ++i) {
      prepare.push_back((*frames)->prepare_seconds(i));
      counters.push_back((*frames)->counters(i));
      effect_errors.push_back(effect_errors_json((*frames)->effect_errors(i)));
    }
    json out = {{"axis", (*frames)->axis_value()},
                {"pixels", (*frames)->pixels()},
                {"prepare_seconds", prepare},
                {"counters", counters},
                {"effect_errors", effect_errors}};
    prepared[id] = std::move(*frames);
    return out;
  }
  auto it = prepared.find(id);
  if (it == prepared.end()) return error_json(internal_error(fmt::format("no scene {}", id)));
  if (op == "release") {
    prepared.erase(it);
    // What the point freed goes back to the system: malloc would otherwise keep a varying share
    // of it in its per-thread arenas, which the next point's peak would carry (the memory
    // estimate's probes do the same, memory_estimate.h).
    malloc_trim(0);
    return json::object();
  }
  if (op == "frame") {
    Expected<study::FrameTime> t = it->second->time_frame(request.at("renderer").get<size_t>());
    if (!t) return error_json(t.error());
    return {{"seconds", t->seconds}, {"phases", t->phases}};
  }
  return error_json(internal_error("unknown request " + op));
}

}  // namespace

std::string own_executable() {
  std::error_code ec;
  std::filesystem::path p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("rvr") : p.string();
}

study::StartSession process_sessions(const std::string& executable,
                                     const std::vector<std::string>& renderers, RenderMode mode) {
  return [=]() -> Expected<std::unique_ptr<study::Session>> {
    RVR_TRY_ASSIGN(worker, Worker::start(executable, renderers, mode));
    return std::unique_ptr<study::Session>(std::make_unique<ProcessSession>(*worker));
  };
}

study::ProbeMemory process_memory_probes(const std::string& executable,
                                         const std::vector<std::string>& renderers,
                                         RenderMode mode) {
  return [=](const study::Family& family, size_t n, int width) -> Expected<study::MemoryProbe> {
    RVR_TRY_ASSIGN(worker, Worker::start(executable, renderers, mode));
    RVR_TRY_ASSIGN(reply, (*worker)->call({{"op", "memory"},
                                           {"id", 0},
                                           {"family", family_json(family)},
                                           {"n", n},
                                           {"width", width}}));
    return study::parse_memory_probe(reply->at("probe").dump());
  };
}

int run_study_worker(const std::vector<std::string>& renderers, RenderMode mode) {
  // Ctrl-C reaches the whole process group: the parent decides what stops. A worker whose
  // parent dies goes with it.
  ::signal(SIGINT, SIG_IGN);
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  std::map<int, std::unique_ptr<study::FrameSource>> prepared;
  std::string line;
  while (std::getline(std::cin, line)) {
    json reply;
    try {
      reply = answer(json::parse(line), renderers, mode, prepared);
    } catch (const json::exception& e) {
      reply = error_json(internal_error(std::string("study worker: bad request: ") + e.what()));
    }
    std::cout << reply.dump() << '\n' << std::flush;
  }
  return 0;
}

}  // namespace rvr::cli
