// Tests of motion_bounds.h: conservative swept boxes, the swept-box cache,
// the time bound of a moving triangle, and the swept oriented-box test.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "gauss6/geometry/bvh.h"
#include "gauss6/ccd/ccd.h"
#include "gauss6/ccd/motion_bounds.h"
#include "triangle_pairs.h"

using namespace gauss6;
using gauss6::test::disjoint_pair;
using gauss6::test::DisjointPair;
using gauss6::test::triangle_distance;

TEST_CASE("BVH: swept boxes contain the moving box over the u-range", "[motion_bounds]") {
  std::mt19937 rng(2);
  std::normal_distribution<double> n(0, 1);
  for (int i = 0; i < 200; ++i) {
    const Pose x0{{n(rng), n(rng), n(rng)}, normalized(Quat{n(rng), n(rng), n(rng), n(rng)})};
    const Pose x1{x0.p + Vec3(n(rng), n(rng), n(rng)),
                  normalized(quat_exp(0.012 * i * Vec3(n(rng), n(rng), n(rng)).normalized()) * x0.q)};
    CcdMotion m;
    REQUIRE(make_ccd_motion(x0, x1, &m) == MotionStatus::kOk);
    const double u0 = 0.5 * std::abs(std::tanh(n(rng))), u1 = std::min(1.0, u0 + 0.3 * std::abs(n(rng)));
    MotionEnclosure e;
    enclose_motion(m, {u0, u1}, &e);
    const Vec3 c(n(rng), n(rng), n(rng)), h = Vec3(n(rng), n(rng), n(rng)).cwiseAbs() * 0.3;
    const Aabb body{c - h, c + h};
    const Aabb w = swept_box(e, body);
    // As tight as the interval product of the enclosure (enclose_point) but
    // for twice the product of the two radii, R_rad h (an entry's product
    // R r: its extreme is at one end of r, where midpoint-radius takes the
    // other end's R_rad |r|), and the rounding allowance.
    const IVec3 iw = enclose_point(e, {Interval{body.lo.x(), body.hi.x()}, Interval{body.lo.y(), body.hi.y()},
                                       Interval{body.lo.z(), body.hi.z()}});
    const Vec3 slack = 2 * (e.R_rad * h) + Vec3::Constant(1e-12 * (1 + c.cwiseAbs().maxCoeff() + h.maxCoeff()));
    for (int i = 0; i < 3; ++i) {
      REQUIRE(w.lo[i] >= iw[i].lo - slack[i]);
      REQUIRE(w.hi[i] <= iw[i].hi + slack[i]);
    }
    for (int k = 0; k <= 10; ++k)
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3 r(corner & 1 ? body.hi.x() : body.lo.x(), corner & 2 ? body.hi.y() : body.lo.y(),
                     corner & 4 ? body.hi.z() : body.lo.z());
        // 1e-12: motion_point's own rounding.
        const Vec3 p = motion_point(m.nominal, u0 + (u1 - u0) * k / 10, r);
        REQUIRE((p.array() >= w.lo.array() - 1e-12).all());
        REQUIRE((p.array() <= w.hi.array() + 1e-12).all());
      }
  }
}

TEST_CASE("swept box cache: returns the box of the asked index in the current sub-interval", "[motion_bounds]") {
  // A 2-entry cache (indices 0 and 2 share a slot): every get() must return the
  // box that make() gives for that index and stamp, recomputing on a slot
  // collision and after next_interval(), and reusing a valid entry.
  SweptBoxCache cache(1);
  int calls = 0, interval = 0;
  const auto box_of = [&](int index) {
    ++calls;
    Aabb b;
    b.lo = Vec3::Constant(index + 100.0 * interval);
    b.hi = b.lo + Vec3::Ones();
    return b;
  };
  const auto check = [&](int index) {
    const Aabb& b = cache.get(cache.nodes, index, [&] { return box_of(index); });
    return b.lo.x() == index + 100.0 * interval;
  };
  cache.next_interval();
  CHECK(check(0));
  CHECK(check(0));
  CHECK(calls == 1);  // reused
  CHECK(check(2));    // same slot as 0: recomputed
  CHECK(check(0));
  CHECK(calls == 3);
  CHECK(check(1));
  CHECK(calls == 4);
  ++interval;
  cache.next_interval();  // every entry stale
  CHECK(check(1));
  CHECK(check(0));
  CHECK(calls == 6);
}

TEST_CASE("triangle_time_lower_bound: no motion within its bounds comes within reach before it", "[motion_bounds]") {
  // A moves by tau v plus a turn about a random centre c at rate omega. Given
  // either way: as a turn (TriangleMotion::omega, centre, and w = the
  // second-order term omega^2 / 2 max |x - c| for tau <= 1), or as any motion
  // of speed w >= |omega| max |x - c| (omega = 0). At sampled tau below the
  // bound (and below 1 for the former), A must stay farther than reach from B
  // (the reference distance of the test above, in long double).
  std::mt19937 rng(43);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> U(0, 1);
  int bounded = 0, infinite = 0, receding = 0, tighter = 0, turning = 0, pivots = 0, pivots_tighter = 0;
  for (int i = 0; i < 4000; ++i) {
    const double scale = std::pow(10.0, 4 * U(rng) - 2);
    const DisjointPair pair = disjoint_pair(rng, n, U, i, scale, 3, /*nearly_parallel=*/false);
    const Vec3 *A = pair.A, *B = pair.B, &c0 = pair.c, &m = pair.m;
    const double gap = pair.gap;
    const double reach = i % 5 == 0 ? 0.0 : gap * U(rng);
    // The motion: towards B, across, or away (v), and a turn.
    Vec3 v = scale * Vec3(n(rng), n(rng), n(rng));
    if (i % 3 == 1) v = scale * (m + 0.1 * Vec3(n(rng), n(rng), n(rng)));
    if (i % 3 == 2) v = -scale * m;
    Vec3 centre = c0 + scale * Vec3(n(rng), n(rng), n(rng));
    Vec3 omega = (i % 2 ? 0.0 : 0.3) * Vec3(n(rng), n(rng), n(rng));
    double lever = 0;
    for (int k = 0; k < 3; ++k) lever = std::max(lever, (A[k] - centre).norm());
    const bool directional = i % 4 == 0 || i % 4 == 2;
    // Given as a turn, one fast enough to close the gap within tau = 1.
    if (directional) omega = 2 * gap / lever * Vec3(n(rng), n(rng), n(rng)).normalized();
    // A pivot (i % 4 == 2), as a peg's tip pressed on a wall while G moves
    // towards it: the turn swings A's centroid away from B about A's corner
    // nearest B (omega along m x (centroid - corner)), and the centre sits
    // beside that corner so that G's translation v = -omega x (corner -
    // centre), which keeps the corner in place to first order, points at B.
    const bool pivot = i % 4 == 2;
    if (pivot) {
      int p = 0;
      for (int k = 1; k < 3; ++k)
        if (m.dot(A[k]) > m.dot(A[p])) p = k;
      const Vec3 axis = m.cross((A[0] + A[1] + A[2]) / 3 - A[p]);
      if (axis.norm() > 0) omega = omega.norm() * axis.normalized();
      if (omega.norm() > 0) centre = A[p] + scale * m.cross(omega.normalized());
      lever = 0;
      for (int k = 0; k < 3; ++k) lever = std::max(lever, (A[k] - centre).norm());
      v = -omega.cross(A[p] - centre);
    }
    TriangleMotion isotropic, turn;
    isotropic.v = turn.v = v;
    isotropic.w = omega.norm() * lever * (1 + 1e-9);
    turn.omega = omega;
    turn.centre = centre;
    turn.w = 0.5 * omega.squaredNorm() * lever * (1 + 1e-9);
    // The turn by t |omega| (quat_exp below) moves x - c by sin(t |omega|) e x
    // (x - c) + ...: lambda = sin(t |omega|) / (t |omega|) >= 1 - (t |omega|)^2 / 6
    // for t <= 1.
    if (directional) turn.lag = std::min(1.0, omega.squaredNorm() / 6 * (1 + 1e-9));
    const double tau = triangle_time_lower_bound(A, B, directional ? turn : isotropic, reach,
                                                 std::numeric_limits<double>::infinity());
    REQUIRE(tau >= 0);
    if (directional && omega != Vec3::Zero()) {
      ++turning;
      const double tau_iso = triangle_time_lower_bound(A, B, isotropic, reach, std::numeric_limits<double>::infinity());
      tighter += std::min(tau, 1.0) > std::min(tau_iso, 1.0);
      if (pivot) {
        // Without the lag bound (lag 1: the turn may fall behind entirely, and
        // the translation alone moves the pivot corner) the bound is never later.
        TriangleMotion lagging = turn;
        lagging.lag = 1;
        const double tau_lagging =
            triangle_time_lower_bound(A, B, lagging, reach, std::numeric_limits<double>::infinity());
        ++pivots;
        REQUIRE(tau >= tau_lagging);
        pivots_tighter += tau > 1.01 * tau_lagging;

      }
    }
    if (std::isinf(tau)) {
      ++infinite;
      REQUIRE(omega == Vec3::Zero());  // only a pure translation can never close the gap
    }
    if (!(tau > 0)) continue;
    ++bounded;
    receding += i % 3 == 2 && omega == Vec3::Zero() && tau > 1e6;  // moving away: only the rounding slack bounds it
    const double t_end = directional ? std::min(tau, 1.0) : (std::isinf(tau) ? 10.0 : tau);
    for (int s = 0; s <= 16; ++s) {
      const double t = t_end * s / 16 * (s == 16 ? 0.999999 : 1.0);
      Vec3 At[3];
      const Mat3 Rt = rotation_matrix(normalized(quat_exp(t * omega)));
      for (int k = 0; k < 3; ++k) At[k] = centre + Rt * (A[k] - centre) + t * v;
      const long double dist = triangle_distance(At, B);
      // Rounding of the posed corners and the reference: 1e-14 of the coordinates.
      REQUIRE(dist >= static_cast<long double>(reach) - 1e-14L * (c0.norm() + 40 * scale));
    }
  }
  std::printf("triangle_time_lower_bound: %d pairs with a positive bound, %d receding ones above 1e6, %d infinite; "
              "the turn's direction gives a later bound (up to 1) on %d of %d turning pairs, the lag bound a later "
              "one on %d of %d pivots\n",
              bounded, receding, infinite, tighter, turning, pivots_tighter, pivots);
  CHECK(bounded > 2000);
  CHECK(receding > 100);
  CHECK(tighter > turning / 10);
  CHECK(pivots_tighter > pivots / 2);
  // Touching triangles: no time at all.
  const Vec3 T[3] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const Vec3 S[3] = {Vec3(0.2, 0.2, 0), Vec3(0.2, 0.2, 1), Vec3(1, 1, 1)};
  TriangleMotion up;
  up.v = Vec3(0, 0, 1);
  up.w = 1;
  CHECK(triangle_time_lower_bound(T, S, up, 0, 1) == 0);
  const Vec3 N[3] = {Vec3(0, 0, std::nan("")), Vec3(1, 0, 2), Vec3(0, 1, 2)};
  CHECK(triangle_time_lower_bound(T, N, up, 0, 1) == 0);
}

TEST_CASE("feature Shapes: the axes formed give the bound of all 11, bit for bit", "[motion_bounds]") {
  // A vertex or an edge passed as a degenerate triangle: with its Shape, only
  // the axes it can have are formed (for_each_separating_axis). The zero axes
  // and the repeated ones (up to sign, exactly) that the 11 would add change
  // nothing, so the two must agree exactly, gap and time bound, on features
  // near and far, with and without an extra axis and an early stop.
  std::mt19937 rng(43);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> U(0, 1);
  int positive = 0;
  for (int i = 0; i < 4000; ++i) {
    Vec3 P[3], Q[3];
    for (int k = 0; k < 3; ++k) {
      P[k] = Vec3(n(rng), n(rng), n(rng));
      Q[k] = Vec3(n(rng), n(rng), n(rng)) + Vec3(2.5 * U(rng), 0, 0);
    }
    TriangleMotion m;
    m.v = Vec3(n(rng), n(rng), n(rng));
    m.omega = i % 3 == 0 ? Vec3::Zero() : Vec3(n(rng), n(rng), n(rng));
    m.centre = Vec3(n(rng), n(rng), n(rng));
    m.w = 0.01 * U(rng);
    m.lag = U(rng);
    const double reach = 0.05 * U(rng), enough = i % 2 ? std::numeric_limits<double>::infinity() : U(rng);
    const Vec3 extra(n(rng), n(rng), n(rng));
    const Vec3* x = i % 4 < 2 ? &extra : nullptr;
    const Vec3 V[3] = {P[0], P[0], P[0]}, E[3] = {P[0], P[1], P[1]}, F[3] = {Q[0], Q[1], Q[2]};
    const Vec3 W[3] = {Q[0], Q[0], Q[0]}, G[3] = {Q[0], Q[1], Q[1]};
    const double vf = triangle_time_lower_bound<Shape::kVertex, Shape::kTriangle>(V, F, m, reach, enough, x);
    const double fv = triangle_time_lower_bound<Shape::kTriangle, Shape::kVertex>(P, W, m, reach, enough, x);
    const double ee = triangle_time_lower_bound<Shape::kEdge, Shape::kEdge>(E, G, m, reach, enough, x);
    REQUIRE(vf == triangle_time_lower_bound(V, F, m, reach, enough, x));
    REQUIRE(fv == triangle_time_lower_bound(P, W, m, reach, enough, x));
    REQUIRE(ee == triangle_time_lower_bound(E, G, m, reach, enough, x));
    positive += (vf > 0) + (fv > 0) + (ee > 0);
  }
  std::printf("feature Shapes: %d of 12000 feature bounds positive, all equal to the 11 axes' bound\n", positive);
  CHECK(positive > 3000);  // the comparison is not of zeros only
}

TEST_CASE("obb_separated: never separates a swept box from a box it reaches, separates far ones", "[motion_bounds]") {
  // The god box (body frame) posed by (R, p), swept along `step` and grown by
  // grow + turn |r_B| (SweptObbFrame::pose); a world point of that swept set is
  // put on the boundary or inside a random oriented world box, which must then
  // not be separated. A world box beyond the swept set's bounding sphere must be.
  std::mt19937 rng(37);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> U(0, 1);
  const auto random_axes = [&](int i) {
    if (i % 5 == 0) return Mat3(Mat3::Identity());
    return rotation_matrix(normalized(Quat{n(rng), n(rng), n(rng), n(rng)}));
  };
  int separated_far = 0, far = 0;
  for (int i = 0; i < 20000; ++i) {
    const double scale = std::pow(10.0, 4 * U(rng) - 2);
    SweptObbFrame f;
    f.set_rotation(rotation_matrix(normalized(Quat{n(rng), n(rng), n(rng), n(rng)})));
    if (i % 7 == 0) f.set_rotation(rotation_matrix(normalized(quat_exp(1e-3 * Vec3(n(rng), n(rng), n(rng))))));
    f.p = scale * 10 * Vec3(n(rng), n(rng), n(rng));
    f.step = i % 3 == 0 ? Vec3::Zero() : Vec3(scale * std::pow(10.0, -4 * U(rng)) * Vec3(n(rng), n(rng), n(rng)));
    f.grow = i % 4 == 0 ? 0.0 : scale * std::pow(10.0, -8 * U(rng));
    f.turn = i % 2 == 0 ? 0.0 : 1e-3 * U(rng);
    // Directional (every third): the turn's first order swept with the box.
    if (i % 3 == 2) {
      f.spin = 1e-2 * U(rng) * Vec3(n(rng), n(rng), n(rng)).normalized();
      f.spread = f.spin.norm() * (1 + 1e-15);
    }
    Obb body;
    body.axes = random_axes(i);
    body.half = scale * Vec3(n(rng), n(rng), n(rng)).cwiseAbs();
    if (i % 4 == 1) body.half[i % 3] *= 100;  // long and thin
    if (i % 6 == 2) body.half[(i + 1) % 3] = 0;  // flat
    body.center = scale * Vec3(n(rng), n(rng), n(rng));
    const PosedObb a = f.pose(body);
    // A point of the body box (a corner or inside), posed, moved along the
    // step (and its turn's first order spin x (R x_B)), and pushed out by up to
    // its grow (turn included).
    Vec3 x_local;
    for (int k = 0; k < 3; ++k) x_local[k] = (i % 2 ? 2 * U(rng) - 1 : (U(rng) < 0.5 ? -1 : 1)) * body.half[k];
    const Vec3 x_B = body.center + body.axes * x_local;
    const double reach = f.grow + f.turn * x_B.norm();
    const Vec3 y = f.rotation() * x_B + f.p + U(rng) * (f.step + f.spin.cross(f.rotation() * x_B)) +
                   0.999 * reach * Vec3(n(rng), n(rng), n(rng)).normalized();
    REQUIRE(reach <= a.grow);
    // A world box with y inside or on its boundary.
    Obb world;
    world.axes = random_axes(i + 1);
    world.half = scale * Vec3(U(rng), U(rng), U(rng));
    if (i % 3 == 1) world.half[i % 3] = 0;
    Vec3 offset;
    for (int k = 0; k < 3; ++k) offset[k] = (i % 5 == 3 ? (U(rng) < 0.5 ? -1 : 1) : 2 * U(rng) - 1) * world.half[k];
    world.center = y - world.axes * offset;
    REQUIRE_FALSE(obb_separated(a, world));
    // A world box beyond the swept set's bounding sphere: separated.
    const double radius = body.half.norm() + a.half_step.norm() + a.grow;
    const Vec3 dir = Vec3(n(rng), n(rng), n(rng)).normalized();
    Obb away;
    away.axes = random_axes(i + 2);
    away.half = Vec3::Constant(scale);
    away.center = a.center + a.half_step + dir * (radius * 1.01 + 2 * std::sqrt(3.0) * scale);
    ++far;
    separated_far += obb_separated(a, away);
  }
  CHECK(separated_far == far);
  // NaN: never separated.
  PosedObb bad;
  bad.center = Vec3(std::nan(""), 0, 0);
  CHECK_FALSE(obb_separated(bad, Obb{}));
}
