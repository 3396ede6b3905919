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

// The god-object updates' budget (RuntimeSettings::budget, docs/sim-step.md):
// how often it ran out, for how many updates in a row, what it left of the
// command, and the updates' CPU time and work against it.
struct BudgetStats {
  long updates = 0;                    // updates recorded (add)
  long exhausted = 0;                  // ... that ran out of their budget
  long longest_run = 0;                // most updates in a row that ran out
  long run = 0;                        // internal: the current run
  double deferred_max = 0, deferred_sum = 0;  // SimStepInfo::budget_deferred over the updates that ran out
  long max_work_units = 0;             // SimStepInfo::work_units, max
  double max_cpu = 0;                  // SimStepInfo::update_cpu_seconds, max (s): the whole sim step
  void add(const SimStepInfo& info);
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
  BudgetStats budget;                  // the sim loop: its updates' budget
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
