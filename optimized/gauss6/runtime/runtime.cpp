// The two run modes of the three loops, lockstep and threaded (runtime.h).
#include "gauss6/runtime/runtime.h"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cmath>
#include <thread>
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "runtime_detail.h"

namespace gauss6 {

using namespace detail;  // the loops' shared machinery (runtime_detail.h)

RuntimeData::RuntimeData(const RuntimeModel& model)
    : channels(model.settings.max_contacts), sim(model), coupling(model.settings.max_contacts) {
  coupling.xs = model.initial_pose;
  haptic.xh = model.initial_pose;
}

// ---------------------------------------------------------------------------
// Runs.
// ---------------------------------------------------------------------------

namespace {

// A sim step with its statistics, events and hook.
void run_sim_step(const RuntimeModel& model, double t, const RuntimeObserver& observer, RuntimeData* data) {
  const SimStepInfo& info = sim_step(model, t, &data->channels, &data->sim);
  data->stats.sim.add_start(t);
  data->stats.sim.work.add(info.update_seconds);
  data->stats.sim.budget.add(info);
  uint32_t events = data->sim.step_events;
  if (info.ccd != CcdStatus::kOk) events |= event_bit(RuntimeEventKind::kCcdGaveUp);
  if (projection_failed(info.projection)) events |= event_bit(RuntimeEventKind::kProjectionFailed);
  report_onsets(events, &data->sim.events, model.settings.event_interval, t, info.step, observer, &data->stats.sim,
                static_cast<int>(info.ccd));
  if (observer.on_sim_step) observer.on_sim_step(observer.user, info);
}

// The run's end: every loop's pending (coalesced) events go out.
void flush_all_events(double t, const RuntimeObserver& observer, RuntimeData* data) {
  flush_events(&data->sim.events, t, observer);
  flush_events(&data->coupling.events, t, observer);
  flush_events(&data->haptic.events, t, observer);
}

}  // namespace

namespace {

// One turn of a busy wait: x86's PAUSE, which lets a sibling hyperthread (a VM's
// other vCPU may be one) run while this one waits.
inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  _mm_pause();
#endif
}

// What a loop's thread asks of the OS (RuntimeSettings::realtime_priority,
// pin_threads), called first thing in the thread; the outcome goes to its stats.
// role: 0 haptic, 1 coupling, 2 sim.
void apply_thread_policy(const RuntimeSettings& settings, int role, LoopStats* stats) {
  if (settings.realtime_priority > 0) {
    sched_param p{};
    p.sched_priority = std::max(1, settings.realtime_priority - role);
    const int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
    stats->realtime = err == 0 ? 1 : -err;
    stats->realtime_priority_applied = err == 0 ? p.sched_priority : 0;
  }
  if (settings.pin_threads) {
    const int n = static_cast<int>(std::thread::hardware_concurrency());
    if (n < 2) return;
    cpu_set_t set;
    CPU_ZERO(&set);
    if (role == 0) {
      CPU_SET(n - 1, &set);
    } else {
      for (int c = 0; c < n - 1; ++c) CPU_SET(c, &set);
    }
    const int err = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    stats->pinned_cpu = err == 0 ? (role == 0 ? n - 1 : 0) : -1;
    stats->pin_error = err == 0 ? 0 : -err;
  }
}

}  // namespace

void run_lockstep(const RuntimeModel& model, Device* device, long num_ticks, const RuntimeObserver& observer,
                  RuntimeData* data) {
  const double rate = model.device.rate_hz;
  const int n = model.settings.lockstep_sim_period;
  data->stats.haptic.nominal_period = 1 / rate;
  data->stats.sim.nominal_period = n / rate;
  double t = 0;
  for (long k = 0; k < num_ticks; ++k) {
    t = static_cast<double>(k) / rate;  // virtual clock
    if (k % n == 0) run_sim_step(model, t, observer, data);
    data->stats.haptic.add_start(t);
    if (!haptic_tick(model, t, device, &data->channels, &data->haptic, &data->coupling, observer, &data->stats))
      break;
  }
  device->write(t, Vec6::Zero());  // leave the handle without force
  flush_all_events(t, observer, data);
  data->stats.run_seconds = t;
}

void run_threaded(const RuntimeModel& model, Device* device, double seconds, const std::atomic<bool>* stop,
                  const RuntimeObserver& observer, RuntimeData* data) {
  const RuntimeSettings& settings = model.settings;
  const bool coupling_thread = settings.force_source == ForceSource::kCouplingLoop;
  const double period = 1 / model.device.rate_hz;
  std::atomic<bool> quit{false};
  const Clock::time_point start = Clock::now();
  auto at = [&](double s) { return start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s)); };
  data->stats.haptic.nominal_period = period;
  data->stats.sim.nominal_period = settings.sim_min_period;
  data->stats.coupling.nominal_period = coupling_thread ? settings.coupling_min_period : period;

  // Sim loop: as fast as it goes, at most one step per sim_min_period.
  std::thread sim([&] {
    apply_thread_policy(settings, 2, &data->stats.sim);
    while (!quit.load(std::memory_order_acquire)) {
      const double t = seconds_since(start);
      run_sim_step(model, t, observer, data);
      if (settings.sim_min_period > 0) std::this_thread::sleep_until(at(t + settings.sim_min_period));
    }
  });

  // Coupling loop (kCouplingLoop): back to back, or at most one step per coupling_min_period.
  std::thread coupling;
  if (coupling_thread) {
    coupling = std::thread([&] {
      apply_thread_policy(settings, 1, &data->stats.coupling);
      while (!quit.load(std::memory_order_acquire)) {
        const double t = seconds_since(start);
        const CouplingStepInfo& info = coupling_step(model, t, &data->channels, &data->coupling);
        data->stats.coupling.add_start(t);
        data->stats.coupling.work.add(info.force_seconds);
        const uint32_t events = projection_failed(info.projection) ? event_bit(RuntimeEventKind::kProjectionFailed) : 0;
        report_onsets(events, &data->coupling.events, settings.event_interval, t, info.god_sequence, observer,
                      &data->stats.coupling);
        if (observer.on_coupling_step) observer.on_coupling_step(observer.user, info);
        if (settings.coupling_min_period > 0) std::this_thread::sleep_until(at(t + settings.coupling_min_period));
        else std::this_thread::yield();
      }
    });
  }

  // Haptic loop: fixed rate, sleep_until pacing (the last spin_wait of each
  // wait busy: RuntimeSettings::spin_wait); a late start beyond one period
  // is an overrun and the schedule resyncs to now. It marks the run time each
  // tick ends at for the watchdog (haptic_alive).
  std::atomic<double> haptic_alive{0};
  std::thread haptic([&] {
    LoopStats& hs = data->stats.haptic;
    apply_thread_policy(settings, 0, &hs);
    double scheduled = 0, t = 0;
    for (;;) {
      std::this_thread::sleep_until(at(scheduled - settings.spin_wait));  // spin_wait 0: to the tick itself
      while (Clock::now() < at(scheduled)) cpu_relax();
      t = seconds_since(start);
      if (t >= seconds || (stop && stop->load(std::memory_order_acquire))) break;
      const double late = t - scheduled;
      hs.max_jitter = std::max(hs.max_jitter, std::abs(late));
      hs.add_start(t);
      if (!haptic_tick(model, t, device, &data->channels, &data->haptic, coupling_thread ? nullptr : &data->coupling,
                       observer, &data->stats))
        break;
      haptic_alive.store(seconds_since(start), std::memory_order_release);
      if (late > period) {
        ++hs.overruns;
        scheduled = t;  // resync
      }
      scheduled += period;
    }
    device->write(t, Vec6::Zero());  // leave the handle without force
    quit.store(true, std::memory_order_release);
  });

  // Watchdog of the haptic loop, in a thread of its own (the device's watchdog in
  // the haptic tick cannot fire while the tick itself is blocked in read() or
  // write()): when no tick has ended for device_timeout, the device is asked to
  // halt its force from here (Device::halt_force; its status is the event's
  // detail) and kHapticStalled is reported. The tick that finally returns finds
  // its sample late and zeroes the force itself (kDeviceTimeout) until a good one.
  std::thread watchdog([&] {
    EventGate gate;
    bool stalled = false;
    const double poll = std::min(settings.device_timeout / 4, period);
    double t = 0;
    while (!quit.load(std::memory_order_acquire)) {
      std::this_thread::sleep_until(at(t + poll));
      t = seconds_since(start);
      const bool now_stalled = t - haptic_alive.load(std::memory_order_acquire) > settings.device_timeout;
      int detail = 0;
      if (now_stalled && !stalled) detail = static_cast<int>(device->halt_force());
      stalled = now_stalled;
      report_onsets(now_stalled ? event_bit(RuntimeEventKind::kHapticStalled) : 0u, &gate, settings.event_interval, t,
                    /*tick=*/0, observer, &data->stats.watchdog, detail);
    }
    flush_events(&gate, t, observer);
  });

  haptic.join();
  sim.join();
  if (coupling.joinable()) coupling.join();
  watchdog.join();
  data->stats.run_seconds = seconds_since(start);
  flush_all_events(data->stats.run_seconds, observer, data);
}

}  // namespace gauss6
