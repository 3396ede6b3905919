// The box bisection's input checks and refusal (bisection.h), shared by every
// narrow-phase query.
#include "gauss6/ccd/bisection.h"

#include <cmath>

namespace gauss6::ccd_detail {

bool valid_window(double u0, double u1) { return 0 <= u0 && u0 <= u1 && u1 <= 1; }
bool valid_settings(const CcdSettings& s) {
  return s.time_tolerance > 0 && s.distance_tolerance > 0 && s.min_separation >= 0 &&
         std::isfinite(s.min_separation) && std::isfinite(s.distance_tolerance) && s.max_iterations > 0;
}

void refuse(double u_end, CcdResult* r) {
  *r = CcdResult{};
  r->status = CcdStatus::kInvalidInput;
  r->hit = false;
  r->u_hit = u_end;
}

}  // namespace gauss6::ccd_detail
