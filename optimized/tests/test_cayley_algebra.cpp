// Tests of the Cayley motion's algebra (METHOD.md section 4, issue 45 item 4)
// on motion.h's code: the exact statements (C(h) orthogonal with determinant 1; D(u) times a contact
// condition is the cubic the theorem gives) hold for the doubles the code
// computes up to their rounding, on random motions built by
// make_cayley_motion (relative rotations up to kMaxMotionAngle, so |g| up to
// tan(85 deg) ~ 11.4, the bound the code enforces) and adversarial Gibbs
// vectors (zero, signed zeros, subnormal, axis-aligned, |h| = 11.43).
// Tolerances: the doubles of C(h) (a dozen roundings of terms <= 3 in
// magnitude) are within 1e-14 of an orthogonal matrix; a contact condition
// (roundings of terms <= S = the largest coordinate magnitude involved, the
// cubic's coefficients up to 2 |g|^2 <= 262 times them) within 1e-12 S D(u)
// of the cubic (3 and 9 times that for the products of two and three
// factors), at u in [0, 1]: a wrong coefficient is off by O(S).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "gauss6/ccd/motion.h"
#include "gauss6/geometry/pose.h"

using namespace gauss6;

namespace {

Vec3 random_vec(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> d(-scale, scale);
  return {d(rng), d(rng), d(rng)};
}
Quat random_quat(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return normalized(Quat{n(rng), n(rng), n(rng), n(rng)});
}
Mat3 cross_of(const Vec3& h) {
  Mat3 K;
  K << 0, -h.z(), h.y(), h.z(), 0, -h.x(), -h.y(), h.x(), 0;
  return K;
}

}  // namespace

TEST_CASE("C(h) is a rotation", "[motion]") {
  std::mt19937_64 rng(4501);
  const double dn = std::numeric_limits<double>::denorm_min();
  std::vector<Vec3> hs = {Vec3::Zero(), Vec3(-0.0, 0.0, -0.0), Vec3(dn, -dn, dn), Vec3(11.43, 0, 0),
                          Vec3(0, -11.43, 0), Vec3(6.6, 6.6, 6.6), Vec3(1e-200, 0, 0)};
  for (int i = 0; i < 5000; ++i) hs.push_back(random_vec(rng, 6.6));
  for (const Vec3& h : hs) {
    const Mat3 C = cayley_rotation(h);
    INFO("h = " << h.transpose());
    REQUIRE((C.transpose() * C - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-14);
    REQUIRE(std::abs(C.determinant() - 1) <= 1e-14);
  }
}

TEST_CASE("contact conditions times D(u) are cubics (METHOD.md section 4)",
          "[motion]") {
  std::mt19937_64 rng(4502);
  std::uniform_real_distribution<double> unit(0, 1);
  int built = 0;
  for (int i = 0; i < 3000; ++i) {
    const Pose x0{random_vec(rng, 10), random_quat(rng)}, x1{random_vec(rng, 10), random_quat(rng)};
    CayleyMotion m;
    if (make_cayley_motion(x0, x1, &m) != MotionStatus::kOk) continue;
    ++built;
    const Vec3 rB = random_vec(rng, 3), eB = random_vec(rng, 3), n = random_vec(rng, 1), a = random_vec(rng, 10),
               Y = random_vec(rng, 10), f = random_vec(rng, 3);
    const Mat3 K = cross_of(m.g), M1 = 2 * K, M2 = m.g.squaredNorm() * Mat3::Identity() + 2 * K * K;
    const double g2 = m.g.squaredNorm();
    const Vec3 c = m.R0 * rB, e = m.R0 * eB, E1 = M1 * e, E2 = M2 * e, ce = c.cross(e);
    const double S = 10 + 2 * 10 + 3 + 10;  // largest magnitudes of p0, dp, r, a / Y
    for (const double u : {0.0, 1.0, unit(rng), unit(rng)}) {
      const double D = 1 + u * u * g2;
      const Vec3 X = motion_point(m, u, rB);
      const Mat3 Ru = motion_rotation(m, u);
      // body_point_rational: D X = D p(u) + c + u M1 c + u^2 M2 c.
      const Vec3 p = m.p0 + u * m.dp;
      REQUIRE((D * X - (D * p + c + u * (M1 * c) + u * u * (M2 * c))).cwiseAbs().maxCoeff() <= 1e-12 * S * D);
      // vertex_face_cubic
      const Vec3 b = m.p0 - a;
      const double vf = (n.dot(b) + n.dot(c)) + (n.dot(m.dp) + n.dot(M1 * c)) * u +
                        (g2 * n.dot(b) + n.dot(M2 * c)) * u * u + (g2 * n.dot(m.dp)) * u * u * u;
      REQUIRE(std::abs(D * n.dot(X - a) - vf) <= 1e-12 * S * D);
      // face_vertex_cubic (V = a, the face's normal n_B = eB)
      const Vec3 bv = a - m.p0;
      const double fv = (e.dot(bv) - e.dot(c)) + (E1.dot(bv) - e.dot(m.dp)) * u +
                        (E2.dot(bv) - E1.dot(m.dp) - g2 * e.dot(c)) * u * u - E2.dot(m.dp) * u * u * u;
      REQUIRE(std::abs(D * (Ru * eB).dot(a - X) - fv) <= 1e-12 * S * 3 * D);
      // edge_edge_cubic
      const Vec3 be = m.p0 - Y;
      const double ee = (e.cross(f).dot(be) + ce.dot(f)) +
                        (e.cross(f).dot(m.dp) + E1.cross(f).dot(be) - ce.dot(M1 * f)) * u +
                        (E1.cross(f).dot(m.dp) + E2.cross(f).dot(be) + ce.dot(M2 * f)) * u * u +
                        E2.cross(f).dot(m.dp) * u * u * u;
      REQUIRE(std::abs(D * (Ru * eB).cross(f).dot(X - Y) - ee) <= 1e-12 * S * 9 * D);
    }
  }
  CHECK(built > 2000);
}

// cayley_gibbs_end: the motion's end rotation C(g) R(q0) is R(q1) (exactly
// for the exact g; the doubles of g, C and the product round within a few
// units of u of terms up to 2 |g|^2 / (1 + |g|^2) |K|^2 <= 2 |g|^2 ~ 262 in
// magnitude before the quotient: 1e-12 covers them), including the sign flip
// of qr and rotations up to kMaxMotionAngle.
TEST_CASE("the motion ends at R(q1)", "[motion]") {
  std::mt19937_64 rng(4503);
  int built = 0;
  for (int i = 0; i < 5000; ++i) {
    Pose x0{random_vec(rng, 10), random_quat(rng)}, x1{random_vec(rng, 10), random_quat(rng)};
    if (i % 3 == 0) x1.q = {-x1.q.w, -x1.q.x, -x1.q.y, -x1.q.z};  // the other sign of q1
    if (i % 5 == 0) x0.q = {4 * x0.q.w, 4 * x0.q.x, 4 * x0.q.y, 4 * x0.q.z};  // not unit
    CayleyMotion m;
    if (make_cayley_motion(x0, x1, &m) != MotionStatus::kOk) continue;
    ++built;
    const Mat3 end = motion_rotation(m, 1.0), R1 = rotation_matrix(x1.q);
    INFO("trial " << i << ", |g| " << m.g.norm());
    REQUIRE((end - R1).cwiseAbs().maxCoeff() <= 1e-12);
  }
  CHECK(built > 4000);
}
