// Motion bounds, the out-of-line half of motion_bounds.h: swept boxes from
// the motion's interval enclosure, the god-object's frame at a sub-interval's
// start (StartFrame::set, StartFrame::obb_frame) and the displacement between
// two poses.
#include "gauss6/ccd/motion_bounds.h"

#include <cmath>

#include "gauss6/numeric/error_allowances.h"

namespace gauss6 {

// In midpoint-radius form: with R within R_rad of R_mid and r within h of c,
// R r = R_mid c + R_mid (r - c) + (R - R_mid) r lies within |R_mid| h + R_rad
// (|c| + h) of R_mid c, rounding covered by kBoxProductRounding (its argument in
// error_allowances.h). A third of the work of the interval product (nine
// interval products of a box and an interval matrix), and as tight but for
// at most 2 R_rad h, the product of the two radii (the matrix's from the
// motion over the sub-interval, small).
Aabb swept_box(const MotionEnclosure& e, const Aabb& body) {
  const Vec3 c = 0.5 * body.lo + 0.5 * body.hi;
  Vec3 h;
  for (int i = 0; i < 3; ++i) h[i] = next_up(std::max(body.hi[i] - c[i], c[i] - body.lo[i]));
  const Vec3 reach = c.cwiseAbs() + h;
  const Vec3 centre = e.R_mid * c;
  const Vec3 half = e.R_abs * h + e.R_rad * reach;
  const Vec3 scale = (e.R_abs + e.R_rad) * reach;
  Aabb w;
  for (int i = 0; i < 3; ++i) {
    const Upper grow = Upper{half[i]} + (Upper{kBoxProductRounding} * Upper{scale[i]} + Upper{kUnderflowFloor});
    const Interval local = {(Lower{centre[i]} - grow).v, (Upper{centre[i]} + grow).v};
    const Interval world = e.p[i] + local;
    w.lo[i] = world.lo;
    w.hi[i] = world.hi;
  }
  return w;
}

namespace detail {

void StartFrame::set(const CcdMotion& m, double u, double rho_in) {
  const StopPose sp = make_stop_pose(m, u, rho_in);
  u0 = u;
  rho = rho_in;
  R = rotation_matrix(sp.pose.q);
  p = sp.pose.p;
  Upper drift2{0};
  for (int i = 0; i < 3; ++i) {
    const Interval& c = m.dp[i];
    dp_mid[i] = 0.5 * c.lo + 0.5 * c.hi;
    drift2 = drift2 + sqr(distance_from(c, dp_mid[i]));
  }
  drift = sqrt(drift2).v;
  const Upper g_norm2{m.g2.hi};
  turn_rate = (2 * sqrt(g_norm2)).v;
  Upper g_err2{0};
  for (int i = 0; i < 3; ++i) {
    const Interval& c = m.g[i];
    omega[i] = c.lo + c.hi;  // 2 g_mid (exact: doubling)
    g_err2 = g_err2 + sqr(distance_from(c, 0.5 * (c.lo + c.hi)));
  }
  omega_error = (2 * sqrt(g_err2)).v;
  omega2 = (4 * g_norm2).v;
  g2 = g_norm2.v;
  omega_norm = norm_up(omega.norm(), kRelativeRounding).v;
  dp_max = norm_upper(m.dp).v;
  speed = (Upper{dp_max} + Upper{turn_rate} * Upper{rho}).v;
  const Upper p_inf{p.cwiseAbs().maxCoeff()};
  static_error = (Upper{sp.deviation} + kPoseRounding * (p_inf + Upper{rho})).v;
  if (!std::isfinite(static_error) || !std::isfinite(speed) || !std::isfinite(drift) || !dp_mid.allFinite() ||
      !omega.allFinite() || !std::isfinite(omega_error) || !std::isfinite(omega2)) {
    static_error = speed = drift = turn_rate = dp_max = std::numeric_limits<double>::infinity();
    omega.setZero();
    omega_norm = 0;
  }
}

SweptObbFrame StartFrame::obb_frame(double u1, double d) const {
  SweptObbFrame f;
  f.set_rotation(R);
  f.p = p;
  const Upper span = Upper{u1} - Lower{u0};
  const Upper omega_n{omega_norm}, error{static_error};
  f.step = (u1 - u0) * dp_mid;
  f.spin = (u1 - u0) * omega;
  f.spread = (span * omega_n).v;
  // The step's own rounding (two roundings per coordinate) joins the drift.
  const Upper step_error = round_up(kRelativeRounding * f.step.cwiseAbs().maxCoeff() * 2);
  const Upper offsets = span * (Upper{turn_rate} + omega_n) * (2 * error);
  f.grow = (((error + Upper{d}) + (span * Upper{drift} + step_error)) + offsets).v;
  const Upper rest = (Upper{omega_error} + Upper{lag(span.v)} * omega_n) + 0.5 * (span * Upper{omega2});
  f.turn = (span * rest).v;
  if (!std::isfinite(f.grow) || !std::isfinite(f.turn) || !std::isfinite(f.spread) || !f.step.allFinite() ||
      !f.spin.allFinite()) {
    f.grow = std::numeric_limits<double>::infinity();
    f.step.setZero();
    f.spin.setZero();
    f.spread = 0;
  }
  return f;
}

Displacement::Displacement(const Pose& a, const Pose& b) {
  const Quat qa = normalized(a.q), qb = normalized(b.q);
  const Vec3 v = qa.w * qb.vec() - qb.w * qa.vec() - qa.vec().cross(qb.vec());  // vec(conj(qa) qb)
  turn = (round_up(2 * v.norm()) + Upper{kQuaternionTurnRounding}).v;
  shift = norm_up((b.p - a.p).norm(), kRelativeRounding).v;
  if (!(turn < std::numeric_limits<double>::infinity() && shift < std::numeric_limits<double>::infinity()))
    turn = shift = std::numeric_limits<double>::infinity();
}

}  // namespace detail

}  // namespace gauss6
