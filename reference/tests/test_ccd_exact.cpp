// Tests of the exact continuous collision detection (gauss6/reference/ccd.h)
// and of the shared CCD query reader (gauss6/io/ccd_queries.h). Every expected
// time here is derived by hand; the comparisons are exact (rationals), so no
// tolerance is involved unless a test says otherwise.
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <sstream>
#include <string>

#include "gauss6/io/ccd_queries.h"
#include "gauss6/reference/ccd.h"

namespace {

using gauss6::Pose;
using gauss6::Quat;
using gauss6::Vec3;
using gauss6::FeaturePairIds;
using gauss6::kPairKinds;
using gauss6::PairKind;
using gauss6::PairKindInfo;
using namespace gauss6::reference;

ExactPoint P(const mpq_class& x, const mpq_class& y, const mpq_class& z) { return {x, y, z}; }
mpq_class Q(long n, long d = 1) {
  mpq_class q(n, d);
  q.canonicalize();
  return q;
}

// The linear queries from the points at t = 0 and t = 1 in the order v, f0, f1,
// f2 (vertex/face) or a0, a1, b0, b1 (edge/edge).
ExactToi vertex_face_linear(const std::array<ExactPoint, 4>& x0, const std::array<ExactPoint, 4>& x1) {
  return ccd_linear_vertex_face({{x0[0], x1[0]}, {{{x0[1], x0[2], x0[3]}, {x1[1], x1[2], x1[3]}}}});
}
ExactToi edge_edge_linear(const std::array<ExactPoint, 4>& x0, const std::array<ExactPoint, 4>& x1) {
  return ccd_linear_edge_edge({{{{x0[0], x0[1]}, {x1[0], x1[1]}}}, {{{x0[2], x0[3]}, {x1[2], x1[3]}}}});
}

mpq_class eval(const std::vector<mpz_class>& poly, const mpq_class& u) {
  mpq_class acc = 0;
  for (auto it = poly.rbegin(); it != poly.rend(); ++it) acc = acc * u + mpq_class(*it);
  return acc;
}

// toi hits exactly at the rational t: the double bracket is the tightest one
// around t, the isolating interval holds t and t is a root of the polynomial.
void require_hit_at(const ExactToi& toi, const mpq_class& t) {
  REQUIRE(toi.hit);
  CHECK(mpq_class(toi.lower) <= t);
  CHECK(t <= mpq_class(toi.upper));
  if (mpq_class(mpq_get_d(t.get_mpq_t())) == t) {
    CHECK(toi.lower == toi.upper);
    CHECK(compare_toi(toi, toi.lower) == 0);
  } else {
    CHECK(toi.upper == std::nextafter(toi.lower, 2.0));
    CHECK(compare_toi(toi, toi.lower) == -1);
    CHECK(compare_toi(toi, toi.upper) == +1);
  }
  CHECK(toi.isolating_lower <= t);
  CHECK(t <= toi.isolating_upper);
  CHECK(eval(toi.poly, t) == 0);
}

std::string data_root() {
#ifdef GAUSS6_SOURCE_DIR
  return std::string(GAUSS6_SOURCE_DIR) + "/../shared/data/ccd-sample-queries";
#else
  return "../shared/data/ccd-sample-queries";
#endif
}

std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path.string();
}

}  // namespace

// ---------------------------------------------------------------------------
// Query reader.

TEST_CASE("ccd query reader parses rows and rejects malformed files", "[refccd]") {
  const std::string row = "0,1,1,1,0,1,1\n";
  std::string good;
  for (int i = 0; i < 8; ++i) good += row;
  const auto queries = gauss6::read_ccd_queries(write_temp("refccd_good.csv", good + "\n"), gauss6::CcdQuery::kEdgeEdge);
  REQUIRE(queries.size() == 1);
  CHECK(queries[0].expected);
  CHECK(queries[0].kind == gauss6::CcdQuery::kEdgeEdge);
  CHECK(queries[0].points[3].xyz[1].num == "1");

  auto message_of = [](const std::string& path) {
    try {
      gauss6::read_ccd_queries(path, gauss6::CcdQuery::kVertexFace);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // Wrong column count on line 2.
  std::string bad = row + "0,1,1,1,0,1\n";
  CHECK(message_of(write_temp("refccd_cols.csv", bad)).find("refccd_cols.csv:2") != std::string::npos);
  // Zero denominator.
  CHECK(message_of(write_temp("refccd_den.csv", "0,0,1,1,0,1,1\n")).find(":1: zero denominator") != std::string::npos);
  // 7 rows only.
  CHECK(message_of(write_temp("refccd_rows.csv", good.substr(row.size()))).find("multiple of 8") != std::string::npos);
  // Ground truth changes inside a query.
  CHECK(message_of(write_temp("refccd_truth.csv", good.substr(row.size()) + "0,1,1,1,0,1,0\n"))
            .find("ground truth differs") != std::string::npos);
  // A negative denominator moves its sign onto the numerator.
  std::string neg = "3,-4,1,1,0,1,0\n";
  for (int i = 0; i < 7; ++i) neg += "0,1,1,1,0,1,0\n";
  const auto q = gauss6::read_ccd_queries(write_temp("refccd_neg.csv", neg), gauss6::CcdQuery::kVertexFace);
  CHECK(q[0].points[0].xyz[0].num == "-3");
  CHECK(q[0].points[0].xyz[0].den == "4");
}

TEST_CASE("to_double rounds to nearest and reports exactness", "[refccd]") {
  bool exact = false;
  CHECK(gauss6::to_double(gauss6::Rational{"-3", "4"}, &exact) == -0.75);
  CHECK(exact);
  CHECK(gauss6::to_double(gauss6::Rational{"1", "3"}, &exact) == 1.0 / 3.0);  // division is correctly rounded
  CHECK_FALSE(exact);
  // 2^53 + 1 is not a double: ties to even gives 2^53.
  CHECK(gauss6::to_double(gauss6::Rational{"9007199254740993", "1"}, &exact) == 9007199254740992.0);
  CHECK_FALSE(exact);
  // A 112-bit numerator over a power of two, as in the sample data: exact.
  CHECK(gauss6::to_double(gauss6::Rational{"2596148429267413814265248164610048", "1"}, &exact) == std::ldexp(1.0, 111));
  CHECK(exact);
  CHECK_THROWS_AS(gauss6::to_double(gauss6::Rational{"1" + std::string(40, '0'), "1"}), std::out_of_range);
}

// ---------------------------------------------------------------------------
// Linear motion, hand-made.

TEST_CASE("linear vertex/face: known exact times", "[refccd]") {
  const ExactPoint a = P(0, 0, 0), b = P(3, 0, 0), c = P(0, 3, 0);
  SECTION("vertex falls onto the face at t = 1/3") {
    require_hit_at(vertex_face_linear({P(1, 1, 1), a, b, c}, {P(1, 1, -2), a, b, c}), Q(1, 3));
  }
  SECTION("contact at t = 0") {
    require_hit_at(vertex_face_linear({P(Q(1, 4), Q(1, 4), 0), a, b, c}, {P(1, 1, -1), a, b, c}), Q(0));
  }
  SECTION("vertex crosses an edge of the face at t = 1/2") {
    require_hit_at(vertex_face_linear({P(1, 0, 1), a, b, c}, {P(1, 0, -1), a, b, c}), Q(1, 2));
  }
  SECTION("grazing a corner: hit; passing 2^-20 beside it: miss") {
    require_hit_at(vertex_face_linear({P(-1, -1, 1), a, b, c}, {P(1, 1, -1), a, b, c}), Q(1, 2));
    const mpq_class e = Q(1, 1 << 20);
    CHECK_FALSE(vertex_face_linear({P(-1 - e, -1, 1), a, b, c}, {P(1 - e, 1, -1), a, b, c}).hit);
  }
  SECTION("coplanar motion: the vertex slides into the face at t = 1/3") {
    require_hit_at(vertex_face_linear({P(-1, Q(1, 4), 0), a, b, c}, {P(2, Q(1, 4), 0), a, b, c}), Q(1, 3));
    // Same plane, passing beside the face: no contact.
    CHECK_FALSE(vertex_face_linear({P(-1, 4, 0), a, b, c}, {P(2, 4, 0), a, b, c}).hit);
  }
  SECTION("the face moves onto a static vertex; the face itself moves") {
    const ExactPoint v = P(1, 1, 0);
    require_hit_at(vertex_face_linear({v, P(0, 0, 2), P(3, 0, 2), P(0, 3, 2)},
                                          {v, P(0, 0, -4), P(3, 0, -4), P(0, 3, -4)}),
                   Q(1, 3));
  }
  SECTION("a triangle collapsing to a segment and flipping, coplanar with the vertex all along") {
    // c(t) = (1 - 2t) (0, 3, 1): the plane of abc is span{(1,0,0), (0,3,1)} for
    // every t != 1/2, and abc collapses onto [a, b] at t = 1/2. In the plane
    // coordinates (x, w) along those two directions the triangle is (0,0),
    // (3,0), (0, 1 - 2t). The vertex (1, 1, 1/3), i.e. (x, w) = (1, 1/3), is
    // inside at t = 0 (1/3 + (1/3) / 1 <= 1).
    require_hit_at(vertex_face_linear({P(1, 1, Q(1, 3)), a, b, P(0, 3, 1)},
                                          {P(1, 1, Q(1, 3)), a, b, P(0, -3, -1)}),
                   Q(0));
    // The vertex (1, -1, -1/3), (x, w) = (1, -1/3), is reached by the flipped
    // triangle (2t - 1 = k > 0) when 1/3 + 1 / (3k) <= 1, i.e. k >= 1/2: t = 3/4.
    require_hit_at(vertex_face_linear({P(1, -1, Q(-1, 3)), a, b, P(0, 3, 1)},
                                          {P(1, -1, Q(-1, 3)), a, b, P(0, -3, -1)}),
                   Q(3, 4));
    // A vertex on the line of [a, b] beyond b: on the collapsed triangle's line
    // but never in the triangle.
    CHECK_FALSE(vertex_face_linear({P(4, 0, 0), a, b, P(0, 3, 1)}, {P(4, 0, 0), a, b, P(0, -3, -1)}).hit);
    // The vertex (1, 0, 0) on edge [a, b]: contact from t = 0.
    require_hit_at(vertex_face_linear({P(1, 0, 0), a, b, P(0, 3, 1)}, {P(1, 0, 0), a, b, P(0, -3, -1)}), Q(0));
  }
}

TEST_CASE("linear edge/edge: known exact times", "[refccd]") {
  SECTION("crossing edges at t = 1/2") {
    const auto toi = edge_edge_linear({P(-1, 0, 1), P(1, 0, 1), P(0, -1, 0), P(0, 1, 0)},
                                          {P(-1, 0, -1), P(1, 0, -1), P(0, -1, 0), P(0, 1, 0)});
    require_hit_at(toi, Q(1, 2));
    CHECK(compare_toi(toi, 0.5) == 0);
    CHECK(compare_toi(toi, std::nextafter(0.5, 0.0)) == -1);
  }
  SECTION("crossing lines whose segments miss") {
    CHECK_FALSE(edge_edge_linear({P(1, 0, 1), P(3, 0, 1), P(0, -1, 0), P(0, 1, 0)},
                                     {P(1, 0, -1), P(3, 0, -1), P(0, -1, 0), P(0, 1, 0)})
                    .hit);
  }
  SECTION("parallel edges: overlap at t = 1/3, collinear without overlap, never coplanar-touching") {
    // b slides in the plane z = 0 towards a, collinear at y = 0 when t = 1/3.
    require_hit_at(edge_edge_linear({P(0, 0, 0), P(2, 0, 0), P(1, 1, 0), P(3, 1, 0)},
                                        {P(0, 0, 0), P(2, 0, 0), P(1, -2, 0), P(3, -2, 0)}),
                   Q(1, 3));
    CHECK_FALSE(edge_edge_linear({P(0, 0, 0), P(2, 0, 0), P(3, 1, 0), P(4, 1, 0)},
                                     {P(0, 0, 0), P(2, 0, 0), P(3, -2, 0), P(4, -2, 0)})
                    .hit);
    // Parallel in z = 1: always coplanar with a (two parallel lines), never touching.
    CHECK_FALSE(edge_edge_linear({P(0, 0, 0), P(2, 0, 0), P(1, 1, 1), P(3, 1, 1)},
                                     {P(0, 0, 0), P(2, 0, 0), P(1, -2, 1), P(3, -2, 1)})
                    .hit);
  }
  SECTION("endpoint touching an edge, and a zero-length edge") {
    // b0 reaches the interior of a at t = 1/3 (b is perpendicular, coming down).
    require_hit_at(edge_edge_linear({P(0, 0, 0), P(2, 0, 0), P(1, 0, 1), P(1, 0, 2)},
                                        {P(0, 0, 0), P(2, 0, 0), P(1, 0, -2), P(1, 0, -1)}),
                   Q(1, 3));
    // Degenerate a (a point) crossing b at t = 1/4.
    require_hit_at(edge_edge_linear({P(1, 1, 0), P(1, 1, 0), P(0, 0, 0), P(2, 0, 0)},
                                        {P(1, -3, 0), P(1, -3, 0), P(0, 0, 0), P(2, 0, 0)}),
                   Q(1, 4));
  }
}

// ---------------------------------------------------------------------------
// The shared sample queries (Tight-Inclusion benchmark), exact ground truth.

TEST_CASE("exact CCD reproduces the ground truth of every sample query", "[refccd]") {
  const auto files = gauss6::list_ccd_query_files(data_root());
  REQUIRE(files.size() == 32);
  int64_t num_queries = 0, false_negatives = 0, false_positives = 0, hits = 0;
  const auto start = std::chrono::steady_clock::now();
  for (const auto& f : files) {
    for (const auto& q : gauss6::read_ccd_queries(f.path, f.kind)) {
      const ExactToi toi = query_toi(q);
      ++num_queries;
      hits += toi.hit;
      if (q.expected && !toi.hit) {
        ++false_negatives;
        UNSCOPED_INFO("false negative: " << f.path << ":" << q.line);
      }
      if (!q.expected && toi.hit) {
        ++false_positives;
        UNSCOPED_INFO("false positive: " << f.path << ":" << q.line);
      }
      if (toi.hit) {
        CHECK(toi.lower >= 0.0);
        CHECK(toi.upper <= 1.0);
      }
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("[refccd] %lld sample queries (%lld hits): %lld false negatives, %lld false positives, %.2f s\n",
              (long long)num_queries, (long long)hits, (long long)false_negatives, (long long)false_positives,
              seconds);
  CHECK(num_queries == 3824);
  CHECK(false_negatives == 0);
  CHECK(false_positives == 0);
}

// ---------------------------------------------------------------------------
// Cayley motion.

namespace {

Pose pose(const Vec3& p, const Quat& q) {
  Pose x;
  x.p = p;
  x.q = q;
  return x;
}

Quat unit(const Quat& q) {
  const double n = std::sqrt(q.norm2());
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}

// Rotation by angle about the unit z axis, in doubles.
Quat about_z(double angle) { return {std::cos(0.5 * angle), 0, 0, std::sin(0.5 * angle)}; }

}  // namespace

TEST_CASE("Cayley pure rotation sweeps features into each other at the exact Cayley time", "[refccd]") {
  // The body turns about G = origin by 90 degrees about z. Under the Cayley
  // motion its rotation angle is 2 atan(u g), g = q1.z / q1.w exactly (q0 = 1).
  // A body direction at angle 0 reaches the direction (3, 4) (angle phi with
  // tan(phi / 2) = 1/2) when u g = 1/2: u* = q1.w / (2 q1.z), an exact rational.
  const Quat q1 = about_z(0.5 * M_PI);
  const auto m = make_exact_cayley_motion(pose(Vec3::Zero(), Quat{}), pose(Vec3::Zero(), q1));
  const mpq_class u_star = mpq_class(q1.w) / (2 * mpq_class(q1.z));

  SECTION("moving vertex into a static face") {
    // Face in the half-plane of direction (3, 4): (rho, z) = (0, -1), (5, -1), (0, 2);
    // the vertex (1, 0, 0) arrives at rho = 1, z = 0, inside.
    require_hit_at(ccd_rigid_vertex_face({&m, Vec3(1, 0, 0), {Vec3(0, 0, -1), Vec3(3, 4, -1), Vec3(0, 0, 2)}}),
                   u_star);
  }
  SECTION("static vertex hit by a moving face") {
    // Body face in the half-plane of direction (1, 0), scaled by 5; static vertex (3, 4, 0).
    require_hit_at(ccd_rigid_face_vertex({&m, Vec3(3, 4, 0), {Vec3(0, 0, -5), Vec3(25, 0, -5), Vec3(0, 0, 10)}}),
                   u_star);
  }
  SECTION("moving edge against a static edge") {
    require_hit_at(ccd_rigid_edge_edge({&m, {Vec3(1, 0, -1), Vec3(1, 0, 1)}, {Vec3(0, 0, 0), Vec3(6, 8, 0)}}),
                   u_star);
  }
  SECTION("the exact positions agree: at u*, the vertex is on the ray of direction (3, 4)") {
    const ExactPoint x = motion_point_exact(m, u_star, Vec3(1, 0, 0));
    CHECK(4 * x[0] == 3 * x[1]);
    CHECK(x[0] * x[0] + x[1] * x[1] == 1);
    CHECK(x[2] == 0);
  }
}

TEST_CASE("Cayley motion without rotation equals the linear motion", "[refccd]") {
  // q0 = q1 = 1: every body point translates; R(q0) = I exactly.
  const Vec3 p0(0.25, -0.5, 1.0), p1(-0.75, 0.5, -2.0);
  const auto m = make_exact_cayley_motion(pose(p0, Quat{}), pose(p1, Quat{}));
  const Vec3 v_B(0.125, 0.375, 0.0);
  const std::array<Vec3, 3> f_W = {Vec3(-1, -1, 0), Vec3(2, -1, 0.5), Vec3(-1, 2, -0.25)};
  auto ex = [](const Vec3& x) { return P(mpq_class(x[0]), mpq_class(x[1]), mpq_class(x[2])); };
  const ExactToi cayley = ccd_rigid_vertex_face({&m, v_B, f_W});
  const ExactToi linear = vertex_face_linear({ex(p0 + v_B), ex(f_W[0]), ex(f_W[1]), ex(f_W[2])},
                                             {ex(p1 + v_B), ex(f_W[0]), ex(f_W[1]), ex(f_W[2])});
  REQUIRE(cayley.hit);
  REQUIRE(linear.hit);
  CHECK(compare_toi(cayley, linear) == 0);
  CHECK(cayley.lower == linear.lower);
  CHECK(cayley.upper == linear.upper);
}

TEST_CASE("Cayley contact polynomials have degree <= 3 and exact brackets", "[refccd]") {
  // Random general motions (translation and rotation) and random features:
  // after removing the positive factors W, the coplanarity polynomial has
  // degree <= 3 (generically exactly 3). At each hit, the signed volume of the
  // 4 points, computed from exact positions along the motion (an independent
  // formula), does not have one strict sign on both ends of the double bracket
  // unless the contact is a touch without crossing (then it is 0 at u*).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  auto rand_vec = [&] { return Vec3(uni(rng), uni(rng), uni(rng)); };
  auto rand_quat = [&] {
    Quat q{uni(rng), uni(rng), uni(rng), uni(rng)};
    return q;
  };
  int num_deg3 = 0, num_hits = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Quat q0 = rand_quat(), q1 = rand_quat();
    const Pose X0 = pose(0.2 * rand_vec(), q0), X1 = pose(0.2 * rand_vec(), q1);
    const auto m = make_exact_cayley_motion(X0, X1);
    const Vec3 v_B = 0.5 * rand_vec();
    const std::array<Vec3, 3> f = {0.5 * rand_vec(), 0.5 * rand_vec(), 0.5 * rand_vec()};
    const std::array<Vec3, 2> e_B = {0.5 * rand_vec(), 0.5 * rand_vec()}, e_W = {0.5 * rand_vec(), 0.5 * rand_vec()};
    const int d1 = coplanarity_degree(RigidVertexFaceQuery{&m, v_B, f}),
              d2 = coplanarity_degree(RigidFaceVertexQuery{&m, v_B, f}),
              d3 = coplanarity_degree(RigidEdgeEdgeQuery{&m, e_B, e_W});
    CHECK(d1 <= 3);
    CHECK(d2 <= 3);
    CHECK(d3 <= 3);
    num_deg3 += (d1 == 3) + (d2 == 3) + (d3 == 3);

    const ExactToi toi = ccd_rigid_vertex_face({&m, v_B, f});
    if (!toi.hit) continue;
    ++num_hits;
    auto volume = [&](double u) {
      const ExactPoint x = motion_point_exact(m, mpq_class(u), v_B);
      mpq_class d[3][3];
      for (int c = 0; c < 3; ++c) {
        d[0][c] = mpq_class(f[1][c]) - mpq_class(f[0][c]);
        d[1][c] = mpq_class(f[2][c]) - mpq_class(f[0][c]);
        d[2][c] = x[c] - mpq_class(f[0][c]);
      }
      const mpq_class det = d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1]) -
                            d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0]) +
                            d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]);
      return sgn(det);
    };
    const int s_lo = volume(toi.lower), s_hi = volume(toi.upper);
    CHECK(s_lo * s_hi <= 0);
  }
  CHECK(num_deg3 > 500);  // 600 polynomials: all but degenerate draws have degree 3
  CHECK(num_hits > 0);
}

TEST_CASE("Cayley motion refuses half turns and zero quaternions", "[refccd]") {
  CHECK_THROWS_AS(make_exact_cayley_motion(pose(Vec3::Zero(), Quat{}), pose(Vec3::Zero(), Quat{0, 1, 0, 0})),
                  std::domain_error);
  CHECK_THROWS_AS(make_exact_cayley_motion(pose(Vec3::Zero(), Quat{0, 0, 0, 0}), pose(Vec3::Zero(), Quat{})),
                  std::domain_error);
  // q1 = -q0 is no rotation at all: the sign fix makes g = 0.
  const auto m = make_exact_cayley_motion(pose(Vec3::Zero(), Quat{1, 0, 0, 0}), pose(Vec3::Zero(), Quat{-1, 0, 0, 0}));
  CHECK(m.v[0] == 0);
  CHECK(m.v[1] == 0);
  CHECK(m.v[2] == 0);
  CHECK(m.s > 0);
}

// ---------------------------------------------------------------------------
// Mesh level.

#include "../../optimized/tests/mesh_shapes.h"
#include "off_reader.h"
#include "stopwatch.h"

namespace {

using gauss6::test::read_off;

}  // namespace

TEST_CASE("mesh first contact: a cube dropped onto a slab touches at the exact time", "[refccd]") {
  // Obstacle: slab 4 x 4 x 2 with its top face at z = 0. Body: unit cube about
  // its centre G. G goes from z = 2 to z = 0: the bottom face (z = G - 1/2)
  // reaches z = 0 at u* = 3/4, with or without a turn about the vertical axis
  // (which keeps the bottom face horizontal, exactly: R(q) has third row (0, 0, 1)).
  const auto slab = gauss6::test::make_box(4, 4, 2, Vec3(0, 0, -1));
  const auto cube = gauss6::test::make_box(1, 1, 1);
  const ExactMeshPair mp = make_exact_mesh_pair(cube, slab);
  CHECK(mp.god_edges.size() == 18);
  for (const double turn : {0.0, 0.3}) {
    const Pose X0 = pose(Vec3(0.125, -0.25, 2), Quat{}), X1 = pose(Vec3(0.125, -0.25, 0), about_z(turn));
    const MeshContact c = mesh_first_contact(mp, X0, X1);
    require_hit_at(c.toi, Q(3, 4));
    REQUIRE_FALSE(c.pairs.empty());
    bool has_vertex_face = false;
    for (const auto& p : c.pairs) has_vertex_face |= p.kind == PairKind::kGodVertexObstacleFace;
    CHECK(has_vertex_face);  // the cube's 4 bottom corners land on the slab's top
    CHECK(c.num_candidate_pairs > 0);
  }
  // Moving up and away: no contact.
  const MeshContact away = mesh_first_contact(mp, pose(Vec3(0, 0, 2), Quat{}), pose(Vec3(1, 0, 3), about_z(0.5)));
  CHECK_FALSE(away.toi.hit);
  // Starting in contact: u* = 0.
  require_hit_at(mesh_first_contact(mp, pose(Vec3(0, 0, 0.5), Quat{}), pose(Vec3(0, 0, 2), Quat{})).toi, Q(0));
}

TEST_CASE("mesh first contact: each touching pair, solved alone, touches at u* (canonical ids)", "[refccd]") {
  const auto slab = gauss6::test::make_box(4, 4, 2, Vec3(0, 0, -1));
  const auto cube = gauss6::test::make_box(1, 1, 1);
  const ExactMeshPair mp = make_exact_mesh_pair(cube, slab);
  const Pose X0 = pose(Vec3(0.125, -0.25, 2), Quat{}), X1 = pose(Vec3(0.125, -0.25, 0), about_z(0.3));
  const MeshContact c = mesh_first_contact(mp, X0, X1);
  REQUIRE(c.toi.hit);
  const auto m = make_exact_cayley_motion(X0, X1);
  for (const FeaturePairIds& p : c.pairs) {
    const PairKindInfo& info = kPairKinds[int(p.kind)];
    CHECK(p.god.feature == info.god);
    CHECK(p.obstacle.feature == info.obstacle);
    if (p.god.feature == gauss6::Feature::kEdge) CHECK(p.god.a < p.god.b);
    CHECK(compare_toi(feature_pair_first_contact(mp, m, p), c.toi) == 0);
  }
  // Ids that do not match the kind, or out of range, are refused.
  FeaturePairIds wrong = c.pairs.front();
  wrong.god = gauss6::face_id(0);
  if (wrong.kind != PairKind::kObstacleVertexGodFace) CHECK_THROWS_AS(feature_pair_first_contact(mp, m, wrong),
                                                                       std::invalid_argument);
  const FeaturePairIds far{PairKind::kGodVertexObstacleFace, gauss6::vertex_id(int32_t(cube.V.rows())),
                           gauss6::face_id(0)};
  CHECK_THROWS_AS(feature_pair_first_contact(mp, m, far), std::invalid_argument);
}

TEST_CASE("canonical feature ids of an optimized feature pair (gauss6/geometry/feature_ids.h)", "[refccd]") {
  gauss6::MatrixX3i god_F(2, 3), obstacle_F(1, 3);
  god_F << 0, 1, 2, 2, 1, 3;
  obstacle_F << 7, 5, 6;
  gauss6::FeaturePair p;
  p.kind = PairKind::kGodVertexObstacleFace;
  p.god_face = 1, p.god_corner = 2, p.obstacle_face = 0, p.obstacle_corner = -1;
  CHECK(gauss6::feature_ids(p, god_F, obstacle_F) ==
        FeaturePairIds{p.kind, gauss6::vertex_id(3), gauss6::face_id(0)});
  p.kind = PairKind::kObstacleVertexGodFace;
  p.god_corner = -1, p.obstacle_corner = 1;
  CHECK(gauss6::feature_ids(p, god_F, obstacle_F) ==
        FeaturePairIds{p.kind, gauss6::face_id(1), gauss6::vertex_id(5)});
  // Edges: sorted vertex pairs, whichever triangle (and direction) names them.
  p.kind = PairKind::kEdgeEdge;
  p.god_face = 0, p.god_corner = 1, p.obstacle_corner = 2;
  const FeaturePairIds e = gauss6::feature_ids(p, god_F, obstacle_F);
  CHECK(e == FeaturePairIds{p.kind, gauss6::edge_id(1, 2), gauss6::edge_id(6, 7)});
  p.god_face = 1, p.god_corner = 0;  // the same god edge, from the other triangle
  CHECK(gauss6::feature_ids(p, god_F, obstacle_F) == e);
}

TEST_CASE("mesh first contact: culling keeps the brute-force minimum (turning stick against a post)", "[refccd]") {
  // Body: a stick along x from 1 to 3 (0.1 thick), turning about the z axis
  // through G = origin by 90 degrees; obstacle: a post in its way. The culled
  // mesh-level answer must equal the brute-force minimum over every feature
  // pair (no culling), exactly, and culling must skip some pairs.
  const auto stick = gauss6::test::make_box(2, 0.1, 0.1, Vec3(2, 0, 0));
  // Post: a box around the point 2.5 (3, 4)/5 = (1.5, 2), 0.2 wide.
  const auto post = gauss6::test::make_box(0.2, 0.2, 1, Vec3(1.5, 2, 0));
  const ExactMeshPair mp = make_exact_mesh_pair(stick, post);
  const Quat q1 = about_z(0.5 * M_PI);
  const Pose X0 = pose(Vec3::Zero(), Quat{}), X1 = pose(Vec3::Zero(), q1);
  const MeshContact c = mesh_first_contact(mp, X0, X1);
  REQUIRE(c.toi.hit);
  // Brute force over every feature pair, without culling: the same exact time.
  const auto m = make_exact_cayley_motion(X0, X1);
  ExactToi best;
  auto consider = [&](const ExactToi& t) {
    if (compare_toi(t, best) < 0) best = t;
  };
  auto V = [](const gauss6::TriangleMesh& mesh, int v) { return Vec3(mesh.V.row(v).transpose()); };
  auto F = [&](const gauss6::TriangleMesh& mesh, int f) {
    return std::array<Vec3, 3>{V(mesh, mesh.F(f, 0)), V(mesh, mesh.F(f, 1)), V(mesh, mesh.F(f, 2))};
  };
  for (int v = 0; v < stick.V.rows(); ++v)
    for (int f = 0; f < post.F.rows(); ++f) consider(ccd_rigid_vertex_face({&m, V(stick, v), F(post, f)}));
  for (int v = 0; v < post.V.rows(); ++v)
    for (int f = 0; f < stick.F.rows(); ++f) consider(ccd_rigid_face_vertex({&m, V(post, v), F(stick, f)}));
  for (const auto& a : mp.god_edges)
    for (const auto& b : mp.obstacle_edges)
      consider(ccd_rigid_edge_edge({&m, {V(stick, a[0]), V(stick, a[1])}, {V(post, b[0]), V(post, b[1])}}));
  REQUIRE(best.hit);
  CHECK(compare_toi(c.toi, best) == 0);
  CHECK(c.num_candidate_pairs < int64_t(stick.V.rows() * post.F.rows() + post.V.rows() * stick.F.rows() +
                                        mp.god_edges.size() * mp.obstacle_edges.size()));
}

TEST_CASE("exact non-interpenetration and separation of posed boxes", "[refccd]") {
  const auto slab = gauss6::test::make_box(4, 4, 2, Vec3(0, 0, -1));
  const auto cube = gauss6::test::make_box(1, 1, 1);
  const ExactMeshPair mp = make_exact_mesh_pair(cube, slab);
  const double gap = std::ldexp(1.0, -30);
  for (const Quat q : {Quat{}, about_z(0.25 * M_PI)}) {
    // Separated by 2^-30 (exactly: turning about z keeps z exact).
    const Pose above = pose(Vec3(0.1, 0.2, 0.5 + gap), q);
    CHECK(count_intersecting_pairs(mp, above) == 0);
    const ExactSeparation s = separation_distance(mp, above, 1e-3);
    REQUIRE(s.within);
    CHECK(s.squared_distance == mpq_class(gap) * mpq_class(gap));
    CHECK(s.lower <= gap);
    CHECK(gap <= s.upper);
    // Touching: the bottom face lies on the top face. Touching counts as intersecting.
    const Pose touching = pose(Vec3(0.1, 0.2, 0.5), q);
    CHECK(count_intersecting_pairs(mp, touching) > 0);
    const ExactSeparation t = separation_distance(mp, touching, 1e-3);
    REQUIRE(t.within);
    CHECK(t.squared_distance == 0);
    // Sunk by 1/4: intersecting.
    CHECK(count_intersecting_pairs(mp, pose(Vec3(0.1, 0.2, 0.25), q)) > 0);
    // Far: nothing within 0.5.
    CHECK_FALSE(separation_distance(mp, pose(Vec3(0, 0, 2), q), 0.5).within);
  }
  // Non-unit quaternion: the exact meaning R(q) = (...)/|q|^2 gives the same pose.
  const Quat big{2, 0, 0, 0};
  CHECK(separation_distance(mp, pose(Vec3(0, 0, 0.5 + gap), big), 1e-3).squared_distance ==
        mpq_class(gap) * mpq_class(gap));
}

TEST_CASE("exact CCD timing on the peg-in-hole and bunny meshes", "[refccd][timing]") {
  const std::string root = std::string(GAUSS6_SOURCE_DIR) + "/datasets_generated/";
  const std::string peg_path = root + "peg_in_hole/peg.off", box_path = root + "peg_in_hole/box_with_hole.off",
                    bunny_path = root + "bunny/bunny.off";
  if (std::filesystem::exists(peg_path) && std::filesystem::exists(box_path)) {
    const auto peg = read_off(peg_path), box = read_off(box_path);
    CHECK(peg.F.rows() == 288);
    CHECK(box.F.rows() == 280);
    auto t0 = std::chrono::steady_clock::now();
    const ExactMeshPair mp = make_exact_mesh_pair(peg, box);
    const double t_build = seconds_since(t0);
    // Peg lying along y above the box top (z = 0.03): its lowest point is at
    // G_z - 0.01. It comes down 2 mm from 1 mm above, turning slightly.
    const Pose X0 = pose(Vec3(0.0, 0.0, 0.041), Quat{}),
               X1 = pose(Vec3(0.0005, 0.0, 0.039), unit(Quat{1, 0.002, 0.001, 0.003}));
    t0 = std::chrono::steady_clock::now();
    const MeshContact c = mesh_first_contact(mp, X0, X1);
    const double t_ccd = seconds_since(t0);
    REQUIRE(c.toi.hit);
    CHECK(c.toi.lower > 0.3);  // 1 mm of a 2 mm descent, up to the small tilt
    CHECK(c.toi.upper < 0.7);
    t0 = std::chrono::steady_clock::now();
    CHECK(count_intersecting_pairs(mp, X0) == 0);
    CHECK(count_intersecting_pairs(mp, X1) > 0);
    const double t_pen = seconds_since(t0) / 2;
    t0 = std::chrono::steady_clock::now();
    const ExactSeparation s = separation_distance(mp, X0, 0.002);
    const double t_sep = seconds_since(t0);
    REQUIRE(s.within);
    // The gap is 0.041 - 0.01 - 0.03 in the doubles' exact values: 1 mm up to
    // the representation errors of those decimals (a few 1e-18).
    CHECK(std::abs(s.lower - 0.001) < 1e-15);
    CHECK(std::abs(s.upper - 0.001) < 1e-15);
    std::printf("[refccd] peg (%d tri) vs box (%d tri): build %.3f s, first contact %.3f s (u* in [%.17g, %.17g], "
                "%lld candidate pairs, %zu at u*), intersection count %.3f s, separation %.3f s\n",
                int(peg.F.rows()), int(box.F.rows()), t_build, t_ccd, c.toi.lower, c.toi.upper,
                (long long)c.num_candidate_pairs, c.pairs.size(), t_pen, t_sep);
  } else {
    WARN("peg-in-hole meshes absent: " << peg_path);
  }
  if (std::filesystem::exists(bunny_path)) {
    const auto bunny = read_off(bunny_path);
    auto t0 = std::chrono::steady_clock::now();
    const ExactMeshPair mp = make_exact_mesh_pair(bunny, bunny);
    const double t_build = seconds_since(t0);
    // Two bunnies side by side along x (extent 0.151; they first touch near
    // an offset of 0.135). The held one starts at 0.137 and moves 10 mm closer
    // and 2 mm sideways while turning by about 0.3 degrees: a step that ends in
    // contact after sliding past many nearby features.
    const Pose X0 = pose(Vec3(0.137, 0.0, 0.0), Quat{}),
               X1 = pose(Vec3(0.127, 0.002, 0.0), unit(Quat{1, 0.001, 0.002, 0.0015}));
    t0 = std::chrono::steady_clock::now();
    const MeshContact c = mesh_first_contact(mp, X0, X1);
    const double t_ccd = seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    const int64_t n0 = count_intersecting_pairs(mp, X0);
    const double t_pen = seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    const ExactSeparation s = separation_distance(mp, X0, 0.01);
    const double t_sep = seconds_since(t0);
    std::printf("[refccd] bunny vs bunny (%d tri each): build %.3f s, first contact %.3f s (hit %d, u* in [%.17g, "
                "%.17g], %lld candidate pairs), intersection count %.3f s, separation %.3f s (within %d, d in "
                "[%.6g, %.6g])\n",
                int(bunny.F.rows()), t_build, t_ccd, int(c.toi.hit), c.toi.lower, c.toi.upper,
                (long long)c.num_candidate_pairs, t_pen, t_sep, int(s.within), s.lower, s.upper);
    // X0 is apart (no intersecting pair, positive distance), X1 is not: the
    // exact first contact lies strictly inside the step.
    CHECK(n0 == 0);
    REQUIRE(s.within);
    CHECK(s.lower > 0);
    CHECK(count_intersecting_pairs(mp, X1) > 0);
    REQUIRE(c.toi.hit);
    CHECK(c.toi.lower > 0);
    CHECK(c.toi.upper < 1);
  } else {
    WARN("bunny mesh absent: " << bunny_path);
  }
}
