// The Cayley in-between motion (METHOD.md section 4): in doubles (its poses,
// the split of a half turn), and enclosed for the CCD (its interval
// enclosure over a parameter range, the stop pose and its deviation, the
// distance bound between two motions).
#include "gauss6/ccd/motion.h"

#include <array>
#include <cmath>
#include <limits>

namespace gauss6 {

const char* to_string(MotionStatus s) {
  switch (s) {
    case MotionStatus::kOk: return "ok";
    case MotionStatus::kHalfTurn: return "half_turn: relative rotation above 170 degrees, split the step";
    case MotionStatus::kInvalidPose: return "invalid_pose: non-finite coordinate or zero quaternion";
  }
  return "unknown";
}

static Mat3 cross_matrix(const Vec3& h) {
  Mat3 K;
  K << 0, -h.z(), h.y(), h.z(), 0, -h.x(), -h.y(), h.x(), 0;
  return K;
}

Mat3 cayley_rotation(const Vec3& h) {
  const Mat3 K = cross_matrix(h);
  return Mat3::Identity() + (2.0 / (1.0 + h.squaredNorm())) * (K + K * K);
}

MotionStatus make_cayley_motion(const Pose& x0, const Pose& x1, CayleyMotion* motion) {
  if (!is_valid_pose(x0) || !is_valid_pose(x1)) return MotionStatus::kInvalidPose;
  // Relative rotation qr = q1 conj(q0), its scalar part made >= 0.
  Quat qr = x1.q * conjugate(x0.q);
  if (qr.w < 0) qr = {-qr.w, -qr.x, -qr.y, -qr.z};
  // |g| = tan(theta/2) = |vec| / w; refuse above kMaxMotionAngle (w ~ 0 near a half turn).
  const double vnorm = qr.vec().norm();
  if (vnorm > std::tan(0.5 * kMaxMotionAngle) * qr.w) return MotionStatus::kHalfTurn;
  motion->p0 = x0.p;
  motion->dp = x1.p - x0.p;
  motion->R0 = rotation_matrix(x0.q);
  motion->g = qr.vec() / qr.w;
  return MotionStatus::kOk;
}

Mat3 motion_rotation(const CayleyMotion& m, double u) { return cayley_rotation(u * m.g) * m.R0; }

Vec3 motion_position(const CayleyMotion& m, double u) { return m.p0 + u * m.dp; }

Vec3 motion_point(const CayleyMotion& m, double u, const Vec3& r_B) {
  return motion_position(m, u) + motion_rotation(m, u) * r_B;
}

Pose motion_pose(const CayleyMotion& m, double u) {
  const Eigen::Quaterniond e(motion_rotation(m, u));
  return {motion_position(m, u), normalized(Quat{e.w(), e.x(), e.y(), e.z()})};
}

double motion_angle(const CayleyMotion& m, double u) { return 2.0 * std::atan(u * m.g.norm()); }

// ---------------------------------------------------------------------------
// The Cayley motion, enclosed.
// ---------------------------------------------------------------------------

bool bounded_coordinates(const Vec3& v) {
  return std::abs(v.x()) <= kMaxCoordinate && std::abs(v.y()) <= kMaxCoordinate && std::abs(v.z()) <= kMaxCoordinate;
}

namespace {

// A quaternion (w, x, y, z) with enclosed components.
using IQuat = std::array<Interval, 4>;

// The Hamilton product a b, each component enclosed.
IQuat hamilton(const IQuat& a, const IQuat& b) {
  const Interval aw = a[0], ax = a[1], ay = a[2], az = a[3], bw = b[0], bx = b[1], by = b[2], bz = b[3];
  return {aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
          aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw};
}

// The rational rotation R(q) of pose.h, every entry enclosed; nullopt-like
// false when |q|^2 is not safely positive.
bool rational_rotation(const Quat& q, IMat3* R) {
  const Interval w = Interval::point(q.w), x = Interval::point(q.x), y = Interval::point(q.y),
                 z = Interval::point(q.z);
  const Interval ww = sqr(w), xx = sqr(x), yy = sqr(y), zz = sqr(z);
  const Interval n = ww + xx + yy + zz;
  if (!(n.lo > 0)) return false;
  const Interval xy = x * y, xz = x * z, yz = y * z, wx = w * x, wy = w * y, wz = w * z;
  const Interval e[9] = {ww + xx - yy - zz, 2.0 * (xy - wz),   2.0 * (xz + wy),
                         2.0 * (xy + wz),   ww - xx + yy - zz, 2.0 * (yz - wx),
                         2.0 * (xz - wy),   2.0 * (yz + wx),   ww - xx - yy + zz};
  for (int i = 0; i < 9; ++i) {
    const Interval v = div_positive(e[i], n);
    (*R)[i] = {std::max(v.lo, -1.0), std::min(v.hi, 1.0)};  // exact R is orthogonal
  }
  return true;
}

}  // namespace

MotionStatus make_ccd_motion(const Pose& x0, const Pose& x1, CcdMotion* m) {
  CayleyMotion nominal;
  const MotionStatus st = make_cayley_motion(x0, x1, &nominal);
  if (st != MotionStatus::kOk) return st;
  if (!bounded_coordinates(x0.p) || !bounded_coordinates(x1.p)) return MotionStatus::kInvalidPose;
  CcdMotion out;
  out.nominal = nominal;
  if (!rational_rotation(x0.q, &out.R0)) return MotionStatus::kInvalidPose;
  out.p0 = to_interval(x0.p);
  out.dp = to_interval(x1.p) - out.p0;
  // qr = q1 conj(q0), exactly enclosed (Hamilton product), with the same sign
  // choice as make_cayley_motion (decided on the double value).
  const auto I = [](double v) { return Interval::point(v); };
  const IQuat r = hamilton({I(x1.q.w), I(x1.q.x), I(x1.q.y), I(x1.q.z)}, {I(x0.q.w), -I(x0.q.x), -I(x0.q.y), -I(x0.q.z)});
  Interval rw = r[0], rx = r[1], ry = r[2], rz = r[3];
  const Quat qr_double = x1.q * conjugate(x0.q);
  if (qr_double.w < 0) { rw = -rw; rx = -rx; ry = -ry; rz = -rz; }
  if (!(rw.lo > 0)) return MotionStatus::kHalfTurn;
  out.g = {div_positive(rx, rw), div_positive(ry, rw), div_positive(rz, rw)};
  out.g2 = sqr(out.g[0]) + sqr(out.g[1]) + sqr(out.g[2]);
  // The hypotheses of proofs/MotionEnclosure.v enclose_motion_encloses (its
  // kMaxGibbsSquared, and the lower end at least -1/8): they keep
  // enclose_motion's denominators 1 + u^2 |g|^2 safely positive. A motion
  // within kMaxMotionAngle has |g|^2 <= tan(85 deg)^2 ~ 131, enclosed within
  // rounding of it, so this refuses none of them.
  constexpr double kMaxGibbsSquared = 1e4, kMinGibbsSquaredLower = -0.125;
  if (!(out.g2.lo >= kMinGibbsSquaredLower && out.g2.hi <= kMaxGibbsSquared)) return MotionStatus::kHalfTurn;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out.K2[3 * i + j] = (i == j) ? sqr(out.g[i]) - out.g2 : out.g[i] * out.g[j];
  *m = out;
  return MotionStatus::kOk;
}

// Machine-checked: proofs/MotionEnclosure.v, enclose_motion_encloses (for
// every u of the interval, p(u) in p, every entry of R(u) in R and within R_rad
// of R_mid; hypotheses: 0 <= u.lo <= u.hi <= 1, and make_ccd_motion's check
// of g2), and swept_box_motion (swept_box over it holds every pose).
void enclose_motion(const CcdMotion& m, Interval u, MotionEnclosure* out) {
  // C(u g) = I + alpha(u) [g]x + beta(u) [g]x^2, alpha = 2u / (1 + u^2 s),
  // beta = 2u^2 / (1 + u^2 s), s = |g|^2, u >= 0.
  const Interval s = m.g2;
  const auto den_at = [&](double v) { return Interval::point(1) + sqr(Interval::point(v)) * s; };
  const auto alpha_at = [&](double v) { return div_positive(Interval::point(2 * v), den_at(v)); };
  const auto beta_at = [&](double v) { return div_positive(2.0 * sqr(Interval::point(v)), den_at(v)); };
  // beta = 2 / (1/u^2 + s) increases with u: its range is spanned by the ends.
  const Interval beta = hull(beta_at(u.lo), beta_at(u.hi));
  // alpha increases up to u = 1/sqrt(s), where it is 1/sqrt(s), then decreases;
  // alpha <= 2u always. (2 v is exact: a power-of-two scaling of v in [0, 1].)
  Interval alpha = hull(alpha_at(u.lo), alpha_at(u.hi));
  const bool increasing = (sqr(Interval::point(u.hi)) * s).hi < 1;
  const bool decreasing = (sqr(Interval::point(u.lo)) * s).lo > 1;
  if (!increasing && !decreasing) {
    double cap = 2 * u.hi;
    if (s.lo > 0) cap = std::min(cap, (Upper{1.0} / sqrt(Lower{s.lo})).v);
    alpha.hi = std::max(alpha.hi, cap);
  }
  // C = I + alpha K + beta K^2, K = [g]x.
  const IVec3& g = m.g;
  const Interval zero = Interval::point(0);
  const IMat3 K = {zero, -g[2], g[1], g[2], zero, -g[0], -g[1], g[0], zero};
  IMat3 C;
  for (int i = 0; i < 9; ++i) {
    C[i] = alpha * K[i] + beta * m.K2[i];
    if (i % 4 == 0) C[i] = Interval::point(1) + C[i];
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Interval e = C[3 * i] * m.R0[j] + C[3 * i + 1] * m.R0[3 + j] + C[3 * i + 2] * m.R0[6 + j];
      const Interval r = {std::max(e.lo, -1.0), std::min(e.hi, 1.0)};
      out->R[3 * i + j] = r;
      const double mid = 0.5 * r.lo + 0.5 * r.hi;  // any double will do: the radius covers it
      out->R_mid(i, j) = mid;
      out->R_rad(i, j) = next_up(std::max(r.hi - mid, mid - r.lo));
    }
  out->R_abs = out->R_mid.cwiseAbs();
  out->u = u;
  for (int i = 0; i < 3; ++i) out->p[i] = m.p0[i] + u * m.dp[i];
}

StopPose make_stop_pose(const CcdMotion& m, double u, double body_radius) {
  StopPose out;
  out.pose = motion_pose(m.nominal, u);
  MotionEnclosure e;
  enclose_motion(m, Interval::point(u), &e);
  IMat3 Rq;
  if (!rational_rotation(out.pose.q, &Rq)) {
    out.deviation = std::numeric_limits<double>::infinity();
    return out;
  }
  // Per world axis i: |dp_i| + rho sum_j |dR_ij|, all rounded up.
  Upper sum2{0};
  for (int i = 0; i < 3; ++i) {
    const Interval dp = Interval::point(out.pose.p[i]) - e.p[i];
    Upper row{0};
    for (int j = 0; j < 3; ++j) row = row + magnitude(Rq[3 * i + j] - e.R[3 * i + j]);
    sum2 = sum2 + sqr(magnitude(dp) + body_radius * row);
  }
  out.deviation = sqrt(sum2).v;
  return out;
}

namespace {

// The unit quaternion q / |q| of a pose, enclosed (false when |q| cannot be
// bounded away from 0).
bool unit_quaternion(const Quat& q, IQuat* out) {
  const double c[4] = {q.w, q.x, q.y, q.z};
  Interval n2 = Interval::point(0);
  for (double v : c) n2 = n2 + sqr(Interval::point(v));
  if (!(n2.lo > 0) || !std::isfinite(n2.hi)) return false;
  const Interval n{sqrt(Lower{n2.lo}).v, sqrt(Upper{n2.hi}).v};
  for (int i = 0; i < 4; ++i) (*out)[static_cast<size_t>(i)] = div_positive(Interval::point(c[i]), n);
  return true;
}

template <size_t N>
Upper difference_norm(const std::array<Interval, N>& a, const std::array<Interval, N>& b) {
  Upper s2{0};
  for (size_t i = 0; i < N; ++i) s2 = s2 + sqr(magnitude(a[i] - b[i]));
  return sqrt(s2);
}

}  // namespace

double motion_distance_bound(const Pose& a0, const CcdMotion& a, const Pose& b0, const CcdMotion& b, double ub,
                             double body_radius, double ua) {
  constexpr double kNone = std::numeric_limits<double>::infinity();
  IQuat qa, qb;
  if (!(ub >= 0 && ub <= 1 && ua >= 0 && ua <= 1 && body_radius >= 0) || !unit_quaternion(a0.q, &qa) ||
      !unit_quaternion(b0.q, &qb))
    return kNone;
  // q and -q are the same rotation: b's quaternions taken on a's side.
  if (a0.q.w * b0.q.w + a0.q.x * b0.q.x + a0.q.y * b0.q.y + a0.q.z * b0.q.z < 0)
    for (Interval& c : qb) c = -c;
  // Rotations: max over u = 0, 1 of the affine quaternions' difference.
  IVec3 ga, gb;
  for (int i = 0; i < 3; ++i) {
    ga[static_cast<size_t>(i)] = ua * a.g[static_cast<size_t>(i)];
    gb[static_cast<size_t>(i)] = ub * b.g[static_cast<size_t>(i)];
  }
  // (1, g) q: the affine quaternion at u = 1 of the motion from q with Gibbs vector g.
  const auto at_end = [](const IVec3& g, const IQuat& q) { return hamilton({Interval::point(1), g[0], g[1], g[2]}, q); };
  const Upper turn = max(difference_norm(qa, qb), difference_norm(at_end(ga, qa), at_end(gb, qb)));
  // Positions: max over u = 0, 1 (b's start is b0.p, its position at ub p0 + ub dp; a's likewise at ua).
  IVec3 pa1, pb1;
  for (int i = 0; i < 3; ++i) {
    pa1[static_cast<size_t>(i)] = a.p0[static_cast<size_t>(i)] + ua * a.dp[static_cast<size_t>(i)];
    pb1[static_cast<size_t>(i)] = b.p0[static_cast<size_t>(i)] + ub * b.dp[static_cast<size_t>(i)];
  }
  const Upper shift = max(difference_norm(a.p0, to_interval(b0.p)), difference_norm(pa1, pb1));
  const double bound = (shift + 2.0 * (turn * Upper{body_radius})).v;
  return std::isfinite(bound) ? bound : kNone;
}

double proven_prefix(const Pose& a0, const CcdMotion& a, const Pose& b0, const CcdMotion& b, double ub,
                     double body_radius, double d) {
  // The whole motion first; when it strays d or more, the share of it the bound allows.
  for (double ua = 1;;) {
    const double bound = motion_distance_bound(a0, a, b0, b, ua * ub, body_radius, ua);
    if (bound < d) return ua;
    if (ua < 1) return 0;
    ua = kPrefixShare * d / bound;
    if (!(ua > 0 && ua < 1)) return 0;  // also NaN, an unbounded whole
  }
}

}  // namespace gauss6
