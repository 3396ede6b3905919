// Tests of the u-filter of the rigid CCD queries (coplanarity cubic and
// separating axis, u_filter.h): on contacts built into random motions and
// verified in exact rationals (GMP) against the exact Cayley motion of the
// input doubles, the filtered query must report a hit no later than the
// contact's parameter; and on haptic-size steps the filtered and the plain
// bisection agree on hit / no hit up to their tolerances; and an edge sliding
// across another just over d apart is decided whole, without a hit.
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "gauss6/ccd/ccd.h"
#include "ccd_test_util.h"

using namespace gauss6;
using namespace gauss6::test;

namespace {

// Exact: is point x within distance d of the triangle (a, b, c), its projection
// on the plane falling inside? (A sufficient test of "within d".)
bool within_of_triangle(const Q3& x, const Q3& a, const Q3& b, const Q3& c, const mpq_class& d) {
  const Q3 n = cross(b - a, c - a);
  const mpq_class nn = dot(n, n);
  if (nn == 0) return false;
  const mpq_class t = dot(x - a, n);
  if (t * t > d * d * nn) return false;
  return dot(cross(b - a, x - a), n) >= 0 && dot(cross(c - b, x - b), n) >= 0 && dot(cross(a - c, x - c), n) >= 0;
}

// Exact: are the segments [p0, p1], [q0, q1] within distance d, their closest
// points interior to both (a sufficient test)?
bool within_of_segment(const Q3& p0, const Q3& p1, const Q3& q0, const Q3& q1, const mpq_class& d) {
  const Q3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const mpq_class a = dot(d1, d1), b = dot(d1, d2), e = dot(d2, d2), c = dot(d1, r), f = dot(d2, r);
  const mpq_class den = a * e - b * b;
  if (den == 0) return false;
  const mpq_class s = (b * f - c * e) / den, t = (a * f - b * c) / den;
  if (s < 0 || s > 1 || t < 0 || t > 1) return false;
  const Q3 w = (p0 + s * d1) - (q0 + t * d2);
  return dot(w, w) <= d * d;
}

Vec3 rnd(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0, scale);
  return {n(rng), n(rng), n(rng)};
}

// A random step: haptic-size (0.1-1 mm, 0.1-1 degree at a 5 cm scale) or large.
void random_step(std::mt19937& rng, int i, Pose* x0, Pose* x1) {
  std::uniform_real_distribution<double> U(0, 1);
  x0->p = rnd(rng, 0.05);
  x0->q = normalized(Quat{U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5});
  const bool haptic = i % 2 == 0;
  const double move = haptic ? 1e-4 + 9e-4 * U(rng) : 0.02 * U(rng);
  const double angle = haptic ? (0.1 + 0.9 * U(rng)) * 3.14159265358979 / 180 : 1.5 * U(rng);
  x1->p = x0->p + move * rnd(rng, 1).normalized();
  x1->q = normalized(quat_exp(angle * rnd(rng, 1).normalized()) * x0->q);
}

}  // namespace

namespace {

// The scaffolding of the exact-contact tests: 400 random steps (haptic-size and
// large, alternately), each with its enclosed and its exact motion and the
// settings settings_for(i). place(i, rng, m, em, s, ws, r) builds a query with a
// contact at a parameter u_c verified in exact rationals, runs it into *r and
// returns u_c, or returns a negative value when the placement is not verified
// (skipped). A miss is no hit, or a hit after u_c (exact comparison: no
// tolerance). Requires at least 200 verified contacts and no miss.
template <class SettingsFor, class Place>
void check_exact_contacts(unsigned seed, const SettingsFor& settings_for, const Place& place) {
  std::mt19937 rng(seed);
  CcdWorkspace ws;
  CcdResult r;
  int verified = 0, misses = 0;
  for (int i = 0; i < 400; ++i) {
    Pose x0, x1;
    random_step(rng, i, &x0, &x1);
    CcdMotion m;
    REQUIRE(make_ccd_motion(x0, x1, &m) == MotionStatus::kOk);
    const ExactMotion em(x0, x1);
    const CcdSettings s = settings_for(i);
    const double u_c = place(i, rng, m, em, s, &ws, &r);
    if (u_c < 0) continue;
    ++verified;
    if (!r.hit || Q(r.u_hit) > Q(u_c)) ++misses;
  }
  INFO("verified contacts: " << verified);
  CHECK(verified >= 200);
  CHECK(misses == 0);
}

// min_separation 0 every third query, 1e-6 otherwise.
CcdSettings alternating_separation(int i) {
  CcdSettings s;
  s.min_separation = (i % 3 == 0) ? 0.0 : 1e-6;
  return s;
}

}  // namespace

TEST_CASE("u-filter keeps every exact contact: body vertex against a static face", "[ccd]") {
  std::uniform_real_distribution<double> U(0.02, 0.98), H(-1, 1);
  check_exact_contacts(101, alternating_separation, [&](int i, std::mt19937& rng, const CcdMotion& m,
                                                        const ExactMotion& em, const CcdSettings& s,
                                                        CcdWorkspace* ws, CcdResult* r) {
    const Vec3 r_B = rnd(rng, 0.03);
    const double u_c = U(rng);
    const Q3 x_star = em.point(Q(u_c), q3(r_B));
    // A static face through a point near x*: off its plane by up to 0.9 d (a
    // grazing approach when the motion runs along the plane), e1/e2 random or,
    // every fourth query, containing the step's direction (a sliding contact).
    Vec3 e1 = rnd(rng, 0.01), e2 = rnd(rng, 0.01);
    if (i % 4 == 1) e1 = 0.01 * m.nominal.dp.normalized();
    const Vec3 nrm = e1.cross(e2).normalized();
    const Vec3 P = to_double(x_star) + 0.9 * s.min_separation * H(rng) * nrm;
    RigidVertexFaceQuery q;
    q.motion = &m;
    q.vertex_B = r_B;
    q.face_W = {P - (e1 + e2) / 3, P + 2 * e1 / 3 - e2 / 3, P - e1 / 3 + 2 * e2 / 3};
    // Tolerance: none. Skip the rare placements whose rounding leaves x* farther
    // than d (only possible with d = 0): the exact check decides.
    if (!within_of_triangle(x_star, q3(q.face_W[0]), q3(q.face_W[1]), q3(q.face_W[2]), Q(s.min_separation)))
      return -1.0;
    ccd_rigid_vertex_face(q, s, ws, r);
    return u_c;
  });
}

TEST_CASE("u-filter keeps every exact contact: static vertex against a body face", "[ccd]") {
  std::uniform_real_distribution<double> U(0.02, 0.98), H(-1, 1);
  check_exact_contacts(202, alternating_separation, [&](int, std::mt19937& rng, const CcdMotion& m,
                                                        const ExactMotion& em, const CcdSettings& s,
                                                        CcdWorkspace* ws, CcdResult* r) {
    const Vec3 c = rnd(rng, 0.03), e1 = rnd(rng, 0.01), e2 = rnd(rng, 0.01);
    const std::array<Vec3, 3> face = {c - (e1 + e2) / 3, c + 2 * e1 / 3 - e2 / 3, c - e1 / 3 + 2 * e2 / 3};
    const double u_c = U(rng);
    Q3 X[3];
    for (int k = 0; k < 3; ++k) X[k] = em.point(Q(u_c), q3(face[k]));
    const Q3 centre = mpq_class(1, 3) * ((X[0] + X[1]) + X[2]);
    const Vec3 nrm = to_double(cross(X[1] - X[0], X[2] - X[0])).normalized();
    RigidFaceVertexQuery q;
    q.motion = &m;
    q.vertex_W = to_double(centre) + 0.9 * s.min_separation * H(rng) * nrm;
    q.face_B = face;
    if (!within_of_triangle(q3(q.vertex_W), X[0], X[1], X[2], Q(s.min_separation))) return -1.0;
    ccd_rigid_face_vertex(q, s, ws, r);
    return u_c;
  });
}

namespace {

// An edge/edge query with an exact contact built in: the body edge a0 a1 at a
// random u_c, and a static edge crossing it at a point x* of it, offset along
// their common normal by up to 0.9 d; every fourth query nearly parallel (1e-3
// rad: line contacts). within: the static edge is within d of the body edge
// at u_c, verified in rationals (the query has a contact at u_c).
struct PlacedEdgeEdge {
  RigidEdgeEdgeQuery q;
  double u_c = 0;
  bool within = false;
};
PlacedEdgeEdge place_edge_edge(int i, std::mt19937& rng, const CcdMotion& m, const ExactMotion& em, double d) {
  std::uniform_real_distribution<double> U(0.02, 0.98), H(-1, 1), S(0.2, 0.8);
  PlacedEdgeEdge out;
  const Vec3 a0 = rnd(rng, 0.03), a1 = a0 + rnd(rng, 0.01);
  out.u_c = U(rng);
  const double t = S(rng);
  const Q3 A0 = em.point(Q(out.u_c), q3(a0)), A1 = em.point(Q(out.u_c), q3(a1));
  const Q3 x_star = A0 + Q(t) * (A1 - A0);
  Vec3 eb = rnd(rng, 0.01);
  const Vec3 ea = to_double(A1 - A0);
  if (i % 4 == 1) eb = ea + 1e-3 * ea.norm() * rnd(rng, 1);
  const Vec3 nrm = ea.cross(eb).normalized();
  const Vec3 P = to_double(x_star) + 0.9 * d * H(rng) * nrm;
  const double sb = S(rng);
  out.q.motion = &m;
  out.q.edge_B = {a0, a1};
  out.q.edge_W = {P - sb * eb, P + (1 - sb) * eb};
  out.within = within_of_segment(A0, A1, q3(out.q.edge_W[0]), q3(out.q.edge_W[1]), Q(d));
  return out;
}

}  // namespace

TEST_CASE("u-filter keeps every exact contact: edge/edge", "[ccd]") {
  check_exact_contacts(303, alternating_separation, [&](int i, std::mt19937& rng, const CcdMotion& m,
                                                        const ExactMotion& em, const CcdSettings& s,
                                                        CcdWorkspace* ws, CcdResult* r) {
    const PlacedEdgeEdge placed = place_edge_edge(i, rng, m, em, s.min_separation);
    if (!placed.within) return -1.0;
    ccd_rigid_edge_edge(placed.q, s, ws, r);
    return placed.u_c;
  });
}

TEST_CASE("u-filter never stops later than a contact certified by the plain bisection", "[ccd]") {
  // Random faces a few tenths of a millimetre from a vertex, haptic-size steps.
  // The plain bisection at d/2 certifies a contact when its accepted box's
  // distance_reached (a rigorous upper bound of the features' distance at
  // u_hit) is <= d: then the filtered query at d must hit no later.
  std::mt19937 rng(404);
  CcdWorkspace ws;
  CcdResult plain, filtered;
  int certified = 0, later = 0;
  for (int i = 0; i < 300; ++i) {
    Pose x0, x1;
    random_step(rng, 2 * i, &x0, &x1);  // haptic-size only
    CcdMotion m;
    REQUIRE(make_ccd_motion(x0, x1, &m) == MotionStatus::kOk);
    CcdSettings s;
    s.min_separation = 1e-6;
    const Vec3 r_B = rnd(rng, 0.03);
    const Vec3 P = motion_point(m.nominal, 0.5, r_B) + rnd(rng, 3e-4);
    const Vec3 e1 = rnd(rng, 0.005), e2 = rnd(rng, 0.005);
    RigidVertexFaceQuery q;
    q.motion = &m;
    q.vertex_B = r_B;
    q.face_W = {P - (e1 + e2) / 3, P + 2 * e1 / 3 - e2 / 3, P - e1 / 3 + 2 * e2 / 3};
    CcdSettings sp = s;
    sp.use_u_filter = false;
    sp.min_separation = 0.5 * s.min_separation;
    ccd_rigid_vertex_face(q, sp, &ws, &plain);
    if (!(plain.hit && plain.status == CcdStatus::kOk && plain.distance_reached <= s.min_separation)) continue;
    ++certified;
    ccd_rigid_vertex_face(q, s, &ws, &filtered);
    if (!filtered.hit || filtered.u_hit > plain.u_hit) ++later;
  }
  INFO("certified contacts: " << certified);
  CHECK(certified > 10);
  CHECK(later == 0);
}

TEST_CASE("early hit: never after an exact contact, never after the bisection, gap measured", "[ccd]") {
  // Edge/edge contacts built into random motions as above, queried with a
  // distance tolerance of 0.1 d (the setting of the mesh-level benchmarks), with
  // and without the early hit. The early hit must never stop after the exact
  // contact u_c (verified in rationals) nor after the query without it, and an
  // early hit reports a pair proven within d + distance_tolerance.
  std::mt19937 rng(505);
  CcdWorkspace ws;
  CcdResult on, off;
  int verified = 0, misses = 0, later_than_bisection = 0, earlier = 0, too_far = 0;
  double worst_gap_on = 0, worst_gap_off = 0, sum_gap_on = 0, sum_gap_off = 0;
  for (int i = 0; i < 400; ++i) {
    Pose x0, x1;
    random_step(rng, i, &x0, &x1);
    CcdMotion m;
    REQUIRE(make_ccd_motion(x0, x1, &m) == MotionStatus::kOk);
    const ExactMotion em(x0, x1);
    CcdSettings s;
    s.min_separation = 1e-5;
    s.distance_tolerance = 1e-6;
    const PlacedEdgeEdge placed = place_edge_edge(i, rng, m, em, s.min_separation);
    if (!placed.within) continue;
    const RigidEdgeEdgeQuery& q = placed.q;
    const double u_c = placed.u_c;
    ++verified;
    ccd_rigid_edge_edge(q, s, &ws, &on);
    CcdSettings s_off = s;
    s_off.early_hit = false;
    ccd_rigid_edge_edge(q, s_off, &ws, &off);
    if (!on.hit || Q(on.u_hit) > Q(u_c)) ++misses;
    if (off.hit && on.u_hit > off.u_hit) ++later_than_bisection;
    if (on.u_hit < off.u_hit) {
      ++earlier;
      if (!(on.distance_reached <= s.min_separation + s.distance_tolerance)) ++too_far;
    }
    // u_c is a contact, not necessarily the first one: u_c - u_hit bounds u* - u_hit from above.
    const double gap_on = u_c - on.u_hit, gap_off = u_c - off.u_hit;
    worst_gap_on = std::max(worst_gap_on, gap_on);
    worst_gap_off = std::max(worst_gap_off, gap_off);
    sum_gap_on += gap_on;
    sum_gap_off += gap_off;
  }
  std::printf("early hit (edge/edge, d 1e-5, tolerance 1e-6): %d exact contacts, %d missed, %d later than the "
              "bisection, %d earlier; u_c - u_hit mean %.3g worst %.3g (bisection: mean %.3g worst %.3g)\n",
              verified, misses, later_than_bisection, earlier, sum_gap_on / std::max(verified, 1), worst_gap_on,
              sum_gap_off / std::max(verified, 1), worst_gap_off);
  CHECK(verified >= 200);
  CHECK(misses == 0);
  CHECK(later_than_bisection == 0);
  CHECK(too_far == 0);  // an early hit's pair is proven within d + distance_tolerance
}

TEST_CASE("sliding edges just over d apart: no hit, decided in few u-intervals", "[ccd]") {
  // The god-object's normal state: an edge sliding across an obstacle edge at
  // a gap just over d while it turns out of their common plane. Built so that
  // the exact distance stays over d: the body edge is centred at G, across the
  // static edge's line, h = d (1 + eps) above it along their common normal n;
  // G moves along the static edge (so the lines keep crossing, inside both
  // segments, and the translation never changes their distance) and the body
  // turns by alpha = sqrt(2 eps) / 2 about a random axis through G. The lines'
  // distance is then h cos(tilt), tilt <= alpha, at least d (1 + eps)(1 - eps / 4)
  // > d (1 + 0.7 eps): a margin of 1e-11 m at least, against roundings of the
  // inputs of 1e-17 m. The edge endpoints meanwhile swing across n by up to 5 mm
  // alpha, a thousand times the margin: the endpoints' separating axis cannot
  // decide the pair, and the lines' distance must (no hit, few u-intervals).
  std::mt19937 rng(606);
  std::uniform_real_distribution<double> U(0, 1);
  CcdWorkspace ws;
  CcdResult r;
  const double d = 1.5e-6;
  int hits = 0, gave_up = 0, worst = 0;
  for (int i = 0; i < 200; ++i) {
    const double eps = std::pow(10.0, -5 + 3 * U(rng));  // 1e-5 .. 1e-2
    const Vec3 n = rnd(rng, 1).normalized();
    const Vec3 t1 = n.cross(rnd(rng, 1)).normalized(), t2 = n.cross(t1);
    const double phi = 6.3 * U(rng), psi = phi + (30 + 120 * U(rng)) * 3.14159265358979 / 180;
    const Vec3 ea = 0.01 * (std::cos(phi) * t1 + std::sin(phi) * t2);  // world, at x0
    const Vec3 eb = 0.05 * (std::cos(psi) * t1 + std::sin(psi) * t2);
    Pose x0, x1;
    x0.p = rnd(rng, 0.05);
    x0.q = normalized(Quat{U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5});
    x1.p = x0.p + (0.002 + 0.02 * U(rng)) * (U(rng) < 0.5 ? -1 : 1) * eb;  // 0.1-1.1 mm along eb
    x1.q = normalized(quat_exp(0.5 * std::sqrt(2 * eps) * rnd(rng, 1).normalized()) * x0.q);
    CcdMotion m;
    REQUIRE(make_ccd_motion(x0, x1, &m) == MotionStatus::kOk);
    const Mat3 R0 = rotation_matrix(x0.q);
    RigidEdgeEdgeQuery q;
    q.motion = &m;
    q.edge_B = {R0.transpose() * (-0.5 * ea), R0.transpose() * (0.5 * ea)};
    const Vec3 b_mid = x0.p - d * (1 + eps) * n;
    q.edge_W = {b_mid - 0.5 * eb, b_mid + 0.5 * eb};
    q.u_begin = 0;
    q.u_end = 1;
    CcdSettings s;
    s.min_separation = d;
    s.time_tolerance = 1e-6;
    ccd_rigid_edge_edge(q, s, &ws, &r);
    gave_up += r.status != CcdStatus::kOk;
    hits += r.hit;
    worst = std::max(worst, r.filter_intervals);
  }
  INFO("hits " << hits << ", gave up " << gave_up << ", most u-intervals " << worst);
  // Tolerance: none on hits (the exact distance stays over d by 0.7 eps d);
  // 4 u-intervals at most (the whole window, once with the stage-1 tests and
  // once with the lines' distance; before it: 256, the cap, and 197 of the 200
  // queries stopped early, 64 of them giving up).
  CHECK(hits == 0);
  CHECK(gave_up == 0);
  CHECK(worst <= 4);
}
