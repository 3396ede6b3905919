// The narrow phase's API pieces that belong to no one algorithm: the names of
// its statuses and the workspace's box array. The algorithms, one a file:
// bisection.h (the box bisection over (u, a, b)), u_filter.h (the u-filter and
// the filtered bisection), rigid_queries.cpp (Cayley rigid motion) and
// linear_queries.cpp (linear motion: its enclosure, the queries). See ccd.h
// for the guarantee and the rounding argument.
#include "gauss6/ccd/ccd.h"

#include <algorithm>

namespace gauss6 {

const char* to_string(CcdStatus s) {
  switch (s) {
    case CcdStatus::kOk: return "ok";
    case CcdStatus::kMaxIterations: return "max_iterations: gave up, hit reported conservatively";
    case CcdStatus::kWorkspaceFull: return "workspace_full: box queue full, hit reported conservatively";
    case CcdStatus::kInvalidInput: return "invalid_input: non-finite or huge coordinate, or bad window/settings";
    case CcdStatus::kHalfTurn: return "half_turn: relative rotation near 180 degrees, split the step";
  }
  return "unknown";
}

CcdWorkspace::CcdWorkspace(int capacity) : boxes_(static_cast<size_t>(std::max(capacity, 16))) {}

}  // namespace gauss6
