// Tests of the Bernstein positivity certificates (bernstein.h), against the
// exact Bernstein coefficients in rationals (GMP): never true where one of the
// least coefficients is <= 0, and true wherever they all clear the rounding
// allowance by a wide margin.
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <cmath>
#include <limits>
#include <random>

#include "gauss6/numeric/bernstein.h"

using namespace gauss6;

namespace {

mpq_class Q(double x) { return mpq_class(x); }

// The exact least Bernstein coefficients S_i = sum_j lo_j w_ij on [u0, u1], and
// T_i = sum_j |lo_j| w_ij, for the doubles as they are.
template <int N>
void exact_coefficients(const double (&lo)[N + 1], double u0, double u1, mpq_class (&S)[N + 1],
                        mpq_class (&T)[N + 1]) {
  const mpq_class a = Q(u0), b = Q(u1);
  for (int i = 0; i <= N; ++i) {
    S[i] = 0;
    T[i] = 0;
    for (int j = 0; j <= N; ++j) {
      mpq_class e = 0;
      for (int k = std::max(0, j - (N - i)); k <= std::min(i, j); ++k) {
        mpq_class term = Q(kBinomial[N - i][j - k] * kBinomial[i][k]);
        for (int p = 0; p < j - k; ++p) term *= a;
        for (int p = 0; p < k; ++p) term *= b;
        e += term;
      }
      e /= Q(kBinomial[N][j]);
      S[i] += Q(lo[j]) * e;
      T[i] += abs(Q(lo[j])) * e;
    }
  }
}

// Random polynomials of degree N moved to the edge of positivity: lo_0 shifted
// so that the least exact coefficient is about +-eps of the others' size
// (then rounded to a double: cases on both sides of zero at rounding scale),
// intervals [u0, u1] from tolerance-wide to whole, near 0 and near 1.
template <int N>
void check_degree(uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1), mant(-1, 1);
  std::uniform_int_distribution<int> ex(-40, 40), wex(-45, 0), pick(0, 5);
  int proven = 0, refuted = 0, near_zero_true = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    double u0 = unit(rng), w = std::ldexp(unit(rng), wex(rng));
    switch (pick(rng)) {
      case 0: u0 = 0; break;
      case 1: u0 = std::ldexp(unit(rng), -200); break;  // powers underflow
      case 2: u0 = 1 - w; break;
      default: break;
    }
    const double u1 = std::min(1.0, u0 + w);
    double lo[N + 1];
    for (int j = 0; j <= N; ++j) lo[j] = std::ldexp(mant(rng), ex(rng));
    mpq_class S[N + 1], T[N + 1];
    exact_coefficients<N>(lo, u0, u1, S, T);
    int imin = 0;
    for (int i = 1; i <= N; ++i)
      if (S[i] < S[imin]) imin = i;
    // Every w_i0 is 1: lo_0 moves every S_i alike.
    const double shift = mpq_class(-S[imin]).get_d();
    const double jitter = std::ldexp(mant(rng), -50) * std::max(T[imin].get_d(), 1e-300);
    lo[0] = lo[0] + shift + jitter;
    exact_coefficients<N>(lo, u0, u1, S, T);
    bool exact_positive = true;
    double margin = std::numeric_limits<double>::infinity();  // least S_i / T_i
    for (int i = 0; i <= N; ++i) {
      exact_positive = exact_positive && S[i] > 0;
      if (T[i] > 0) margin = std::min(margin, mpq_class(S[i] / T[i]).get_d());
    }
    Interval k[N + 1];
    for (int j = 0; j <= N; ++j) k[j] = {lo[j], lo[j] + std::abs(lo[j])};  // hi plays no part
    LowerCoefficients<N> c;
    c.set(k);
    const BernsteinBasis<N> basis(u0, u1);
    const bool certified = positive_on(c, basis);
    INFO("degree " << N << ", trial " << trial << ", [" << u0 << ", " << u1 << "], margin " << margin);
    // Never a false certificate. And never looser than its allowance: the
    // allowance is 2^-48 (3.6e-15) of T_i plus a term near 2^-1000, so a
    // least coefficient over 1e-13 T_i (28 times that) must be certified.
    if (certified) REQUIRE(exact_positive);
    if (exact_positive && margin > 1e-13) REQUIRE(certified);
    proven += certified;
    refuted += !exact_positive;
    near_zero_true += certified && margin < 1e-12;
  }
  // The cases straddle zero: some refuted, some certified near it.
  CHECK(refuted > 400);
  CHECK(proven > 400);
  CHECK(near_zero_true > 50);
}

}  // namespace

TEST_CASE("Bernstein certificate: never true where an exact least coefficient is <= 0, cubics", "[bernstein]") {
  check_degree<3>(31);
}

TEST_CASE("Bernstein certificate: never true where an exact least coefficient is <= 0, sextics", "[bernstein]") {
  check_degree<6>(32);
}

TEST_CASE("Bernstein certificate: a polynomial with a root inside is never positive", "[bernstein]") {
  // (u - r)^2 (u - s) - e with a root in the interval, e >= 0 tiny: the least
  // value there is <= 0 whatever the coefficients' roundings (taken as lo).
  std::mt19937_64 rng(33);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int trial = 0; trial < 2000; ++trial) {
    const double u0 = unit(rng) * 0.9, u1 = u0 + 0.1 * unit(rng), r = u0 + (u1 - u0) * unit(rng);
    const mpq_class R = Q(r), Sx = Q(u1 + 1);  // s > u1: (u - s) < 0 there
    // Exact coefficients of -(u - r)^2 (u - s) = -(u^3 - (2r + s) u^2 + (r^2 + 2rs) u - r^2 s) >= 0, rounded down.
    const mpq_class k[4] = {R * R * Sx, -(R * R + 2 * R * Sx), 2 * R + Sx, mpq_class(-1)};
    Interval I[4];
    for (int j = 0; j < 4; ++j) {
      double d = k[j].get_d();
      if (Q(d) > k[j]) d = std::nextafter(d, -INFINITY);  // below: the exact one is in [d, ...]
      I[j] = {d, std::nextafter(d, INFINITY)};
    }
    // The polynomial with coefficients I.lo is <= the exact one, which is 0 at r.
    LowerCoefficients<3> c;
    c.set(I);
    INFO("trial " << trial << " r " << r);
    REQUIRE_FALSE(positive_on(c, BernsteinBasis<3>(u0, u1)));
  }
}

TEST_CASE("Bernstein certificate: NaN or infinite coefficients never certify", "[bernstein]") {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (const double bad : {nan, inf, -inf}) {
    for (int j = 0; j < 4; ++j) {
      Interval k[4] = {{1, 1}, {1, 1}, {1, 1}, {1, 1}};
      k[j] = {bad, bad};
      LowerCoefficients<3> c;
      c.set(k);
      CHECK_FALSE(positive_on(c, BernsteinBasis<3>(0.25, 0.5)));
    }
  }
  Interval ok[4] = {{1, 1}, {0, 0}, {0, 0}, {0, 0}};
  LowerCoefficients<3> c;
  c.set(ok);
  CHECK(positive_on(c, BernsteinBasis<3>(0.25, 0.5)));
}
