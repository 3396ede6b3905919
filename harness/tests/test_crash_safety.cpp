// Crash safety of recordings: a process recording a run (lockstep and threaded)
// is killed with SIGKILL at random moments; the trace it leaves must read without
// error, and lose at most the last second of run time (the writer flushes every
// flush_period = 0.25 s of run time: scenario.h). The child publishes each tick's
// run time through shared memory (ScenarioOptions::run_time_out), so the loss is
// measured against the run time the child had reached when it was killed.
#include <catch2/catch.hpp>

#include <signal.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <new>
#include <random>
#include <string>
#include <thread>

#include "../../optimized/tests/mesh_shapes.h"
#include "gauss6/geometry/mass_properties.h"
#include "gauss6/scenario.h"
#include "slab_scene.h"

using namespace gauss6;

namespace {

HandScript slide_script(double seconds) {
  HandScript h;
  for (int i = 0; i <= static_cast<int>(seconds / 0.5); ++i) {
    HandKeyframe k;
    k.t = 0.5 * i;
    k.X_WA.p = Vec3(i % 2 ? 0.02 : -0.02, 0, i == 0 ? 0.02 : 0.005);
    h.keys.push_back(k);
  }
  h.end_time = seconds;
  return h;
}

struct KillResult {
  bool killed = false;     // false: the run ended before the kill
  double run_time = 0;     // s of run time the child had reached
  double last_tick = 0;    // s: the last tick in the file (0: none; the run starts at 0)
  size_t num_ticks = 0;
};

// Forks a child that records the run; kills it `delay` s of wall time after its
// first tick; reads what it left.
KillResult record_and_kill(bool threaded, double seconds, double delay, const std::string& path) {
  auto* shared = static_cast<std::atomic<double>*>(
      mmap(nullptr, sizeof(std::atomic<double>), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0));
  REQUIRE(shared != MAP_FAILED);
  new (shared) std::atomic<double>(-1.0);
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ScenarioOptions options;
    options.threaded = threaded;
    options.trace_path = path;
    options.run_time_out = shared;
    run_scenario(test::make_slab_scene(), slide_script(seconds), options);
    _exit(0);
  }
  const auto start = std::chrono::steady_clock::now();
  while (shared->load() < 0 && std::chrono::steady_clock::now() - start < std::chrono::seconds(20))
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  std::this_thread::sleep_for(std::chrono::duration<double>(delay));
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  KillResult out;
  out.killed = WIFSIGNALED(status);
  out.run_time = shared->load();
  munmap(shared, sizeof(std::atomic<double>));
  const Trace tr = read_trace(path);  // must not throw
  out.num_ticks = tr.ticks.num_rows();
  if (out.num_ticks) out.last_tick = tr.ticks.row(out.num_ticks - 1)[0];
  for (size_t i = 1; i < out.num_ticks; ++i) REQUIRE(tr.ticks.row(i)[0] > tr.ticks.row(i - 1)[0]);
  return out;
}

void kill_at_random_moments(bool threaded, double seconds, double max_delay, int num_kills) {
  std::mt19937_64 rng(threaded ? 2 : 1);
  std::uniform_real_distribution<double> delay(0.02, max_delay);
  const std::string path =
      (std::filesystem::temp_directory_path() / ("gauss6_crash_" + std::to_string(getpid()) + ".g6trace")).string();
  int num_killed = 0;
  for (int k = 0; k < num_kills; ++k) {
    const KillResult r = record_and_kill(threaded, seconds, delay(rng), path);
    INFO((threaded ? "threaded" : "lockstep") << " kill " << k << ": run time " << r.run_time << " s, last tick "
                                               << r.last_tick << " s, " << r.num_ticks << " ticks");
    if (!r.killed) continue;  // the run ended first: nothing was lost
    ++num_killed;
    // At most the last second of run time is lost (the writer's bound is flush_period, 0.25 s).
    CHECK(r.run_time - r.last_tick <= 1.0);
  }
  std::remove(path.c_str());
  CHECK(num_killed >= num_kills / 2);
}

}  // namespace

TEST_CASE("crash safety: a lockstep recording killed at random moments loses at most 1 s of run", "[scenario][crash]") {
  kill_at_random_moments(/*threaded=*/false, /*seconds=*/60, /*max_delay=*/0.8, /*num_kills=*/6);
}

TEST_CASE("crash safety: a threaded recording killed at random moments loses at most 1 s of run", "[scenario][crash][threaded]") {
  kill_at_random_moments(/*threaded=*/true, /*seconds=*/3, /*max_delay=*/1.5, /*num_kills=*/4);
}
