// Rounding-safe arithmetic: next_up / next_down, the branch-free outward
// rounding of one double, and Interval, the closed interval whose every
// operation is widened outward, so that a bound computed in doubles holds for
// the exact reals it stands for. The conservative bounds of the collision
// pipeline (ccd.h, aabb.h, the motion bounds) are built on these.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace gauss6 {

// ---------------------------------------------------------------------------
// Interval arithmetic with outward rounding.
//
// Proof of enclosure. Every operation below computes its double result(s) in the
// default round-to-nearest mode (IEEE 754, SSE2 on x86-64: no excess precision)
// and then widens the lower bound down and the upper bound up, branch-free:
//   next_up(r) = fl(r' + t),  r' = max(r, -DBL_MAX),  t = fl(|r'| 2^-52 + 2^-1074).
// Let s be the gap from a finite r to the next float above it (r+). For normal r,
// s <= |r| 2^-52 (also at r = -2^e, where s is half the usual gap); for
// subnormal r or 0, s = 2^-1074. If |r| 2^-52 underflows, its rounding loses at
// most 2^-1075 and adding 2^-1074 (exact there) restores it. So t >= s, and,
// rounding being monotone, fl(r + t) >= fl(r + s) = r+ (or +inf past DBL_MAX).
// If r = fl(x) is a nearest float to the exact real x, then x <= r+, hence
// next_up(r) >= x; the result is r+ or the float after it. The argument only uses
// r + t >= (smallest float >= x), so it still holds if a compiler contracts the
// product that produced r into a fused multiply-add with the "+ t" (x + t >= that
// float too). Overflow: fl(x) = -inf means x < -DBL_MAX, and r' = -DBL_MAX
// gives a result >= -DBL_MAX >= x; +inf stays +inf. next_down(r) = -next_up(-r) mirrors all this.
// No -frounding-math is needed: the rounding mode is never changed. A NaN bound
// makes every exclusion test false (comparisons with NaN are false, and the max
// keeps a NaN first argument), so a NaN can only cause a false positive, never a
// miss.
// ---------------------------------------------------------------------------

// Forces inlining of the few-instruction interval helpers: they run dozens of
// times per feature test, and GCC's -O2 size heuristics otherwise leave many of
// their call sites as calls (measured: Interval products were ~18% of a step).
#define GAUSS6_ALWAYS_INLINE [[gnu::always_inline]] inline

GAUSS6_ALWAYS_INLINE double next_up(double x) {
  constexpr double kMax = std::numeric_limits<double>::max();
  constexpr double kUlp = 0x1p-52, kTiny = std::numeric_limits<double>::denorm_min();
  const double r = x < -kMax ? -kMax : x;  // maxsd; keeps a NaN (the comparison is false)
  return r + (std::abs(r) * kUlp + kTiny);
}
GAUSS6_ALWAYS_INLINE double next_down(double x) { return -next_up(-x); }

// A closed interval [lo, hi] of reals; lo <= hi unless a NaN crept in.
struct Interval {
  double lo = 0, hi = 0;
  static Interval point(double x) { return {x, x}; }
  double width() const { return hi - lo; }
  bool contains(double x) const { return lo <= x && x <= hi; }
};

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

}  // namespace gauss6
