// Rounding-safe arithmetic: next_up / next_down, the branch-free outward
// rounding of one double; Interval, the closed interval whose every operation
// is widened outward; and Upper / Lower, one-sided bounds whose every
// operation rounds the safe way; so that a bound computed in doubles holds for
// the exact reals it stands for. The conservative bounds of the collision
// pipeline (ccd.h, aabb.h, the motion bounds) are built on these, with the
// named allowances of error_allowances.h.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "gauss6/numeric/error_allowances.h"

namespace gauss6 {

// ---------------------------------------------------------------------------
// Interval arithmetic with outward rounding.
//
// Proof of enclosure, machine-checked in proofs/Rounding.v (Flocq, binary64,
// round to nearest, finite results, gradual underflow): next_up_ge,
// next_down_le (and next_up_ge_fma for the contracted forms); each operation's
// theorem is named above it. The argument, and what the theorems leave to it
// (overflow, NaN, flush to zero):
// Every operation below computes its double result(s) in the
// default round-to-nearest mode (IEEE 754, SSE2 on x86-64: no excess precision)
// and then widens the lower bound down and the upper bound up, branch-free:
//   next_up(r) = fl(r' + t),  r' = max(r, -DBL_MAX),  t = fl(|r'| 2^-52 + 2^-600).
// Let s be the gap from a finite r to the next float above it (r+). For normal r,
// s <= |r| 2^-52 (also at r = -2^e, where s is half the usual gap), and the
// product |r| 2^-52 is exact while it is normal; for |r| < 2^-970 (the product
// subnormal, inexact or flushed to zero), s <= 2^-1022 < 2^-600. Rounding being
// monotone, t >= max(fl(|r'| 2^-52), 2^-600) >= s, and fl(r + t) >= fl(r + s) = r+
// (or +inf past DBL_MAX). If r = fl(x) is a nearest float to the exact real x,
// then x <= r+, hence next_up(r) >= x: the result is r+ or the float after it
// for |r| >= 2^-548, and within 2^-599 of r below (an absolute widening no
// length of a scene comes near: scene.h bounds them far above). The argument
// only uses r + t >= (smallest float >= x), so it still holds if a compiler
// contracts the product that produced r into a fused multiply-add with the
// "+ t" (x + t >= that float too). Overflow: fl(x) = -inf means x < -DBL_MAX,
// and r' = -DBL_MAX gives a result >= -DBL_MAX >= x; +inf stays +inf.
// next_down(r) = -next_up(-r) mirrors all this.
// Why 2^-600 and not the least subnormal, 2^-1074, which widened r by exactly
// one float: every interval holding a zero then had a subnormal end, and
// products with subnormal operands take a microcode assist on Intel cores (on
// the 2-core Xeon VM, about half of a scenario step's median time;
// docs/benchmarks.md, issue 20, tenth session). 2^-600 times a few factors
// down to 1e-30 stays normal. It also keeps the bounds sound on a thread that
// flushes subnormals to zero (FTZ and DAZ, as audio and game hosts often set):
// a result flushed to zero errs by < 2^-1022; a subnormal operand read as zero
// errs by < 2^-1022 times the other operand, which the collision pipeline
// keeps under 1e30 (2^100: the CCD queries refuse larger coordinates), so by < 2^-922;
// the widening covers both, where 2^-1074, read as zero, widened nothing.
// No -frounding-math is needed: the rounding mode is never changed. A NaN bound
// makes every exclusion test false (comparisons with NaN are false, and the max
// keeps a NaN first argument), so a NaN can only cause a false positive, never a
// miss.
// ---------------------------------------------------------------------------

// Forces inlining of the few-instruction interval helpers: they run dozens of
// times per feature test, and GCC's -O2 size heuristics otherwise leave many of
// their call sites as calls (measured: Interval products were ~18% of a step).
#define GAUSS6_ALWAYS_INLINE [[gnu::always_inline]] inline

// Rounding.v: next_up_ge, next_up_ge_fma.
GAUSS6_ALWAYS_INLINE double next_up(double x) {
  constexpr double kMax = std::numeric_limits<double>::max();
  constexpr double kUlp = 0x1p-52, kTiny = 0x1p-600;  // (the proof above)
  const double r = x < -kMax ? -kMax : x;  // maxsd; keeps a NaN (the comparison is false)
  return r + (std::abs(r) * kUlp + kTiny);
}
// Rounding.v: next_down_le.
GAUSS6_ALWAYS_INLINE double next_down(double x) { return -next_up(-x); }

// A closed interval [lo, hi] of reals; lo <= hi unless a NaN crept in.
struct Interval {
  double lo = 0, hi = 0;
  static Interval point(double x) { return {x, x}; }
  double width() const { return hi - lo; }
  bool contains(double x) const { return lo <= x && x <= hi; }
};

// Rounding.v: interval_point_encloses (point), interval_add_encloses,
// interval_sub_encloses, interval_neg_encloses, interval_mul_encloses,
// interval_scale_encloses, interval_div_positive_encloses,
// interval_sqr_encloses, interval_hull_encloses, in the order below.
GAUSS6_ALWAYS_INLINE Interval operator+(Interval a, Interval b) { return {next_down(a.lo + b.lo), next_up(a.hi + b.hi)}; }
GAUSS6_ALWAYS_INLINE Interval operator-(Interval a, Interval b) { return {next_down(a.lo - b.hi), next_up(a.hi - b.lo)}; }
GAUSS6_ALWAYS_INLINE Interval operator-(Interval a) { return {-a.hi, -a.lo}; }  // exact
GAUSS6_ALWAYS_INLINE Interval operator*(Interval a, Interval b) {
  const double p1 = a.lo * b.lo, p2 = a.lo * b.hi, p3 = a.hi * b.lo, p4 = a.hi * b.hi;
  const double lo = std::min(std::min(p1, p2), std::min(p3, p4));
  const double hi = std::max(std::max(p1, p2), std::max(p3, p4));
  return {next_down(lo), next_up(hi)};
}
GAUSS6_ALWAYS_INLINE Interval operator*(double s, Interval a) {
  const double p1 = s * a.lo, p2 = s * a.hi;
  return {next_down(std::min(p1, p2)), next_up(std::max(p1, p2))};
}
// Quotient by an interval that lies in (0, inf): the caller guarantees b.lo > 0.
GAUSS6_ALWAYS_INLINE Interval div_positive(Interval a, Interval b) {
  const double q1 = a.lo / b.lo, q2 = a.lo / b.hi, q3 = a.hi / b.lo, q4 = a.hi / b.hi;
  return {next_down(std::min(std::min(q1, q2), std::min(q3, q4))),
          next_up(std::max(std::max(q1, q2), std::max(q3, q4)))};
}
// Square of an interval (tight: never negative).
GAUSS6_ALWAYS_INLINE Interval sqr(Interval a) {
  if (a.lo >= 0) return {next_down(a.lo * a.lo), next_up(a.hi * a.hi)};
  if (a.hi <= 0) return {next_down(a.hi * a.hi), next_up(a.lo * a.lo)};
  const double m = std::max(-a.lo, a.hi);
  return {0.0, next_up(m * m)};
}
GAUSS6_ALWAYS_INLINE Interval hull(Interval a, Interval b) { return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)}; }

using IVec3 = std::array<Interval, 3>;
using IMat3 = std::array<Interval, 9>;  // row-major

// ---------------------------------------------------------------------------
// One-sided bounds: Upper, a double v known to be >= the exact real it stands
// for, and Lower, one known to be <= it. Each operation computes its double
// result once, rounded to nearest, and moves it outward by one next_up (Upper)
// or next_down (Lower): by the proof above, the result bounds the exact result
// of the same operation on the exact reals, the way its type says, provided
// the operands bound them the way theirs do and the signs noted below hold
// (a product of upper bounds bounds the exact product only for nonnegative
// reals). So a chain of these is a bound of the exact chain, each rounding
// applied once, by the type.
//
// Entering: Upper{x} / Lower{x} state that x already is such a bound (an
// exact double, a bound rounded the safe way, or an allowance whose margin
// covers its own rounding); round_up(x) / round_down(x) take x, a computed
// value within one last rounding of the real it stands for (any earlier error
// covered by an allowance of error_allowances.h), and move it outward. A
// plain double operand (a scale s, a divisor) is exact.
// Leaving: .v. Comparisons prove: Lower > Upper only when the exact reals
// are ordered so.
// ---------------------------------------------------------------------------

struct Upper {
  double v = 0;
};
struct Lower {
  double v = 0;
};

// Rounding.v: round_up_bounds, round_down_bounds; upper_add, upper_sub,
// upper_mul, upper_scale, upper_div (its Lower divisor's double must be > 0,
// not only its real), upper_div_scalar, upper_sqr, upper_sqrt, upper_max,
// upper_min; lower_add, lower_sub, lower_div, lower_sqr (its operand's double
// must be >= 0, not only its real), lower_sqrt; lower_gt_upper.
GAUSS6_ALWAYS_INLINE Upper round_up(double x) { return {next_up(x)}; }
GAUSS6_ALWAYS_INLINE Lower round_down(double x) { return {next_down(x)}; }

GAUSS6_ALWAYS_INLINE Upper operator+(Upper a, Upper b) { return {next_up(a.v + b.v)}; }
GAUSS6_ALWAYS_INLINE Upper operator-(Upper a, Lower b) { return {next_up(a.v - b.v)}; }
// Products and quotients of nonnegative reals (a divisor's real: positive).
GAUSS6_ALWAYS_INLINE Upper operator*(Upper a, Upper b) { return {next_up(a.v * b.v)}; }
GAUSS6_ALWAYS_INLINE Upper operator*(double s, Upper a) { return {next_up(s * a.v)}; }  // s >= 0
GAUSS6_ALWAYS_INLINE Upper operator/(Upper a, Lower b) { return {next_up(a.v / b.v)}; }
GAUSS6_ALWAYS_INLINE Upper operator/(Upper a, double s) { return {next_up(a.v / s)}; }  // s > 0
GAUSS6_ALWAYS_INLINE Upper sqr(Upper a) { return {next_up(a.v * a.v)}; }
GAUSS6_ALWAYS_INLINE Upper sqrt(Upper a) { return {next_up(std::sqrt(a.v))}; }
GAUSS6_ALWAYS_INLINE Upper max(Upper a, Upper b) { return {std::max(a.v, b.v)}; }  // exact
GAUSS6_ALWAYS_INLINE Upper min(Upper a, Upper b) { return {std::min(a.v, b.v)}; }  // exact

GAUSS6_ALWAYS_INLINE Lower operator+(Lower a, Lower b) { return {next_down(a.v + b.v)}; }
GAUSS6_ALWAYS_INLINE Lower operator-(Lower a, Upper b) { return {next_down(a.v - b.v)}; }
// Quotients and squares of nonnegative reals (a divisor's real: positive).
GAUSS6_ALWAYS_INLINE Lower operator/(Lower a, Upper b) { return {next_down(a.v / b.v)}; }
GAUSS6_ALWAYS_INLINE Lower sqr(Lower a) { return {next_down(a.v * a.v)}; }
GAUSS6_ALWAYS_INLINE Lower sqrt(Lower a) { return {next_down(std::sqrt(a.v))}; }

GAUSS6_ALWAYS_INLINE bool operator>(Lower a, Upper b) { return a.v > b.v; }  // false on NaN

// Rounding.v: interval_widen_encloses, magnitude_bounds, distance_from_bounds,
// norm_upper_bounds.
// [lo - e, hi + e] for e >= 0, rounded outward.
GAUSS6_ALWAYS_INLINE Interval widen(Interval a, Upper e) { return {next_down(a.lo - e.v), next_up(a.hi + e.v)}; }
// Bounds read off an interval: the largest magnitude of its points (exact),
// and the largest distance of its points from the double x.
GAUSS6_ALWAYS_INLINE Upper magnitude(Interval a) { return {std::max(std::abs(a.lo), std::abs(a.hi))}; }
GAUSS6_ALWAYS_INLINE Upper distance_from(Interval a, double x) {
  return max(Upper{a.hi} - Lower{x}, Upper{x} - Lower{a.lo});
}
// The largest Euclidean norm of the vectors in the box v.
GAUSS6_ALWAYS_INLINE Upper norm_upper(const IVec3& v) {
  Upper s2{0};
  for (const Interval& c : v) s2 = s2 + sqr(magnitude(c));
  return sqrt(s2);
}

// Bounds of the exact Euclidean norm of a double 3-vector v from its computed
// norm (v.norm() or std::sqrt(v.squaredNorm()): the square root of the sum of
// the three rounded squares, in any order), with a relative allowance
// (kRelativeRounding or kRelativeRoundingWide) and the absolute floor
// kNormFloor where the squares underflow; norm_down is 0 where the computed
// norm is that small, so that a divisor it gives is > 0 or tested.
// proofs/Allowances.v: norm_upper_bound, norm_lower_bound.
GAUSS6_ALWAYS_INLINE Upper norm_up(double norm, double relative) {
  return max(round_up(norm * (1 + relative)), Upper{kNormFloor});
}
GAUSS6_ALWAYS_INLINE Lower norm_down(double norm, double relative) {
  const Lower d = round_down(norm * (1 - relative));
  return d.v > kNormFloor ? d : Lower{0};
}

}  // namespace gauss6
