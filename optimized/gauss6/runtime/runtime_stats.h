// Timing statistics of the runtime's loops (runtime.h): running sums of
// periods and work times, jitter and overruns, and event counts. No
// allocation: each loop updates its own LoopStats in place.
//
// Units: seconds.
#pragma once

#include "gauss6/runtime/runtime_events.h"

namespace gauss6 {

// ---------------------------------------------------------------------------
// Timing statistics (no allocation: running sums).
// ---------------------------------------------------------------------------

struct DurationStats {
  long count = 0;
  double min = 0, max = 0, sum = 0;    // s
  double mean() const { return count ? sum / count : 0; }
  void add(double seconds);
};

// One loop's statistics, written only by the thread that runs the loop. In
// lockstep runs, periods are virtual (exact) and work times are real.
struct LoopStats {
  double nominal_period = 0;           // s (0: free-running loop)
  DurationStats period;                // between successive starts
  DurationStats work;                  // the step itself (force computation / god-object update)
  double max_jitter = 0;               // paced loops: max |actual start - scheduled start| (s)
  long overruns = 0;                   // paced loops: starts more than one period late (the schedule then resyncs)
  long event_counts[kNumRuntimeEventKinds] = {};  // events reported by this loop (onsets)
  // Threaded runs (RuntimeSettings::realtime_priority, pin_threads): 1 SCHED_FIFO applied at
  // realtime_priority_applied, 0 not asked, -errno refused (EPERM: no CAP_SYS_NICE, no RT budget);
  // pinned_cpu the CPU the thread is bound to (-1: not pinned), pin_error -errno when refused.
  int realtime = 0;
  int realtime_priority_applied = 0;
  int pinned_cpu = -1;
  int pin_error = 0;
  double last_start = -1;              // s, internal
  void add_start(double t);            // records a start at t (updates period)
};

struct RuntimeStats {
  LoopStats haptic, coupling, sim;     // coupling: filled by the haptic loop with kHapticTick
  LoopStats watchdog;                  // threaded runs: the watchdog thread's events (kHapticStalled)
  double run_seconds = 0;              // wall time (threaded) or virtual time (lockstep)
};

}  // namespace gauss6
