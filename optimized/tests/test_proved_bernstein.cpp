// Tests of the theorems of proofs/Bernstein.v on bernstein.h: when
// positive_on certifies a coefficient box on [u0, u1] (bernstein_certificate),
// every polynomial with coefficients in the box is > 0 there, checked exactly
// (GMP rationals) at the interval's ends and at points inside, for corners of
// the box and points inside it, degrees 1 to 6, with the constant term moved
// to the edge of positivity (so that certificates near zero are exercised),
// intervals from 2^-45 wide to whole, at 0, near 0 (powers underflowing) and
// near 1.
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <cmath>
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

}  // namespace

TEST_CASE("a Bernstein certificate proves the polynomial positive (Bernstein.v bernstein_certificate)",
          "[proved]") {
  check_certificate<1>(451);
  check_certificate<2>(452);
  check_certificate<3>(453);
  check_certificate<4>(454);
  check_certificate<5>(455);
  check_certificate<6>(456);
}
