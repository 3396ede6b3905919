// Running sums of the loops' timing statistics (runtime_stats.h).
#include "gauss6/runtime/runtime_stats.h"

namespace gauss6 {

void DurationStats::add(double seconds) {
  if (count == 0 || seconds < min) min = seconds;
  if (count == 0 || seconds > max) max = seconds;
  sum += seconds;
  ++count;
}

void LoopStats::add_start(double t) {
  if (last_start >= 0) period.add(t - last_start);
  last_start = t;
}

}  // namespace gauss6
