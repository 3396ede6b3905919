// Tests of the posed-mesh queries of the reference (count_intersecting_pairs,
// separation_distance in gauss6/reference/ccd.h): their box culling and
// interval filters must give exactly the answers of a plain exact computation,
// every (body triangle, obstacle triangle) pair tested in Gmpq with no culling
// and no filter. Poses include exact touching (face on face, edge on face, edge
// across edge, shared edges and vertices, vertex on face), built with rational
// rotations so that the contacts are exact, and gaps of one unit in the last
// place. Counts and squared distances are compared exactly: no tolerance.
#include <catch2/catch.hpp>

#include <CGAL/Gmpq.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/intersections.h>
#include <CGAL/squared_distance_3.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "gauss6/reference/ccd.h"
#include "../../optimized/tests/mesh_shapes.h"
#include "off_reader.h"
#include "stopwatch.h"

namespace {

using gauss6::Pose;
using gauss6::Quat;
using gauss6::TriangleMesh;
using gauss6::Vec3;
using namespace gauss6::reference;

using Plain = CGAL::Simple_cartesian<CGAL::Gmpq>;

Pose make_pose(const Vec3& p, const Quat& q) {
  Pose X;
  X.p = p;
  X.q = q;
  return X;
}

Plain::Point_3 plain_point(const ExactPoint& x) {
  return {CGAL::Gmpq(x[0].get_mpq_t()), CGAL::Gmpq(x[1].get_mpq_t()), CGAL::Gmpq(x[2].get_mpq_t())};
}

// The body's triangles at pose X and the obstacle's, in exact coordinates.
struct PlainTriangles {
  std::vector<Plain::Triangle_3> body, obstacle;
};

PlainTriangles plain_triangles(const TriangleMesh& body, const TriangleMesh& obstacle, const Pose& X) {
  std::vector<Plain::Point_3> posed;
  for (int v = 0; v < body.V.rows(); ++v) posed.push_back(plain_point(transform_point_exact(X, body.V.row(v))));
  PlainTriangles t;
  for (int f = 0; f < body.F.rows(); ++f) t.body.emplace_back(posed[body.F(f, 0)], posed[body.F(f, 1)], posed[body.F(f, 2)]);
  auto p = [&](int v) { return Plain::Point_3(obstacle.V(v, 0), obstacle.V(v, 1), obstacle.V(v, 2)); };
  for (int f = 0; f < obstacle.F.rows(); ++f)
    t.obstacle.emplace_back(p(obstacle.F(f, 0)), p(obstacle.F(f, 1)), p(obstacle.F(f, 2)));
  return t;
}

// Every pair, exactly.
int64_t plain_count(const TriangleMesh& body, const TriangleMesh& obstacle, const Pose& X) {
  const PlainTriangles t = plain_triangles(body, obstacle, X);
  int64_t n = 0;
  for (const auto& a : t.body)
    for (const auto& b : t.obstacle) n += CGAL::do_intersect(a, b) ? 1 : 0;
  return n;
}

// The exact minimum squared distance over every pair.
mpq_class plain_squared_distance(const TriangleMesh& body, const TriangleMesh& obstacle, const Pose& X) {
  const PlainTriangles t = plain_triangles(body, obstacle, X);
  CGAL::Gmpq best;
  bool first = true;
  for (const auto& a : t.body)
    for (const auto& b : t.obstacle) {
      const CGAL::Gmpq d2 = CGAL::squared_distance(a, b);
      if (first || d2 < best) best = d2, first = false;
    }
  return mpq_class(best.mpq());
}

// Checks both queries against the plain computation at pose X; returns the count.
int64_t check_pose(const ExactMeshPair& mp, const Pose& X, double max_distance) {
  const int64_t n = count_intersecting_pairs(mp, X);
  CHECK(n == plain_count(mp.god, mp.obstacle, X));
  const mpq_class d2 = plain_squared_distance(mp.god, mp.obstacle, X);
  const ExactSeparation s = separation_distance(mp, X, max_distance);
  const bool within = d2 <= mpq_class(max_distance) * mpq_class(max_distance);
  CHECK(s.within == within);
  if (s.within && within) {
    CHECK(s.squared_distance == d2);
    CHECK(mpq_class(s.lower) * mpq_class(s.lower) <= d2);
    CHECK(d2 <= mpq_class(s.upper) * mpq_class(s.upper));
  }
  CHECK((n > 0) == (d2 == 0));  // closed triangles: intersecting means distance zero
  return n;
}

// z that puts the body's lowest vertex (under rotation q, at p = 0) exactly on
// the plane z = target; *x_low, *y_low: that vertex's x and y at p = 0 (exact
// doubles). Requires those values to be doubles (the tests choose the meshes
// and the rational rotations so that they are).
double rest_on(const TriangleMesh& body, const Quat& q, double target, double* x_low = nullptr,
               double* y_low = nullptr) {
  ExactPoint low;
  for (int v = 0; v < body.V.rows(); ++v) {
    const ExactPoint x = transform_point_exact(make_pose(Vec3::Zero(), q), body.V.row(v));
    if (v == 0 || x[2] < low[2]) low = x;
  }
  const mpq_class z = mpq_class(target) - low[2];
  REQUIRE(mpq_class(z.get_d()) == z);
  REQUIRE(mpq_class(low[0].get_d()) == low[0]);
  REQUIRE(mpq_class(low[1].get_d()) == low[1]);
  if (x_low) *x_low = low[0].get_d();
  if (y_low) *y_low = low[1].get_d();
  return z.get_d();
}

}  // namespace

TEST_CASE("posed counts and distances equal the plain exact ones on random poses", "[refccd][posed]") {
  // A 4 x 4 x 2 slab (top at z = 0) and a 1 x 1 x 1 cube or a tetrahedron-like
  // icosphere, posed at random around the slab's top face, edges and corners,
  // with non-unit quaternions (their exact meaning normalises them).
  const auto slab = gauss6::test::make_box(4, 4, 2, Vec3(0, 0, -1));
  const auto cube = gauss6::test::make_box(1, 1, 1);
  const auto ball = gauss6::test::make_icosphere(1, 0.4);
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> xy(-2.6, 2.6), z(-0.4, 1.0), c(-1, 1);
  int hits = 0, misses = 0;
  for (const TriangleMesh* body : {&cube, &ball}) {
    const ExactMeshPair mp = make_exact_mesh_pair(*body, slab);
    for (int i = 0; i < 40; ++i) {
      const Quat q{c(rng), c(rng), c(rng), c(rng)};
      const Vec3 p(xy(rng), xy(rng), z(rng));
      const int64_t n = check_pose(mp, make_pose(p, q), 0.5);
      (n > 0 ? hits : misses) += 1;
      // q scaled by 2^300 has the same exact meaning but is out of the
      // intervals' range: the same answers through the exact-only path.
      if (i % 8 == 0) {
        const double k = std::ldexp(1.0, 300);
        const Pose scaled = make_pose(p, Quat{k * q.w, k * q.x, k * q.y, k * q.z});
        CHECK(count_intersecting_pairs(mp, scaled) == n);
        const ExactSeparation a = separation_distance(mp, make_pose(p, q), 0.5), b = separation_distance(mp, scaled, 0.5);
        CHECK(a.within == b.within);
        CHECK(a.squared_distance == b.squared_distance);
      }
    }
  }
  // Both outcomes occur, so both branches of the comparison were exercised.
  CHECK(hits > 10);
  CHECK(misses > 10);
}

TEST_CASE("posed counts and distances equal the plain exact ones on exactly touching poses", "[refccd][posed]") {
  const auto slab = gauss6::test::make_box(4, 4, 2, Vec3(0, 0, -1));  // x, y in [-2, 2], z in [-2, 0]
  // Half side h = 25/64: under the rotations below (|q|^2 = 5 or 25, integer
  // entries) every posed coordinate at a dyadic p is dyadic, hence a double.
  const double h = 25.0 / 64;
  const auto cube = gauss6::test::make_box(2 * h, 2 * h, 2 * h);
  const ExactMeshPair mp = make_exact_mesh_pair(cube, slab);
  const double ulp = std::ldexp(1.0, -51);  // of the doubles in [2, 4)

  SECTION("face on face, turned about z by any angle (the z row of R(q) is exactly (0, 0, 1))") {
    for (const Quat q : {Quat{}, Quat{0.9, 0, 0, 0.3}, Quat{std::cos(0.2), 0, 0, std::sin(0.2)}, Quat{2, 0, 0, 1}}) {
      CHECK(check_pose(mp, make_pose(Vec3(0.1, -0.3, h), q), 0.1) > 0);
      CHECK(check_pose(mp, make_pose(Vec3(0.1, -0.3, h + std::ldexp(1.0, -53)), q), 0.1) == 0);
      CHECK(check_pose(mp, make_pose(Vec3(0.1, -0.3, h - std::ldexp(1.0, -53)), q), 0.1) > 0);
    }
  }
  SECTION("shared edge, shared vertex and gaps of one ulp beside the slab") {
    // Cube beside the slab, its bottom face in the slab's top plane.
    CHECK(check_pose(mp, make_pose(Vec3(2 + h, 0, h), Quat{}), 0.1) > 0);         // shares the edge x = 2, z = 0
    CHECK(check_pose(mp, make_pose(Vec3(2 + h, 2 + h, h), Quat{}), 0.1) > 0);     // shares the corner (2, 2, 0)
    CHECK(check_pose(mp, make_pose(Vec3(2 + h + ulp, 0, h), Quat{}), 0.1) == 0);  // one ulp apart
    CHECK(check_pose(mp, make_pose(Vec3(2 + h + ulp, 2 + h + ulp, h), Quat{}), 0.1) == 0);
    // Hanging below the top plane, its face against the slab's side face x = 2.
    CHECK(check_pose(mp, make_pose(Vec3(2 + h, 0.5, -0.5), Quat{}), 0.1) > 0);
  }
  SECTION("edge on face and edge across the slab's edge (rational turn about x, then about z)") {
    // q = (2, 1, 0, 0): R = [[1, 0, 0], [0, 3/5, -4/5], [0, 4/5, 3/5]], the
    // lowest edge runs along x; (4, 2, 1, 2) = (2, 0, 0, 1) (2, 1, 0, 0) turns it
    // about z, keeping the z row.
    for (const Quat q : {Quat{2, 1, 0, 0}, Quat{4, 2, 1, 2}}) {
      const double z = rest_on(cube, q, 0.0);
      CHECK(check_pose(mp, make_pose(Vec3(0.3, 0.2, z), q), 0.1) > 0);         // edge on the top face
      CHECK(check_pose(mp, make_pose(Vec3(2.0, 0.2, z), q), 0.1) > 0);         // edge across the edge x = 2
      CHECK(check_pose(mp, make_pose(Vec3(0.3, 0.2, z + 1e-12), q), 0.1) == 0);  // lifted by 1 pm
    }
  }
  SECTION("vertex on face, vertex on the slab's edge and corner (q = (4, 2, 2, 1), |q|^2 = 25)") {
    const Quat q{4, 2, 2, 1};
    double x_low = 0, y_low = 0;
    const double z = rest_on(cube, q, 0.0, &x_low, &y_low);
    CHECK(check_pose(mp, make_pose(Vec3(0.25, -0.5, z), q), 0.1) > 0);  // vertex on the top face
    CHECK(check_pose(mp, make_pose(Vec3(2 - x_low, 0.5, z), q), 0.1) > 0);  // vertex on the edge x = 2
    CHECK(check_pose(mp, make_pose(Vec3(2 - x_low, 2 - y_low, z), q), 0.1) > 0);  // vertex on the corner
    CHECK(check_pose(mp, make_pose(Vec3(std::nextafter(2 - x_low, 3), std::nextafter(2 - y_low, 3), z), q), 0.1) ==
          0);  // the vertex one ulp beyond the corner
  }
  SECTION("edge across a ridge: a single point of contact between two edges") {
    // A wedge whose top edge is the x axis, and the cube turned about y by
    // q = (2, 0, 1, 0) (R = [[3/5, 0, 4/5], [0, 1, 0], [-4/5, 0, 3/5]]): its
    // lowest edge runs along y and crosses the ridge at one point.
    TriangleMesh wedge = gauss6::test::make_mesh(
        {Vec3(-1, -1, -1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(1, 1, -1), Vec3(-1, 0, 0), Vec3(1, 0, 0)},
        {{0, 2, 1}, {1, 2, 3}, {0, 1, 5}, {0, 5, 4}, {2, 4, 5}, {2, 5, 3}, {0, 4, 2}, {1, 3, 5}}, "wedge");
    const ExactMeshPair on_ridge = make_exact_mesh_pair(cube, wedge);
    const Quat q{2, 0, 1, 0};
    const double z = rest_on(cube, q, 0.0);
    CHECK(check_pose(on_ridge, make_pose(Vec3(0.1, 0.05, z), q), 0.1) > 0);
    CHECK(check_pose(on_ridge, make_pose(Vec3(0.1, 0.05, std::nextafter(z, 1.0)), q), 0.1) == 0);
    // Sunk by 1 nm: the edge cuts both faces of the ridge.
    CHECK(check_pose(on_ridge, make_pose(Vec3(0.1, 0.05, z - 1e-9), q), 0.1) >= 2);
  }
}

TEST_CASE("posed counts on the peg-in-hole meshes equal the plain exact count", "[refccd][posed]") {
  const std::string root = std::string(GAUSS6_SOURCE_DIR) + "/datasets_generated/peg_in_hole/";
  if (!std::filesystem::exists(root + "peg.off")) {
    WARN("peg-in-hole meshes absent: " << root);
    return;
  }
  const auto peg = gauss6::test::read_off(root + "peg.off"), box = gauss6::test::read_off(root + "box_with_hole.off");
  const ExactMeshPair mp = make_exact_mesh_pair(peg, box);
  // The peg lies along y; its lowest point is 0.01 below G. Over the top
  // (z = 0.03): 1 um above it, tilted 0.5 mm above it, 0.1 mm into it; in the
  // hole on its axis (0.2 mm of clearance), and 0.5 mm off the axis.
  const Pose poses[5] = {make_pose(Vec3(0, 0, 0.040001), Quat{}),
                         make_pose(Vec3(0, 0, 0.0405), Quat{1, 0.002, 0.001, 0.003}),
                         make_pose(Vec3(0, 0, 0.0399), Quat{}), make_pose(Vec3(0, -0.05, 0), Quat{}),
                         make_pose(Vec3(0, -0.05, 0.0005), Quat{})};
  const bool intersects[5] = {false, false, true, false, true};
  for (int i = 0; i < 5; ++i) {
    const int64_t n = count_intersecting_pairs(mp, poses[i]);
    CHECK(n == plain_count(peg, box, poses[i]));
    CHECK((n > 0) == intersects[i]);
  }
}

TEST_CASE("posed-mesh check timing on the peg-in-hole and bunny scenes", "[refccd][posed][timing]") {
  // Prints the mean time of count_intersecting_pairs per pose (no timed
  // assertion): poses near contact, where the boxes overlap the most.
  const std::string root = std::string(GAUSS6_SOURCE_DIR) + "/datasets_generated/";
  auto time_poses = [](const ExactMeshPair& mp, const std::vector<Pose>& poses, int64_t* total) {
    const auto t0 = std::chrono::steady_clock::now();
    *total = 0;
    for (const Pose& X : poses) *total += count_intersecting_pairs(mp, X);
    return seconds_since(t0) / double(poses.size());
  };
  std::mt19937_64 rng(7);
  std::normal_distribution<double> jitter(0, 1e-4);
  if (std::filesystem::exists(root + "peg_in_hole/peg.off")) {
    const auto peg = gauss6::test::read_off(root + "peg_in_hole/peg.off"),
               box = gauss6::test::read_off(root + "peg_in_hole/box_with_hole.off");
    const ExactMeshPair mp = make_exact_mesh_pair(peg, box);
    std::vector<Pose> poses;
    for (int i = 0; i < 20; ++i)  // in the hole, near its axis (0.2 mm clearance)
      poses.push_back(make_pose(Vec3(jitter(rng), -0.05 + 0.01 * i / 20, jitter(rng)), Quat{1, jitter(rng), 0, jitter(rng)}));
    int64_t total = 0;
    const double t = time_poses(mp, poses, &total);
    std::printf("[refccd] peg in the hole: count_intersecting_pairs %.3f ms per pose (%zu poses, %lld pairs)\n",
                1e3 * t, poses.size(), (long long)total);
  }
  if (std::filesystem::exists(root + "bunny/bunny.off")) {
    const auto bunny = gauss6::test::read_off(root + "bunny/bunny.off");
    const ExactMeshPair mp = make_exact_mesh_pair(bunny, bunny);
    std::vector<Pose> poses;
    for (int i = 0; i < 20; ++i)  // side by side, about to touch (first contact near x = 0.135)
      poses.push_back(make_pose(Vec3(0.137 + jitter(rng), jitter(rng), jitter(rng)), Quat{1, jitter(rng), jitter(rng), 0}));
    int64_t total = 0;
    const double t = time_poses(mp, poses, &total);
    std::printf("[refccd] bunny beside bunny: count_intersecting_pairs %.3f ms per pose (%zu poses, %lld pairs)\n",
                1e3 * t, poses.size(), (long long)total);
  }
}
