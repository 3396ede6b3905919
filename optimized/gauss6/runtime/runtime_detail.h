// Machinery the runtime's loops share (sim_loop.cpp, coupling_loop.cpp,
// haptic_loop.cpp, runtime.cpp): the clock, event bits and their onsets, and
// the copy of a pose into a channel payload. Not part of the public headers.
#pragma once

#include <time.h>

#include <chrono>
#include <cstdint>

#include "gauss6/runtime/runtime_channels.h"
#include "gauss6/runtime/runtime_events.h"
#include "gauss6/runtime/runtime_stats.h"

namespace gauss6::detail {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// CPU time of the calling thread (s): unlike the wall clock, it leaves out the
// time the thread was preempted, which on a loaded machine is most of a wall p99.
inline double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Reports the conditions of `events` that did not hold last time (gate->active),
// counts each in stats, and hands them to the observer rate-limited by the gate
// (EventGate, runtime_events.h): a kind reported less than `interval` ago is
// counted as pending; pending onsets go out as one event (count = their
// number) once `interval` has passed.
inline void emit_event(RuntimeEventKind kind, double t, uint64_t tick, int detail, uint32_t count,
                       const RuntimeObserver& observer) {
  if (!observer.on_event) return;
  RuntimeEvent e;
  e.kind = kind;
  e.time = t;
  e.tick = tick;
  e.detail = detail;
  e.count = count;
  observer.on_event(observer.user, e);
}

inline void report_onsets(uint32_t events, EventGate* gate, double interval, double t, uint64_t tick,
                          const RuntimeObserver& observer, LoopStats* stats, int detail = 0) {
  const uint32_t onset = events & ~gate->active;
  gate->active = events;
  for (int k = 0; k < kNumRuntimeEventKinds; ++k) {
    const bool due = !gate->reported[k] || t - gate->last_report[k] >= interval;
    if (onset & (1u << k)) {
      ++stats->event_counts[k];
      if (!due) {
        if (gate->pending[k]++ == 0) gate->pending_tick[k] = tick;
        gate->pending_detail[k] = detail;
        continue;
      }
      emit_event(static_cast<RuntimeEventKind>(k), t, tick, detail, gate->pending[k] + 1, observer);
    } else if (gate->pending[k] && due) {
      emit_event(static_cast<RuntimeEventKind>(k), t, gate->pending_tick[k], gate->pending_detail[k],
                 gate->pending[k], observer);
    } else {
      continue;
    }
    gate->pending[k] = 0;
    gate->reported[k] = true;
    gate->last_report[k] = t;
  }
}

// At the end of a run: the onsets still pending go out (time t).
inline void flush_events(EventGate* gate, double t, const RuntimeObserver& observer) {
  for (int k = 0; k < kNumRuntimeEventKinds; ++k) {
    if (!gate->pending[k]) continue;
    emit_event(static_cast<RuntimeEventKind>(k), t, gate->pending_tick[k], gate->pending_detail[k], gate->pending[k],
               observer);
    gate->pending[k] = 0;
    gate->reported[k] = true;
    gate->last_report[k] = t;
  }
}

inline void store_pose(const Pose& x, double p[3], double q[4]) {
  for (int i = 0; i < 3; ++i) p[i] = x.p[i];
  q[0] = x.q.w, q[1] = x.q.x, q[2] = x.q.y, q[3] = x.q.z;
}

// Step 1 of the sim and coupling loops: the latest handle sample (false when
// none was published yet).
inline bool read_handle(const RuntimeChannels& ch, HandleSample* sample) { return ch.handle.try_read(sample); }

inline bool projection_failed(ProjectionStatus s) {
  return s == ProjectionStatus::kBadInput || s == ProjectionStatus::kIterationCap ||
         s == ProjectionStatus::kUncertified;
}

}  // namespace gauss6::detail
