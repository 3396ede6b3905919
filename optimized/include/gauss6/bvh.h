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
  // Per triangle, a slab that holds it: unit normal n (doubles; zero for a
  // degenerate triangle) and lo <= n.x <= hi for every point x of the triangle,
  // the bounds rounded outward. Any n would do: the slab is what is rigorous.
  struct Slab { Vec3 n = Vec3::Zero(); double lo = 0, hi = 0; };
  std::vector<Slab> slabs;           // #F
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
// can cache them: see SweptBoxCache).
template <class GodNodeBox, class GodFaceBox, class Visit>
TraversalStatus for_each_candidate_pair_indexed([[maybe_unused]] const TriangleMesh& god_mesh, const Bvh& god,
                                                const TriangleMesh& obs_mesh, const Bvh& obs,
                                                const GodNodeBox& god_node_box, const GodFaceBox& god_face_box,
                                                double margin, BvhStack* stack, Visit&& visit, int* num_node_pairs) {
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
    if (!overlap(gw, inflate(on.box, margin))) continue;
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
  int num_slab_culls = 0;                  // triangle pairs dropped whole by a face slab (no pair test)
  long num_box_iterations = 0;             // narrow-phase boxes, all tests together
};

// Everything ccd_step needs, allocated once.
// World boxes of god nodes, faces and vertices over the current sub-interval, so each is
// enclosed once per sub-interval however many obstacle nodes it meets: a
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
// from the obstacle face's slab and a bound on the god-object's speed; pairs
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
