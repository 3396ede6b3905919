// Bounding volume hierarchies over triangle meshes: the tree (Bvh, BvhNode,
// each node an axis-aligned box and an oriented box), its load-time build
// (surface-area heuristic, oriented-box fitting, feature ownership) and the
// simultaneous descent of two trees (for_each_candidate_pair and its resumable
// form) that lists the triangle pairs whose boxes may meet. The bounds of the
// god-object's motion that the CCD step gives the descent are in
// motion_bounds.h; the CCD step itself in ccd_step.h.
//
// Frames: an obstacle's mesh and BVH are in the world frame W (apply a fixed
// pose to the vertices once at load time); the god-object's are in its body
// frame B (origin at G). Boxes of obstacles are exact (min/max of doubles).
//
// Build: load time (allocates). Traversal: no allocation, no locks, no
// exceptions; a fixed-capacity stack (BvhStack).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "gauss6/geometry/aabb.h"
#include "gauss6/geometry/feature_pair.h"
#include "gauss6/geometry/mesh.h"
#include "gauss6/numeric/error_allowances.h"

namespace gauss6 {

// An oriented box: the points center + axes x with |x_i| <= half_i (axes:
// orthonormal columns, up to rounding). Fitted to the node's vertices at build
// time (the principal axes of their spread, or the frame's axes when that box
// is smaller), so that a node of long thin triangles on a curved wall (a peg's
// side strips, the hole's wall) stays as thin as the wall's sagitta in every
// orientation, where its axis-aligned box is as wide as it is long.
struct Obb {
  Mat3 axes = Mat3::Identity();
  Vec3 center = Vec3::Zero(), half = Vec3::Zero();
};

// True when the columns of m and its rows are orthonormal to within
// `tolerance` (kObbFrameTolerance unless said): every entry of m^T m and of
// m m^T, computed in doubles, within it of the identity's (false on NaN). The
// oriented boxes' tests rest on it at kObbFrameTolerance (error_allowances.h,
// proofs/ObbSeparation.v); at the tighter kObbAxesTight and kObbRotationTight
// it tells SweptObbFrame::pose that the posed axes R A pass it too
// (proofs/ObbFrameProduct.v). Both Gram matrices are symmetric bit for bit (a
// product commutes exactly), so only their six distinct entries are computed,
// each dot in the order ((p0 + p1) + p2) that frame_check_sound models.
inline bool near_orthonormal(const Mat3& m, double tolerance = kObbFrameTolerance) {
  for (int i = 0; i < 3; ++i) {
    for (int j = i; j < 3; ++j) {
      const double id = i == j ? 1.0 : 0.0;
      const double columns = m(0, i) * m(0, j) + m(1, i) * m(1, j) + m(2, i) * m(2, j);
      const double rows = m(i, 0) * m(j, 0) + m(i, 1) * m(j, 1) + m(i, 2) * m(j, 2);
      if (!(std::abs(columns - id) <= tolerance && std::abs(rows - id) <= tolerance)) return false;
    }
  }
  return true;
}

struct BvhNode {
  Aabb box;            // the mesh's own frame
  Obb obb;             // the mesh's own frame; holds every vertex of the node's triangles
  bool obb_pays = false;  // the oriented box is less than half the axis-aligned one (obb_volume_ratio)
  bool obb_tight = false; // obb.axes pass near_orthonormal at kObbAxesTight (SweptObbFrame::pose)
  int32_t first = 0;   // leaf: first slot in Bvh::triangles; inner: left child (right = first + 1)
  int32_t count = 0;   // leaf: number of triangles (> 0); inner: 0
};

// Feature ownership: each vertex and each undirected edge belongs to exactly one
// of its triangles (the lowest-numbered), so that the feature pairs of all
// triangle pairs test every (vertex, face) and (edge, edge) pair exactly once.
struct Bvh {
  std::vector<BvhNode> nodes;        // nodes[0] is the root (empty mesh: no nodes)
  std::vector<int32_t> triangles;    // triangle indices, in leaf order
  std::vector<uint8_t> owned;        // #F: bit k owns vertex F(f,k); bit 3+k owns edge F(f,k)->F(f,(k+1)%3)
  std::vector<int32_t> neighbor;     // 3 #F: triangle across edge k of f, -1 on a boundary
  int depth = 0;                     // levels (1: the root is a leaf)
  double radius = 0;                 // max |vertex| about the frame's origin (scene units)
  double build_seconds = 0;
  size_t memory_bytes() const;
};

// A mesh and its BVH (built from that mesh): what the CCD step and the contact
// generation take of each body. Obstacles: world frame; god-object: body frame.
struct CcdBody {
  const TriangleMesh* mesh = nullptr;
  const Bvh* bvh = nullptr;
};

// Top-down build: each node's triangles split where the surface-area
// heuristic puts the split of their centroids sorted along an axis (the least
// area(left) n_left + area(right) n_right over the three axes), leaves of at
// most leaf_size triangles, each node's oriented box fitted to its vertices
// (fit_obb). Load time.
Bvh build_bvh(const TriangleMesh& mesh, int leaf_size = 4);

// The oriented box of the given points: the eigenvectors of their covariance
// or the frame's axes, whichever box is smaller (volume of the box grown by a
// thousandth of its diagonal, so that flat boxes compare by area); extents
// grown to cover the roundings of the projections. Load time.
Obb fit_obb(const Vec3* points, int num_points);

// Volume of an oriented box over that of the axis-aligned box with the given
// half extents, both grown by a thousandth of the oriented box's diagonal (so
// flat boxes compare by area): below 1/2, the box pays for its test
// (node_pair_separated).
inline double obb_volume_ratio(const Vec3& obb_half, const Vec3& aabb_half) {
  const double e = 1e-3 * obb_half.norm();
  return (obb_half + Vec3::Constant(e)).prod() / (aabb_half + Vec3::Constant(e)).prod();
}

// Exact box of triangle f of the mesh (its own frame). Inline: the traversal
// calls it for every leaf triangle pair.
inline Aabb triangle_box(const TriangleMesh& mesh, int f) {
  const Vec3 a = mesh.V.row(mesh.F(f, 0)).transpose(), c = mesh.V.row(mesh.F(f, 1)).transpose(),
             d = mesh.V.row(mesh.F(f, 2)).transpose();
  return {a.cwiseMin(c).cwiseMin(d), a.cwiseMax(c).cwiseMax(d)};
}

// Fixed-capacity stack of node pairs for the simultaneous descent.
struct BvhStack {
  explicit BvhStack(int capacity = 1024) : items(static_cast<size_t>(capacity)) {}
  std::vector<std::pair<int32_t, int32_t>> items;
};

enum class TraversalStatus { kDone = 0, kStopped, kStackFull, kPaused };

// Calls visit(god_triangle, obstacle_triangle) for every pair whose boxes may
// overlap: god boxes mapped to the world by god_box(Aabb body) -> Aabb world
// (conservative), obstacle boxes inflated by margin. visit returns false to
// stop. *num_node_pairs counts the node pairs tested. On kStackFull some pairs
// were not visited: the caller must treat the result as unknown.
//
// for_each_candidate_pair_indexed() is the same traversal with the god boxes
// given by index: god_node_box(int node) -> Aabb world for god.nodes[node], and
// god_face_box(int face) -> Aabb world for face `face` of god_mesh (so a caller
// can cache them: see SweptBoxCache); and node pairs whose world boxes overlap
// are then dropped when separated(god_node, obstacle_node) proves them apart
// (node_pair_separated; for_each_candidate_pair drops none).
//
// resume_candidate_pairs() runs the same traversal from the node pairs
// pending in stack->items[0 .. *size) (the root pair {0, 0} to start one) for
// at most `budget` node pairs, and returns kPaused with the rest pending there
// when the budget runs out: a traversal spread over several calls (the
// proximity cache's background fill, ccd_step). On kStopped the pairs of the
// leaf pair being visited are not all visited. The budget is a count of node
// pairs (take_node_pair below), or a caller's own allowance with its own
// take_node_pair (found by argument-dependent lookup), which visit may also
// draw on: the proximity cache's fills count a node pair's triangle pairs
// too (proximity_stages.cpp), so a traversal pauses before the node pair that
// follows the one whose triangle pairs spent the allowance.
//
// cut(god_node, obstacle_node), when given, gets every node pair the traversal
// stops at: those found apart and the leaf pairs (before their triangles are
// visited). With the pairs still pending on kStopped or kPaused they are a cut
// of the two trees' traversal: every leaf pair it could reach from the pairs
// it started from lies at or below exactly one of them (a later traversal may
// start from a cut instead of the root pair: ccd_step.h, DescentFront). On
// kStackFull the pair being expanded is in neither: no cut.
struct NoCut {
  void operator()(int, int) const {}
};
// A budget of node pairs: true when it allows one more (and counts it).
inline bool take_node_pair(long& budget) { return budget-- > 0; }
template <class GodNodeBox, class GodFaceBox, class Budget, class Visit, class Separated, class Cut = NoCut>
TraversalStatus resume_candidate_pairs([[maybe_unused]] const TriangleMesh& god_mesh, const Bvh& god,
                                       const TriangleMesh& obs_mesh, const Bvh& obs, const GodNodeBox& god_node_box,
                                       const GodFaceBox& god_face_box, double margin, BvhStack* stack, int* pending,
                                       Budget budget, Visit&& visit, int* num_node_pairs, const Separated& separated,
                                       const Cut& cut = Cut{}) {
  const int capacity = static_cast<int>(stack->items.size());
  auto* items = stack->items.data();
  int size = *pending;
  const auto leave = [&](TraversalStatus status) {
    *pending = size;
    return status;
  };
  while (size > 0) {
    if (!take_node_pair(budget)) return leave(TraversalStatus::kPaused);
    const auto [gi, oi] = items[--size];
    const BvhNode& gn = god.nodes[gi];
    const BvhNode& on = obs.nodes[oi];
    ++*num_node_pairs;
    const Aabb gw = god_node_box(gi);
    if (!overlap(gw, inflate(on.box, margin)) || separated(gi, oi)) {
      cut(gi, oi);
      continue;
    }
    if (gn.count > 0 && on.count > 0) {
      cut(gi, oi);
      // Leaf pair: test triangle boxes, then hand the pair over.
      for (int i = 0; i < gn.count; ++i) {
        const int gf = god.triangles[gn.first + i];
        const Aabb gt = god_face_box(gf);
        for (int j = 0; j < on.count; ++j) {
          const int of = obs.triangles[on.first + j];
          if (!overlap(gt, inflate(triangle_box(obs_mesh, of), margin))) continue;
          if (!visit(gf, of)) return leave(TraversalStatus::kStopped);
        }
      }
      continue;
    }
    if (size + 2 > capacity) return leave(TraversalStatus::kStackFull);
    // Descend the inner node with the larger box (or the only inner one).
    const double gs = (gw.hi - gw.lo).sum(), os = (on.box.hi - on.box.lo).sum();
    if (on.count > 0 || (gn.count == 0 && gs >= os)) {
      items[size++] = {gn.first + 1, oi};
      items[size++] = {gn.first, oi};
    } else {
      items[size++] = {gi, on.first + 1};
      items[size++] = {gi, on.first};
    }
  }
  return leave(TraversalStatus::kDone);
}
// Starts a traversal for resume_candidate_pairs: the root pair pending on
// `stack` (none when a tree is empty: nothing to visit). False when the stack
// has no room for it (kStackFull).
inline bool start_candidate_pairs(const Bvh& god, const Bvh& obs, BvhStack* stack, int* pending) {
  *pending = 0;
  if (god.nodes.empty() || obs.nodes.empty()) return true;
  if (stack->items.empty()) return false;
  stack->items[0] = {0, 0};
  *pending = 1;
  return true;
}
template <class GodNodeBox, class GodFaceBox, class Visit, class Separated>
TraversalStatus for_each_candidate_pair_indexed(const TriangleMesh& god_mesh, const Bvh& god,
                                                const TriangleMesh& obs_mesh, const Bvh& obs,
                                                const GodNodeBox& god_node_box, const GodFaceBox& god_face_box,
                                                double margin, BvhStack* stack, Visit&& visit, int* num_node_pairs,
                                                const Separated& separated) {
  int pending = 0;
  if (!start_candidate_pairs(god, obs, stack, &pending)) return TraversalStatus::kStackFull;
  return resume_candidate_pairs(god_mesh, god, obs_mesh, obs, god_node_box, god_face_box, margin, stack, &pending,
                                std::numeric_limits<long>::max(), std::forward<Visit>(visit), num_node_pairs,
                                separated);
}
template <class GodBox, class Visit>
TraversalStatus for_each_candidate_pair(const TriangleMesh& god_mesh, const Bvh& god, const TriangleMesh& obs_mesh,
                                        const Bvh& obs, const GodBox& god_box, double margin, BvhStack* stack,
                                        Visit&& visit, int* num_node_pairs) {
  return for_each_candidate_pair_indexed(
      god_mesh, god, obs_mesh, obs, [&](int node) { return god_box(god.nodes[node].box); },
      [&](int face) { return god_box(triangle_box(god_mesh, face)); }, margin, stack, std::forward<Visit>(visit),
      num_node_pairs, [](int, int) { return false; });
}

}  // namespace gauss6
