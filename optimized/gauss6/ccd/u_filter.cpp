// The u-filter's helpers that are no template (u_filter.h): the triangle
// parameters of a guide's closest point, and the filter's whole-window axis test.
#include "gauss6/ccd/u_filter.h"

namespace gauss6::ccd_detail {

void triangle_parameters(const Vec3& c, const Vec3& t0, const Vec3& t1, const Vec3& t2, double* a, double* b) {
  const Vec3 e1 = t1 - t0, e2 = t2 - t0, w = c - t0;
  const double d11 = e1.dot(e1), d12 = e1.dot(e2), d22 = e2.dot(e2), w1 = w.dot(e1), w2 = w.dot(e2);
  const double det = d11 * d22 - d12 * d12;
  double x = 0, y = 0;
  if (det > 0 && std::isfinite(det)) {
    x = (w1 * d22 - w2 * d12) / det;
    y = (w2 * d11 - w1 * d12) / det;
  }
  x = std::isfinite(x) ? std::clamp(x, 0.0, 1.0) : 0.0;
  y = std::isfinite(y) ? std::clamp(y, 0.0, 1.0 - x) : 0.0;
  *a = x;
  *b = y;
}

bool axis_clears(const UFilter& filter, double u_begin, double u_end, CcdResult* r) {
  if (filter.axis.num_corners == 0 || !filter.excludes(u_begin, u_end)) return false;
  *r = CcdResult{};
  r->status = CcdStatus::kOk;
  r->hit = false;
  r->u_hit = u_end;
  r->filter_intervals = 1;  // the whole window, once
  return true;
}

}  // namespace gauss6::ccd_detail
