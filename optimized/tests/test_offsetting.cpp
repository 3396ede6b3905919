// Tests of constraint offsetting (offsetting.h), the rule the coupling loop
// runs: the threshold and the offset profile (f(0) = d, f(T) = 0, increasing,
// flat at both ends); the right-hand sides of a first set (d_k = J_k au); the
// row matching (a row that moved less than the match distance keeps its
// running offset, one that did not starts anew); d_k taken from the previous
// set's projection; the stand-in set after an empty one; and, with the
// projection, that a new deep contact starts with no force jump and ramps up
// monotonically to the un-offset force; that a press and release with an
// offset relaxing under load returns no more than the zero-order hold (the
// energy account); and that a row turning with the god-object keeps its
// offset when named by its feature pair.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <utility>

#include "gauss6/contact/coupling.h"
#include "gauss6/contact/offsetting.h"
#include "mass_matrices.h"

namespace {

using gauss6::Mat6;
using gauss6::OffsetRows;
using gauss6::OffsetRule;
using gauss6::OffsetSettings;
using gauss6::OffsetState;
using gauss6::Pose;
using gauss6::Vec3;
using gauss6::Vec6;

constexpr double kEps = std::numeric_limits<double>::epsilon();

using gauss6::test::box_mass_matrix;

// A contact set of up to 4 rows at points I_k with normals n_k, for a god-object
// at G = 0 (identity pose): J_k = [n_k, I_k x n_k].
struct TestSet {
  int num_rows = 0;
  double J[4 * 6] = {};
  double point[4][3] = {};
  double normal[4][3] = {};
  void add(const Vec3& I, const Vec3& n) {
    Vec6 row;
    row << n, I.cross(n);
    for (int i = 0; i < 6; ++i) J[6 * num_rows + i] = row[i];
    for (int i = 0; i < 3; ++i) point[num_rows][i] = I[i], normal[num_rows][i] = n[i];
    ++num_rows;
  }
  OffsetRows rows() const { return {num_rows, J, point, normal}; }
};

OffsetRule test_rule(const OffsetSettings& s) {
  OffsetRule rule;
  rule.offsets = s;
  rule.match_distance = 1e-3;
  return rule;
}

// The god-object on a floor (normal +z), pressed 1 cm into it.
const Vec3 kUp(0, 0, 1);
const Vec6 kPressDown = (Vec6() << 0, 0, -0.01, 0, 0, 0).finished();

}  // namespace

TEST_CASE("offset settings and threshold", "[offsetting]") {
  OffsetSettings s;
  s.eps = -1e-3;
  s.T = 0.2;
  CHECK(gauss6::valid_offset_settings(s));
  CHECK(gauss6::needs_offset(-2e-3, s));
  CHECK_FALSE(gauss6::needs_offset(-1e-3, s));  // d = eps: not below, no offset
  CHECK_FALSE(gauss6::needs_offset(-0.5e-3, s));  // between eps and 0: felt as a small jump
  CHECK_FALSE(gauss6::needs_offset(0.1, s));
  CHECK_FALSE(gauss6::valid_offset_settings({0.0, 0.2}));
  CHECK_FALSE(gauss6::valid_offset_settings({1e-3, 0.2}));
  CHECK_FALSE(gauss6::valid_offset_settings({-1e-3, 0.0}));
  CHECK_FALSE(gauss6::valid_offset_settings({-1e-3, std::numeric_limits<double>::quiet_NaN()}));
}

TEST_CASE("offset profile: smoothstep from d to 0 in T", "[offsetting]") {
  const OffsetSettings s{-1e-4, 0.25};
  const double d = -3e-3;
  CHECK(gauss6::offset_rhs(d, 0.0, s) == d);
  CHECK(gauss6::offset_rhs(d, -1.0, s) == d);
  CHECK(gauss6::offset_rhs(d, s.T, s) == 0.0);
  CHECK(gauss6::offset_rhs(d, 10.0, s) == 0.0);
  // Smoothstep is symmetric: half way, half the offset (a few ulps).
  CHECK(gauss6::offset_rhs(d, s.T / 2, s) == Approx(d / 2).epsilon(4 * kEps));
  // Strictly increasing on (0, T), sampled at 1000 points.
  double prev = gauss6::offset_rhs(d, 0.0, s);
  for (int i = 1; i <= 1000; ++i) {
    const double f = gauss6::offset_rhs(d, s.T * i / 1000.0, s);
    CHECK(f > prev);
    prev = f;
  }
  // Flat ends: the one-sided slope over h = 1e-6 T is O(h) (smoothstep's
  // derivative 6u(1-u) ~ 6u), against |d|/T * 1.5 at the middle.
  const double h = 1e-6 * s.T;
  const double slope0 = (gauss6::offset_rhs(d, h, s) - d) / h;
  const double slope1 = (0.0 - gauss6::offset_rhs(d, s.T - h, s)) / h;
  const double mid_slope = 1.5 * std::abs(d) / s.T;
  CHECK(slope0 <= 1e-5 * mid_slope);
  CHECK(slope1 <= 1e-5 * mid_slope);
  const double slope_mid = (gauss6::offset_rhs(d, s.T / 2 + h, s) - gauss6::offset_rhs(d, s.T / 2 - h, s)) / (2 * h);
  CHECK(slope_mid == Approx(mid_slope).epsilon(1e-6));
}

TEST_CASE("offset right-hand sides for a first contact set", "[offsetting]") {
  const OffsetSettings s{-1e-3, 0.1};
  const Mat6 M = box_mass_matrix();
  // Three rows at G's height (no angular part): deep (d = -0.01), shallow
  // (normal tilted: d = -0.5e-3 > eps), separating (d > 0). No previous set:
  // d_k = J_k au.
  TestSet set;
  set.add(Vec3(0, 0, 0), kUp);
  set.add(Vec3(0.1, 0, 0), Vec3(0, 0, 0.05));
  set.add(Vec3(0.2, 0, 0), -kUp);
  OffsetState st;
  CHECK(gauss6::start_offsets(test_rule(s), 0.0, kPressDown, M, Pose{}, set.rows(), &st) == 1);
  CHECK(st.start[0] == -0.01);
  CHECK(st.start[1] == 0.0);
  CHECK(st.start[2] == 0.0);
  CHECK(gauss6::fill_offsets(s, 0.0, &st) == 1);
  CHECK(st.rhs[0] == -0.01);
  CHECK(st.rhs[1] == 0.0);
  CHECK(st.rhs[2] == 0.0);
  CHECK(gauss6::fill_offsets(s, 0.05, &st) == 1);
  CHECK(st.rhs[0] == Approx(-0.005).epsilon(4 * kEps));
  CHECK(gauss6::fill_offsets(s, 0.1, &st) == 0);
  CHECK(st.rhs[0] == 0.0);
  // Invalid settings: no offsets at all.
  OffsetState fresh;
  CHECK(gauss6::start_offsets(test_rule({0.5, 0.1}), 0.0, kPressDown, M, Pose{}, set.rows(), &fresh) == 0);
  CHECK(fresh.start[0] == 0.0);
  CHECK(gauss6::fill_offsets({-1e-3, -1}, 0.0, &st) == 0);
  CHECK(st.rhs[0] == 0.0);
}

TEST_CASE("a row that moved less than the match distance keeps its offset", "[offsetting]") {
  const OffsetSettings s{-1e-3, 0.1};
  const OffsetRule rule = test_rule(s);
  const Mat6 M = box_mass_matrix();
  TestSet first;
  first.add(Vec3(0, 0, 0), kUp);
  OffsetState st;
  REQUIRE(gauss6::start_offsets(rule, 0.0, kPressDown, M, Pose{}, first.rows(), &st) == 1);

  // Same constraint, moved by half the match distance: its offset runs on.
  TestSet same;
  same.add(Vec3(0.5e-3, 0, 0), kUp);
  CHECK(gauss6::start_offsets(rule, 0.04, kPressDown, M, Pose{}, same.rows(), &st) == 0);
  CHECK(st.start[0] == -0.01);
  CHECK(st.t0[0] == 0.0);
  CHECK(gauss6::fill_offsets(s, 0.05, &st) == 1);
  CHECK(st.rhs[0] == gauss6::offset_rhs(-0.01, 0.05, s));

  // Moved by twice the match distance (or a turned normal): a new row, whose
  // offset starts now from the previous set's projection.
  TestSet moved;
  moved.add(Vec3(2.5e-3, 0, 0), kUp);
  OffsetState kept = st;
  gauss6::start_offsets(rule, 0.05, kPressDown, M, Pose{}, moved.rows(), &st);
  CHECK(st.t0[0] == 0.05);
  TestSet turned;
  turned.add(Vec3(0.5e-3, 0, 0), Vec3(0, std::sin(1e-3), std::cos(1e-3)));
  gauss6::start_offsets(rule, 0.05, kPressDown, M, Pose{}, turned.rows(), &kept);
  CHECK(kept.t0[0] == 0.05);
}

TEST_CASE("a new row's d_k is taken from the previous set's projection", "[offsetting]") {
  const OffsetSettings s{-1e-3, 0.1};
  const OffsetRule rule = test_rule(s);
  const Mat6 M = box_mass_matrix();
  // The floor's contact slides to another triangle (a new row 5 cm away):
  // J_k au = -0.01 would start a new offset, but the previous row already holds
  // the god-object (J_k ac_old = 0 up to rounding): none starts.
  TestSet first, next;
  first.add(Vec3(0, 0, 0), kUp);
  next.add(Vec3(0.05, 0, 0), kUp);
  const double d_au = Eigen::Map<const Vec6>(next.J).dot(kPressDown);
  REQUIRE(gauss6::needs_offset(d_au, s));
  OffsetState st;
  REQUIRE(gauss6::start_offsets(rule, 0.0, kPressDown, M, Pose{}, first.rows(), &st) == 1);
  OffsetState after_end = st;
  CHECK(gauss6::start_offsets(rule, 0.1, kPressDown, M, Pose{}, next.rows(), &after_end) == 0);
  CHECK(after_end.start[0] == 0.0);
  // Half way through the previous offset, the new row starts where the user
  // was: d_k = J_k ac_old = f(T/2) = -0.005 (the projection's rounding).
  CHECK(gauss6::start_offsets(rule, 0.05, kPressDown, M, Pose{}, next.rows(), &st) == 1);
  CHECK(st.start[0] == Approx(gauss6::offset_rhs(-0.01, 0.05, s)).epsilon(1e-12));
  CHECK(st.t0[0] == 0.05);
}

TEST_CASE("after an empty set the last non-empty one stands in for offset_time", "[offsetting]") {
  const OffsetSettings s{-1e-3, 0.1};
  const OffsetRule rule = test_rule(s);
  const Mat6 M = box_mass_matrix();
  TestSet first, empty, next;
  first.add(Vec3(0, 0, 0), kUp);
  next.add(Vec3(0.05, 0, 0), kUp);
  OffsetState st;
  REQUIRE(gauss6::start_offsets(rule, 0.0, kPressDown, M, Pose{}, first.rows(), &st) == 1);
  CHECK(gauss6::start_offsets(rule, 0.02, kPressDown, M, Pose{}, empty.rows(), &st) == 0);
  CHECK(st.num_rows == 0);
  CHECK(gauss6::fill_offsets(s, 0.02, &st) == 0);
  // Less than T after the set emptied: the first set stands in, without its
  // offset (J ac_old = 0): the contact found again is not ramped again.
  OffsetState soon = st;
  CHECK(gauss6::start_offsets(rule, 0.02 + 0.5 * s.T, kPressDown, M, Pose{}, next.rows(), &soon) == 0);
  CHECK(soon.start[0] == 0.0);
  // More than T after: nothing stands in, d_k = J_k au.
  CHECK(gauss6::start_offsets(rule, 0.02 + 2 * s.T, kPressDown, M, Pose{}, next.rows(), &st) == 1);
  CHECK(st.start[0] == -0.01);
}

TEST_CASE("a deep new contact with an offset starts without a force jump", "[offsetting]") {
  // A god-object resting on a floor (normal +z, contact point 0.1 below and
  // 0.05 beside G); the device is 1 cm below the contact plane when the set
  // arrives. Without an offset the force jumps to its full value; with one it
  // starts at exactly zero and grows monotonically to that value at T.
  const Mat6 M = box_mass_matrix();
  const Vec6 au = (Vec6() << 0.002, 0, -0.01, 0, 0.001, 0).finished();
  TestSet set;
  set.add(Vec3(0.05, 0, -0.1), kUp);
  const OffsetSettings s{-1e-3, 0.1};
  const double kh = 100.0;
  OffsetState st;
  REQUIRE(gauss6::start_offsets(test_rule(s), 0.0, au, M, Pose{}, set.rows(), &st) == 1);

  gauss6::ProjectionWorkspace ws;
  gauss6::ProjectionResult res;
  gauss6::ProjectionProblem pb;
  pb.M = &M;
  pb.au = au;
  pb.J = set.J;
  pb.num_rows = 1;
  // Reference: no offset.
  REQUIRE(gauss6::project(pb, {}, &ws, &res) == gauss6::ProjectionStatus::kOptimal);
  const Vec6 F_full = gauss6::coupling_force(M, au, res.ac, kh);
  REQUIRE(F_full.norm() > 0);

  pb.b = st.rhs.data();
  double prev = -1;
  for (int i = 0; i <= 100; ++i) {
    const double t = s.T * i / 100.0;
    gauss6::fill_offsets(s, t, &st);
    REQUIRE(gauss6::project(pb, {}, &ws, &res) == gauss6::ProjectionStatus::kOptimal);
    const double F = gauss6::coupling_force(M, au, res.ac, kh).norm();
    if (i == 0) CHECK(F == 0.0);  // au satisfies J au >= d exactly: ac = au
    // Monotone up to rounding of the projection (eps-relative to the full force).
    CHECK(F >= prev - 1e-12 * F_full.norm());
    prev = F;
  }
  // At T the offset is gone: the force is the un-offset one (same problem, b = 0).
  CHECK((gauss6::coupling_force(M, au, res.ac, kh) - F_full).norm() <= 1e-12 * F_full.norm());
}

namespace {

// The work done on the user over a scripted press and release of the floor
// (1 kHz, 1-D along z, hand positions in au units: au = ks xh): Fc at each
// step times the next step's hand motion, summed (the port's passivity
// observer, as the oracle computes it). With `passive` the energy account runs
// (release_offsets, account_offsets); without, the right-hand sides are f_k(t).
// Returns the work and the zero-order hold's share of it, k/2 sum |dx|^2 over
// the steps with force (k = kh m ks, the stiffness felt at the handle). With
// `tip`, two more rows at the same point lean 30 degrees either way about y
// (a probe's tip on a face: its edge/edge rows), offset less deep than the
// face's row and not pushing while it holds.
std::pair<double, double> press_and_release_work(bool passive, bool tip = false) {
  const Mat6 M = box_mass_matrix();
  const double kh = 4000, ks = 0.5;
  const OffsetSettings s{-1e-5, 0.05};
  TestSet floor;
  floor.add(Vec3(0, 0, 0), kUp);
  if (tip) {
    floor.add(Vec3(0, 0, 0), Vec3(0.5, 0, std::sqrt(0.75)));
    floor.add(Vec3(0, 0, 0), Vec3(-0.5, 0, std::sqrt(0.75)));
  }
  const int rows = tip ? 3 : 1;
  OffsetState st;
  gauss6::ProjectionWorkspace ws;
  gauss6::ProjectionResult res;
  // The hand arrives 0.2 mm deep (the set arrives late), presses on to 2 mm
  // in 40 ms (offset still relaxing), holds 100 ms, and backs out in 40 ms.
  auto hand = [](int i) {
    const double t = 1e-3 * i;
    if (t < 0.04) return -2e-4 - 1.8e-3 * t / 0.04;
    if (t < 0.14) return -2e-3;
    if (t < 0.18) return -2e-3 + 2.1e-3 * (t - 0.14) / 0.04;
    return 1e-4;
  };
  double work = 0, hold = 0;
  const double k = kh * M(2, 2) * ks;
  Vec6 F_prev = Vec6::Zero();
  double z_prev = 0;
  for (int i = 0; i <= 200; ++i) {
    const double t = 1e-3 * i;
    const Vec6 au = (Vec6() << 0, 0, hand(i), 0, 0, 0).finished();
    if (i > 0) work += F_prev[2] * (au[2] - z_prev) / ks;
    if (i > 0 && F_prev[2] != 0) hold += 0.5 * k * std::pow((au[2] - z_prev) / ks, 2);
    if (i == 0) REQUIRE(gauss6::start_offsets(test_rule(s), t, au, M, Pose{}, floor.rows(), &st) == rows);
    gauss6::fill_offsets(s, t, &st);
    const Vec6 moved = (Vec6() << 0, 0, i > 0 ? hand(i) - hand(i - 1) : 0.0, 0, 0, 0).finished();
    if (passive) gauss6::release_offsets(kh / ks, au, moved, floor.J, &st);
    gauss6::ProjectionProblem pb;
    pb.M = &M;
    pb.au = au;
    pb.J = floor.J;
    pb.b = st.rhs.data();
    pb.num_rows = rows;
    const bool optimal = gauss6::project(pb, {}, &ws, &res) == gauss6::ProjectionStatus::kOptimal;
    REQUIRE(optimal);
    if (passive) gauss6::account_offsets(s, kh / ks, t, au, res.ac, res.lambda.data(), optimal, M, floor.J, &st);
    F_prev = gauss6::coupling_force(M, au, res.ac, kh);
    z_prev = au[2];
  }
  REQUIRE(F_prev.norm() == 0.0);  // released: the cycle is closed
  return {work, hold};
}

}  // namespace

TEST_CASE("an offset relaxing under load gives its energy back on release", "[offsetting]") {
  // The zero-order hold of a stiff spring sampled at 1 kHz alone returns
  // k/2 sum |dx|^2 to the user. The offset that relaxes while the hand presses
  // on puts in far more (loaded softly, released at full stiffness) without
  // the energy account; with it, the cycle returns the hold and no more (up
  // to the account's first-order rounding).
  const auto [active, active_hold] = press_and_release_work(false);
  const auto [passive, hold] = press_and_release_work(true);
  INFO("work without the account " << active << " J (hold " << active_hold << " J), with " << passive
                                   << " J (hold " << hold << " J)");
  // Measured: 5.42e-3 J (1.49e-3 of it the hold) without; 1.364e-3 J with,
  // 5e-6 J over its hold (the account takes each step's lambda, not its mean).
  CHECK(active - active_hold > 1e-3);
  CHECK(passive - hold <= 0.01 * (active - active_hold));
}

TEST_CASE("rows that do not push are given back with the pushing ones", "[offsetting]") {
  // The thin wall's probe: a face row pushing, two edge/edge rows at the same
  // point offset less deep. When only the pushing row went down as the hand
  // backed off, the others took the force over and the account gave nothing
  // back (the oracle's observer: -4.3 mJ on the thin wall). Every offset row
  // the hand backs off from goes down; the cycle returns the hold and no more,
  // as with the face alone (1% of what the offsets lend without the account).
  const auto [active, active_hold] = press_and_release_work(false, true);
  const auto [passive, hold] = press_and_release_work(true, true);
  INFO("work without the account " << active << " J (hold " << active_hold << " J), with " << passive
                                   << " J (hold " << hold << " J)");
  CHECK(active - active_hold > 1e-3);
  CHECK(passive - hold <= 0.01 * (active - active_hold));
}

TEST_CASE("a turning row with the same feature pair keeps its offset", "[offsetting]") {
  // An edge/edge row's normal turns with the god-object (1e-4 rad a set, more
  // than the match's cosine allows): by its point and normal alone it is new
  // at every set and its offset restarts; named by its feature pair it is the
  // same constraint, and its offset returns to 0 at T after the first set.
  const OffsetSettings s{-1e-3, 0.05};
  const OffsetRule rule = test_rule(s);
  const Mat6 M = box_mass_matrix();
  gauss6::FeaturePair pair;
  pair.kind = gauss6::PairKind::kEdgeEdge;
  pair.obstacle = 0;
  pair.god_face = 3, pair.god_corner = 1, pair.obstacle_face = 7, pair.obstacle_corner = 2;
  OffsetState named, unnamed;
  double t = 0;
  for (int k = 0; k <= 60; ++k, t += 1e-3) {
    TestSet set;
    const double a = 1e-4 * k;
    set.add(Vec3(0, 0, 0), Vec3(std::sin(a), 0, std::cos(a)));
    OffsetRows rows = set.rows();
    gauss6::start_offsets(rule, t, kPressDown, M, Pose{}, rows, &unnamed);
    rows.features = &pair;
    gauss6::start_offsets(rule, t, kPressDown, M, Pose{}, rows, &named);
    gauss6::fill_offsets(s, t, &named);
    gauss6::fill_offsets(s, t, &unnamed);
    CHECK(named.t0[0] == 0.0);
    if (t >= s.T + 1e-9) {
      CHECK(named.rhs[0] == 0.0);
      CHECK(unnamed.rhs[0] < 0.0);  // restarted at each set: still offset
    }
  }
}
