// The budget of one god-object update (update_budget.h): its start, and the
// check of the CPU clock and the work count.
#include "gauss6/step/update_budget.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <time.h>

namespace gauss6 {

namespace {
// The calling thread's CPU time (s): CLOCK_THREAD_CPUTIME_ID, a system call.
double thread_cpu_now() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
}  // namespace

const char* update_budget_settings_problem(const UpdateBudgetSettings& s) {
  if (!(s.cpu_seconds >= 0 && std::isfinite(s.cpu_seconds))) return "budget.cpu_seconds must be >= 0 and finite";
  if (s.work_units < 0) return "budget.work_units must be >= 0";
  if (s.check_interval < 1) return "budget.check_interval must be >= 1";
  return nullptr;
}

void UpdateBudget::start(const UpdateBudgetSettings& settings) noexcept {
  settings_ = settings;
  used_ = 0;
  for (long& p : pieces_) p = 0;
  exhausted_ = false;
  cpu_start_ = settings.cpu_seconds > 0 ? thread_cpu_now() : 0.0;
  // No budget: never checked. A count alone: checked when it is reached.
  next_check_ = !settings.active() ? std::numeric_limits<long>::max()
                : settings.cpu_seconds > 0
                    ? (settings.work_units > 0 ? std::min(settings.check_interval, settings.work_units)
                                               : settings.check_interval)
                    : settings.work_units;
}

void UpdateBudget::check() noexcept {
  if (exhausted_) return;
  const UpdateBudgetSettings& s = settings_;
  if (s.work_units > 0 && used_ >= s.work_units) exhausted_ = true;
  if (!exhausted_ && s.cpu_seconds > 0 && thread_cpu_now() - cpu_start_ >= s.cpu_seconds)
    exhausted_ = true;
  if (exhausted_) {
    next_check_ = std::numeric_limits<long>::max();
    return;
  }
  // The next check: check_interval units on (a time budget), or the count's end, whichever first.
  long next = s.cpu_seconds > 0 ? used_ + s.check_interval : std::numeric_limits<long>::max();
  if (s.work_units > 0) next = std::min(next, s.work_units);
  next_check_ = next;
}

}  // namespace gauss6
