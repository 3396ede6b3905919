// Tests of the theorems of proofs/Rounding.v on the code they speak for
// (rounding.h): every operation of Interval, Upper and Lower, on random and
// adversarial doubles (signed zeros, subnormals, the least normal, values near
// the largest finite), encloses the exact result of the same operation on its
// operands' values, computed in rationals (GMP). The theorems' hypotheses are
// the tests' preconditions (nonnegative operands, positive divisors); where a
// result overflows (outside the theorems' model), the test checks rounding.h's
// fail-safe claim instead: the bound is then infinite on its own side, or
// still a finite bound. A NaN bound makes the comparisons false.
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "gauss6/numeric/rounding.h"

using namespace gauss6;

namespace {

constexpr double kMax = std::numeric_limits<double>::max();
constexpr double kMinNormal = std::numeric_limits<double>::min();
constexpr double kDenorm = std::numeric_limits<double>::denorm_min();

mpq_class Q(double x) { return mpq_class(x); }

// a <= x for a double a (possibly infinite) and an exact x; false for NaN.
bool below(double a, const mpq_class& x) {
  if (std::isnan(a)) return false;
  if (std::isinf(a)) return a < 0;
  return Q(a) <= x;
}
bool above(double a, const mpq_class& x) {
  if (std::isnan(a)) return false;
  if (std::isinf(a)) return a > 0;
  return Q(a) >= x;
}
bool holds(Interval I, const mpq_class& x) { return below(I.lo, x) && above(I.hi, x); }

// Doubles of every binade, half of them drawn from the adversarial values.
class Doubles {
 public:
  explicit Doubles(uint64_t seed) : rng_(seed) {}
  double operator()() {
    static const std::array<double, 16> kSpecial = {
        0.0, -0.0, kDenorm, -kDenorm, 3 * kDenorm, kMinNormal, -kMinNormal, kMinNormal - kDenorm,
        1.0, -1.0, 0x1p-600, 0x1p-548, -0x1p-970, 0x1p500, -0x1p511, 1 + 0x1p-52};
    if (coin_(rng_)) return kSpecial[pick_(rng_) % kSpecial.size()];
    return std::ldexp(mant_(rng_), ex_(rng_));
  }
  // Up to 2^511, so that products and sums stay finite (the theorems' model).
  std::uniform_int_distribution<int> ex_{-1074, 511};

 private:
  std::mt19937_64 rng_;
  std::bernoulli_distribution coin_{0.5};
  std::uniform_int_distribution<size_t> pick_;
  std::uniform_real_distribution<double> mant_{-1, 1};
};

Interval interval(Doubles& d) {
  const double a = d(), b = d();
  return {std::min(a, b), std::max(a, b)};
}

// The exact real sqrt(a) lies below u iff u >= 0 and u^2 >= a (a >= 0).
bool sqrt_below(const mpq_class& a, double u) {
  if (std::isinf(u)) return u > 0;
  return !std::isnan(u) && u >= 0 && Q(u) * Q(u) >= a;
}
bool sqrt_above(const mpq_class& a, double l) { return !std::isnan(l) && (l <= 0 || Q(l) * Q(l) <= a); }

}  // namespace

// next_up_ge, next_down_le: the widening moves every double strictly outward
// (so a rounded result moves past its exact value), by about an ulp.
TEST_CASE("next_up_ge and next_down_le: outward by at least one float", "[proved]") {
  Doubles d(45);
  for (int i = 0; i < 20000; ++i) {
    const double x = d();
    REQUIRE(next_up(x) > x);
    REQUIRE(next_up(x) >= std::nextafter(x, kMax * 2));
    REQUIRE(next_down(x) <= std::nextafter(x, -kMax * 2));
    // The exact sum of two doubles: its rounding moved outward holds it.
    const double y = d();
    REQUIRE(above(next_up(x + y), Q(x) + Q(y)));
    REQUIRE(below(next_down(x + y), Q(x) + Q(y)));
  }
  // Fail-safe at the ends: +inf stays +inf; -inf is clamped to -DBL_MAX and
  // moved up (still below every real); DBL_MAX moves to +inf.
  CHECK(std::isinf(next_up(kMax)));
  CHECK(next_up(-std::numeric_limits<double>::infinity()) > -std::numeric_limits<double>::infinity());
  CHECK(std::isinf(next_up(std::numeric_limits<double>::infinity())));
  CHECK(std::isnan(next_up(std::nan(""))));
}

// interval_*_encloses: x in A, y in B (taken at the intervals' ends and at a
// double inside) gives op(x, y) in op(A, B).
TEST_CASE("interval operations enclose their exact results (Rounding.v interval_*_encloses)", "[proved]") {
  Doubles d(4545);
  for (int i = 0; i < 20000; ++i) {
    const Interval A = interval(d), B = interval(d);
    const double s = d();
    for (const double x : {A.lo, A.hi, A.lo + (A.hi - A.lo) / 2}) {
      if (!A.contains(x)) continue;
      const mpq_class qx = Q(x);
      REQUIRE(holds(-A, -qx));
      REQUIRE(holds(sqr(A), qx * qx));
      REQUIRE(holds(s * A, Q(s) * qx));
      REQUIRE(holds(hull(A, B), qx));
      REQUIRE(holds(widen(A, Upper{std::abs(s)}), qx + Q(std::abs(s))));
      REQUIRE(holds(widen(A, Upper{std::abs(s)}), qx - Q(std::abs(s))));
      REQUIRE(above(magnitude(A).v, abs(qx)));
      REQUIRE(above(distance_from(A, s).v, abs(qx - Q(s))));
      for (const double y : {B.lo, B.hi}) {
        const mpq_class qy = Q(y);
        REQUIRE(holds(A + B, qx + qy));
        REQUIRE(holds(A - B, qx - qy));
        REQUIRE(holds(A * B, qx * qy));
        if (B.lo > 0) REQUIRE(holds(div_positive(A, B), qx / qy));
      }
    }
    const IVec3 v = {A, B, interval(d)};
    mpq_class n2 = 0;
    for (const Interval& c : v) {
      const mpq_class m = Q(std::max(std::abs(c.lo), std::abs(c.hi)));
      n2 += m * m;
    }
    REQUIRE(sqrt_below(n2, norm_upper(v).v));
  }
}

// upper_* and lower_*: the one-sided operations, under their theorems'
// hypotheses (nonnegative reals for products, squares and square roots,
// positive divisors), bound the exact results the way their types say.
TEST_CASE("Upper and Lower operations bound their exact results (Rounding.v upper_*, lower_*)", "[proved]") {
  Doubles d(454545);
  for (int i = 0; i < 20000; ++i) {
    const double a = d(), b = d();
    const mpq_class qa = Q(a), qb = Q(b);
    REQUIRE(above(round_up(a).v, qa));
    REQUIRE(below(round_down(a).v, qa));
    REQUIRE(above((Upper{a} + Upper{b}).v, qa + qb));
    REQUIRE(above((Upper{a} - Lower{b}).v, qa - qb));
    REQUIRE(below((Lower{a} + Lower{b}).v, qa + qb));
    REQUIRE(below((Lower{a} - Upper{b}).v, qa - qb));
    REQUIRE((max(Upper{a}, Upper{b}).v == std::max(a, b)));
    REQUIRE((min(Upper{a}, Upper{b}).v == std::min(a, b)));
    const double p = std::abs(a), q = std::abs(b);
    const mpq_class qp = Q(p), qq = Q(q);
    REQUIRE(above((Upper{p} * Upper{q}).v, qp * qq));
    REQUIRE(above((p * Upper{b}).v, qp * qb));
    REQUIRE(above(sqr(Upper{p}).v, qp * qp));
    REQUIRE(below(sqr(Lower{p}).v, qp * qp));
    REQUIRE(sqrt_below(qp, sqrt(Upper{p}).v));
    REQUIRE(sqrt_above(qp, sqrt(Lower{p}).v));
    if (q > 0) {
      REQUIRE(above((Upper{p} / Lower{q}).v, qp / qq));
      REQUIRE(above((Upper{a} / q).v, qa / qq));
      REQUIRE(below((Lower{-p} / Upper{q}).v, mpq_class(0)));  // a Lower below the real 0
      REQUIRE(below((Lower{p} / Upper{q}).v, qp / qq));
    }
  }
}

// The ends of the range, outside the theorems' finite model: rounding.h's
// fail-safe claims. Overflowed upper bounds are +inf, lower bounds of huge
// values stay finite and below; a NaN bound never proves an order.
TEST_CASE("overflow and NaN fail safe (rounding.h)", "[proved]") {
  const Interval big{kMax, kMax}, neg{-kMax, -kMax};
  const mpq_class M = Q(kMax);
  CHECK(holds(big + big, M + M));
  CHECK(holds(big * big, M * M));
  CHECK(holds(big * neg, -M * M));
  CHECK(holds(neg - big, -M - M));
  CHECK(holds(sqr(neg), M * M));
  CHECK(above((Upper{kMax} * Upper{kMax}).v, M * M));
  CHECK(below((Lower{-kMax} - Upper{kMax}).v, -M - M));
  const double nan = std::nan("");
  CHECK_FALSE(Lower{nan} > Upper{0.0});
  CHECK_FALSE(Lower{1.0} > Upper{nan});
  CHECK_FALSE(Lower{1.0} > (Upper{nan} + Upper{0.0}));
  CHECK_FALSE((Interval{nan, 1.0} + Interval{0.0, 1.0}).contains(0.5));
}
