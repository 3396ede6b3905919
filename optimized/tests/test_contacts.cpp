// Tests of contacts.h: a box resting on a box (four corner contacts, normals +z,
// the Jacobian rows), duplicates merged, the edge/edge normal's sign, the
// contact sets found from the CCD's near pairs against those of a full descent,
// a dense coplanar patch reduced to its support, and the rows of a vertex
// beside a face (a flat plate's vertex beside a tool's bottom edge, a sharp
// vertex on a sharp edge, a curved vertex beside a ridge at any distance), and
// the merge cells of ContactCollector against comparing every contact (the
// merging as it was before the cells, kept here).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "gauss6/step/ccd_step.h"
#include "gauss6/contact/contacts.h"
#include "mesh_shapes.h"

using namespace gauss6;
using gauss6::test::make_box;

namespace {
constexpr double kDelta = 1e-5;

// A unit box (the god-object, body frame centred on G) over a 4 x 4 x 1 slab
// whose top face z = 0 is split along y = x, contacts within 1.1 delta.
struct BoxOverSlab {
  TriangleMesh god = make_box(1, 1, 1), slab = make_box(4, 4, 1, Vec3(0, 0, -0.5));
  Bvh gb = build_bvh(god), sb = build_bvh(slab);
  CcdBody obstacle{&slab, &sb};
  ContactWorkspace ws{god};
  ContactSet set{16};
  ContactSettings cs = [] {
    ContactSettings c;
    c.distance = 1.1 * kDelta;
    return c;
  }();
  ContactStatus contacts_at(const Pose& X) { return generate_contacts(&obstacle, 1, {&god, &gb}, X, cs, &ws, &set); }
};
}  // namespace

TEST_CASE("contacts: a unit box resting on a slab inside one top triangle", "[contacts]") {
  // Slab top z = 0 is split along y = x; the god box's footprint x in [0.5, 1.5],
  // y in [-1.5, -0.5] lies in the triangle y < x, far from every slab edge.
  BoxOverSlab f;
  const ContactSet& set = f.set;
  const Pose X{Vec3(1, -1, 0.5 + kDelta), Quat{}};
  REQUIRE(f.contacts_at(X) == ContactStatus::kOk);
  REQUIRE(set.num_contacts == 4);
  int corners = 0;
  for (int k = 0; k < set.num_contacts; ++k) {
    const Contact& c = set.contacts[k];
    // Normal +z exactly (axis-aligned face: the cross product is exact).
    CHECK(c.normal == Vec3(0, 0, 1));
    CHECK(c.features.kind == PairKind::kGodVertexObstacleFace);
    // Separation delta up to rounding of 0.5 + delta - 0.5 (1e-16 of 1).
    CHECK(std::abs(c.separation - kDelta) < 1e-15);
    const Vec3 r = c.point - X.p;  // (+-1/2, +-1/2, -1/2)
    CHECK(std::abs(std::abs(r.x()) - 0.5) < 1e-15);
    CHECK(std::abs(std::abs(r.y()) - 0.5) < 1e-15);
    CHECK(std::abs(r.z() + 0.5) < 1e-15);
    corners |= 1 << ((r.x() > 0 ? 1 : 0) + (r.y() > 0 ? 2 : 0));
    // J_k = [n, (I - G) x n] = [0 0 1, r_y, -r_x, 0].
    CHECK((set.J.row(k).transpose() - (Vec6() << 0, 0, 1, r.y(), -r.x(), 0).finished()).norm() < 1e-15);
  }
  CHECK(set.num_pairs_within == 4);
  CHECK(corners == 15);  // one contact at each of the four bottom corners
  // Lifted by 2 delta: out of range, no contact.
  REQUIRE(f.contacts_at({Vec3(1, -1, 0.5 + 2 * kDelta), Quat{}}) == ContactStatus::kOk);
  CHECK(set.num_contacts == 0);
}

TEST_CASE("contacts: corners over the slab's diagonal are merged", "[contacts]") {
  // Centred box: corners (-1/2, -1/2) and (1/2, 1/2) lie on the diagonal y = x
  // shared by the two top triangles: each is seen by both (6 pairs), 4 contacts.
  BoxOverSlab f;
  const ContactSet& set = f.set;
  REQUIRE(f.contacts_at({Vec3(0, 0, 0.5 + kDelta), Quat{}}) == ContactStatus::kOk);
  CHECK(set.num_pairs_within == 6);
  CHECK(set.num_contacts == 4);
  for (int k = 0; k < set.num_contacts; ++k) CHECK(set.contacts[k].normal == Vec3(0, 0, 1));
}

TEST_CASE("contacts: edge/edge normal points from the obstacle to the god-object", "[contacts]") {
  // God box turned 45 degrees about x (lowest edge along x), obstacle box turned
  // 45 degrees about y (highest edge along y): the edges cross at the origin.
  const double h = std::sqrt(0.5);  // half diagonal of a unit square
  const TriangleMesh god = make_box(1, 1, 1);
  TriangleMesh obs = make_box(1, 1, 1);
  const Mat3 Ry = rotation_matrix(quat_exp(Vec3(0, M_PI / 4, 0)));
  for (int v = 0; v < obs.V.rows(); ++v) obs.V.row(v) = (Ry * obs.V.row(v).transpose()).transpose();
  const Quat qx = quat_exp(Vec3(M_PI / 4, 0, 0));
  const Bvh gb = build_bvh(god), ob = build_bvh(obs);
  ContactWorkspace ws(god);
  ContactSet set(16);
  ContactSettings cs;
  cs.distance = 1.1 * kDelta;
  for (const double side : {+1.0, -1.0}) {
    // Obstacle centred at the origin (its extreme edges at z = +-h); god centred
    // at z = +-(2 h + delta/2), so its nearest edge is delta/2 away.
    const TriangleMesh& o = obs;
    const CcdBody obstacle{&o, &ob};
    const Pose X{Vec3(0, 0, side * (2 * h + 0.5 * kDelta)), qx};
    REQUIRE(generate_contacts(&obstacle, 1, {&god, &gb}, X, cs, &ws, &set) == ContactStatus::kOk);
    REQUIRE(set.num_contacts == 1);
    const Contact& c = set.contacts[0];
    CHECK(c.features.kind == PairKind::kEdgeEdge);
    // +z when the god-object is above, -z below (1e-12: rounding of the turned boxes).
    CHECK((c.normal - Vec3(0, 0, side)).norm() < 1e-12);
    CHECK(std::abs(c.separation - 0.5 * kDelta) < 1e-12);
    // J row: I - G = (0, 0, -side h) is parallel to n: no torque part.
    CHECK(set.J.row(0).tail<3>().norm() < 1e-12);
  }
}

TEST_CASE("contacts: the CCD's near pairs give the same set as the descent", "[contacts]") {
  // Steps that slide a box or a small ball over a slab or a large ball, about
  // a contact distance above it, some pressing into it: at each stop pose the
  // contact set from ccd_step's near pairs (when the runtime's conditions let
  // it be used) must equal the set found by descending the trees, contact for
  // contact (point, normal and separation are computed the same way; the order
  // may differ, and where two feature pairs tie the merge may keep either).
  const TriangleMesh box = make_box(1, 1, 1), slab = make_box(4, 4, 1, Vec3(0, 0, -0.5));
  const TriangleMesh ball = gauss6::test::make_icosphere(2, 0.5), big = gauss6::test::make_icosphere(3, 2.0);
  const Bvh box_bvh = build_bvh(box), slab_bvh = build_bvh(slab), ball_bvh = build_bvh(ball), big_bvh = build_bvh(big);
  CcdStepSettings settings;
  settings.narrow.min_separation = kDelta;
  settings.narrow.distance_tolerance = 0.1 * kDelta;
  settings.near_distance = 1.7 * kDelta;
  CcdStepWorkspace ccd_ws;
  std::mt19937 rng(53);
  std::uniform_real_distribution<double> U(-1, 1);
  int used = 0, with_contacts = 0;
  for (int i = 0; i < 400; ++i) {
    const bool balls = i % 2;
    const TriangleMesh& gm = balls ? ball : box;
    const Bvh& gb = balls ? ball_bvh : box_bvh;
    const CcdBody god{&gm, &gb};
    const CcdBody obstacle{balls ? &big : &slab, balls ? &big_bvh : &slab_bvh};
    ContactWorkspace ws(gm);
    ContactSet listed(64), descended(64);
    // Start 1.05 to 1.4 delta above the top (the slab's face z = 0, or the big
    // ball's pole: the small ball's lowest vertex), tilted a little.
    const Quat q0 = balls ? normalized(quat_exp(0.3 * Vec3(U(rng), U(rng), U(rng)))) : Quat{};
    double lowest = 1e300;
    const Mat3 R0 = rotation_matrix(q0);
    for (int v = 0; v < gm.V.rows(); ++v) lowest = std::min(lowest, (R0 * gm.V.row(v).transpose()).z());
    const double top = balls ? big.V.col(2).maxCoeff() : 0.0;
    const Vec3 p0(0.05 * U(rng), 0.05 * U(rng), top - lowest + (1.225 + 0.175 * U(rng)) * kDelta);
    const Pose x0{p0, q0};
    const Pose x1{p0 + Vec3(0.01 * U(rng), 0.01 * U(rng), kDelta * (U(rng) - 0.5)),
                  normalized(quat_exp(1e-6 * Vec3(U(rng), U(rng), U(rng))) * q0)};
    CcdStepResult r;
    ccd_step(&obstacle, 1, god, {x0, x1}, settings, &ccd_ws, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    const double u = r.hit ? r.u_hit : 1.0;
    const StopPose stop = make_stop_pose(r.motion, u, gb.radius);
    ContactSettings cs;
    cs.distance = 1.5 * kDelta;
    const double slack = stop.deviation + 1e-13 * (stop.pose.p.cwiseAbs().maxCoeff() + gb.radius);
    REQUIRE(generate_contacts(&obstacle, 1, god, stop.pose, cs, &ws, &descended) == ContactStatus::kOk);
    if (!(r.num_near_pairs >= 0 && u >= r.near_u0 && cs.distance + slack <= r.near_reach)) continue;
    ++used;
    REQUIRE(generate_contacts(&obstacle, 1, god, stop.pose, cs, &ws, &listed, ccd_ws.near_pairs(r.num_near_pairs)) ==
            ContactStatus::kOk);
    with_contacts += descended.num_contacts > 0;
    REQUIRE(listed.num_contacts == descended.num_contacts);
    for (int k = 0; k < descended.num_contacts; ++k) {
      const Contact& c = descended.contacts[k];
      bool found = false;
      for (int j = 0; j < listed.num_contacts && !found; ++j) {
        const Contact& o = listed.contacts[j];
        found = (o.point - c.point).norm() <= 1e-12 && (o.normal - c.normal).norm() <= 1e-12 &&
                o.separation == c.separation;
      }
      CHECK(found);
    }
  }
  std::printf("near pairs: used at %d of 400 stop poses, %d of them with contacts\n", used, with_contacts);
  CHECK(used > 300);
  CHECK(with_contacts > 100);
}

namespace {
// A sheet of grid x grid squares over [-2, 2]^2 at z = 0, two triangles each:
// without rng its vertices on the grid lines x, y = -2 + 4 i / grid; with it,
// the interior ones moved in the plane by up to a quarter square (seeded by
// rng): a dense coplanar tessellation.
TriangleMesh grid_sheet(int grid, std::mt19937* rng) {
  std::uniform_real_distribution<double> U(-1, 1);
  std::vector<Eigen::Vector3d> V;
  std::vector<std::array<int, 3>> F;
  for (int i = 0; i <= grid; ++i)
    for (int j = 0; j <= grid; ++j) {
      if (!rng) {
        V.emplace_back(-2 + 4.0 * i / grid, -2 + 4.0 * j / grid, 0.0);
        continue;
      }
      const bool edge = i == 0 || j == 0 || i == grid || j == grid;
      const double h = 4.0 / grid, jx = edge ? 0 : 0.25 * h * U(*rng), jy = edge ? 0 : 0.25 * h * U(*rng);
      V.emplace_back(-2 + i * h + jx, -2 + j * h + jy, 0.0);
    }
  for (int i = 0; i < grid; ++i)
    for (int j = 0; j < grid; ++j) {
      const int a = i * (grid + 1) + j, b = a + grid + 1;
      F.push_back({a, b, b + 1});
      F.push_back({a, b + 1, a + 1});
    }
  return gauss6::test::make_mesh(V, F, "sheet");
}
}  // namespace

namespace {
// The merging as it was before the merge cells: every contact of the set
// compared in order (the reduction is reduce_to_patch_supports). The
// reference the cells must reproduce bit for bit.
namespace before_cells {
// Returns false when the contact was left out for want of room (overflow).
bool add(const Contact& c, const ContactSettings& s, ContactSet* set) {
  ++set->num_pairs_within;
  const double md = s.merge_distance > 0 ? s.merge_distance : 1e-3 * s.distance, mc = std::cos(s.merge_angle);
  const double reject = md * (1 + 8 * std::numeric_limits<double>::epsilon());
  for (int i = 0; i < set->num_contacts; ++i) {
    Contact& o = set->contacts[i];
    if (std::abs(o.point.x() - c.point.x()) > reject || std::abs(o.point.y() - c.point.y()) > reject) continue;
    if ((o.point - c.point).norm() <= md && o.normal.dot(c.normal) >= mc) {
      if (c.separation < o.separation) o = c;
      return true;
    }
  }
  if (set->num_contacts == set->capacity()) {
    ++set->num_reductions;
    if (reduce_to_patch_supports(s.patch_angle, set) == 0) return false;
  }
  set->contacts[set->num_contacts++] = c;
  return true;
}
}  // namespace before_cells

// The two sets hold the same contacts, bit for bit, in the same order.
void require_same_set(const ContactSet& a, const ContactSet& b) {
  REQUIRE(a.num_contacts == b.num_contacts);
  REQUIRE(a.num_pairs_within == b.num_pairs_within);
  REQUIRE(a.num_reductions == b.num_reductions);
  for (int k = 0; k < a.num_contacts; ++k) {
    INFO("contact " << k);
    const Contact &x = a.contacts[k], &y = b.contacts[k];
    REQUIRE(x.point == y.point);
    REQUIRE(x.normal == y.normal);
    REQUIRE(x.separation == y.separation);
    REQUIRE(x.features == y.features);
  }
}
}  // namespace

TEST_CASE("contacts: a dense coplanar patch is reduced to its support, the same cone", "[contacts]") {
  // A unit box laid flat on a 40 x 40 grid sheet (3,200 coplanar triangles, the
  // interior vertices jittered in the plane), turned about z and moved by seeded
  // amounts, a delta above it: over 200 contacts within the distance, against a
  // set of 16. Without the reduction the set kept the first 16 found, one
  // corner of the patch. Reduced, it must give the same constraints: the least
  // J_k a over every contact found (a set of 4096, never reduced) and over the
  // reduced set agree for any motion a, since each row is affine in its point
  // and the least of an affine function over a patch is at a hull vertex.
  // 1e-12: rounding of rows of norm ~1 (points within 2 of G) and of |a| = 1.
  // A set merged through the cells and one that compares every contact are
  // equal, bit for bit.
  std::mt19937 rng(43);
  std::uniform_real_distribution<double> U(-1, 1);
  const TriangleMesh sheet = grid_sheet(40, &rng), god = make_box(1, 1, 1);
  const Bvh sb = build_bvh(sheet), gb = build_bvh(god);
  const CcdBody obstacle{&sheet, &sb};
  ContactWorkspace ws(god);
  ContactSet small(16), all(4096), every(16);
  every.merge_head.clear();  // no merge buckets: every contact is compared, as before the cells
  ContactSettings cs;
  cs.distance = 1.5 * kDelta;
  for (int trial = 0; trial < 20; ++trial) {
    const Pose X{Vec3(0.3 * U(rng), 0.3 * U(rng), 0.5 + kDelta), quat_exp(Vec3(0, 0, 0.5 * U(rng)))};
    REQUIRE(generate_contacts(&obstacle, 1, {&god, &gb}, X, cs, &ws, &all) == ContactStatus::kOk);
    REQUIRE(all.num_reductions == 0);
    REQUIRE(all.num_contacts > 200);
    REQUIRE(generate_contacts(&obstacle, 1, {&god, &gb}, X, cs, &ws, &small) == ContactStatus::kOk);
    CHECK(small.num_reductions > 0);
    CHECK(small.num_contacts <= 16);
    CHECK(small.num_pairs_within == all.num_pairs_within);
    REQUIRE(generate_contacts(&obstacle, 1, {&god, &gb}, X, cs, &ws, &every) == ContactStatus::kOk);
    require_same_set(small, every);
    // The smallest separation is kept.
    double least_all = 1e300, least_small = 1e300;
    for (int k = 0; k < all.num_contacts; ++k) least_all = std::min(least_all, all.contacts[k].separation);
    for (int k = 0; k < small.num_contacts; ++k) least_small = std::min(least_small, small.contacts[k].separation);
    CHECK(least_small == least_all);
    for (int d = 0; d < 50; ++d) {
      Vec6 a;
      for (int i = 0; i < 6; ++i) a[i] = U(rng);
      a.normalize();
      const double min_all = (all.J.topRows(all.num_contacts) * a).minCoeff();
      const double min_small = (small.J.topRows(small.num_contacts) * a).minCoeff();
      CHECK(std::abs(min_all - min_small) <= 1e-12);
    }
  }
}

namespace {
// A flat sheet of grid x grid squares (grid_sheet without jitter).
TriangleMesh flat_sheet(int grid) { return grid_sheet(grid, nullptr); }
}  // namespace

TEST_CASE("contacts: a flat plate's vertices beside a tool's bottom edge hold it by its bottom, not its side",
          "[contacts]") {
  // A unit box flat on a sheet of 0.1 squares, half a delta above it, its +x
  // bottom edge 0.3 delta short of the grid line x = 0.6: ten sheet vertices
  // lie beside that edge, 0.58 delta from it, within the distance of both the
  // box's bottom face and its +x side face. The side face's normal (-x for the
  // row) is no contact normal of a flat sheet's vertex (its neighbours lie on
  // both sides of the plane x = 0.6); the bottom face's (+z) is. Left with the
  // side rows, a slide along +x was blocked (J a < 0 for a = +x).
  const TriangleMesh sheet = flat_sheet(40), god = make_box(1, 1, 1);
  const Bvh sb = build_bvh(sheet), gb = build_bvh(god);
  const CcdBody obstacle{&sheet, &sb};
  ContactWorkspace ws(god);
  ContactSet set(4096);
  ContactSettings cs;
  cs.distance = 1.5 * kDelta;
  for (const double turn : {0.0, 0.3}) {  // the box also turned about z: its edge then crosses the grid lines
    const Quat q = quat_exp(Vec3(0, 0, turn));
    // The +x bottom edge's midpoint 0.3 delta (along the box's +x) short of x = 0.6.
    const Vec3 ex = rotation_matrix(q) * Vec3(1, 0, 0);
    const Vec3 mid = Vec3(0.6, 0.0, 0.0) - 0.3 * kDelta * ex;
    const Pose X{Vec3(mid.x() - 0.5 * ex.x(), mid.y() - 0.5 * ex.y(), 0.5 + 0.5 * kDelta), q};
    REQUIRE(generate_contacts(&obstacle, 1, {&god, &gb}, X, cs, &ws, &set) == ContactStatus::kOk);
    REQUIRE(set.num_reductions == 0);
    if (turn == 0) CHECK(set.num_beside >= 10);
    CHECK(set.num_beside > 0);
    for (int k = 0; k < set.num_contacts; ++k) {
      const Contact& c = set.contacts[k];
      INFO("turn " << turn << ": " << static_cast<int>(c.features.kind) << " at " << c.point.transpose() << ", n "
                   << c.normal.transpose());
      CHECK((c.normal - Vec3(0, 0, 1)).norm() < 1e-12);
    }
    // Sliding along the box's +x, or any tangent motion, is not held back.
    for (const Vec6& a : {(Vec6() << ex, 0, 0, 0).finished(), (Vec6() << -ex, 0, 0, 0).finished(),
                          (Vec6() << 0, 0, 0, 0, 0, 1).finished()})
      CHECK((set.J.topRows(set.num_contacts) * a).minCoeff() >= -1e-12);
  }
}

TEST_CASE("contacts: a sharp vertex on a sharp edge keeps both faces' rows", "[contacts]") {
  // An octahedron (the god-object, G at its lowest vertex) half a delta above
  // the ridge of a triangular prism (ridge along x at z = r, flank normals
  // (0, +-sin 60, cos 60)). Its vertex lies beside both flanks; neither flank's
  // normal supports the octahedron at that vertex (its edges rise at 45 degrees
  // on both sides), so neither row is left out: the vertex is held by both.
  const double s = 0.2, r = 0.5;
  const TriangleMesh god = gauss6::test::make_mesh(
      {{0, 0, 0}, {s, 0, s}, {0, s, s}, {-s, 0, s}, {0, -s, s}, {0, 0, 2 * s}},
      {{0, 2, 1}, {0, 3, 2}, {0, 4, 3}, {0, 1, 4}, {5, 1, 2}, {5, 2, 3}, {5, 3, 4}, {5, 4, 1}}, "octahedron");
  TriangleMesh knife = gauss6::test::make_prism(3, r, 1);
  // The prism's axis z to -x, its vertex on +x to +z: (x, y, z) -> (-z, y, x).
  for (int v = 0; v < knife.V.rows(); ++v) {
    const Vec3 p = knife.V.row(v).transpose();
    knife.V.row(v) = Vec3(-p.z(), p.y(), p.x()).transpose();
  }
  const Bvh gb = build_bvh(god), kb = build_bvh(knife);
  const CcdBody obstacle{&knife, &kb};
  ContactWorkspace ws(god);
  ContactSet set(16);
  ContactSettings cs;
  cs.distance = 1.5 * kDelta;
  REQUIRE(generate_contacts(&obstacle, 1, {&god, &gb}, {Vec3(0.1, 0, r + 0.5 * kDelta), Quat{}}, cs, &ws, &set) ==
          ContactStatus::kOk);
  CHECK(set.num_beside == 0);
  REQUIRE(set.num_contacts == 2);
  const double sy = std::sin(M_PI / 3), cz = std::cos(M_PI / 3);
  int flanks = 0;
  for (int k = 0; k < set.num_contacts; ++k) {
    const Vec3& n = set.contacts[k].normal;
    CHECK(set.contacts[k].features.kind == PairKind::kGodVertexObstacleFace);
    if ((n - Vec3(0, sy, cz)).norm() < 1e-12) flanks |= 1;
    if ((n - Vec3(0, -sy, cz)).norm() < 1e-12) flanks |= 2;
  }
  CHECK(flanks == 3);
}

TEST_CASE("contacts: a vertex whose body turns between two faces' normals keeps both rows, at every distance",
          "[contacts]") {
  // The octahedron's lowest vertex (its edges rise at 45 degrees: it supports
  // every normal within 45 degrees of -z) half a delta from the ridge of an
  // asymmetric prism, on the bisector of its flanks: flank g's normal is 20
  // degrees from +z (the vertex supports it, and normals turned from it towards
  // the other flank's), flank f's 60 degrees (it does not). The vertex's
  // contact with the ridge pushes along a normal between the two, which g's
  // row alone does not span: both rows stay. Nor does the set lose a row when
  // the distance grows.
  const double s = 0.2, a = 20 * M_PI / 180, b = 60 * M_PI / 180;
  const TriangleMesh god = gauss6::test::make_mesh(
      {{0, 0, 0}, {s, 0, s}, {0, s, s}, {-s, 0, s}, {0, -s, s}, {0, 0, 2 * s}},
      {{0, 2, 1}, {0, 3, 2}, {0, 4, 3}, {0, 1, 4}, {5, 1, 2}, {5, 2, 3}, {5, 3, 4}, {5, 4, 1}}, "octahedron");
  // The ridge along x at z = 0; flank g down to -y (normal (0, -sin a, cos a)),
  // flank f down to +y (normal (0, sin b, cos b)), both to z = -1.
  const double yg = -std::cos(a) / std::sin(a), yf = std::cos(b) / std::sin(b);
  const TriangleMesh ridge = gauss6::test::make_mesh(
      {{-1, 0, 0}, {-1, yg, -1}, {-1, yf, -1}, {1, 0, 0}, {1, yg, -1}, {1, yf, -1}},
      {{0, 2, 1}, {3, 4, 5}, {0, 4, 3}, {0, 1, 4}, {0, 5, 2}, {0, 3, 5}, {1, 5, 4}, {1, 2, 5}}, "ridge");
  const Vec3 ng(0, -std::sin(a), std::cos(a)), nf(0, std::sin(b), std::cos(b));
  for (int f = 0; f < ridge.F.rows(); ++f) {  // outward: each face's normal points away from the prism's inside
    const Vec3 p0 = ridge.V.row(ridge.F(f, 0)).transpose(), p1 = ridge.V.row(ridge.F(f, 1)).transpose(),
               p2 = ridge.V.row(ridge.F(f, 2)).transpose();
    REQUIRE((p1 - p0).cross(p2 - p0).dot((p0 + p1 + p2) / 3 - Vec3(0, (yg + yf) / 3, -2.0 / 3)) > 0);
  }
  const Bvh gb = build_bvh(god), rb = build_bvh(ridge);
  const CcdBody obstacle{&ridge, &rb};
  ContactWorkspace ws(god);
  ContactSet set(16);
  ContactSettings cs;
  const Vec3 G = 0.5 * kDelta * (ng + nf).normalized() + Vec3(0.1, 0, 0);
  for (const double distance : {1.5 * kDelta, 3 * kDelta, 30 * kDelta}) {
    cs.distance = distance;
    REQUIRE(generate_contacts(&obstacle, 1, {&god, &gb}, {G, Quat{}}, cs, &ws, &set) == ContactStatus::kOk);
    INFO("distance " << distance / kDelta << " delta");
    CHECK(set.num_beside == 0);
    int flanks = 0;
    for (int k = 0; k < set.num_contacts; ++k) {
      const Vec3& n = set.contacts[k].normal;
      if ((n - ng).norm() < 1e-12) flanks |= 1;
      if ((n - nf).norm() < 1e-12) flanks |= 2;
    }
    CHECK(flanks == 3);
  }
}

TEST_CASE("contacts: the merge cells give the set that comparing every contact gives, on dense coplanar patches",
          "[contacts]") {
  // Streams of contacts as a dense coplanar patch gives them (a jittered grid
  // of points in a plane of any orientation, one normal to rounding), with a
  // second patch tilted beyond patch_angle, separations drawn from a few
  // values (ties decide the patch's closest), and near-duplicates of earlier
  // points at 0 to 2 merge distances (some merge, some not), some of them
  // placed on the cells' boundaries. Each is added to sets of several
  // capacities by ContactCollector and by the rule of comparing every contact:
  // the sets must be equal, bit for bit and in order, after every contact. A
  // merge the cells miss leaves a duplicate or a larger separation, or shifts
  // a reduction: the comparison fails.
  std::mt19937 rng(58);
  std::uniform_real_distribution<double> U(-1, 1), U01(0, 1);
  const double seps[4] = {0.3e-6, 0.7e-6, 1e-6 / 3, 1e-6};
  for (int trial = 0; trial < 60; ++trial) {
    ContactSettings cs;
    cs.distance = 1.1e-6;
    const double md = 1e-3 * cs.distance;
    const int capacity = trial % 3 == 0 ? 8 : trial % 3 == 1 ? 16 : 64;
    ContactSet cells(capacity), every(capacity);
    ContactCollector col(cs, &cells);
    REQUIRE(col.indexed);
    // The plate: normal n (near +z in half the trials, any in the others), in-plane axes u, v.
    Vec3 n = trial % 2 == 0 ? Vec3(0.01 * U(rng), 0.01 * U(rng), 1) : Vec3(U(rng), U(rng), U(rng));
    n.normalize();
    const Vec3 u = n.unitOrthogonal(), v = n.cross(u), origin(0.05 * U(rng), 0.05 * U(rng), 0.01 * U(rng));
    const Vec3 tilted = (n + 2e-3 * u).normalized();  // another patch
    const double spacing = 1e-3;
    const int grid = 20 + trial % 20;
    std::vector<Contact> made;
    bool overflow = false;
    for (int k = 0; k < grid * grid + 200; ++k) {
      Contact c;
      const double r = U01(rng);
      if (r < 0.25 && !made.empty()) {  // a near-duplicate of an earlier contact
        const Contact& o = made[static_cast<size_t>(U01(rng) * static_cast<double>(made.size())) % made.size()];
        c = o;
        Vec3 off(U(rng), U(rng), U(rng));
        c.point = o.point + (2 * md * U01(rng)) * off.normalized();
        if (U01(rng) < 0.3) {  // on a cell boundary of x (the cells' side is 4 reject)
          const double side = 4 * col.reject;
          c.point.x() = std::round(c.point.x() / side) * side;
        }
        c.normal = (o.normal + 1e-9 * Vec3(U(rng), U(rng), U(rng))).normalized();
      } else {
        const int i = k % grid, j = (k / grid) % grid;
        const Vec3 p = origin + ((i - grid / 2) + 0.25 * U(rng)) * spacing * u + ((j - grid / 2) + 0.25 * U(rng)) * spacing * v;
        c.point = p;
        c.normal = (r < 0.9 ? n : tilted) + 1e-12 * Vec3(U(rng), U(rng), U(rng));
        c.normal.normalize();
      }
      c.separation = seps[static_cast<int>(U01(rng) * 4) % 4];
      c.features = {PairKind::kObstacleVertexGodFace, 0, k % 7, -1, k, k % 3};
      made.push_back(c);
      col.add(c);
      overflow = !before_cells::add(c, cs, &every) || overflow;
      REQUIRE(col.overflow == overflow);
      require_same_set(cells, every);
    }
    REQUIRE(cells.num_reductions > 0);
  }
}
