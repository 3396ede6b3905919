// Tests of mesh.h: adjacency on closed meshes, angle-weighted normals, and
// validate_mesh() catching each defect on a mesh broken on purpose.
#include <catch2/catch.hpp>

#include <cmath>
#include <set>

#include <Eigen/Geometry>

#include "gauss6/geometry/mesh.h"
#include "mesh_shapes.h"

using namespace gauss6;
using gauss6::test::concatenate;
using gauss6::test::make_box;
using gauss6::test::make_icosphere;
using gauss6::test::make_mesh;
using gauss6::test::make_prism;
using gauss6::test::make_unit_tetrahedron;

namespace {

// Removes triangle f.
TriangleMesh without_triangle(TriangleMesh m, int f) {
  MatrixX3i F(m.F.rows() - 1, 3);
  for (int i = 0, j = 0; i < m.F.rows(); ++i)
    if (i != f) F.row(j++) = m.F.row(i);
  m.F = F;
  return m;
}

// Checks FE, EF, E and VF against each other and against F.
void check_adjacency_consistent(const TriangleMesh& m) {
  const MeshAdjacency& adj = m.adjacency;
  REQUIRE(adj.FE.rows() == m.F.rows());
  for (int f = 0; f < m.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int e = adj.FE(f, k);
      const int a = m.F(f, k), b = m.F(f, (k + 1) % 3);
      REQUIRE(adj.E(e, 0) == std::min(a, b));
      REQUIRE(adj.E(e, 1) == std::max(a, b));
      REQUIRE((adj.EF(e, 0) == f || adj.EF(e, 1) == f));
    }
  }
  for (int e = 0; e < adj.E.rows(); ++e) {
    REQUIRE(adj.E(e, 0) < adj.E(e, 1));
    if (e > 0) {  // lexicographic numbering, no duplicates
      REQUIRE((adj.E(e - 1, 0) < adj.E(e, 0) ||
               (adj.E(e - 1, 0) == adj.E(e, 0) && adj.E(e - 1, 1) < adj.E(e, 1))));
    }
  }
  REQUIRE(adj.VF_start.size() == static_cast<size_t>(m.V.rows()) + 1);
  for (int v = 0; v < m.V.rows(); ++v) {
    for (int i = adj.VF_start[v]; i < adj.VF_start[v + 1]; ++i) {
      const int f = adj.VF[i];
      REQUIRE((m.F(f, 0) == v || m.F(f, 1) == v || m.F(f, 2) == v));
    }
  }
  REQUIRE(adj.VF.size() == 3 * static_cast<size_t>(m.F.rows()));
}

}  // namespace

TEST_CASE("Box adjacency: 8 vertices, 12 triangles, 18 edges, two faces each", "[mesh]") {
  TriangleMesh box = make_box(1.0, 2.0, 3.0);
  REQUIRE(num_vertices(box) == 8);
  REQUIRE(num_triangles(box) == 12);
  build_adjacency(&box);
  REQUIRE(box.adjacency.E.rows() == 18);
  for (int e = 0; e < 18; ++e) {
    CHECK(box.adjacency.edge_face_count[e] == 2);
    CHECK(box.adjacency.EF(e, 0) >= 0);
    CHECK(box.adjacency.EF(e, 1) >= 0);
    CHECK(box.adjacency.EF(e, 0) != box.adjacency.EF(e, 1));
  }
  check_adjacency_consistent(box);
}

TEST_CASE("Closed meshes satisfy Euler's formula and validate clean", "[mesh]") {
  const TriangleMesh shapes[] = {make_box(1.0, 1.0 / 3.0, 7.0), make_unit_tetrahedron(),
                                 make_prism(7, 1.0, 2.0), make_icosphere(2, 1.0)};
  for (TriangleMesh m : shapes) {
    INFO(m.source);
    build_adjacency(&m);
    check_adjacency_consistent(m);
    // V - E + F = 2 for a closed genus-0 surface.
    CHECK(num_vertices(m) - m.adjacency.E.rows() + num_triangles(m) == 2);
    const MeshReport r = validate_mesh(m);
    CHECK(r.num_edges == m.adjacency.E.rows());
    CHECK(r.ok());
    CHECK(r.closed());
    CHECK(r.manifold());
    CHECK(r.describe().empty());
  }
}

TEST_CASE("Angle-weighted normals: box corners point along the diagonals", "[mesh]") {
  // Each box corner meets three faces at right angles, split into one or two
  // triangles; angle weighting makes the normal the exact diagonal regardless
  // of the split (area or face-count weighting would not).
  TriangleMesh box = make_box(1.0, 2.0, 3.0);
  compute_vertex_normals(&box);
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d expected =
        Eigen::Vector3d((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1).normalized();
    // Tolerance: a few roundings in atan2 and the sums (values are O(1)).
    CHECK((Eigen::Vector3d(box.N.row(i)) - expected).norm() < 1e-14);
  }

  // On an icosphere each normal is close to radial: within 1 degree at level 3
  // (edge length about 0.08 r), and unit length to rounding.
  TriangleMesh sphere = make_icosphere(3, 2.0);
  compute_vertex_normals(&sphere);
  for (int i = 0; i < num_vertices(sphere); ++i) {
    const Eigen::Vector3d n = sphere.N.row(i);
    const Eigen::Vector3d radial = Eigen::Vector3d(sphere.V.row(i)).normalized();
    CHECK(std::abs(n.norm() - 1.0) < 1e-14);
    CHECK(n.dot(radial) > std::cos(M_PI / 180.0));
  }

  // Face normals are unit and outward on the box.
  for (int f = 0; f < num_triangles(box); ++f) {
    const Eigen::Vector3d n = face_normal(box, f);
    const Eigen::Vector3d centroid =
        (box.V.row(box.F(f, 0)) + box.V.row(box.F(f, 1)) + box.V.row(box.F(f, 2))).transpose() /
        3.0;
    CHECK(std::abs(n.norm() - 1.0) < 1e-15);
    CHECK(n.dot(centroid) > 0.0);
  }
}

TEST_CASE("validate_mesh: a missing triangle leaves three boundary edges", "[mesh]") {
  const MeshReport r = validate_mesh(without_triangle(make_box(1, 1, 1), 5));
  CHECK(r.num_boundary_edges == 3);
  CHECK(r.boundary_edges.size() == 3);
  CHECK_FALSE(r.closed());
  CHECK_FALSE(r.ok());
  CHECK(r.num_nonmanifold_edges == 0);
  CHECK(r.num_inconsistent_edges == 0);
  CHECK(r.describe().find("boundary") != std::string::npos);
}

TEST_CASE("validate_mesh: a NaN coordinate is reported", "[mesh]") {
  TriangleMesh box = make_box(1, 1, 1);
  box.V(6, 1) = std::nan("");
  const MeshReport r = validate_mesh(box);
  REQUIRE(r.num_nonfinite_vertices == 1);
  CHECK(r.nonfinite_vertices == std::vector<int>{6});
  CHECK_FALSE(r.ok());
  box.V(6, 1) = INFINITY;
  CHECK(validate_mesh(box).num_nonfinite_vertices == 1);
}

TEST_CASE("validate_mesh: degenerate triangles are decided exactly", "[mesh]") {
  // Exactly collinear: all corners on the line x = y = z.
  const TriangleMesh collinear =
      make_mesh({{0.1, 0.1, 0.1}, {0.2, 0.2, 0.2}, {0.3, 0.3, 0.3}}, {{0, 1, 2}}, "collinear");
  const MeshReport r1 = validate_mesh(collinear);
  CHECK(r1.num_degenerate_triangles == 1);
  CHECK(r1.degenerate_triangles == std::vector<int>{0});

  // Not collinear, by 2^-60: the cross product evaluated in doubles rounds to
  // exactly zero here ((1 - 2^-60) rounds to 1), the exact predicate does not.
  const double tiny = std::ldexp(1.0, -60);
  const TriangleMesh sliver =
      make_mesh({{tiny, 0, 0}, {1, 1, 0}, {2, 2, 0}}, {{0, 1, 2}}, "sliver");
  const Eigen::Vector3d a = sliver.V.row(0), b = sliver.V.row(1), c = sliver.V.row(2);
  REQUIRE((b - a).cross(c - a).isZero(0.0));  // the rounded test would call it degenerate
  CHECK(validate_mesh(sliver).num_degenerate_triangles == 0);

  // A zero-area triangle inside a closed box: a corner moved onto an edge's line.
  TriangleMesh box = make_box(2, 2, 2);
  box.V.row(3) = box.V.row(0) + 2.0 * (box.V.row(1) - box.V.row(0));  // 0, 1, 3 now collinear
  const MeshReport r2 = validate_mesh(box);
  CHECK(r2.num_degenerate_triangles == 1);  // triangle (0, 3, 1) is the only one on 0, 1, 3
  CHECK_FALSE(r2.ok());
}

TEST_CASE("validate_mesh: bad and repeated indices", "[mesh]") {
  TriangleMesh box = make_box(1, 1, 1);
  box.F(2, 1) = 8;   // out of range
  box.F(7, 2) = box.F(7, 0);  // repeated corner
  const MeshReport r = validate_mesh(box);
  CHECK(r.num_bad_indices == 2);
  CHECK(r.bad_triangles == std::vector<int>{2, 7});
  CHECK_FALSE(r.ok());
  CHECK_THROWS_AS(build_adjacency(&box), std::invalid_argument);
  box.F(2, 1) = -1;
  CHECK(validate_mesh(box).num_bad_indices == 2);
}

TEST_CASE("validate_mesh: three triangles on one edge make it non-manifold", "[mesh]") {
  // Three fins around the edge (0, 1) on the z axis.
  const TriangleMesh fins = make_mesh({{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {-1, 1, 0}, {-1, -1, 0}},
                                      {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}, "fins");
  const MeshReport r = validate_mesh(fins);
  CHECK(r.num_nonmanifold_edges == 1);
  CHECK(r.nonmanifold_edges == std::vector<int>{0});  // edge (0, 1) is the first
  CHECK_FALSE(r.manifold());
  CHECK_FALSE(r.closed());
  CHECK(r.describe().find("non-manifold edges") != std::string::npos);
}

TEST_CASE("validate_mesh: two boxes sharing one corner vertex", "[mesh]") {
  // Box A = [0,1]^3 and box B = [1,2]^3 touch at (1,1,1): A's vertex 7 and B's
  // vertex 0 are made one vertex. Every edge still has two faces.
  const TriangleMesh a = make_box(1, 1, 1, Eigen::Vector3d(0.5, 0.5, 0.5));
  const TriangleMesh b = make_box(1, 1, 1, Eigen::Vector3d(1.5, 1.5, 1.5));
  TriangleMesh both = concatenate(a, b);
  for (int f = 12; f < 24; ++f)
    for (int k = 0; k < 3; ++k)
      if (both.F(f, k) == 8) both.F(f, k) = 7;
  // Vertex 8 (B's corner) is now unused; drop it by moving the last vertex there.
  both.V.row(8) = both.V.row(15);
  for (int f = 12; f < 24; ++f)
    for (int k = 0; k < 3; ++k)
      if (both.F(f, k) == 15) both.F(f, k) = 8;
  both.V.conservativeResize(15, 3);

  const MeshReport r = validate_mesh(both);
  CHECK(r.num_boundary_edges == 0);
  CHECK(r.num_nonmanifold_edges == 0);
  CHECK(r.num_isolated_vertices == 0);
  CHECK(r.num_nonmanifold_vertices == 1);
  CHECK(r.nonmanifold_vertices == std::vector<int>{7});
  CHECK(r.closed());
  CHECK_FALSE(r.manifold());
  CHECK_FALSE(r.ok());
}

TEST_CASE("validate_mesh: a flipped triangle breaks orientation on its three edges", "[mesh]") {
  TriangleMesh box = make_box(1, 2, 3);
  std::swap(box.F(4, 1), box.F(4, 2));
  const MeshReport r = validate_mesh(box);
  CHECK(r.num_inconsistent_edges == 3);
  CHECK(r.closed());
  CHECK_FALSE(r.manifold());
  CHECK_FALSE(r.ok());
  CHECK(r.describe().find("orientation") != std::string::npos);
}

TEST_CASE("validate_mesh: isolated vertices and empty meshes are not ok", "[mesh]") {
  TriangleMesh box = make_box(1, 1, 1);
  box.V.conservativeResize(9, 3);
  box.V.row(8) << 5, 5, 5;
  const MeshReport r = validate_mesh(box);
  CHECK(r.num_isolated_vertices == 1);
  CHECK(r.isolated_vertices == std::vector<int>{8});
  CHECK(r.closed());
  CHECK(r.manifold());
  CHECK_FALSE(r.ok());

  const MeshReport empty = validate_mesh(TriangleMesh{});
  CHECK_FALSE(empty.ok());
  CHECK_FALSE(empty.describe().empty());
}

TEST_CASE("validate_mesh: lists are capped, counts are exact", "[mesh]") {
  // An icosphere with every triangle but one removed from the first half: many
  // boundary edges, at most kMaxListed listed.
  const TriangleMesh sphere = make_icosphere(2, 1.0);  // 320 triangles
  TriangleMesh open = sphere;
  open.F = sphere.F.bottomRows(160);
  const MeshReport r = validate_mesh(open);
  CHECK(r.num_boundary_edges > MeshReport::kMaxListed);
  CHECK(static_cast<int>(r.boundary_edges.size()) == MeshReport::kMaxListed);
  CHECK(r.describe().find("...") != std::string::npos);
}
