// Tests of bvh.h: tree structure, boxes and feature ownership, and the
// oriented boxes fitted to a node's points.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "gauss6/geometry/bvh.h"
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

// A traversal started from the cut another one stopped at (resume_candidate_pairs'
// cut callback) lists the same triangle pairs as one from the root pair, each
// once, whatever the boxes the first one saw: with boxes that hold their
// children's (a translated god-object's axis-aligned boxes, inflated), a leaf
// pair's triangle boxes meet only where every ancestor pair's boxes do, so the
// tests the cut skips could drop nothing. And the cut covers every leaf pair
// exactly once: a traversal that tests nothing (boxes that always meet) from
// the cut reaches every triangle pair once.
TEST_CASE("resume_candidate_pairs from a cut: the same pairs as from the root, each once", "[bvh]") {
  const TriangleMesh god = make_icosphere(2, 1.0), obs = make_icosphere(3, 1.5);
  const Bvh gb = build_bvh(god), ob = build_bvh(obs);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  using NodePair = std::pair<int32_t, int32_t>;
  const auto run = [&](const Vec3& shift, double margin, const std::vector<NodePair>* from, std::vector<NodePair>* cut,
                       std::vector<NodePair>* tris) {
    BvhStack stack(4096);
    int pending = 0;
    if (from == nullptr) {
      REQUIRE(start_candidate_pairs(gb, ob, &stack, &pending));
    } else {
      REQUIRE(from->size() <= stack.items.size());
      for (const NodePair& p : *from) stack.items[static_cast<size_t>(pending++)] = p;
    }
    const auto box = [&](const Aabb& b) { return Aabb{b.lo + shift, b.hi + shift}; };
    int num_node_pairs = 0;
    const TraversalStatus ts = resume_candidate_pairs(
        god, gb, obs, ob, [&](int n) { return box(gb.nodes[static_cast<size_t>(n)].box); },
        [&](int f) { return box(triangle_box(god, f)); }, margin, &stack, &pending, std::numeric_limits<long>::max(),
        [&](int gf, int of) {
          tris->push_back({gf, of});
          return true;
        },
        &num_node_pairs, [](int, int) { return false; }, [&](int g, int h) { cut->push_back({g, h}); });
    REQUIRE(ts == TraversalStatus::kDone);
  };
  int cut_sizes = 0, listed = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Vec3 a(U(rng), U(rng), U(rng)), b = a + 0.3 * Vec3(U(rng), U(rng), U(rng));
    const double margin = 0.02 + 0.1 * (U(rng) + 1);
    std::vector<NodePair> cut_a, cut_b, cut_ab, tris_a, tris_b, tris_ab;
    run(1.2 * a, margin, nullptr, &cut_a, &tris_a);
    run(1.2 * b, margin, nullptr, &cut_b, &tris_b);
    run(1.2 * b, margin, &cut_a, &cut_ab, &tris_ab);
    std::sort(tris_b.begin(), tris_b.end());
    std::sort(tris_ab.begin(), tris_ab.end());
    CHECK(std::adjacent_find(tris_ab.begin(), tris_ab.end()) == tris_ab.end());  // each once
    CHECK(tris_ab == tris_b);
    // The cut covers every leaf pair once: boxes that always meet reach all of them.
    std::vector<NodePair> all, unused;
    run(Vec3::Zero(), 1e9, &cut_ab, &unused, &all);
    CHECK(static_cast<long>(all.size()) == static_cast<long>(god.F.rows()) * obs.F.rows());
    std::sort(all.begin(), all.end());
    CHECK(std::adjacent_find(all.begin(), all.end()) == all.end());
    cut_sizes += static_cast<int>(cut_a.size());
    listed += static_cast<int>(tris_b.size());
  }
  CHECK(cut_sizes > 40);  // the trees were descended, not culled at the root
  CHECK(listed > 0);      // and some trials listed pairs
}
