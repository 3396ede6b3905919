// Tests of the theorems of proofs/LinesDistance.v: the edge/edge cubic and the
// lines' sextic of the rigid u-filter (u_filter.h: edge_edge_cubic,
// lines_sextic), computed by the code from a motion made by make_ccd_motion,
// against the exact values in rationals (GMP) of the exact Cayley motion of
// the same doubles, found another way: the lines' distance as
// ((x_a0(u) - b0).(C ea x eb))^2 / |C ea x eb|^2 with C = C(u g) formed
// directly. At dyadic u in [0, 1] (and the motions' ends), on random and
// adversarial inputs: near-parallel and parallel edges, turns up to 170
// degrees, coordinates from 2^-30 to 2^30, subnormal edge components, d = 0.
// Checked: the computed intervals enclose D P and S = D^2 (P^2 - d^2 |M|^2)
// (lines_sextic, edge_edge_cubic), and wherever the sextic's lower bound is
// positive the lines are more than d apart (lines_filter_sound).
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <array>
#include <cmath>
#include <random>

#include "gauss6/ccd/motion.h"
#include "gauss6/ccd/u_filter.h"

using namespace gauss6;
using namespace gauss6::ccd_detail;

namespace {

using QVec = std::array<mpq_class, 3>;
mpq_class Q(double x) { return mpq_class(x); }
QVec Qv(const Vec3& v) { return {Q(v.x()), Q(v.y()), Q(v.z())}; }
QVec sub(const QVec& a, const QVec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
QVec add(const QVec& a, const QVec& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
QVec scale(const mpq_class& s, const QVec& a) { return {s * a[0], s * a[1], s * a[2]}; }
mpq_class dot(const QVec& a, const QVec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
QVec cross(const QVec& a, const QVec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// The exact motion of the doubles of x0, x1 (motion.h, METHOD.md section 4):
// R0 = N(q0) / |q0|^2, g = vec(qr) / scalar(qr) with qr = q1 conj(q0) (its sign
// made positive), p0 = x0.p, dp = x1.p - x0.p.
struct ExactMotion {
  std::array<QVec, 3> R0;  // rows
  QVec g, p0, dp;
};
ExactMotion exact_motion(const Pose& x0, const Pose& x1) {
  ExactMotion m;
  const mpq_class w = Q(x0.q.w), x = Q(x0.q.x), y = Q(x0.q.y), z = Q(x0.q.z);
  const mpq_class n2 = w * w + x * x + y * y + z * z;
  m.R0 = {QVec{(w * w + x * x - y * y - z * z) / n2, 2 * (x * y - w * z) / n2, 2 * (x * z + w * y) / n2},
          QVec{2 * (x * y + w * z) / n2, (w * w - x * x + y * y - z * z) / n2, 2 * (y * z - w * x) / n2},
          QVec{2 * (x * z - w * y) / n2, 2 * (y * z + w * x) / n2, (w * w - x * x - y * y + z * z) / n2}};
  // qr = q1 (w1, v1) times conj(q0) (w, -v).
  const mpq_class w1 = Q(x1.q.w);
  const QVec v1 = {Q(x1.q.x), Q(x1.q.y), Q(x1.q.z)}, v0 = {-x, -y, -z};
  mpq_class rw = w1 * w - dot(v1, v0);
  QVec rv = add(add(scale(w1, v0), scale(w, v1)), cross(v1, v0));
  if (rw < 0) rw = -rw, rv = scale(-1, rv);
  m.g = scale(1 / rw, rv);
  m.p0 = Qv(x0.p);
  m.dp = sub(Qv(x1.p), m.p0);
  return m;
}
QVec mul(const std::array<QVec, 3>& R, const QVec& v) { return {dot(R[0], v), dot(R[1], v), dot(R[2], v)}; }

// C(h) v = v + 2 / (1 + |h|^2) (h x v + h x (h x v)).
QVec cayley(const QVec& h, const QVec& v) {
  const QVec hv = cross(h, v);
  return add(v, scale(mpq_class(2) / (1 + dot(h, h)), add(hv, cross(h, hv))));
}

// Sum of k_i u^i over the interval coefficients' lower (upper) ends, u >= 0.
template <int N>
mpq_class poly_end(const Interval (&k)[N], const mpq_class& u, bool upper) {
  mpq_class s = 0, p = 1;
  for (int i = 0; i < N; ++i, p *= u) s += Q(upper ? k[i].hi : k[i].lo) * p;
  return s;
}

double scaled(std::mt19937_64& rng, int e_lo, int e_hi) {
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<int> e(e_lo, e_hi);
  return std::ldexp(unit(rng), e(rng));
}
Vec3 random_vec(std::mt19937_64& rng, int e_lo, int e_hi) {
  return {scaled(rng, e_lo, e_hi), scaled(rng, e_lo, e_hi), scaled(rng, e_lo, e_hi)};
}
Quat random_quat(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return {n(rng), n(rng), n(rng), n(rng)};  // not normalised: the code takes any non-zero quaternion
}

}  // namespace

TEST_CASE("the edge/edge cubic and the lines' sextic enclose the exact motion's (LinesDistance.v)", "[proved]") {
  std::mt19937_64 rng(20261206);
  std::uniform_real_distribution<double> turn(0, 1);
  int cases = 0, excluded = 0;
  for (int c = 0; c < 1500; ++c) {
    const int scale_e = static_cast<int>(rng() % 61) - 30;  // coordinates 2^-30 .. 2^30
    Pose x0{random_vec(rng, scale_e - 2, scale_e), random_quat(rng)};
    // The second orientation: q0 turned about a random axis by up to 170 degrees.
    const double angle = (c % 5 == 0 ? 170.0 : 60.0) * turn(rng) * M_PI / 180;
    const Vec3 axis = random_vec(rng, 0, 0).normalized();
    const Quat dq{std::cos(angle / 2), std::sin(angle / 2) * axis.x(), std::sin(angle / 2) * axis.y(),
                  std::sin(angle / 2) * axis.z()};
    Pose x1{x0.p + random_vec(rng, scale_e - 4, scale_e - 1), dq * x0.q};
    CcdMotion m;
    if (make_ccd_motion(x0, x1, &m) != MotionStatus::kOk) continue;
    // Edges: random, or the static edge parallel to the moving one at u = 0,
    // or nearly so, or with subnormal components.
    Vec3 a0 = random_vec(rng, scale_e - 3, scale_e), a1 = a0 + random_vec(rng, scale_e - 3, scale_e);
    Vec3 b0 = x0.p + random_vec(rng, scale_e - 3, scale_e), b1;
    const int kind = c % 4;
    const Mat3 R0d = rotation_matrix(x0.q);
    if (kind == 1) {
      b1 = b0 + 1.5 * (R0d * (a1 - a0));
    } else if (kind == 2) {
      b1 = b0 + R0d * (a1 - a0) + random_vec(rng, scale_e - 40, scale_e - 30);
    } else if (kind == 3) {
      a1 = a0 + Vec3(std::ldexp(1.0, -1060), scaled(rng, scale_e - 3, scale_e), 0.0);
      b1 = b0 + random_vec(rng, scale_e - 3, scale_e);
    } else {
      b1 = b0 + random_vec(rng, scale_e - 3, scale_e);
    }
    const double d = (c % 7 == 0) ? 0.0 : std::ldexp(1.0, scale_e - 3 - static_cast<int>(rng() % 8));
    // The code's inputs, as ccd_rigid_edge_edge forms them.
    const IVec3 a0i = to_interval(a0), eai = to_interval(a1) - a0i;
    const IVec3 b0i = to_interval(b0), ebi = to_interval(b1) - b0i;
    const IVec3 a0W = ccd_detail::mul(m.R0, a0i), eaW = ccd_detail::mul(m.R0, eai);
    const CayleyCoefficients ca = cayley_coefficients(m, eaW), cb = cayley_coefficients(m, ebi);
    const EdgeEdgeCubic ee = edge_edge_cubic(m, a0W, eaW, ca, b0i, ebi, cb);
    const Sextic S = lines_sextic(ee, d);
    // The exact motion and edges.
    const ExactMotion X = exact_motion(x0, x1);
    const QVec A0 = mul(X.R0, Qv(a0)), EA = mul(X.R0, sub(Qv(a1), Qv(a0)));
    const QVec B0 = Qv(b0), EB = sub(Qv(b1), Qv(b0));
    const mpq_class d2 = Q(d) * Q(d);
    for (int k = 0; k < 5; ++k) {
      const mpq_class u = k == 0 ? mpq_class(0) : k == 1 ? mpq_class(1) : mpq_class(static_cast<long>(rng() % 1025), 1024);
      const QVec h = scale(u, X.g);
      const mpq_class D = 1 + dot(h, h);
      const QVec x = add(add(X.p0, scale(u, X.dp)), cayley(h, A0));
      const QVec M = cross(cayley(h, EA), EB);  // normal to both lines at u
      const mpq_class P = dot(sub(x, B0), M);   // the lines' distance is |P| / |M|
      const mpq_class S_exact = D * D * (P * P - d2 * dot(M, M));
      CAPTURE(c, kind, d, u.get_d());
      // edge_edge_cubic: the cubic encloses D P (= (x_a0 - b0).N, N = D M).
      CHECK(poly_end(ee.P.k, u, false) <= D * P);
      CHECK(D * P <= poly_end(ee.P.k, u, true));
      // lines_sextic: the sextic encloses S = D^2 (P^2 - d^2 |M|^2).
      CHECK(poly_end(S.k, u, false) <= S_exact);
      CHECK(S_exact <= poly_end(S.k, u, true));
      // lines_filter_sound: a positive lower bound puts the lines more than d apart.
      if (poly_end(S.k, u, false) > 0) {
        ++excluded;
        CHECK(dot(M, M) > 0);
        CHECK(P * P > d2 * dot(M, M));
      }
    }
    ++cases;
  }
  CHECK(cases > 1000);
  CHECK(excluded > 100);  // the conclusion is exercised, not only the enclosure
}
