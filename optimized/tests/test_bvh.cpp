// Tests of bvh.h: tree structure, boxes and feature ownership, and the
// oriented boxes fitted to a node's points.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "gauss6/bvh.h"
#include "mesh_shapes.h"

using namespace gauss6;
using gauss6::test::make_icosphere;

namespace {

bool contains(const Aabb& outer, const Aabb& inner) {
  return (outer.lo.array() <= inner.lo.array()).all() && (inner.hi.array() <= outer.hi.array()).all();
}

}  // namespace

TEST_CASE("BVH: structure, boxes and feature ownership", "[bvh]") {
  const TriangleMesh mesh = make_icosphere(3, 1.0);  // 1280 triangles
  const Bvh bvh = build_bvh(mesh, 4);
  std::printf("BVH of %d triangles: %zu nodes, depth %d, %.1f KiB, built in %.3f ms\n", static_cast<int>(mesh.F.rows()),
              bvh.nodes.size(), bvh.depth, bvh.memory_bytes() / 1024.0, 1e3 * bvh.build_seconds);
  // Every triangle in exactly one leaf, inside its leaf's box; children inside parents.
  std::vector<int> seen(mesh.F.rows(), 0);
  for (const BvhNode& n : bvh.nodes) {
    if (n.count > 0) {
      CHECK(n.count <= 4);
      for (int i = 0; i < n.count; ++i) {
        const int f = bvh.triangles[n.first + i];
        ++seen[f];
        CHECK(contains(n.box, triangle_box(mesh, f)));
      }
    } else {
      CHECK(contains(n.box, bvh.nodes[n.first].box));
      CHECK(contains(n.box, bvh.nodes[n.first + 1].box));
    }
  }
  for (int c : seen) REQUIRE(c == 1);
  CHECK(bvh.depth <= 12);  // balanced: ceil(log2(1280 / 4)) + 1 = 10
  // Each vertex owned once; each undirected edge owned once.
  std::vector<int> vown(mesh.V.rows(), 0);
  std::map<std::pair<int, int>, int> eown;
  for (int f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      if (bvh.owned[f] & (1u << k)) ++vown[mesh.F(f, k)];
      const auto e = std::minmax(mesh.F(f, k), mesh.F(f, (k + 1) % 3));
      eown[e] += (bvh.owned[f] & (8u << k)) ? 1 : 0;
      CHECK(bvh.neighbor[3 * f + k] >= 0);  // closed mesh: every edge has a neighbour
    }
  for (int c : vown) CHECK(c == 1);
  for (const auto& [e, c] : eown) CHECK(c == 1);
}

TEST_CASE("fit_obb: holds every point, and is thin for points on a thin arc", "[bvh]") {
  std::mt19937 rng(41);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> U(0, 1);
  for (int i = 0; i < 2000; ++i) {
    const double scale = std::pow(10.0, 6 * U(rng) - 3);
    const Vec3 c = 10 * scale * Vec3(n(rng), n(rng), n(rng));
    std::vector<Vec3> pts(3 + i % 20);
    const Vec3 dir = Vec3(n(rng), n(rng), n(rng)).normalized();
    for (Vec3& x : pts) {
      x = c + scale * Vec3(n(rng), n(rng), n(rng));
      if (i % 3 == 0) x = c + scale * n(rng) * dir;                     // collinear
      if (i % 3 == 1) x -= dir * dir.dot(x - c);                        // coplanar
    }
    const Obb b = fit_obb(pts.data(), static_cast<int>(pts.size()));
    REQUIRE((b.axes.transpose() * b.axes - Mat3::Identity()).cwiseAbs().maxCoeff() < 1e-14);
    for (const Vec3& x : pts) {
      const Vec3 local = b.axes.transpose() * (x - b.center);
      // The test's own rounding: the subtraction and product, 1e-15 of the coordinates.
      REQUIRE((local.cwiseAbs() - b.half).maxCoeff() <= 1e-15 * (c.norm() + 10 * scale));
    }
  }
  // Two 10 cm strips of a 1 cm cylinder, 5 degrees each (a peg's leaf): its
  // thickness is the arc's sagitta, where its axis-aligned box at 45 degrees
  // is half a millimetre thick.
  std::vector<Vec3> strip;
  for (int k = 0; k < 3; ++k)
    for (double y : {-0.05, 0.05}) {
      const double a = M_PI / 4 + (k - 1) * 5 * M_PI / 180;
      strip.push_back(Vec3(0.01 * std::cos(a), y, 0.01 * std::sin(a)));
    }
  const Obb s = fit_obb(strip.data(), static_cast<int>(strip.size()));
  CHECK(s.half.minCoeff() < 0.01 * (1 - std::cos(5 * M_PI / 180)));
  CHECK(obb_volume_ratio(s.half, Vec3(0.0006, 0.05, 0.0006)) < 0.5);
}
