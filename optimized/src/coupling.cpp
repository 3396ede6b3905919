// The coupling force Fc = kh M (ac - au) (METHOD.md section 3). See coupling.h.
#include "gauss6/coupling.h"

namespace gauss6 {

Vec6 coupling_force(const Mat6& M, const Vec6& au, const Vec6& ac, double kh) noexcept {
  const Vec6 F = kh * (M * (ac - au));
  return F.allFinite() ? F : Vec6::Zero();
}

}  // namespace gauss6
