// The coupling force Fc = kh M (ac - au) (METHOD.md section 3). See coupling.h.
#include "gauss6/contact/coupling.h"

#include <cmath>

namespace gauss6 {

bool valid_coupling_gain(double kh) noexcept { return std::isfinite(kh) && kh > 0; }

Vec6 coupling_force(const Mat6& M, const Vec6& au, const Vec6& ac, double kh) noexcept {
  if (!valid_coupling_gain(kh)) return Vec6::Zero();
  const Vec6 F = kh * (M * (ac - au));
  return F.allFinite() ? F : Vec6::Zero();
}

}  // namespace gauss6
