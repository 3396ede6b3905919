// Tests of the theorems of proofs/AxisAllowances.v: each proved bound,
// computed by its site's code (tied to the theorem by the hash
// tools/check_proofs.sh compares), against the exact value in rationals
// (GMP), on random and adversarial inputs: signed zeros, subnormals, axes at
// the floor kNormFloor, coordinates up to the largest the CCD accepts
// (kMaxCoordinate, 1e30), triangles nearly touching (the gap within a few
// hundred roundings of the coordinates) and motions whose velocity cancels
// the turn at a corner (the approach rate far below the turn's magnitude), so
// that the allowances, not the margins around them, decide.
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "gauss6/ccd/motion_bounds.h"
#include "gauss6/geometry/bvh.h"
#include "gauss6/geometry/distance.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/numeric/error_allowances.h"
#include "gauss6/numeric/rounding.h"
#include "gauss6/step/ccd_step.h"
#include "mesh_shapes.h"

using namespace gauss6;

namespace {

mpq_class Q(double x) { return mpq_class(x); }
using QVec = std::array<mpq_class, 3>;
QVec exact(const Vec3& v) { return {Q(v[0]), Q(v[1]), Q(v[2])}; }
mpq_class dot(const QVec& a, const QVec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
QVec cross(const QVec& a, const QVec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
mpq_class squared(const QVec& v) { return dot(v, v); }

// A double of scale 2^e, e in [e_lo, e_hi], or an adversarial one.
double scaled(std::mt19937_64& rng, int e_lo, int e_hi) {
  static const std::array<double, 8> kSpecial = {0.0,     -0.0,  std::numeric_limits<double>::denorm_min(),
                                                 -std::numeric_limits<double>::min(), 0x1p-500, -0x1p-502,
                                                 1.0,     -1e30};
  std::uniform_int_distribution<int> ex(e_lo, e_hi), pick(0, 11);
  std::uniform_real_distribution<double> mant(-1, 1);
  const int k = pick(rng);
  return k < 8 ? kSpecial[static_cast<size_t>(k)] : std::ldexp(mant(rng), ex(rng));
}
Vec3 scaled_vec(std::mt19937_64& rng, int e_lo, int e_hi) {
  Vec3 v;
  for (int i = 0; i < 3; ++i) v[i] = std::clamp(scaled(rng, e_lo, e_hi), -1e30, 1e30);
  return v;
}

// An axis: random, with components at the floor (|a|_1 near kNormFloor, where
// kAxisProductRounding |a|_1 is still normal), subnormal or zero.
Vec3 axis(std::mt19937_64& rng) {
  std::uniform_int_distribution<int> kind(0, 3), ex(-60, 60);
  std::uniform_real_distribution<double> mant(-1, 1);
  Vec3 a;
  switch (kind(rng)) {
    case 0:
      for (int i = 0; i < 3; ++i) a[i] = std::ldexp(mant(rng), -499);  // |a|_1 about the floor
      break;
    case 1:
      a = scaled_vec(rng, -1074, 60);
      break;
    default:
      for (int i = 0; i < 3; ++i) a[i] = std::ldexp(mant(rng), ex(rng));
      break;
  }
  return a;
}

// The exact least and largest projections of the first n corners of T on a.
std::array<mpq_class, 2> projections(const QVec& a, const Vec3 T[3], int n) {
  mpq_class lo = dot(a, exact(T[0])), hi = lo;
  for (int k = 1; k < n; ++k) {
    const mpq_class p = dot(a, exact(T[k]));
    lo = std::min(lo, p);
    hi = std::max(hi, p);
  }
  return {lo, hi};
}

// Two features: A of na corners at scale 2^e, B beside it (B = A moved by a
// gap a few hundred to a few million roundings of the coordinates wide, or
// apart), features repeating their corners as for_each_separating_axis takes
// them.
void features(std::mt19937_64& rng, int na, int nb, Vec3 A[3], Vec3 B[3]) {
  std::uniform_int_distribution<int> scale(-1000, 99), near(-50, -30), bit(0, 1);
  std::uniform_real_distribution<double> unit(-1, 1);
  const int e = scale(rng);
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 3; ++i)
      A[k][i] = std::clamp(bit(rng) ? std::ldexp(unit(rng), e) : scaled(rng, e - 4, e), -1e30, 1e30);
  const Vec3 shift = bit(rng) ? Vec3(std::ldexp(unit(rng), e + near(rng)), std::ldexp(unit(rng), e + near(rng)),
                                     std::ldexp(unit(rng), e + near(rng)))
                              : Vec3(std::ldexp(unit(rng), e + 1), std::ldexp(unit(rng), e + 1), 0.0);
  for (int k = 0; k < 3; ++k) B[k] = (A[(k + 1) % 3] + shift).cwiseMax(-1e30).cwiseMin(1e30);
  for (int k = na; k < 3; ++k) A[k] = A[na - 1];
  for (int k = nb; k < 3; ++k) B[k] = B[nb - 1];
}

// For each axis for_each_separating_axis<SA, SB> hands on (the extra axis a
// first): the exact gap of the corners' projections on the side it gives is
// > 0 and at least g |a| (axis_gap_rounding, axis_gap_distance); *worst: the
// largest excess of the unslacked computed difference over the exact gap, in
// units of kAxisProductRounding |a|_1 s (the allowance's share the
// projections' rounding takes), and *needed: the axes where that excess is
// positive (where the allowance is what keeps g below the gap).
template <Shape SA, Shape SB>
void check_axes(const Vec3 A[3], const Vec3 B[3], const Vec3& a, double* worst, int* needed, int* proved) {
  constexpr int na = static_cast<int>(SA), nb = static_cast<int>(SB);
  const SatSide sa = sat_side<SA>(A), sb = sat_side<SB>(B);
  const double s = std::max(sa.abs_max, sb.abs_max);
  for_each_separating_axis<SA, SB>(
      sa, sb,
      [&](const Vec3& axis, double g, double side) {
        const QVec qa = exact(axis);
        const auto pa = projections(qa, A, na), pb = projections(qa, B, nb);
        const mpq_class gap = side > 0 ? pb[0] - pa[1] : pa[0] - pb[1];
        REQUIRE(gap > 0);
        // g may be a little below 0 (down to -2^-600: next_down of a tiny
        // quotient), which bounds the distance too and which both callers drop.
        if (g > 0) REQUIRE(Q(g) * Q(g) * squared(qa) <= gap * gap);
        ++*proved;
        // the unslacked difference, as the code computes it
        double a_lo = axis.dot(A[0]), a_hi = a_lo, b_lo = axis.dot(B[0]), b_hi = b_lo;
        for (int k = 1; k < na; ++k) {
          a_lo = std::min(a_lo, axis.dot(A[k]));
          a_hi = std::max(a_hi, axis.dot(A[k]));
        }
        for (int k = 1; k < nb; ++k) {
          b_lo = std::min(b_lo, axis.dot(B[k]));
          b_hi = std::max(b_hi, axis.dot(B[k]));
        }
        const double raw = std::max(b_lo - a_hi, a_lo - b_hi);
        const double unit = kAxisProductRounding * axis.cwiseAbs().sum() * s;
        if (Q(raw) > gap) ++*needed;
        if (unit > 0x1p-900) *worst = std::max(*worst, mpq_class((Q(raw) - gap) / Q(unit)).get_d());
        return false;
      },
      &a);
}

}  // namespace

// axis_gap_rounding, axis_gap_distance: along every axis for_each_separating_axis
// proves, the exact gap of the corners' projections on the side it reports is
// positive and at least g |a|, for triangles, edges and vertices of every
// scale (2^-1000 to 1e30), nearly touching or apart, extra axes at the floor,
// subnormal or huge.
TEST_CASE("a separating axis's gap is at most the exact gap of the projections (AxisAllowances.v "
          "axis_gap_rounding, axis_gap_distance)",
          "[proved]") {
  std::mt19937_64 rng(45045045);
  std::uniform_int_distribution<int> shapes(0, 3);
  double worst = -1;
  int needed = 0, proved = 0;
  for (int n = 0; n < 20000; ++n) {
    Vec3 A[3], B[3];
    const Vec3 a = axis(rng);
    switch (shapes(rng)) {
      case 0:
        features(rng, 3, 3, A, B);
        check_axes<Shape::kTriangle, Shape::kTriangle>(A, B, a, &worst, &needed, &proved);
        break;
      case 1:
        features(rng, 1, 3, A, B);
        check_axes<Shape::kVertex, Shape::kTriangle>(A, B, a, &worst, &needed, &proved);
        break;
      case 2:
        features(rng, 2, 2, A, B);
        check_axes<Shape::kEdge, Shape::kEdge>(A, B, a, &worst, &needed, &proved);
        break;
      default:
        features(rng, 3, 1, A, B);
        check_axes<Shape::kTriangle, Shape::kVertex>(A, B, a, &worst, &needed, &proved);
        break;
    }
  }
  CHECK(proved > 10000);
  CHECK(needed > 100);  // the raw difference does exceed the gap: the allowance decides there
  // The proof's bound, 8.1 u |a|_1 s above the underflow, is 0.009 of the allowance.
  CHECK(worst <= 0.009);
}

// axis_turn_rounding: along the axis triangle_time_lower_bound uses (an edge
// of A against a vertex B: the extra axis only), the time bound t it returns
// keeps t times the exact approach rate of every corner, side a.v + h(side
// a.(omega x r_k)) with h(b) = b + lag max(0, -b), below the exact gap (reach
// 0, w 0). Motions of every scale; one in two pivots about corner 0 (v =
// -omega x r_0, the velocity cancelling the turn there) with the edge short
// against its distance from the centre, so that the exact rate is far below
// the turn's magnitude and only the allowance covers the rounding.
TEST_CASE("triangle_time_lower_bound's approach rate bounds the exact one (AxisAllowances.v axis_turn_rounding)",
          "[proved]") {
  std::mt19937_64 rng(4504504);
  std::uniform_int_distribution<int> bit(0, 1), scale(-40, 40), lags(0, 3);
  std::uniform_real_distribution<double> unit(-1, 1), mant(0, 1);
  double worst = -1;  // the largest excess of an exact rate over the unslacked approach, in units of the slack
  int needed = 0, checked = 0;
  for (int n = 0; n < 20000; ++n) {
    const bool pivot = bit(rng);
    const int e = scale(rng);
    TriangleMotion m;
    m.centre = scaled_vec(rng, -1074, 40);
    Vec3 A[3], B[3];
    // A: an edge at distance ~2^e from the centre, of length ~2^(e - 20) when pivoting.
    for (int i = 0; i < 3; ++i) A[0][i] = m.centre[i] + std::ldexp(unit(rng), e);
    for (int i = 0; i < 3; ++i) A[1][i] = A[0][i] + std::ldexp(unit(rng), pivot ? e - 20 : e);
    A[2] = A[1];
    const Vec3 a = axis(rng);
    // B: a vertex beyond A along a, at a gap ~2^e.
    const double an = a.norm();
    if (!(an > 0) || !std::isfinite(an)) continue;
    B[0] = B[1] = B[2] = (A[0] + (std::ldexp(mant(rng) + 1, e) / an) * a).cwiseMax(-1e30).cwiseMin(1e30);
    m.omega = bit(rng) ? scaled_vec(rng, -1074, 10) : Vec3(std::ldexp(unit(rng), -3), std::ldexp(unit(rng), -3),
                                                         std::ldexp(unit(rng), -3));
    m.v = pivot ? Vec3(-m.omega.cross(Vec3(A[0] - m.centre))) : scaled_vec(rng, -1074, e);
    switch (lags(rng)) {
      case 0: m.lag = 0; break;
      case 1: m.lag = 1; break;
      case 2: m.lag = std::numeric_limits<double>::denorm_min(); break;
      default: m.lag = mant(rng); break;
    }
    m.w = 0;
    if (!(m.omega.cwiseAbs().maxCoeff() > 0)) continue;  // the turn's branch
    Vec3 r[3];
    const double r_inf = corner_offsets<Shape::kEdge>(A, m.centre, r);
    const SatSide sa = sat_side<Shape::kEdge>(A), sb = sat_side<Shape::kVertex>(B);
    const double t = triangle_time_lower_bound<Shape::kEdge, Shape::kVertex>(
        sa, r, r_inf, sb, m, 0.0, std::numeric_limits<double>::infinity(), &a);
    // the axis, its gap and side as the code sees them
    double g = 0, side = 0;
    for_each_separating_axis<Shape::kEdge, Shape::kVertex>(
        sa, sb,
        [&](const Vec3&, double gg, double ss) {
          g = gg;
          side = ss;
          return true;
        },
        &a);
    if (g == 0) {
      REQUIRE(t == 0);
      continue;
    }
    REQUIRE(t >= 0);
    const QVec qa = exact(a), qv = exact(m.v), qw = exact(m.omega);
    const auto pa = projections(qa, A, 2), pb = projections(qa, B, 1);
    const mpq_class gap = side > 0 ? pb[0] - pa[1] : pa[0] - pb[1];
    REQUIRE(gap > 0);
    // the exact rate of each corner, and the largest
    mpq_class rate;
    const mpq_class lag = Q(m.lag);
    for (int k = 0; k < 2; ++k) {
      const mpq_class b = Q(side) * dot(qa, cross(qw, exact(r[k])));
      const mpq_class h = b + lag * std::max(mpq_class(0), mpq_class(-b));
      const mpq_class rk = Q(side) * dot(qa, qv) + h;
      if (k == 0 || rk > rate) rate = rk;
    }
    if (rate > 0) REQUIRE(Q(t) * rate <= gap);
    ++checked;
    // the unslacked approach, as the code computes it, against the exact rate
    const double a_1 = a.cwiseAbs().sum();
    const Vec3 c = a.cross(m.omega);
    const double along_v = side * a.dot(m.v);
    double approach = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < 2; ++k) {
      const double b = side * r[k].dot(c);
      approach = std::max(approach, along_v + b + m.lag * std::max(0.0, -b));
    }
    const double slack_v = kAxisVelocityRounding * a_1 * m.v.cwiseAbs().maxCoeff();
    const double slack_w = kAxisProductRounding * a_1 * m.omega.cwiseAbs().maxCoeff() * r_inf;
    if (rate > Q(max(Upper{0.0}, round_up(approach)).v) + Q(slack_v)) ++needed;
    if (slack_v + slack_w > 0x1p-900)
      worst = std::max(worst, mpq_class((rate - Q(approach)) / (Q(slack_v) + Q(slack_w))).get_d());
  }
  CHECK(checked > 5000);
  CHECK(needed > 100);  // without the turn's slack the bound would fall below the exact rate
  // The proof's bound per corner, 8 u |a|_1 v_inf + 23 u |a|_1 omega_inf r_inf
  // above the underflow, is at most 0.09 of the two slacks.
  CHECK(worst <= 0.09);
}

// spin_rounding: SweptObbFrame::pose's node step, step + spin x (R center)
// computed in doubles, is within the grow's share Upper{spread} * half +
// Upper{rounding} of the exact step + spin x (R center) (R the double matrix),
// in the Euclidean norm; R = rotation_matrix(q) of every scale of q, centres
// and spins of every scale (subnormal, zero, up to 1e12 and 2^10), steps zero,
// tiny or large.
TEST_CASE("the node's sweep step within kSpinRounding (AxisAllowances.v spin_rounding)", "[proved]") {
  std::mt19937_64 rng(4504505);
  std::uniform_int_distribution<int> bit(0, 1), scale(-1000, 1000);
  double worst = -1;  // the largest error, in units of kSpinRounding (spin_inf radius + step_inf)
  int needed = 0;
  for (int n = 0; n < 20000; ++n) {
    Quat q;
    for (;;) {
      const int e = bit(rng) ? 0 : scale(rng);
      q = {std::ldexp(scaled(rng, -60, 0), e), std::ldexp(scaled(rng, -60, 0), e), std::ldexp(scaled(rng, -60, 0), e),
           std::ldexp(scaled(rng, -60, 0), e)};
      const bool finite = std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
      if (finite && (q.w != 0 || q.x != 0 || q.y != 0 || q.z != 0)) break;
    }
    SweptObbFrame f;
    f.set_rotation(rotation_matrix(q));
    f.p = scaled_vec(rng, -1074, 40);
    f.step = bit(rng) ? Vec3::Zero() : scaled_vec(rng, -1074, 20);
    f.spin = scaled_vec(rng, -1074, 10);
    f.grow = 0;
    f.turn = 0;
    f.spread = std::numeric_limits<double>::denorm_min();  // the directional branch, spread's term ~0
    Obb b;
    b.axes = Mat3::Identity();
    b.center = bit(rng) ? scaled_vec(rng, -1074, 40) : scaled_vec(rng, -560, -490);
    b.half = scaled_vec(rng, -1074, 40).cwiseAbs();
    const PosedObb out = f.pose(b);
    // node_step as the code computes it (tied to the code by its half, bit for bit)
    const Vec3 node_step = f.step + f.spin.cross(Vec3(f.rotation() * b.center));
    REQUIRE((out.half_step.array() == (0.5 * node_step).array()).all());
    QVec C;
    for (int i = 0; i < 3; ++i) C[i] = dot(exact(f.rotation().row(i).transpose()), exact(b.center));
    const QVec X = cross(exact(f.spin), C);
    mpq_class err2 = 0;
    for (int i = 0; i < 3; ++i) {
      const mpq_class e = Q(node_step[i]) - (Q(f.step[i]) + X[i]);
      err2 += e * e;
    }
    REQUIRE(out.grow >= 0);
    REQUIRE(err2 <= Q(out.grow) * Q(out.grow));
    const double half = norm_up(b.half.norm(), kRelativeRounding).v;
    const double spread_term = (Upper{f.spread} * Upper{half}).v;
    if (err2 > Q(spread_term) * Q(spread_term)) ++needed;
    const Upper radius =
        norm_up(b.center.norm(), kRelativeRoundingWide) + norm_up(b.half.norm(), kRelativeRoundingWide);
    const double unit = kSpinRounding * (f.spin.cwiseAbs().maxCoeff() * radius.v + f.step.cwiseAbs().maxCoeff());
    if (unit > 0x1p-900) worst = std::max(worst, std::sqrt(mpq_class(err2 / (Q(unit) * Q(unit))).get_d()));
  }
  CHECK(needed > 1000);  // the rounding is what the grow must cover
  // The proof's bound, 63.01 u spin_inf radius + 3 u step_inf above the
  // underflow, is 0.70 of the allowance.
  CHECK(worst <= 0.70);
}

// axis_turn_rounding's hypothesis r_inf <= 2^400 on every path into
// triangle_time_lower_bound: ccd_step refuses a god-object whose radius about
// G exceeds kMaxCoordinate (make_ccd_motion refuses poses beyond it), so the
// posed corners' offsets from G stay below 2^103. A god-object of radius 1e31
// at poses the motion accepts is refused as invalid input; the control, of
// radius 1e29, is served.
TEST_CASE("ccd_step refuses a god-object beyond kMaxCoordinate (AxisAllowances.v axis_turn_rounding's hypothesis)",
          "[proved]") {
  const TriangleMesh slab = test::make_box(3, 3, 1, Vec3(0, 0, -0.5));
  const Bvh sb = build_bvh(slab, 2);
  const CcdBody obstacles[1] = {{&slab, &sb}};
  const CcdStepSettings settings;
  CcdStepWorkspace ws;
  for (const double radius : {1e31, 1e29}) {
    const TriangleMesh god = test::make_icosphere(1, radius);
    const Bvh gb = build_bvh(god, 2);
    REQUIRE(gb.radius >= 0.9 * radius);
    // G within kMaxCoordinate (make_ccd_motion accepts the poses), moving up.
    const Pose x0{Vec3(0, 0, 1e29), Quat{}};
    const Pose x1{Vec3(0, 0, 2e29), Quat{}};
    CcdStepResult r;
    ccd_step(obstacles, 1, {&god, &gb}, {x0, x1}, settings, &ws, &r);
    if (radius > kMaxCoordinate) CHECK(r.status == CcdStatus::kInvalidInput);
    else CHECK(r.status != CcdStatus::kInvalidInput);
  }
}
