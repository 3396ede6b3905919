// The coupling force Fc = kh M (ac - au) and the constraint offsets of new
// contacts (METHOD.md section 3). See coupling.h.
#include "gauss6/coupling.h"

#include <algorithm>
#include <cmath>

namespace gauss6 {

Vec6 coupling_force(const Mat6& M, const Vec6& au, const Vec6& ac, double kh) noexcept {
  const Vec6 F = kh * (M * (ac - au));
  return F.allFinite() ? F : Vec6::Zero();
}

bool valid_offset_settings(const OffsetSettings& s) noexcept {
  return std::isfinite(s.eps) && s.eps < 0 && std::isfinite(s.T) && s.T > 0;
}

bool needs_offset(double d_k, const OffsetSettings& s) noexcept { return d_k < s.eps; }

double offset_rhs(double d_k, double t, const OffsetSettings& s) noexcept {
  const double u = std::clamp(t / s.T, 0.0, 1.0);
  const double smooth = u * u * (3.0 - 2.0 * u);
  return u >= 1.0 ? 0.0 : d_k * (1.0 - smooth);
}

int begin_offsets(std::span<const double> J, int num_rows, const Vec6& au,
                  const OffsetSettings& s, std::span<double> start_values) noexcept {
  const int n = std::clamp(num_rows, 0, static_cast<int>(std::min(start_values.size(), J.size() / 6)));
  const bool valid = valid_offset_settings(s) && au.allFinite();
  int count = 0;
  for (int k = 0; k < n; ++k) {
    const double d = Eigen::Map<const Vec6>(J.data() + 6 * k).dot(au);
    const bool offset = valid && std::isfinite(d) && needs_offset(d, s);
    start_values[k] = offset ? d : 0.0;
    count += offset ? 1 : 0;
  }
  return count;
}

bool fill_offset_rhs(std::span<const double> start_values, int num_rows, double t,
                     const OffsetSettings& s, std::span<double> b) noexcept {
  const int n = std::clamp(num_rows, 0, static_cast<int>(std::min(start_values.size(), b.size())));
  const bool valid = valid_offset_settings(s) && !std::isnan(t);
  bool running = false;
  for (int k = 0; k < n; ++k) {
    b[k] = valid ? offset_rhs(start_values[k], t, s) : 0.0;
    running = running || b[k] < 0;
  }
  return running;
}

}  // namespace gauss6
