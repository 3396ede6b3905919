// gauss6_soak: a long threaded run of a scene with the simulated device on its
// hand script (played over and over), while other processes load every core,
// checking what the loops promise on every haptic tick: a finite force within
// the device's limits, and memory that stays flat (resident set sampled). It
// reports the haptic loop's deadline misses and jitter (period percentiles),
// the sim and coupling work and the events. Not a test: `make soak` (10 minutes).
//
//   gauss6_soak SCENE [--seconds S] [--load N] [--rss-period S] [--json FILE]
//
// Exit status: 0 when every tick's force was finite and within the limits and
// the resident set grew by less than 8 MiB after the first minute; 1 otherwise;
// 2 on bad arguments.
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "gauss6/runtime/runtime.h"
#include "gauss6/scenario.h"
#include "gauss6/io/scene.h"
#include "gauss6/simulated_device.h"

using namespace gauss6;

namespace {

// The simulated device, its hand script started over whenever it ends (the
// handle is put back on the hand at the script's start).
class LoopingDevice final : public Device {
 public:
  LoopingDevice(const HandScript& script, const SimulatedHandleParams& params)
      : device_(script, params, "simulated, looped"),
        period_(script.end_time >= 0 ? script.end_time : script.keys.back().t) {
    device_.reset(0);
  }
  const DeviceInfo& info() const override { return device_.info(); }
  DeviceStatus read(double t, DeviceState* state) override {
    if (t - start_ > period_) {
      start_ = t;
      device_.reset(0);
      ++cycles;
    }
    const DeviceStatus s = device_.read(t - start_, state);
    state->time = t;
    return s == DeviceStatus::kEnded ? DeviceStatus::kOk : s;
  }
  DeviceStatus write(double t, const Vec6& F) override { return device_.write(t - start_, F); }
  DeviceStatus halt_force() noexcept override { return device_.halt_force(); }
  long cycles = 0;

 private:
  SimulatedDevice device_;
  double period_;
  double start_ = 0;
};

// What the hooks check and measure (haptic thread; events from every loop).
struct Soak {
  double max_force = 0, max_torque = 0;  // the device's limits
  long ticks = 0, non_finite = 0, over_limit = 0;
  double largest_force = 0, largest_torque = 0;
  double last_t = -1;
  std::vector<long> period_us;           // histogram of haptic periods, 1 us bins (the last bin: beyond)
  std::atomic<long> events[kNumRuntimeEventKinds] = {};
};

void on_tick(void* user, const HapticTickRecord& r) {
  auto* s = static_cast<Soak*>(user);
  ++s->ticks;
  const double f = r.F_sent.head<3>().norm(), tau = r.F_sent.tail<3>().norm();
  if (!r.F_sent.allFinite()) ++s->non_finite;
  if (f > s->max_force * (1 + 1e-12) || tau > s->max_torque * (1 + 1e-12)) ++s->over_limit;
  s->largest_force = std::max(s->largest_force, f);
  s->largest_torque = std::max(s->largest_torque, tau);
  if (s->last_t >= 0) {
    const auto bin = static_cast<size_t>(std::max(0.0, (r.time - s->last_t) * 1e6));
    ++s->period_us[std::min(bin, s->period_us.size() - 1)];
  }
  s->last_t = r.time;
}

void on_event(void* user, const RuntimeEvent& e) {
  static_cast<Soak*>(user)->events[static_cast<int>(e.kind)].fetch_add(e.count, std::memory_order_relaxed);
}

// Resident set size (bytes) of this process.
long resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return resident * sysconf(_SC_PAGESIZE);
}

// The period (s) below which a fraction q of the periods fall.
double percentile(const std::vector<long>& hist, long total, double q) {
  long seen = 0;
  for (size_t b = 0; b < hist.size(); ++b) {
    seen += hist[b];
    if (seen >= q * total) return 1e-6 * static_cast<double>(b);
  }
  return 1e-6 * static_cast<double>(hist.size());
}

// A process that keeps one core busy until it is killed.
pid_t spawn_load() {
  const pid_t pid = fork();
  if (pid == 0) {
    volatile double x = 1;
    for (;;) x = x * 1.0000001 + 1e-9;
  }
  return pid;
}

int usage() {
  std::fprintf(stderr, "usage: gauss6_soak SCENE [--seconds S] [--load N] [--rss-period S] [--json FILE]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return usage();
  std::string scene_path = argv[1], json_path;
  double seconds = 600, rss_period = 5;
  int load = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) return usage();
    const char* v = argv[++i];
    if (a == "--seconds") seconds = std::atof(v);
    else if (a == "--load") load = std::atoi(v);
    else if (a == "--rss-period") rss_period = std::atof(v);
    else if (a == "--json") json_path = v;
    else return usage();
  }
  if (!(seconds > 0) || load < 0 || !(rss_period > 0)) return usage();

  Scene scene;
  HandScript script;
  try {
    scene = load_scene(scene_path);
    script = load_scene_script(scene);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gauss6_soak: %s\n", e.what());
    return 2;
  }
  const RuntimeModel model(scene, RuntimeSettings{});
  SimulatedHandleParams handle;
  handle.rate_hz = scene.device.rate_hz;
  handle.max_force = scene.device.max_force;
  handle.max_torque = scene.device.max_torque;
  LoopingDevice device(script, handle);
  auto data = std::make_unique<RuntimeData>(model);
  Soak soak;
  const WrenchLimits limits = resolve_wrench_limits(model, device.info());
  soak.max_force = limits.max_force;
  soak.max_torque = limits.max_torque;
  soak.period_us.assign(100000, 0);  // up to 0.1 s
  RuntimeObserver observer;
  observer.user = &soak;
  observer.on_haptic_tick = on_tick;
  observer.on_event = on_event;

  std::vector<pid_t> loaders;
  for (int k = 0; k < load; ++k) loaders.push_back(spawn_load());

  // Resident set, sampled from this thread while the run's threads run.
  std::vector<std::pair<double, long>> rss;
  std::atomic<bool> done{false};
  const auto t0 = std::chrono::steady_clock::now();
  std::thread runner([&] {
    run_threaded(model, &device, seconds, nullptr, observer, data.get());
    done.store(true);
  });
  while (!done.load()) {
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rss.emplace_back(t, resident_bytes());
    for (double waited = 0; waited < rss_period && !done.load(); waited += 0.1)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  runner.join();
  rss.emplace_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), resident_bytes());
  for (pid_t p : loaders) kill(p, SIGKILL);
  for (pid_t p : loaders) waitpid(p, nullptr, 0);

  // Memory: growth after the first minute (or the first tenth of a short run).
  const double settle = std::min(60.0, 0.1 * seconds);
  long rss_settled = rss.front().second, rss_max = 0;
  for (const auto& [t, b] : rss) {
    if (t <= settle) rss_settled = b;
    rss_max = std::max(rss_max, b);
  }
  const long rss_growth = rss.back().second - rss_settled;
  const RuntimeStats& st = data->stats;
  const long periods = std::max(1L, soak.ticks - 1);
  const double nominal = st.haptic.nominal_period;
  long late = 0;  // periods more than 10% over the nominal one
  for (size_t b = 0; b < soak.period_us.size(); ++b)
    if (1e-6 * static_cast<double>(b) > 1.1 * nominal) late += soak.period_us[b];
  const bool ok = soak.non_finite == 0 && soak.over_limit == 0 && rss_growth < (8L << 20);

  std::string events;
  for (int k = 0; k < kNumRuntimeEventKinds; ++k) {
    const long n = soak.events[k].load();
    if (!n) continue;
    events += std::string(events.empty() ? "" : ", ") + "\"" + to_string(static_cast<RuntimeEventKind>(k)) +
              "\": " + std::to_string(n);
  }
  char buf[4096];
  std::snprintf(
      buf, sizeof buf,
      "{\"scene\": \"%s\", \"seconds\": %.1f, \"load_processes\": %d, \"script_cycles\": %ld,\n"
      " \"haptic\": {\"ticks\": %ld, \"nominal_period\": %.6f, \"period_p50\": %.6f, \"period_p99\": %.6f, "
      "\"period_p999\": %.6f, \"period_max\": %.6f, \"max_jitter\": %.6f, \"deadline_misses\": %ld, "
      "\"periods_over_110pct\": %ld, \"work_mean\": %.3e, \"work_max\": %.3e},\n"
      " \"sim\": {\"steps\": %ld, \"work_mean\": %.3e, \"work_max\": %.3e},\n"
      " \"force\": {\"non_finite\": %ld, \"over_limit\": %ld, \"largest_force\": %.4f, \"largest_torque\": %.4f, "
      "\"max_force\": %.4f, \"max_torque\": %.4f},\n"
      " \"rss\": {\"samples\": %zu, \"first\": %ld, \"settled\": %ld, \"last\": %ld, \"max\": %ld, \"growth\": %ld},\n"
      " \"events\": {%s},\n \"ok\": %s}\n",
      scene_path.c_str(), st.run_seconds, load, device.cycles, soak.ticks, nominal,
      percentile(soak.period_us, periods, 0.5), percentile(soak.period_us, periods, 0.99),
      percentile(soak.period_us, periods, 0.999), st.haptic.period.max, st.haptic.max_jitter, st.haptic.overruns, late,
      st.haptic.work.mean(), st.haptic.work.max, st.sim.work.count, st.sim.work.mean(), st.sim.work.max,
      soak.non_finite, soak.over_limit, soak.largest_force, soak.largest_torque, soak.max_force, soak.max_torque,
      rss.size(), rss.front().second, rss_settled, rss.back().second, rss_max, rss_growth, events.c_str(),
      ok ? "true" : "false");
  std::fputs(buf, stdout);
  if (!json_path.empty()) std::ofstream(json_path) << buf;
  return ok ? 0 : 1;
}
