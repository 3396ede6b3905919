// Bounding volume hierarchies (axis-aligned boxes) over triangle meshes, their
// conservative traversal under the Cayley motion, and the mesh-level CCD step
// ccd_step(): the first contact between the moving god-object and the static
// obstacles along the in-between motion of METHOD.md section 4.
//
// Frames: an obstacle's mesh and BVH are in the world frame W (apply a fixed
// pose to the vertices once at load time); the god-object's are in its body
// frame B (origin at G). Swept boxes of god-object nodes over a parameter range
// U come from the interval enclosure of the motion (ccd.h): for every u in U
// and every body point in the node's box, the world point lies in the swept box,
// rounding included. Boxes of obstacles are exact (min/max of doubles).
//
// Build: load time (allocates). Traversal and ccd_step: no allocation, no
// locks, no exceptions; fixed-capacity stacks in the workspace.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "gauss6/ccd.h"
#include "gauss6/mesh.h"

// Forces a hot lambda inline (GCC and Clang), as GAUSS6_ALWAYS_INLINE in ccd.h.
#define GAUSS6_ALWAYS_INLINE_LAMBDA __attribute__((always_inline))

namespace gauss6 {

struct Aabb {
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
};
inline bool overlap(const Aabb& a, const Aabb& b) {
  return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

struct BvhNode {
  Aabb box;            // the mesh's own frame
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

// Top-down build: median split of the triangles' centroids along the longest
// axis of their bounds, leaves of at most leaf_size triangles. Load time.
Bvh build_bvh(const TriangleMesh& mesh, int leaf_size = 4);

// Exact box of triangle f of the mesh (its own frame). Inline: the traversal
// calls it for every leaf triangle pair.
inline Aabb triangle_box(const TriangleMesh& mesh, int f) {
  const Vec3 a = mesh.V.row(mesh.F(f, 0)).transpose(), c = mesh.V.row(mesh.F(f, 1)).transpose(),
             d = mesh.V.row(mesh.F(f, 2)).transpose();
  return {a.cwiseMin(c).cwiseMin(d), a.cwiseMax(c).cwiseMax(d)};
}
// Conservative world box of every p(u) + R(u) r_B, u in e.u, r_B in body_box.
Aabb swept_box(const MotionEnclosure& e, const Aabb& body_box);
// box grown by margin on every side, rounded outward. Inline: the traversal
// calls it for every node pair.
inline Aabb inflate(const Aabb& box, double margin) {
  if (margin == 0) return box;
  Aabb out;
  for (int i = 0; i < 3; ++i) {
    out.lo[i] = next_down(box.lo[i] - margin);
    out.hi[i] = next_up(box.hi[i] + margin);
  }
  return out;
}

// Separating-axis bound of the distance of two triangles A and B given by their
// corners (one frame, doubles): the largest gap proven along the two face
// normals and the nine edge cross products, rounding included (0 when none
// proves a positive gap), returned as soon as one axis proves more than
// `enough`.
//
// Proof. For convex sets and any vector a != 0, dist(A, B) >= (min_B a.y -
// max_A a.x) / |a| (or the mirror). Whatever the rounded axis a is, each
// rounded projection fl(a.x) is within 3.4e-16 |a|_1 |x|_inf of a.x (three
// products and two sums), and the difference of two within twice that plus its
// own rounding; so raw - 1e-13 |a|_1 s, s the largest coordinate of the six
// corners, is below the exact gap along a. Dividing by |a| (1 + 1e-12), with
// the quotient rounded down, covers the roundings of the norm and the quotient.
// Inline: the mesh step and the contact generation call it for every candidate
// triangle pair.
inline double triangle_gap_lower_bound(const Vec3 A[3], const Vec3 B[3], double enough) {
  double s = 0;
  for (int k = 0; k < 3; ++k) s = std::max(s, std::max(A[k].cwiseAbs().maxCoeff(), B[k].cwiseAbs().maxCoeff()));
  double best = 0;
  const auto along = [&](const Vec3& a) GAUSS6_ALWAYS_INLINE_LAMBDA {
    double a_lo = a.dot(A[0]), a_hi = a_lo, b_lo = a.dot(B[0]), b_hi = b_lo;
    for (int k = 1; k < 3; ++k) {
      const double pa = a.dot(A[k]), pb = a.dot(B[k]);
      a_lo = std::min(a_lo, pa);
      a_hi = std::max(a_hi, pa);
      b_lo = std::min(b_lo, pb);
      b_hi = std::max(b_hi, pb);
    }
    const double proven = std::max(b_lo - a_hi, a_lo - b_hi) - 1e-13 * a.cwiseAbs().sum() * s;
    if (!(proven > 0)) return false;  // also on NaN
    const double g = next_down(proven / next_up(a.norm() * (1 + 1e-12)));
    if (g > best) best = g;           // a zero axis gives +inf or NaN: dropped below
    if (!(best < std::numeric_limits<double>::infinity())) best = 0;
    return best > enough;
  };
  const Vec3 ea[3] = {A[1] - A[0], A[2] - A[1], A[0] - A[2]}, eb[3] = {B[1] - B[0], B[2] - B[1], B[0] - B[2]};
  if (along(ea[0].cross(ea[1])) || along(eb[0].cross(eb[1]))) return best;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (along(ea[i].cross(eb[j]))) return best;
  return best;
}

// Oriented-box test of the simultaneous descent. A god node's box is tight in the
// body frame, but its world box (swept_box) grows with the rotation: a 10 cm
// side strip of the peg tilted by half a degree gets a world box about 1 mm
// wide, five times the hole's clearance, and meets every box near the hole.
// Posed as an oriented box, it stays as thin as it is. `pose` is the
// god-object's double pose (X = R r_B + p) and `grow` must cover how far the
// node's mesh points may lie from their double posed positions over the range
// tested, plus the distance sought (the mesh step: static_error + (u1 - u0)
// speed + d, see StartFrame in bvh.cpp); the box grown by `grow` along its own
// axes holds the ball of that radius around each of its points.
struct OrientedBoxFilter {
  OrientedBoxFilter() = default;
  OrientedBoxFilter(const Mat3& R_in, const Vec3& p_in, double grow_in) : R(R_in), p(p_in), grow(grow_in) {
    A = R.cwiseAbs();
    A.array() += 1e-15;
  }
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero();
  double grow = 0;
  Mat3 A = Mat3::Constant(1e-15) + Mat3::Identity();  // |R| + 1e-15
  // True when the posed god box (body frame), grown, provably misses the world
  // box: a separating axis among the 15 of the two boxes (Gottschalk, Lin and
  // Manocha 1996). Rounding: every side of every comparison is a sum of at most
  // a dozen products of an |R| entry (<= 1 + 1e-15) and a number <= s (the
  // largest coordinate or half extent involved), each rounded to within 2^-53
  // of itself, and the centres' differences are rounded likewise; 1e-11 s
  // covers them many times over, and |R| + 1e-15 keeps the
  // edge axes of near-parallel edges from proving a gap out of rounding noise.
  GAUSS6_ALWAYS_INLINE bool separated(const Aabb& body_box, const Aabb& world_box) const {
    const Vec3 ha = 0.5 * (body_box.hi - body_box.lo) + Vec3::Constant(grow);
    const Vec3 hb = 0.5 * (world_box.hi - world_box.lo);
    const Vec3 cb = 0.5 * (body_box.lo + body_box.hi), cw = 0.5 * (world_box.lo + world_box.hi);
    const Vec3 ca = R * cb + p;
    const Vec3 t_w = cw - ca;             // world frame
    const Vec3 t = R.transpose() * t_w;   // the god box's frame
    const double s = std::max({ha.maxCoeff(), hb.maxCoeff(), t_w.cwiseAbs().maxCoeff(), ca.cwiseAbs().maxCoeff(),
                               cb.cwiseAbs().maxCoeff(), cw.cwiseAbs().maxCoeff(), p.cwiseAbs().maxCoeff()});
    const double eps = 1e-11 * s;
    // Axes of the god box (rows of R^T), then the world axes.
    for (int i = 0; i < 3; ++i)
      if (std::abs(t[i]) > ha[i] + A.col(i).dot(hb) + eps) return true;
    for (int j = 0; j < 3; ++j)
      if (std::abs(t_w[j]) > hb[j] + A.row(j).dot(ha) + eps) return true;
    // Cross products of a god box axis i (world direction R.col(i)) and world axis j.
    for (int i = 0; i < 3; ++i) {
      const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
      for (int j = 0; j < 3; ++j) {
        const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
        const double dist = std::abs(t[i2] * R(j, i1) - t[i1] * R(j, i2));
        const double ra = ha[i1] * A(j, i2) + ha[i2] * A(j, i1);
        const double rb = hb[j1] * A(j2, i) + hb[j2] * A(j1, i);
        if (dist > ra + rb + eps) return true;
      }
    }
    return false;  // also on NaN
  }
};

// Fixed-capacity stack of node pairs for the simultaneous descent.
struct BvhStack {
  explicit BvhStack(int capacity = 1024) : items(static_cast<size_t>(capacity)) {}
  std::vector<std::pair<int32_t, int32_t>> items;
};

enum class TraversalStatus { kDone = 0, kStopped, kStackFull };

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
// are then dropped when separated(god_node_box_body, obstacle_node_box) proves
// them apart (an OrientedBoxFilter, or nothing: see the overload).
template <class GodNodeBox, class GodFaceBox, class Visit, class Separated>
TraversalStatus for_each_candidate_pair_indexed([[maybe_unused]] const TriangleMesh& god_mesh, const Bvh& god,
                                                const TriangleMesh& obs_mesh, const Bvh& obs,
                                                const GodNodeBox& god_node_box, const GodFaceBox& god_face_box,
                                                double margin, BvhStack* stack, Visit&& visit, int* num_node_pairs,
                                                const Separated& separated) {
  if (god.nodes.empty() || obs.nodes.empty()) return TraversalStatus::kDone;
  const int capacity = static_cast<int>(stack->items.size());
  auto* items = stack->items.data();
  int size = 0;
  items[size++] = {0, 0};
  while (size > 0) {
    const auto [gi, oi] = items[--size];
    const BvhNode& gn = god.nodes[gi];
    const BvhNode& on = obs.nodes[oi];
    ++*num_node_pairs;
    const Aabb gw = god_node_box(gi);
    if (!overlap(gw, inflate(on.box, margin)) || separated(gn.box, on.box)) continue;
    if (gn.count > 0 && on.count > 0) {
      // Leaf pair: test triangle boxes, then hand the pair over.
      for (int i = 0; i < gn.count; ++i) {
        const int gf = god.triangles[gn.first + i];
        const Aabb gt = god_face_box(gf);
        for (int j = 0; j < on.count; ++j) {
          const int of = obs.triangles[on.first + j];
          if (!overlap(gt, inflate(triangle_box(obs_mesh, of), margin))) continue;
          if (!visit(gf, of)) return TraversalStatus::kStopped;
        }
      }
      continue;
    }
    if (size + 2 > capacity) return TraversalStatus::kStackFull;
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
  return TraversalStatus::kDone;
}
template <class GodNodeBox, class GodFaceBox, class Visit>
TraversalStatus for_each_candidate_pair_indexed(const TriangleMesh& god_mesh, const Bvh& god,
                                                const TriangleMesh& obs_mesh, const Bvh& obs,
                                                const GodNodeBox& god_node_box, const GodFaceBox& god_face_box,
                                                double margin, BvhStack* stack, Visit&& visit, int* num_node_pairs) {
  return for_each_candidate_pair_indexed(god_mesh, god, obs_mesh, obs, god_node_box, god_face_box, margin, stack,
                                         std::forward<Visit>(visit), num_node_pairs,
                                         [](const Aabb&, const Aabb&) { return false; });
}
template <class GodBox, class Visit>
TraversalStatus for_each_candidate_pair(const TriangleMesh& god_mesh, const Bvh& god, const TriangleMesh& obs_mesh,
                                        const Bvh& obs, const GodBox& god_box, double margin, BvhStack* stack,
                                        Visit&& visit, int* num_node_pairs) {
  return for_each_candidate_pair_indexed(
      god_mesh, god, obs_mesh, obs, [&](int node) { return god_box(god.nodes[node].box); },
      [&](int face) { return god_box(triangle_box(god_mesh, face)); }, margin, stack, std::forward<Visit>(visit),
      num_node_pairs);
}

// ---------------------------------------------------------------------------
// Mesh-level CCD step.
// ---------------------------------------------------------------------------

// A mesh and its BVH (built from that mesh). Obstacles: world frame; god-object:
// body frame.
struct CcdBody {
  const TriangleMesh* mesh = nullptr;
  const Bvh* bvh = nullptr;
};

// Which features touch. A vertex is F(face, corner); an edge runs from
// F(face, corner) to F(face, (corner + 1) % 3); a face is `face` (corner -1).
enum class PairKind { kGodVertexObstacleFace = 0, kObstacleVertexGodFace, kEdgeEdge };
const char* to_string(PairKind k);
struct FeaturePair {
  PairKind kind = PairKind::kGodVertexObstacleFace;
  int obstacle = -1;                       // index into the obstacle list
  int god_face = -1, god_corner = -1;
  int obstacle_face = -1, obstacle_corner = -1;
};

struct CcdStepSettings {
  CcdSettings narrow;                      // tolerances and min_separation of every pair test
  int max_sub_intervals = 16;              // u-ranges whose swept boxes are computed separately
  double sub_interval_angle = 0.1;         // radians of rotation per sub-interval (at most)
  double sub_interval_travel = 0.25;       // travel of G per sub-interval, in god-object radii (at most)
};

struct CcdStepResult {
  CcdStatus status = CcdStatus::kOk;       // kOk, kHalfTurn (split the step: split_step()),
                                           // kInvalidInput, or a pair test's give-up (hit kept conservative)
  bool hit = false;
  double u_hit = 1;                        // first possible contact over all pairs (<= u*); 1 when none
  FeaturePair pair;                        // the pair that gave u_hit (when hit)
  double time_tolerance_reached = 0, distance_reached = 0;  // of that pair's test
  CcdMotion motion;                        // the enclosed motion used (for make_stop_pose)
  int num_sub_intervals = 0, num_node_pairs = 0, num_triangle_pairs = 0, num_pair_tests = 0;
  int num_slab_culls = 0;                  // triangle pairs dropped whole by a separating-axis bound (no pair test)
  long num_box_iterations = 0;             // narrow-phase boxes, all tests together
};

// Everything ccd_step needs, allocated once.
// World boxes of god nodes, faces and vertices over the current sub-interval (ccd_step
// keeps node and face boxes grown by min_separation, vertex boxes as they are), so
// each is enclosed once per sub-interval however many obstacle nodes it meets: a
// direct-mapped cache (index & mask -> entry; a collision just recomputes), of
// fixed size, so any mesh fits without allocation. Entries are valid while
// their stamp equals `stamp` (next_interval() invalidates them all in O(1)).
struct SweptBoxCache {
  struct Entry {
    Aabb box;
    int32_t key = -1;
    uint32_t stamp = 0;
  };
  explicit SweptBoxCache(int capacity_log2 = 12)
      : nodes(size_t{1} << std::clamp(capacity_log2, 0, 24)), faces(nodes.size()), vertices(nodes.size()) {}
  void next_interval() {
    if (++stamp != 0) return;
    for (Entry& e : nodes) e.stamp = 0;  // wrapped around (every 2^32 sub-intervals)
    for (Entry& e : faces) e.stamp = 0;
    for (Entry& e : vertices) e.stamp = 0;
    stamp = 1;
  }
  // The cached box of `index` in `table`, computed by make() when missing.
  template <class Make>
  const Aabb& get(std::vector<Entry>& table, int index, const Make& make) {
    Entry& e = table[static_cast<size_t>(index) & (table.size() - 1)];
    if (e.key != index || e.stamp != stamp) {
      e.box = make();
      e.key = index;
      e.stamp = stamp;
    }
    return e.box;
  }
  std::vector<Entry> nodes, faces, vertices;  // god BVH nodes, faces, vertices (by mesh index)
  uint32_t stamp = 0;
};

struct CcdStepWorkspace {
  explicit CcdStepWorkspace(int box_capacity = 1 << 14, int stack_capacity = 1024, int candidate_capacity = 1 << 14)
      : narrow(box_capacity), stack(stack_capacity), candidates(static_cast<size_t>(std::max(candidate_capacity, 0))) {}
  // A candidate triangle pair of one sub-interval and a lower bound of its first contact parameter.
  struct Candidate {
    double earliest;
    int32_t god_face, obstacle_face, obstacle;
  };
  CcdWorkspace narrow;
  BvhStack stack;
  std::vector<Candidate> candidates;  // tested earliest-first; overflow is tested in traversal order
  SweptBoxCache swept;                // god boxes of the current sub-interval

};

// The first contact of the god-object moving from X0 to X1 (the Cayley motion)
// with any obstacle: u_hit <= u* over all feature pairs. Per sub-interval, the
// candidate triangle pairs get a rigorous lower bound of their first contact
// from a separating-axis bound of their distance at the sub-interval's start
// (triangle_gap_lower_bound) and a bound on the god-object's speed; pairs
// that cannot touch in time are dropped, the rest are tested earliest-first,
// each only up to (best u so far) - time_tolerance, and the step reports the
// best u less time_tolerance (so u* - u_hit grows by at most that tolerance).
// Inputs: obstacles[0 .. num_obstacles) (world frame), god (body frame), X0, X1
// (poses of G). Stop pose: make_stop_pose(result.motion, result.u_hit,
// god.bvh->radius) when hit (u = 1 otherwise); with narrow.min_separation = d
// its exact separation is >= d - deviation.
void ccd_step(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const Pose& X0, const Pose& X1,
              const CcdStepSettings& settings, CcdStepWorkspace* ws, CcdStepResult* result);

}  // namespace gauss6
