// Running sums of the loops' timing statistics (runtime_stats.h).
#include "gauss6/runtime/runtime_stats.h"

namespace gauss6 {

void DurationStats::add(double seconds) {
  if (count == 0 || seconds < min) min = seconds;
  if (count == 0 || seconds > max) max = seconds;
  sum += seconds;
  ++count;
}

void BudgetStats::add(const SimStepInfo& info) {
  ++updates;
  run = info.budget_exhausted ? run + 1 : 0;
  if (run > longest_run) longest_run = run;
  if (info.budget_exhausted) {
    ++exhausted;
    deferred_sum += info.budget_deferred;
    if (info.budget_deferred > deferred_max) deferred_max = info.budget_deferred;
  }
  if (info.work_units > max_work_units) max_work_units = info.work_units;
  if (info.update_cpu_seconds > max_cpu) max_cpu = info.update_cpu_seconds;
}

void LoopStats::add_start(double t) {
  if (last_start >= 0) period.add(t - last_start);
  last_start = t;
}

}  // namespace gauss6
