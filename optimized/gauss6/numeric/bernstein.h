// Certified positivity of a polynomial on an interval, from its Bernstein
// coefficients in doubles: the u-filter of the narrow phase (ccd/u_filter.h) tests
// each of its exclusion conditions, cubics and a sextic in u, with these.
// Depends on rounding.h and error_allowances.h only; no allocation.
#pragma once

#include <algorithm>
#include <cmath>

#include "gauss6/numeric/error_allowances.h"
#include "gauss6/numeric/rounding.h"

namespace gauss6 {

// Positivity on an interval [u0, u1] within [0, 1], from the Bernstein
// coefficients of every polynomial with coefficients in given intervals, in
// doubles with a certified rounding bound.
//
// Proof (over the reals machine-checked in proofs/Bernstein.v:
// bernstein_certificate, from bernstein_positive, bernstein_blossom and
// bernstein_end_rows; the doubles' part in proofs/BernsteinRounding.v:
// bernstein_rounding, bernstein_certificate_doubles). On [u0, u1] (0 <= u0 <= u1 <= 1) a polynomial sum_j k_j u^j of degree
// N is sum_i b_i B_i(t), t = (u - u0) / (u1 - u0), with B_i >= 0 summing to 1
// (the Bernstein basis), so it is >= min_i b_i there, and b_i = sum_j k_j w_ij
// with w_ij = e_j(u0 repeated N - i times, u1 i times) / C(N, j) (the blossom
// of u^j; e_j the j-th elementary symmetric polynomial): every w_ij >= 0. So
// over coefficients k_j in [lo_j, hi_j], b_i >= S_i = sum_j lo_j w_ij exactly:
// the polynomial is > 0 on the interval when every S_i is. BernsteinBasis
// computes w_ij in doubles (powers, products with exact integers, sums of
// nonnegative terms, a quotient by an exact integer), and positive_on() the sum
// S~_i; the allowances kBernsteinRounding (relative to T_i = sum_j |lo_j| w_ij)
// and kBernsteinUnderflow (absolute, times 1 + sum_j |lo_j|) bound |S~_i - S_i|
// with their own roundings (error_allowances.h), so S~_i minus them > 0,
// rounded, proves S_i > 0. NaN or
// infinite coefficients make a comparison false or NaN: the interval is kept.
// S_i is the exact least value of b_i over the coefficient box, where a
// Taylor shift in interval arithmetic widens it; it costs a few products per
// coefficient, and the weights serve every polynomial tested on the same
// interval (the narrow phase's UFilter::excludes).
//   C(n, k) for n, k <= 6, exact in doubles.
inline constexpr double kBinomial[7][7] = {{1}, {1, 1}, {1, 2, 1}, {1, 3, 3, 1}, {1, 4, 6, 4, 1}, {1, 5, 10, 10, 5, 1},
                                    {1, 6, 15, 20, 15, 6, 1}};
template <int N>
struct BernsteinBasis {
  static_assert(N >= 1 && N <= 6, "kBinomial covers degrees up to 6");
  // w[i][j]: the weight of coefficient j in Bernstein coefficient i. Rows 0
  // and N (the values at u0 and u1: the powers) at once; the inner rows
  // when a condition first passes both ends (inner()).
  mutable double w[N + 1][N + 1];
  mutable bool has_inner = false;
  BernsteinBasis(double u0, double u1) {
    w[0][0] = w[N][0] = 1;
    for (int a = 1; a <= N; ++a) {
      w[0][a] = w[0][a - 1] * u0;
      w[N][a] = w[N][a - 1] * u1;
    }
  }
  void inner() const {
    if (has_inner) return;
    has_inner = true;
    const double* p0 = w[0];
    const double* p1 = w[N];
    for (int i = 1; i < N; ++i)
      for (int j = 0; j <= N; ++j) {
        double e = 0;
        for (int b = std::max(0, j - (N - i)); b <= std::min(i, j); ++b)
          e += (kBinomial[N - i][j - b] * kBinomial[i][b]) * (p0[j - b] * p1[b]);
        w[i][j] = e / kBinomial[N][j];
      }
  }
};
// A condition's coefficients as positive_on() reads them: their lower ends, and
// the underflow allowance kBernsteinUnderflow (1 + sum_j |lo_j|), rounded up.
template <int N>
struct LowerCoefficients {
  double lo[N + 1] = {}, abs_lo[N + 1] = {};
  double floor = 0;
  void set(const Interval (&k)[N + 1]) {
    Upper sum{1};
    for (int j = 0; j <= N; ++j) {
      lo[j] = k[j].lo;
      abs_lo[j] = std::abs(lo[j]);
      sum = sum + Upper{abs_lo[j]};
    }
    floor = (Upper{kBernsteinUnderflow} * sum).v;
  }
};
// True when every polynomial with coefficients in the intervals behind c is
// > 0 on all of the basis's u-interval (see above). The ends (b_0, b_N: the
// values at u0 and u1) are tried first: they decide most calls.
template <int N>
bool positive_on(const LowerCoefficients<N>& c, const BernsteinBasis<N>& basis) {
  const auto positive = [&](int i) {
    double s = 0, t = 0;
    for (int j = 0; j <= N; ++j) s += c.lo[j] * basis.w[i][j];
    if (!(s > 0)) return false;  // the bound below is >= 0
    for (int j = 0; j <= N; ++j) t += c.abs_lo[j] * basis.w[i][j];
    return s - (kBernsteinRounding * t + c.floor) > 0;
  };
  if (!positive(0) || !positive(N)) return false;
  basis.inner();
  for (int i = 1; i < N; ++i)
    if (!positive(i)) return false;
  return true;
}

}  // namespace gauss6
