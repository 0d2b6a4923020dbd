// Progress on long work: what the renderers count, cancelling them part way, the line the command
// line draws from it, and rvr itself run under a pseudo-terminal (a bar, a rate and a time left,
// erased at the end), with stderr redirected (nothing but the summary), with --quiet and TERM=dumb
// (nothing), and failing after the bar was drawn (one clean "error:" line).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/progress.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/scene_loader.h"
#include "terminal_progress.h"

namespace fs = std::filesystem;
using namespace rvr;

namespace {

// ------------------------------------------------------------------------ sink and line

TEST(ProgressSink, CountsFromManyThreadsAndBeginResets) {
  ProgressSink sink;
  sink.begin("trace", 8000, "pixels", "rays");
  std::vector<std::thread> workers;
  for (int t = 0; t < 4; ++t)
    workers.emplace_back([&] {
      for (int i = 0; i < 1000; ++i) sink.advance(2, 5);
    });
  for (std::thread& w : workers) w.join();
  ProgressSnapshot s = sink.snapshot();
  EXPECT_EQ(s.phase, "trace");
  EXPECT_EQ(s.total, 8000u);
  EXPECT_EQ(s.done, 8000u);
  EXPECT_EQ(s.rate_unit, "rays");
  EXPECT_EQ(s.rate_done, 20000u);

  sink.begin("setup", 10, "triangles");  // no rate unit: the speed is in the unit itself
  sink.advance(3);
  s = sink.snapshot();
  EXPECT_EQ(s.done, 3u);
  EXPECT_EQ(s.rate_unit, "triangles");
  EXPECT_EQ(s.rate_done, 3u);
}

// `seconds` is the time since the phase began: bracketed by the test's own clock read around
// begin() and snapshot(), so it holds on a machine of any speed. A sink made long before the
// phase (the sleep) tells a clock started at construction, or not restarted by begin(), from
// the right one; the sleep inside the phase tells milliseconds or a stuck zero from seconds.
TEST(ProgressSink, SecondsCountFromTheStartOfThePhase) {
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  ProgressSink sink;
  sink.begin("build", 10);
  std::this_thread::sleep_for(std::chrono::milliseconds(60));
  const Clock::time_point before_begin = Clock::now();
  sink.begin("trace", 10);
  const ProgressSnapshot fresh = sink.snapshot();
  const double fresh_bound = since(before_begin);
  EXPECT_GE(fresh.seconds, 0.0);
  EXPECT_LE(fresh.seconds, fresh_bound);  // not the 60 ms of the phase before

  const Clock::time_point before_sleep = Clock::now();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const ProgressSnapshot later = sink.snapshot();
  const double later_bound = since(before_begin);
  // sleep_for waits at least as long as asked; the phase began before the sleep.
  EXPECT_GE(later.seconds, 0.050);
  EXPECT_GE(later.seconds, std::chrono::duration<double>(before_sleep - before_begin).count());
  EXPECT_LE(later.seconds, later_bound);
}

TEST(ProgressLine, PercentBarRateAndTimeLeft) {
  ProgressSnapshot s;
  s.phase = "trace";
  s.unit = "pixels";
  s.rate_unit = "rays";
  s.total = 1000;
  s.done = 250;
  s.rate_done = 2'460'000;
  s.seconds = 2.0;
  EXPECT_EQ(format_progress_line("2/3 raytrace", s, 120),
            "2/3 raytrace  trace   25% [#####...............]  1.23M rays/s  ETA 6s");
  // Narrow terminals lose the bar, then the end; the line never wraps.
  std::string narrow = format_progress_line("2/3 raytrace", s, 60);
  EXPECT_EQ(narrow, "2/3 raytrace  trace   25%  1.23M rays/s  ETA 6s");
  EXPECT_LT(format_progress_line("2/3 raytrace", s, 20).size(), 20u);
  s.done = 0;
  s.rate_done = 0;
  EXPECT_NE(format_progress_line("", s, 120).find("ETA --"), std::string::npos);
  // Nothing counted: the phase and its time only.
  ProgressSnapshot t;
  t.phase = "render";
  t.seconds = 2.05;
  EXPECT_EQ(format_progress_line("raster", t, 120), "raster  render  2.0s");
}

TEST(ProgressLine, CountsAndDurations) {
  EXPECT_EQ(format_count(850), "850");
  EXPECT_EQ(format_count(12'340), "12.3k");
  EXPECT_EQ(format_count(4'560'000'000.0), "4.56G");
  EXPECT_EQ(format_duration(2.2), "3s");
  EXPECT_EQ(format_duration(125), "2m05s");
  EXPECT_EQ(format_duration(3720), "1h02m");
}

// Counting is all a renderer does with the sink: the same bytes whether watched or not. Tracers
// and softraster count their last phase to its end; the GL raster (both back ends) reports
// phases, readback last.
TEST(ProgressSink, EveryRendererAndRasterOnEglDrawsTheSameWhenWatched) {
  Scene scene = load_scene("builtin:spheres").value();
  scene.image.width = 70;  // not a multiple of any tile size
  scene.image.height = 37;
  // Every renderer of the table; the raster on OSMesa, and on EGL as its GL-context variant.
  for (const RendererChoice& c : renderer_choices()) {
    if (c.variant && c.variant->of != VariantOf::GlContext) continue;
    RendererConfig config{GlBackend::OsMesa};
    RenderOptions options;
    options.mode = RenderMode::Full;
    c.apply(config, options);
    const std::string& label = c.name;
    std::unique_ptr<Renderer> renderer = c.info->create(config).value();
    RenderOutput plain = renderer->render(scene, options).value();
    ProgressSink sink;
    options.progress = &sink;
    RenderOutput watched = renderer->render(scene, options).value();
    EXPECT_EQ(plain.buffers.colour, watched.buffers.colour) << label;
    EXPECT_EQ(plain.buffers.object_id, watched.buffers.object_id) << label;
    ProgressSnapshot s = sink.snapshot();  // the last phase
    if (c.info->name == "raster") {
      EXPECT_EQ(s.phase, "readback") << label;
      continue;
    }
    EXPECT_GT(s.total, 0u) << label;
    EXPECT_EQ(s.done, s.total) << label;
    if (c.info->order != LoopOrder::TriangleMajor) {  // the tracers, and the hybrids' trace phase
      EXPECT_EQ(s.phase, "trace");
      EXPECT_EQ(s.total, 70u * 37u);
      EXPECT_EQ(s.rate_unit, "rays");
      EXPECT_EQ(double(s.rate_done), plain.stats["rays.primary"] + plain.stats["rays.shadow"] +
                                         plain.stats["rays.reflection"] +
                                         plain.stats["rays.refraction"]);
    }
  }
}

// Cancelling from another thread once the render's work has begun: after its first counted unit
// (a tile, a chunk, rows), or for the GL z-buffer, which looks between passes and has one pass
// here, in its setup or upload, before that pass. Every renderer of the table returns
// ErrorKind::Cancelled, its work left undone. The time from the cancel to the return is bounded
// by a quarter of the time the same render takes when this test runs it to its end, so the bound
// scales with however loaded the machine is.
TEST(ProgressSink, CancelFromAnotherThreadStopsEveryRendererPartWay) {
  using Clock = std::chrono::steady_clock;
  Scene scene = load_scene("builtin:soup:200000").value();
  scene.image.width = 1024;
  scene.image.height = 768;
  for (const RendererChoice& c : renderer_choices()) {
    if (c.variant) continue;
    RendererConfig config{GlBackend::OsMesa};
    RenderOptions options;
    options.mode = RenderMode::Local;
    c.apply(config, options);
    const std::string& label = c.name;
    std::unique_ptr<Renderer> renderer = c.info->create(config).value();

    const Clock::time_point full_start = Clock::now();
    ASSERT_TRUE(renderer->render(scene, options).ok()) << label;
    const double full_seconds = std::chrono::duration<double>(Clock::now() - full_start).count();

    ProgressSink sink;
    options.progress = &sink;
    std::atomic<bool> returned{false};
    Clock::time_point cancelled_at{};
    std::thread canceller([&] {
      while (!returned.load()) {
        const ProgressSnapshot s = sink.snapshot();
        if (s.done > 0 || s.phase == "setup" || s.phase == "upload") {
          cancelled_at = Clock::now();
          sink.cancel();
          return;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    });
    Expected<RenderOutput> out = renderer->render(scene, options);
    const Clock::time_point returned_at = Clock::now();
    returned.store(true);
    canceller.join();
    ASSERT_TRUE(sink.cancelled()) << label << ": finished before its work was seen to begin";
    ASSERT_FALSE(out.ok()) << label << ": rendered to the end although cancelled";
    EXPECT_EQ(out.error().kind, ErrorKind::Cancelled) << label;
    EXPECT_EQ(out.error().message, "cancelled") << label;
    const double stop_seconds = std::chrono::duration<double>(returned_at - cancelled_at).count();
    EXPECT_LT(stop_seconds, full_seconds / 4) << label << ": full render " << full_seconds << " s";
    std::printf("%-12s full %.3f s, cancel to return %.3f s\n", label.c_str(), full_seconds,
                stop_seconds);
  }
}

// ----------------------------------------------------------------------- rvr on a terminal

struct PtyRun {
  int status = -1;
  std::string err;  // what the terminal received on stderr (with the tty's \n -> \r\n)
  double seconds_after_interrupt = -1;  // from SIGINT to the exit; -1 when none was sent
};

bool has_progress_bar(const std::string& text);

// Runs rvr with stderr on a new pseudo-terminal (stdout to /dev/null), TERM set to `term`;
// with `interrupt_on_bar`, sends SIGINT as soon as a progress bar has been drawn (whenever that
// is on this machine, not after a guessed time).
PtyRun run_on_pty(const std::vector<std::string>& args, const char* term = "xterm",
                  bool interrupt_on_bar = false) {
  PtyRun r;
  int master = ::posix_openpt(O_RDWR | O_NOCTTY);
  if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0) return r;
  winsize ws{};
  ws.ws_col = 120;
  ws.ws_row = 40;
  ::ioctl(master, TIOCSWINSZ, &ws);
  std::string slave_name = ::ptsname(master);
  pid_t pid = ::fork();
  if (pid == 0) {
    ::setsid();
    int slave = ::open(slave_name.c_str(), O_RDWR);
    int null = ::open("/dev/null", O_RDWR);
    if (slave < 0 || null < 0) ::_exit(127);
    ::dup2(null, 0);
    ::dup2(null, 1);
    ::dup2(slave, 2);
    ::setenv("TERM", term, 1);
    std::vector<char*> argv{const_cast<char*>(RVR_BINARY)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(RVR_BINARY, argv.data());
    ::_exit(127);
  }
  // Read until every holder of the terminal has gone (EIO), with a guard: nothing on the
  // terminal for the process time limit kills it.
  char buf[4096];
  std::chrono::steady_clock::time_point interrupted{};
  while (true) {
    pollfd p{master, POLLIN, 0};
    int ready = ::poll(&p, 1, RVR_PROCESS_TIMEOUT * 1000);
    if (ready <= 0) {
      ::kill(pid, SIGKILL);
      break;
    }
    ssize_t n = ::read(master, buf, sizeof buf);
    if (n <= 0) break;
    r.err.append(buf, size_t(n));
    if (interrupt_on_bar && interrupted == decltype(interrupted){} && has_progress_bar(r.err)) {
      interrupted = std::chrono::steady_clock::now();
      ::kill(pid, SIGINT);
    }
  }
  int raw = 0;
  ::waitpid(pid, &raw, 0);
  ::close(master);
  if (interrupted != decltype(interrupted){})
    r.seconds_after_interrupt =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - interrupted).count();
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

// What a terminal shows after interpreting "\r", "\n" and "ESC [ K" (erase to end of line).
std::vector<std::string> screen(const std::string& bytes) {
  std::vector<std::string> lines{""};
  size_t col = 0;
  for (size_t i = 0; i < bytes.size(); ++i) {
    std::string& line = lines.back();
    char c = bytes[i];
    if (c == '\r') {
      col = 0;
    } else if (c == '\n') {
      lines.emplace_back();
      col = 0;
    } else if (c == '\x1b' && bytes.compare(i, 3, "\x1b[K") == 0) {
      line.resize(std::min(line.size(), col));
      i += 2;
    } else {
      if (col < line.size())
        line[col] = c;
      else
        line.push_back(c);
      ++col;
    }
  }
  if (lines.back().empty()) lines.pop_back();
  return lines;
}

class ProgressCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("rvr_progress_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
            std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Tracing on one thread (20000 triangles, no BVH, 64x48 pixels, 12 tiles) for about two
  // seconds on this machine, whatever its speed: the samples per pixel are scaled by a timed
  // run of one sample (spp_for_seconds). Well over the half second before a bar appears and
  // several redraws, well under the test's time budget.
  std::vector<std::string> long_render(const std::string& out, double seconds = 2.0) const {
    return {"render",    "builtin:soup:20000",
            "-r",        "raytrace",
            "--accel",   "none",
            "--mode",    "local",
            "--threads", "1",
            "--width",   "64",
            "--height",  "48",
            "--spp",     std::to_string(spp_for_seconds(seconds)),
            "-o",        out};
  }

  // Samples per pixel for the render above to last about `seconds`: the render phase of one
  // sample (its --stats "time.render", so process start-up does not count) is measured once
  // per test binary, the slower of two runs, so that a lucky run does not shrink the work.
  static int spp_for_seconds(double seconds) {
    static const double one_sample = [] {
      const fs::path stem =
          fs::temp_directory_path() / ("rvr_progress_calibrate_" + std::to_string(::getpid()));
      double slowest = 0;
      for (int run = 0; run < 2; ++run) {
        const std::string cmd =
            "timeout -k 10 " + std::to_string(RVR_PROCESS_TIMEOUT) + " " + RVR_BINARY +
            " render builtin:soup:20000 -r raytrace --accel none --mode local "
            "--threads 1 --width 64 --height 48 --spp 1 --quiet -o " +
            stem.string() + ".png --stats " + stem.string() + ".json </dev/null >/dev/null 2>&1";
        EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
        std::ifstream in(stem.string() + ".json");
        nlohmann::json stats = nlohmann::json::parse(in, nullptr, false);
        const double render = stats.is_object() && stats["time"].contains("render")
                                  ? stats["time"]["render"].get<double>()
                                  : 0.0;
        EXPECT_GT(render, 0.0) << cmd;
        slowest = std::max(slowest, render);
      }
      fs::remove(stem.string() + ".png");
      fs::remove(stem.string() + ".json");
      return slowest;
    }();
    return std::clamp(int(std::ceil(seconds / std::max(one_sample, 1e-3))), 1, 4096);
  }

  fs::path dir_;
};

// Whether `text` holds a line like "39% [#######.............]  1.14M rays/s  ETA 1s". (By hand:
// std::regex draws false -Wmaybe-uninitialized warnings from g++ 12 in the sanitizer build.)
bool has_progress_bar(const std::string& text) {
  for (size_t at = text.find("% ["); at != std::string::npos; at = text.find("% [", at + 1)) {
    if (at == 0 || !std::isdigit(static_cast<unsigned char>(text[at - 1]))) continue;
    const size_t bar = at + 3;
    if (text.size() < bar + 22) break;
    bool cells = std::all_of(text.begin() + bar, text.begin() + bar + 20,
                             [](char c) { return c == '#' || c == '.'; });
    if (!cells || text.compare(bar + 20, 3, "]  ") != 0) continue;
    size_t rate = bar + 23, digits = rate;
    while (digits < text.size() &&
           (std::isdigit(static_cast<unsigned char>(text[digits])) || text[digits] == '.'))
      ++digits;
    if (digits == rate) continue;
    if (digits < text.size() && std::string("kMG").find(text[digits]) != std::string::npos)
      ++digits;
    if (text.compare(digits, 13, " rays/s  ETA ") != 0) continue;
    const size_t eta = digits + 13;
    if (eta < text.size() && std::isdigit(static_cast<unsigned char>(text[eta]))) return true;
  }
  return false;
}

TEST_F(ProgressCli, TerminalShowsPercentRateAndTimeLeftThenErases) {
  PtyRun r = run_on_pty(long_render((dir_ / "a.png").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has_progress_bar(r.err)) << r.err;
  EXPECT_NE(r.err.find("raytrace  trace"), std::string::npos) << r.err;
  // Erased before the summary, which then stands alone on the screen.
  EXPECT_NE(r.err.find("\r\x1b[Kraytrace: builtin:soup:20000 64x48 local in"), std::string::npos)
      << r.err;
  std::vector<std::string> shown = screen(r.err);
  ASSERT_EQ(shown.size(), 1u) << r.err;
  EXPECT_EQ(shown[0].rfind("raytrace: builtin:soup:20000", 0), 0u) << shown[0];
  EXPECT_TRUE(fs::exists(dir_ / "a.png"));
}

TEST_F(ProgressCli, CompareNamesWhichRendererOfHowMany) {
  PtyRun r = run_on_pty({"compare", "builtin:soup:20000", "-r", "softraster,raytrace", "--accel",
                         "none", "--threads", "1", "--width", "64", "--height", "48", "--spp",
                         std::to_string(spp_for_seconds(2.0)), "-o", (dir_ / "cmp").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("2/2 raytrace  trace"), std::string::npos) << r.err;
  EXPECT_TRUE(has_progress_bar(r.err)) << r.err;
  for (const std::string& line : screen(r.err))  // only warnings remain, if any
    EXPECT_EQ(line.rfind("warning: ", 0), 0u) << line;
}

TEST_F(ProgressCli, RedirectedStderrGetsOnlyTheSummary) {
  std::string cmd = std::string(RVR_BINARY);
  for (const std::string& a : long_render((dir_ / "a.png").string())) cmd += " " + a;
  cmd += " 2>" + (dir_ / "err.txt").string() + " >/dev/null </dev/null";
  // Bounded: a hang fails (timeout's status 124) instead of stalling the suite.
  ASSERT_EQ(
      std::system(
          ("TERM=xterm timeout -k 10 " + std::to_string(RVR_PROCESS_TIMEOUT) + " " + cmd).c_str()),
      0);
  std::ifstream in(dir_ / "err.txt");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string err = ss.str();
  EXPECT_EQ(err.rfind("raytrace: builtin:soup:20000 64x48 local in ", 0), 0u) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_EQ(err.find_first_of("\r\x1b%"), std::string::npos) << err;
}

TEST_F(ProgressCli, QuietAndDumbTerminalsShowNoProgress) {
  std::vector<std::string> quiet = long_render((dir_ / "q.png").string());
  quiet.push_back("--quiet");
  PtyRun q = run_on_pty(quiet);
  EXPECT_EQ(q.status, 0) << q.err;
  EXPECT_EQ(q.err, "");  // not even the summary

  PtyRun dumb = run_on_pty(long_render((dir_ / "d.png").string()), "dumb");
  EXPECT_EQ(dumb.status, 0) << dumb.err;
  EXPECT_EQ(dumb.err.find_first_of("\x1b%"), std::string::npos) << dumb.err;
  EXPECT_EQ(screen(dumb.err).size(), 1u) << dumb.err;
}

TEST_F(ProgressCli, ErrorAfterTheBarIsOneCleanLine) {
  // The output's folder would have to be made inside a regular file: found out only when
  // writing, after the render and its progress bar.
  std::ofstream(dir_ / "file") << "x";
  PtyRun r = run_on_pty(long_render((dir_ / "file" / "a.png").string()));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has_progress_bar(r.err)) << r.err;
  EXPECT_NE(r.err.find("\r\x1b[Kerror: "), std::string::npos) << r.err;
  std::vector<std::string> shown = screen(r.err);
  ASSERT_EQ(shown.size(), 1u) << r.err;
  EXPECT_EQ(shown[0].rfind("error: ", 0), 0u) << shown[0];
}

TEST_F(ProgressCli, InterruptedWhileTheBarIsShownIsOneCleanLine) {
  // Far longer than it takes for the bar to appear; interrupted as soon as it has.
  PtyRun r = run_on_pty(long_render((dir_ / "i.png").string(), 60.0), "xterm", true);
  EXPECT_EQ(r.status, 130) << r.err;
  ASSERT_GE(r.seconds_after_interrupt, 0.0) << "no bar was drawn: " << r.err;
  // The handler exits at once; the bound is for a loaded machine, far below the render's 60 s.
  EXPECT_LT(r.seconds_after_interrupt, 5.0);
  EXPECT_NE(r.err.find('%'), std::string::npos) << r.err;
  std::vector<std::string> shown = screen(r.err);
  ASSERT_EQ(shown.size(), 1u) << r.err;
  EXPECT_EQ(shown[0], "error: interrupted");
  EXPECT_FALSE(fs::exists(dir_ / "i.png"));
}

}  // namespace
