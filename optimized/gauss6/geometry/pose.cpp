// Poses, pose difference and pose update (METHOD.md section 1).
#include "gauss6/geometry/pose.h"

#include <algorithm>
#include <cmath>

namespace gauss6 {

Quat operator*(const Quat& a, const Quat& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
          a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
          a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

Quat conjugate(const Quat& q) { return {q.w, -q.x, -q.y, -q.z}; }

namespace {
constexpr int kMaxQuatExponent = 400;  // largest component kept in [2^-400, 2^400]

double max_abs_component(const Quat& q) {
  return std::max(std::max(std::abs(q.w), std::abs(q.x)), std::max(std::abs(q.y), std::abs(q.z)));
}
}  // namespace

Quat rescaled(const Quat& q) {
  const double m = max_abs_component(q);
  if (!(m > 0) || !std::isfinite(m)) return q;
  int e = 0;
  std::frexp(m, &e);  // m = f 2^e, f in [0.5, 1)
  if (e >= -kMaxQuatExponent && e <= kMaxQuatExponent) return q;
  // Components that fall below the smallest double are < 2^-1074 of the largest:
  // their part of the rotation is below rounding.
  return {std::ldexp(q.w, -e), std::ldexp(q.x, -e), std::ldexp(q.y, -e), std::ldexp(q.z, -e)};
}

Quat normalized(const Quat& q_in) {
  const Quat q = rescaled(q_in);
  const double n = std::sqrt(q.norm2());
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}

Mat3 rotation_matrix(const Quat& q_in) {
  // Rational form: every entry is a quadratic in (w, x, y, z) over |q|^2, of degree 0:
  // rescaling by a power of two changes no bit of it, and keeps |q|^2 finite.
  const Quat q = rescaled(q_in);
  const double w = q.w, x = q.x, y = q.y, z = q.z;
  const double s = q.norm2();
  Mat3 R;
  R << w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y),
       2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x),
       2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z;
  return R / s;
}

Vec3 transform_point(const Pose& X_WB, const Vec3& r_B) {
  return X_WB.p + rotation_matrix(X_WB.q) * r_B;
}

Quat quat_exp(const Vec3& v) {
  const double angle = v.norm();
  // sin(angle/2)/angle, by its series near 0 so that tiny rotations stay exact to rounding.
  const double k = angle < 1e-8 ? 0.5 - angle * angle / 48.0 : std::sin(0.5 * angle) / angle;
  return {std::cos(0.5 * angle), k * v.x(), k * v.y(), k * v.z()};
}

Vec3 quat_log(const Quat& q_in) {
  // Shortest way round: q and -q are the same rotation; take the one with w >= 0.
  Quat q = normalized(q_in);
  if (q.w < 0) q = {-q.w, -q.x, -q.y, -q.z};
  const Vec3 v = q.vec();
  const double s = v.norm();
  if (s == 0) return Vec3::Zero();
  const double angle = 2.0 * std::atan2(s, q.w);  // in [0, pi]
  return v * (angle / s);
}

Vec6 pose_difference(const Pose& xh, const Pose& xs) {
  Vec6 d;
  d.head<3>() = xh.p - xs.p;
  d.tail<3>() = quat_log(xh.q * conjugate(xs.q));
  return d;
}

Pose pose_update(const Pose& xs, const Vec6& a) {
  Pose x;
  x.p = xs.p + a.head<3>();
  x.q = normalized(quat_exp(a.tail<3>()) * xs.q);
  return x;
}

bool is_valid_pose(const Pose& x) {
  const bool finite = x.p.allFinite() && std::isfinite(x.q.w) && std::isfinite(x.q.x) &&
                      std::isfinite(x.q.y) && std::isfinite(x.q.z);
  if (!finite) return false;
  const double m = max_abs_component(x.q);
  return m >= std::ldexp(1.0, -kMaxQuatExponent - 1) && m < std::ldexp(1.0, kMaxQuatExponent);
}

Pose to_pose(const double p[3], const double q[4]) {
  Pose x;
  x.p = Vec3(p[0], p[1], p[2]);
  x.q = Quat{q[0], q[1], q[2], q[3]};
  return x;
}

}  // namespace gauss6
