// Motion bounds, the out-of-line half of motion_bounds.h: swept boxes from
// the motion's interval enclosure, the god-object's frame at a sub-interval's
// start (StartFrame::set, StartFrame::obb_frame) and the displacement between
// two poses.
#include "gauss6/motion_bounds.h"

#include <cmath>

namespace gauss6 {

Aabb swept_box(const MotionEnclosure& e, const Aabb& body) {
  const IVec3 r = {Interval{body.lo.x(), body.hi.x()}, Interval{body.lo.y(), body.hi.y()},
                   Interval{body.lo.z(), body.hi.z()}};
  const IVec3 w = enclose_point(e, r);
  return {Vec3(w[0].lo, w[1].lo, w[2].lo), Vec3(w[0].hi, w[1].hi, w[2].hi)};
}

namespace detail {

void StartFrame::set(const CcdMotion& m, double u, double rho_in) {
  const StopPose sp = make_stop_pose(m, u, rho_in);
  u0 = u;
  rho = rho_in;
  R = rotation_matrix(sp.pose.q);
  p = sp.pose.p;
  double dp2 = 0, drift2 = 0;
  for (int i = 0; i < 3; ++i) {
    const Interval& c = m.dp[i];
    const double a = std::max(std::abs(c.lo), std::abs(c.hi));
    dp2 = next_up(dp2 + next_up(a * a));
    dp_mid[i] = 0.5 * c.lo + 0.5 * c.hi;
    const double r = std::max(next_up(c.hi - dp_mid[i]), next_up(dp_mid[i] - c.lo));
    drift2 = next_up(drift2 + next_up(r * r));
  }
  drift = next_up(std::sqrt(drift2));
  turn_rate = next_up(2 * next_up(std::sqrt(m.g2.hi)));
  double g_err2 = 0;
  for (int i = 0; i < 3; ++i) {
    const Interval& c = m.g[i];
    omega[i] = c.lo + c.hi;  // 2 g_mid (exact: doubling)
    const double r = std::max(next_up(c.hi - 0.5 * (c.lo + c.hi)), next_up(0.5 * (c.lo + c.hi) - c.lo));
    g_err2 = next_up(g_err2 + next_up(r * r));
  }
  omega_error = next_up(2 * next_up(std::sqrt(g_err2)));
  omega2 = next_up(4 * m.g2.hi);
  g2 = m.g2.hi;
  omega_norm = next_up(omega.norm() * (1 + 1e-15));
  dp_max = next_up(std::sqrt(dp2));
  speed = next_up(dp_max + next_up(turn_rate * rho));
  static_error = next_up(sp.deviation + next_up(1e-13 * next_up(p.cwiseAbs().maxCoeff() + rho)));
  if (!std::isfinite(static_error) || !std::isfinite(speed) || !std::isfinite(drift) || !dp_mid.allFinite() ||
      !omega.allFinite() || !std::isfinite(omega_error) || !std::isfinite(omega2)) {
    static_error = speed = drift = turn_rate = dp_max = std::numeric_limits<double>::infinity();
    omega.setZero();
    omega_norm = 0;
  }
}

SweptObbFrame StartFrame::obb_frame(double u1, double d) const {
  SweptObbFrame f;
  f.R = R;
  f.p = p;
  const double span = next_up(u1 - u0);
  f.step = (u1 - u0) * dp_mid;
  f.spin = (u1 - u0) * omega;
  f.spread = next_up(span * omega_norm);
  // The step's own rounding (relative 2^-53 per coordinate) joins the drift.
  const double step_error = next_up(1e-15 * f.step.cwiseAbs().maxCoeff() * 2);
  const double offsets = next_up(next_up(span * next_up(turn_rate + omega_norm)) * next_up(2 * static_error));
  f.grow = next_up(next_up(next_up(static_error + d) + next_up(next_up(span * drift) + step_error)) + offsets);
  const double rest = next_up(next_up(omega_error + next_up(lag(span) * omega_norm)) + next_up(0.5 * next_up(span * omega2)));
  f.turn = next_up(span * rest);
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
  turn = next_up(next_up(2 * v.norm()) + 1e-14);
  shift = next_up((b.p - a.p).norm() * (1 + 1e-15));
  if (!(turn < std::numeric_limits<double>::infinity() && shift < std::numeric_limits<double>::infinity()))
    turn = shift = std::numeric_limits<double>::infinity();
}

}  // namespace detail

}  // namespace gauss6
