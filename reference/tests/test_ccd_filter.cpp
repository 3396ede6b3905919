// The reference's filtered paths against its exact-only ones: mesh_first_contact
// with the interval filter (the default) and without it (every candidate pair
// solved exactly) must give the same exact u* and the same touching pairs;
// separation_within must agree with the exact minimum of separation_distance.
// Steps and poses cover free motions, hits, exact touching at u = 0 (coplanar
// faces all along: the filter's undecidable case) and grazing at the contact
// distance.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "gauss6/reference/ccd.h"
#include "../../optimized/tests/mesh_shapes.h"

namespace {

using gauss6::Pose;
using gauss6::Quat;
using gauss6::TriangleMesh;
using gauss6::Vec3;
using namespace gauss6::reference;

Pose at(const Vec3& p, const Quat& q) {
  Pose x;
  x.p = p;
  x.q = q;
  return x;
}

std::vector<gauss6::FeaturePairIds> sorted(std::vector<gauss6::FeaturePairIds> v) {
  auto key = [](const gauss6::FeaturePairIds& p) {
    return std::make_tuple(int(p.kind), int(p.god.feature), p.god.a, p.god.b, int(p.obstacle.feature), p.obstacle.a,
                           p.obstacle.b);
  };
  std::sort(v.begin(), v.end(), [&](const auto& a, const auto& b) { return key(a) < key(b); });
  return v;
}

// Filtered and unfiltered answers are the same; returns the filtered one.
MeshContact both_paths(const ExactMeshPair& mp, const Pose& X0, const Pose& X1) {
  const MeshContact f = mesh_first_contact(mp, X0, X1, true), e = mesh_first_contact(mp, X0, X1, false);
  REQUIRE(f.toi.hit == e.toi.hit);
  CHECK(compare_toi(f.toi, e.toi) == 0);
  CHECK(f.toi.lower == e.toi.lower);
  CHECK(f.toi.upper == e.toi.upper);
  CHECK(sorted(f.pairs) == sorted(e.pairs));
  CHECK(f.num_candidate_pairs == e.num_candidate_pairs);
  CHECK(f.num_filtered_pairs + f.num_exact_pairs <= f.num_candidate_pairs);
  CHECK(e.num_exact_pairs == e.num_candidate_pairs);
  return f;
}

}  // namespace

TEST_CASE("filtered first contact equals the exact-only one on random steps near a slab", "[refccd][filter]") {
  // A 4 x 4 x 2 slab (top at z = 0); a cube or an icosphere moving from above
  // its top, edges and corners, turning by up to about 100 degrees, with
  // non-unit quaternions.
  const auto slab = gauss6::test::make_box(4, 4, 2, Vec3(0, 0, -1));
  const auto cube = gauss6::test::make_box(1, 1, 1);
  const auto ball = gauss6::test::make_icosphere(1, 0.4);
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<double> xy(-2.6, 2.6), z(0.5, 1.2), dz(-1.0, 0.2), c(-1, 1), turn(-0.5, 0.5);
  int hits = 0, misses = 0;
  int64_t filtered = 0, candidates = 0;
  for (const TriangleMesh* body : {&cube, &ball}) {
    const ExactMeshPair mp = make_exact_mesh_pair(*body, slab);
    for (int i = 0; i < 30; ++i) {
      const Quat q0{c(rng), c(rng), c(rng), c(rng)};
      const Quat dq{1, turn(rng), turn(rng), turn(rng)};  // about up to 2 atan(0.87) = 82 degrees
      const Quat q1{dq.w * q0.w - dq.x * q0.x - dq.y * q0.y - dq.z * q0.z,
                    dq.w * q0.x + dq.x * q0.w + dq.y * q0.z - dq.z * q0.y,
                    dq.w * q0.y - dq.x * q0.z + dq.y * q0.w + dq.z * q0.x,
                    dq.w * q0.z + dq.x * q0.y - dq.y * q0.x + dq.z * q0.w};
      const Vec3 p0(xy(rng), xy(rng), z(rng));
      const Vec3 p1 = p0 + Vec3(0.3 * c(rng), 0.3 * c(rng), dz(rng));
      const MeshContact m = both_paths(mp, at(p0, q0), at(p1, q1));
      (m.toi.hit ? hits : misses) += 1;
      filtered += m.num_filtered_pairs;
      candidates += m.num_candidate_pairs;
    }
  }
  CHECK(hits > 10);
  CHECK(misses > 5);
  CHECK(filtered > candidates / 2);  // the filter did most of the work
}

TEST_CASE("filtered first contact: touching all along, grazing and landing flat", "[refccd][filter]") {
  const auto slab = gauss6::test::make_box(4, 4, 2, Vec3(0, 0, -1));
  const auto cube = gauss6::test::make_box(1, 1, 1);
  const ExactMeshPair mp = make_exact_mesh_pair(cube, slab);
  const Quat id{1, 0, 0, 0};
  // Face on face at z = 0, sliding along x: coplanar faces all along, contact at u = 0.
  const MeshContact sliding = both_paths(mp, at(Vec3(0, 0, 0.5), id), at(Vec3(0.5, 0, 0.5), id));
  CHECK(sliding.toi.hit);
  CHECK(sliding.toi.lower == 0);
  // Sliding 1e-6 above it (parallel faces at a constant distance): never touches.
  const MeshContact grazing = both_paths(mp, at(Vec3(0, 0, 0.5 + 1e-6), id), at(Vec3(0.5, 0, 0.5 + 1e-6), id));
  CHECK_FALSE(grazing.toi.hit);
  CHECK(grazing.num_exact_pairs == 0);  // decided by the filter alone
  // Landing flat: four corners and the face touch together at u = 1/2.
  const MeshContact flat = both_paths(mp, at(Vec3(0, 0, 1.5), id), at(Vec3(0, 0, -0.5), id));
  REQUIRE(flat.toi.hit);
  CHECK(flat.toi.lower == 0.5);
  CHECK(flat.toi.upper == 0.5);
  // Resting on the slab and turning about G: its bottom corners dip in at once (u = 0).
  const double h = std::sin(0.25);
  const MeshContact tipping =
      both_paths(mp, at(Vec3(0.5, 0, 0.5), id), at(Vec3(0.5, 0, 0.5), Quat{std::cos(0.25), 0, h, 0}));
  CHECK(tipping.toi.hit);
}

TEST_CASE("separation_within agrees with the exact minimum distance", "[refccd][filter]") {
  const auto slab = gauss6::test::make_box(4, 4, 2, Vec3(0, 0, -1));
  const auto cube = gauss6::test::make_box(1, 1, 1);
  const auto ball = gauss6::test::make_icosphere(1, 0.4);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> xy(-2.6, 2.6), z(-0.1, 1.0), c(-1, 1);
  int within = 0, beyond = 0;
  for (const TriangleMesh* body : {&cube, &ball}) {
    const ExactMeshPair mp = make_exact_mesh_pair(*body, slab);
    for (int i = 0; i < 40; ++i) {
      const Pose X = at(Vec3(xy(rng), xy(rng), z(rng)), Quat{c(rng), c(rng), c(rng), c(rng)});
      for (double d : {0.0, 1e-3, 0.2}) {
        const ExactSeparation e = separation_distance(mp, X, d);
        const SeparationBound b = separation_within(mp, X, d);
        REQUIRE(b.within == e.within);
        (b.within ? within : beyond) += 1;
        if (b.within) {
          CHECK(b.upper >= e.upper);  // an upper bound of the exact distance (e.upper >= it, adjacent)
          CHECK(b.upper <= d * (1 + 1e-12) + 1e-300);
        }
      }
    }
  }
  // The cube resting flat 1e-6 above the slab: parallel faces at the bound's scale.
  const ExactMeshPair mp = make_exact_mesh_pair(cube, slab);
  const Pose resting = at(Vec3(0.3, -0.2, 0.5 + 1e-6), Quat{1, 0, 0, 0});
  CHECK(separation_within(mp, resting, 3e-6).within);
  CHECK_FALSE(separation_within(mp, resting, 0.5e-6).within);
  CHECK(within > 10);
  CHECK(beyond > 10);
}

TEST_CASE("separation_within refuses a bad bound", "[refccd][filter]") {
  const auto slab = gauss6::test::make_box(4, 4, 2, Vec3(0, 0, -1));
  const ExactMeshPair mp = make_exact_mesh_pair(gauss6::test::make_box(1, 1, 1), slab);
  CHECK_THROWS_AS(separation_within(mp, at(Vec3(0, 0, 1), Quat{1, 0, 0, 0}), -1), std::invalid_argument);
  CHECK_THROWS_AS(separation_within(mp, at(Vec3(0, 0, 1), Quat{1, 0, 0, 0}), NAN), std::invalid_argument);
}
