// Tests of the theorems of proofs/Bernstein.v on bernstein.h: when
// positive_on certifies a coefficient box on [u0, u1] (bernstein_certificate),
// every polynomial with coefficients in the box is > 0 there, checked exactly
// (GMP rationals) at the interval's ends and at points inside, for corners of
// the box and points inside it, degrees 1 to 6, with the constant term moved
// to the edge of positivity (so that certificates near zero are exercised),
// intervals from 2^-45 wide to whole, at 0, near 0 (powers underflowing) and
// near 1. And the rounding half (BernsteinRounding.v): the weights that
// BernsteinBasis computes are within the proved error of the exact ones, and
// positive_on's answer true means every exact S_i = sum_j lo_j w_ij > 0, on
// rows moved to the edge of the allowance (S_i a few u T_i either side of
// zero), with subnormal, signed-zero and huge coefficients and ends.
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "gauss6/numeric/bernstein.h"

using namespace gauss6;

namespace {

mpq_class Q(double x) { return mpq_class(x); }

template <int N>
mpq_class value(const mpq_class (&k)[N + 1], const mpq_class& u) {
  mpq_class v = k[N];
  for (int j = N - 1; j >= 0; --j) v = v * u + k[j];
  return v;
}

template <int N>
void check_certificate(uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1), mant(-1, 1);
  std::uniform_int_distribution<int> ex(-30, 30), wex(-45, 0), pick(0, 5);
  int certified_count = 0;
  for (int trial = 0; trial < 600; ++trial) {
    double u0 = unit(rng);
    const double w = std::ldexp(unit(rng), wex(rng));
    switch (pick(rng)) {
      case 0: u0 = 0; break;
      case 1: u0 = std::ldexp(unit(rng), -200); break;
      case 2: u0 = 1 - w; break;
      default: break;
    }
    const double u1 = std::min(1.0, u0 + w);
    Interval k[N + 1];
    for (int j = 0; j <= N; ++j) {
      const double a = std::ldexp(mant(rng), ex(rng));
      k[j] = {a, a + std::abs(a) * unit(rng) * 1e-3};
    }
    // Move the constant term so that the least sampled value of the lower
    // polynomial is about 0 (+- a relative 2^-40).
    const int kPoints = 17;
    mpq_class least;
    for (int m = 0; m <= kPoints; ++m) {
      mpq_class lo[N + 1];
      for (int j = 0; j <= N; ++j) lo[j] = Q(k[j].lo);
      const mpq_class u = Q(u0) + (Q(u1) - Q(u0)) * m / kPoints;
      const mpq_class v = value<N>(lo, u);
      if (m == 0 || v < least) least = v;
    }
    const double shift = mpq_class(-least).get_d() * (1 + std::ldexp(mant(rng), -40));
    k[0] = {k[0].lo + shift, k[0].hi + shift};
    if (!(k[0].lo <= k[0].hi)) k[0].hi = k[0].lo;
    LowerCoefficients<N> c;
    c.set(k);
    const BernsteinBasis<N> basis(u0, u1);
    if (!positive_on(c, basis)) continue;
    ++certified_count;
    // Certified: every polynomial of the box is > 0 on [u0, u1].
    for (int corner = 0; corner < 8; ++corner) {
      mpq_class kk[N + 1];
      for (int j = 0; j <= N; ++j) {
        const bool high = corner == 7 ? unit(rng) < 0.5 : ((corner >> (j % 3)) & 1);
        kk[j] = Q(high ? k[j].hi : k[j].lo);
      }
      for (int m = 0; m <= 2 * kPoints; ++m) {
        const mpq_class u = Q(u0) + (Q(u1) - Q(u0)) * m / (2 * kPoints);
        INFO("degree " << N << ", trial " << trial << ", [" << u0 << ", " << u1 << "], point " << m);
        REQUIRE(value<N>(kk, u) > 0);
      }
    }
  }
  CHECK(certified_count > 40);  // the cases reach the certificate
}

// C(n, k) as a rational (kBinomial is exact).
mpq_class binomial(int n, int k) { return mpq_class(kBinomial[n][k]); }

// The exact weights w_ij of Bernstein.v (weight): sum_b C(N-i, j-b) C(i, b)
// u0^(j-b) u1^b / C(N, j), for the double ends u0, u1.
template <int N>
void exact_weights(double u0, double u1, mpq_class (&W)[N + 1][N + 1]) {
  mpq_class p0[N + 1], p1[N + 1];
  p0[0] = p1[0] = 1;
  for (int a = 1; a <= N; ++a) {
    p0[a] = p0[a - 1] * Q(u0);
    p1[a] = p1[a - 1] * Q(u1);
  }
  for (int i = 0; i <= N; ++i)
    for (int j = 0; j <= N; ++j) {
      mpq_class e = 0;
      for (int b = 0; b <= j; ++b)
        if (b <= i && j - b <= N - i) e += binomial(N - i, j - b) * binomial(i, b) * p0[j - b] * p1[b];
      W[i][j] = e / binomial(N, j);
    }
}

// g(k) = (1 + u)^k - 1, u = 2^-53, exactly.
mpq_class rounding_factor(int k) {
  const mpq_class one_u = 1 + mpq_class(1, mpz_class(1) << 53);
  mpq_class p = 1;
  for (int m = 0; m < k; ++m) p *= one_u;
  return p - 1;
}

// An end of a u-interval: random in [0, 1], or adversarial (signed zero,
// subnormal, 1, the least normal, just below 1).
double interval_end(std::mt19937_64& rng) {
  static const std::array<double, 7> kSpecial = {0.0, -0.0, std::numeric_limits<double>::denorm_min(), 1.0,
                                                 std::numeric_limits<double>::min(), 1 - 0x1p-53, 0x1p-600};
  std::uniform_int_distribution<int> pick(0, 11), ex(-1074, 0);
  std::uniform_real_distribution<double> unit(0, 1);
  const int k = pick(rng);
  if (k < 7) return kSpecial[static_cast<size_t>(k)];
  if (k < 9) return std::ldexp(unit(rng), ex(rng));
  return unit(rng);
}
// A coefficient of any scale, or adversarial (signed zero, subnormal, huge).
double coefficient(std::mt19937_64& rng, int scale) {
  static const std::array<double, 6> kSpecial = {0.0, -0.0, std::numeric_limits<double>::denorm_min(), -0x1p-1060,
                                                 0x1p600, -0x1p900};
  std::uniform_int_distribution<int> pick(0, 9), spread(-20, 20);
  std::uniform_real_distribution<double> mant(-1, 1);
  const int k = pick(rng);
  if (k < 2) return kSpecial[static_cast<size_t>(pick(rng) % 6)];
  return std::ldexp(mant(rng), scale + spread(rng));
}

template <int N>
void check_rounding(uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> scale_pick(0, 5), edge(-60, 200);
  static const std::array<int, 6> kScales = {0, -1050, -980, 300, 900, -30};
  const mpq_class weight_rel = rounding_factor(N + 4), weight_abs = mpq_class(1, mpz_class(1) << 1032);
  int certified = 0, refused_positive = 0;
  for (int trial = 0; trial < 400; ++trial) {
    double u0 = interval_end(rng), u1 = interval_end(rng);
    if (u1 < u0) std::swap(u0, u1);
    const BernsteinBasis<N> basis(u0, u1);
    basis.inner();
    mpq_class W[N + 1][N + 1];
    exact_weights<N>(u0, u1, W);
    // Every computed weight within g(N + 4) w + 2^-1032 of the exact one
    // (cweight_err, the step the theorem rests on).
    for (int i = 0; i <= N; ++i)
      for (int j = 0; j <= N; ++j) {
        INFO("degree " << N << ", trial " << trial << ", w[" << i << "][" << j << "], [" << u0 << ", " << u1 << "]");
        REQUIRE(abs(Q(basis.w[i][j]) - W[i][j]) <= weight_rel * W[i][j] + weight_abs);
      }
    // Coefficients, then lo_0 set so that the least of c u T_i - S_i(lo_0 = 0)
    // over the rows is met: every exact S_i >= about c u T_i, with equality at
    // one row (every w_i0 is 1: lo_0 moves every row alike). c from -60 to
    // 200: refused below about 51, certified above.
    const int scale = kScales[static_cast<size_t>(scale_pick(rng))];
    Interval k[N + 1];
    for (int j = 0; j <= N; ++j) {
      const double a = coefficient(rng, scale);
      k[j] = {a, a};
    }
    const double c = edge(rng);
    mpq_class need;
    for (int i = 0; i <= N; ++i) {
      mpq_class rest = 0, T = 0;
      for (int j = 1; j <= N; ++j) {
        rest += Q(k[j].lo) * W[i][j];
        T += abs(Q(k[j].lo)) * W[i][j];
      }
      const mpq_class lo0_i = -rest + T * mpq_class(c) / (mpz_class(1) << 53);
      if (i == 0 || lo0_i > need) need = lo0_i;
    }
    const double lo0 = need.get_d();
    k[0] = {lo0, lo0};
    LowerCoefficients<N> lc;
    lc.set(k);
    const bool answer = positive_on(lc, basis);
    // The exact rows; "clear": every S_i > 64 u T_i + 2^-998 (1 + sum_j |lo_j|)
    // + 2^-598, where the allowances (32 u T_i + 2^-1000 (1 + sum_j |lo_j|),
    // the floor rounded up by next_up, which adds 2^-600) and the rounding
    // (about 19 u T_i) cannot refuse the certificate.
    mpq_class least, L = 1;
    for (int j = 0; j <= N; ++j) L += abs(Q(k[j].lo));
    bool clear = true;
    for (int i = 0; i <= N; ++i) {
      mpq_class S = 0, Ti = 0;
      for (int j = 0; j <= N; ++j) {
        S += Q(k[j].lo) * W[i][j];
        Ti += abs(Q(k[j].lo)) * W[i][j];
      }
      if (i == 0 || S < least) least = S;
      clear = clear && S > Ti * 64 / (mpz_class(1) << 53) + L / (mpz_class(1) << 998) + mpq_class(0x1p-598);
    }
    INFO("degree " << N << ", trial " << trial << ", c " << c << ", [" << u0 << ", " << u1
                   << "], least S_i " << least.get_d());
    // bernstein_rounding: true only when every exact S_i > 0.
    if (answer) {
      ++certified;
      REQUIRE(least > 0);
    } else if (least > 0) {
      ++refused_positive;
    }
    // Not the theorem, but its converse at a margin: the allowances are not
    // so wide that a clearly positive box is refused.
    if (clear) REQUIRE(answer);
  }
  CHECK(certified > 30);         // the cases reach the certificate ...
  CHECK(refused_positive > 10);  // ... and the edge, where positive S_i are refused
}

}  // namespace

TEST_CASE("a Bernstein row computed in doubles bounds its exact S_i (BernsteinRounding.v bernstein_rounding)",
          "[proved]") {
  check_rounding<1>(461);
  check_rounding<2>(462);
  check_rounding<3>(463);
  check_rounding<4>(464);
  check_rounding<5>(465);
  check_rounding<6>(466);
}

TEST_CASE("a Bernstein certificate proves the polynomial positive (Bernstein.v bernstein_certificate)",
          "[proved]") {
  check_certificate<1>(451);
  check_certificate<2>(452);
  check_certificate<3>(453);
  check_certificate<4>(454);
  check_certificate<5>(455);
  check_certificate<6>(456);
}
