// Bounding volume hierarchies over triangle meshes (each node: an axis-aligned
// box and an oriented box), their conservative traversal under the Cayley
// motion, and the mesh-level CCD step ccd_step(): the first contact between the
// moving god-object and the static obstacles along the in-between motion of
// METHOD.md section 4.
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
#include <limits>
#include <utility>
#include <vector>

#include "gauss6/aabb.h"
#include "gauss6/ccd.h"
#include "gauss6/distance.h"
#include "gauss6/feature_pair.h"
#include "gauss6/mesh.h"

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

struct BvhNode {
  Aabb box;            // the mesh's own frame
  Obb obb;             // the mesh's own frame; holds every vertex of the node's triangles
  bool obb_pays = false;  // the oriented box is less than half the axis-aligned one (obb_volume_ratio)
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
// axis of their bounds, leaves of at most leaf_size triangles, each node's
// oriented box fitted to its vertices (fit_obb). Load time.
Bvh build_bvh(const TriangleMesh& mesh, int leaf_size = 4);

// The oriented box of the given points: the eigenvectors of their covariance
// or the frame's axes, whichever box is smaller (volume of the box grown by a
// thousandth of its diagonal, so that flat boxes compare by area); extents
// grown to cover the roundings of the projections. Load time.
Obb fit_obb(const Vec3* points, int num_points);

// Exact box of triangle f of the mesh (its own frame). Inline: the traversal
// calls it for every leaf triangle pair.
inline Aabb triangle_box(const TriangleMesh& mesh, int f) {
  const Vec3 a = mesh.V.row(mesh.F(f, 0)).transpose(), c = mesh.V.row(mesh.F(f, 1)).transpose(),
             d = mesh.V.row(mesh.F(f, 2)).transpose();
  return {a.cwiseMin(c).cwiseMin(d), a.cwiseMax(c).cwiseMax(d)};
}
// Conservative world box of every p(u) + R(u) r_B, u in e.u, r_B in body_box.
Aabb swept_box(const MotionEnclosure& e, const Aabb& body_box);

// How a triangle moves in time tau (units of the motion's parameter), as
// triangle_time_lower_bound() takes it: each point x moves by at most
//   tau v + (rotation of x - centre by an angle <= tau |omega| about omega)
//   + tau w (any further motion of speed w).
// A turn by phi about the unit axis e moves x - centre = r by sin(phi) e x r +
// (1 - cos(phi)) e x (e x r): along a unit n by at most phi |n.(e x r)| +
// phi^2 / 2 |r| <= tau |n.(omega x r)| + tau^2 |omega|^2 / 2 |r|. The second
// term is the caller's to put in w (as tau_max |omega|^2 / 2 max |r| for the
// horizon tau <= tau_max it uses the bound for); the first is directional: a
// peg turning about its centre moves its tip across the rim's wall, not into
// it. omega = 0: no turn (w holds all of it).
//
// lag: how far the turn may fall behind tau omega. The turn by phi (tau) moves
// r by sin(phi) e x r = lambda tau omega x r with lambda in [1 - lag, 1] (1:
// anything from no turn to the full one). A small lag is what lets a pivoting
// motion cancel: a peg turned about its tip while G moves by tau v = -tau
// omega x r_tip moves its tip by (lambda - 1) tau omega x r_tip only, where
// the translation and a turn that may lag entirely would move it by up to
// tau |v|. For the Cayley motion, lambda = sin(phi) / (tau 2 |g|) and lag =
// u1^2 |g|^2 + (tau 2 |g|)^2 / 6 (StartFrame in bvh.cpp).
struct TriangleMotion {
  Vec3 v = Vec3::Zero(), omega = Vec3::Zero(), centre = Vec3::Zero();
  double w = 0;
  double lag = 1;  // in [0, 1]
};

// A lower bound of the time (in units of the motion's parameter, from the
// triangles' current positions) before the moving triangle A can come within
// `reach` of the fixed triangle B, A moving as `m` says: along a separating
// axis with unit direction n and gap g (B beyond A on side = +-1), a corner x
// of A moves towards B by at most tau (side n.v + lambda b), b = side n.(omega
// x r) (r = x - centre), lambda in [1 - lag, 1] the same for all corners, plus
// the rest (second order, w); lambda b <= b + lag max(0, -b). So A's
// projection approaches B's at most at max(0, max over corners of side n.v + b
// + lag max(0, -b)) + w (the corners' projections bound every point's: the
// first-order motion is affine in x), and it needs (g - reach) / that;
// the largest such time over the 11 axes (and `extra`:
// for_each_separating_axis), or 0 when none proves g > reach; +inf when an
// axis proves a gap that the motion never closes. Returns as soon as one axis
// proves more than `enough`. Rounding: n.v from the rounded axis is within
// 1e-14 |a|_1 |v|_inf / |a| of the exact one's; a.(omega x r) = r.(a x omega),
// a sum of a few products of magnitude <= |a|_1 |omega|_inf |r|_inf, within
// 1e-13 of that; each quotient is rounded up or down the safe way. Inline: the
// mesh step calls it for every candidate triangle pair and feature pair.
inline double triangle_time_lower_bound(const Vec3 A[3], const Vec3 B[3], const TriangleMotion& m, double reach,
                                        double enough, const Vec3* extra = nullptr) {
  const double v_inf = m.v.cwiseAbs().maxCoeff(), omega_inf = m.omega.cwiseAbs().maxCoeff();
  const Vec3 r[3] = {A[0] - m.centre, A[1] - m.centre, A[2] - m.centre};
  double r_inf = 0;
  for (int k = 0; k < 3; ++k) r_inf = std::max(r_inf, r[k].cwiseAbs().maxCoeff());
  double best = 0;
  for_each_separating_axis(A, B, [&](const Vec3& a, double g, double side) GAUSS6_ALWAYS_INLINE_LAMBDA {
    const double clear = next_down(g - reach);
    if (!(clear > 0)) return false;
    const double a_1 = a.cwiseAbs().sum();
    const double along_v = side * a.dot(m.v);
    double approach = along_v, slack = 1e-14 * a_1 * v_inf;
    if (omega_inf > 0) {
      const Vec3 c = a.cross(m.omega);  // r.(a x omega) = a.(omega x r)
      approach = -std::numeric_limits<double>::infinity();
      for (int k = 0; k < 3; ++k) {
        const double b = side * r[k].dot(c);
        approach = std::max(approach, along_v + b + m.lag * std::max(0.0, -b));
      }
      slack += 1e-13 * a_1 * omega_inf * r_inf;
    }
    const double toward = next_up(std::max(0.0, next_up(approach)) + slack);
    const double speed = next_up(next_up(toward / next_down(a.norm() * (1 - 1e-12))) + m.w);
    const double t = speed > 0 ? next_down(clear / speed) : std::numeric_limits<double>::infinity();
    if (!(t <= std::numeric_limits<double>::infinity())) return false;  // NaN
    best = std::max(best, t);
    return best > enough;
  }, extra);
  return best;
}

// Oriented-box test of the simultaneous descent. A god node's box is tight in the
// body frame, but its world box (swept_box) grows with the rotation: a 10 cm
// side strip of the peg tilted by half a degree gets a world box about 1 mm
// wide, five times the hole's clearance; and the hole's wall, a ring of strips,
// has axis-aligned boxes as wide as its arcs. Their oriented boxes stay as thin
// as the arcs' sagittas: for a peg resting in the hole (0.2 mm of clearance)
// they keep the leaves of facing strips apart, where the axis-aligned boxes of
// all of them meet.
//
// Over a sub-interval [u0, u1] of the motion, every point r_B of the god-object
// is at X(u) = p(u) + R(u) r_B with p(u) = p(u0) + (u - u0) dp, so X(u) lies in
//   Xd + s step + ball(grow),  s = (u - u0) / (u1 - u0) in [0, 1],
// where Xd = p + R r_B is its double position at u0 (StartFrame in bvh.cpp:
// within static_error of the exact one), step = (u1 - u0) dp_mid (dp's
// midpoint), and grow = static_error + (u1 - u0) (|dp - dp_mid| + 2 |g| |r_B|)
// (R(u) R(u0)^T turns by at most 2 (u - u0) |g|); plus the distance sought d.
// The swept set of a node's oriented box is then the posed box plus the
// segment [0, step] plus that ball, and the node pair is apart when one of the
// 15 axes of the two boxes separates the projections: along an axis L the
// swept set's projection is the posed box's, centred at its centre plus step/2,
// widened by |L.step| / 2 and grow |L| (|L| <= 1 for the 15 axes, so grow).
// The segment is what lets a peg sliding 50 um a step along the hole's axis
// keep its facing arcs apart: the motion does not approach them.
struct PosedObb {
  Mat3 axes = Mat3::Identity();   // world frame
  Vec3 center = Vec3::Zero(), half = Vec3::Zero();
  Vec3 half_step = Vec3::Zero();  // step / 2
  double grow = 0;
  bool pays = false;              // less than half its world axis-aligned box (obb_volume_ratio)
};

// Volume of an oriented box over that of the axis-aligned box with the given
// half extents, both grown by a thousandth of the oriented box's diagonal (so
// flat boxes compare by area): below 1/2, the box pays for its test
// (node_pair_separated).
inline double obb_volume_ratio(const Vec3& obb_half, const Vec3& aabb_half) {
  const double e = 1e-3 * obb_half.norm();
  return (obb_half + Vec3::Constant(e)).prod() / (aabb_half + Vec3::Constant(e)).prod();
}

// The pose and motion bounds of one sub-interval (or of a fixed pose: step 0,
// turn 0), which pose() applies to a god node's body-frame box.
//
// The turn, two ways. Isotropic (spin zero): every point r_B may move by a
// further turn |r_B| in any direction, so a node 5 cm from G turned by 6 mrad
// gets 0.3 mm more on every side. Directional (spin = (u1 - u0) omega, the
// turn's first order): a point at offset r = R r_B from G moves by s (step +
// spin x r) up to the rest, s in [0, 1]; for the node's box, r = c + e (c = R
// center, |e| <= |half|), so the box sweeps along its own segment step + spin
// x c, grown by |spin| |half| for its spread and by turn |r_B| for the rest
// (the second order, the turn's lag behind spin and the enclosure's width:
// StartFrame::obb_frame). A peg pivoting about its tip, G moving by -spin x
// r_tip, then sweeps its tip's boxes by almost nothing.
struct SweptObbFrame {
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero();
  Vec3 step = Vec3::Zero();  // world translation of G over the sub-interval (its midpoint)
  Vec3 spin = Vec3::Zero();  // directional: the turn's first order over the sub-interval (zero: isotropic)
  double grow = 0;           // static_error + d + (u1 - u0) |dp - dp_mid| (any point)
  double turn = 0;           // times |r_B| for a point's turn (isotropic) or its rest (directional)
  double spread = 0;         // directional: >= |spin| (times |half|)
  PosedObb pose(const Obb& b) const {
    PosedObb out;
    out.axes = R * b.axes;
    const Vec3 c = R * b.center;
    out.center = c + p;
    out.half = b.half;
    // |r_B| <= |center| + |half| for every point of the box.
    const double radius = next_up(next_up(b.center.norm() + b.half.norm()) * (1 + 1e-12));
    out.grow = turn > 0 ? next_up(grow + next_up(turn * radius)) : grow;
    if (spread > 0) {
      const Vec3 node_step = step + spin.cross(c);
      out.half_step = 0.5 * node_step;
      // The spread; the roundings of c (as R r_B's), the cross product and the
      // sum: a few units of 2^-53 of |spin|_inf radius and |step|_inf.
      const double rounding = 1e-14 * (spin.cwiseAbs().maxCoeff() * radius + step.cwiseAbs().maxCoeff());
      out.grow = next_up(out.grow + next_up(next_up(spread * next_up(b.half.norm() * (1 + 1e-15))) + rounding));
    } else {
      out.half_step = 0.5 * step;
    }
    if (!(out.grow < std::numeric_limits<double>::infinity())) out.grow = std::numeric_limits<double>::infinity();
    out.pays = obb_volume_ratio(b.half, out.axes.cwiseAbs() * b.half) < 0.5;
    return out;
  }
};

// True when a separating axis among the 15 of the two boxes (Gottschalk, Lin
// and Manocha 1996) proves the swept posed god box `a` (see above) apart from
// the obstacle's box `b` (world frame). Rounding: every side of every
// comparison is a sum of at most a dozen products of an entry of |C| (<= 1 +
// 1e-15) and a number <= s (the largest coordinate, extent or step involved),
// each within a few units of 2^-53 of itself, and the axes are orthonormal to
// within 1e-15; 1e-11 s covers all of it many times over, and |C| + 1e-15
// keeps the cross axes of near-parallel edges from proving a gap out of
// rounding noise. False on NaN.
GAUSS6_ALWAYS_INLINE bool obb_separated(const PosedObb& a, const Obb& b) {
  const Mat3 C = a.axes.transpose() * b.axes;  // C(i, j) = a_i . b_j
  Mat3 A = C.cwiseAbs();
  A.array() += 1e-15;
  const Vec3 t_w = b.center - (a.center + a.half_step);
  const Vec3 ta = a.axes.transpose() * t_w, tb = b.axes.transpose() * t_w;
  const Vec3 da = a.axes.transpose() * a.half_step, db = b.axes.transpose() * a.half_step;
  const Vec3 &ha = a.half, &hb = b.half;
  const double s = std::max({ha.maxCoeff(), hb.maxCoeff(), t_w.cwiseAbs().maxCoeff(), a.center.cwiseAbs().maxCoeff(),
                             b.center.cwiseAbs().maxCoeff(), a.half_step.cwiseAbs().maxCoeff(), a.grow});
  const double g = a.grow + 1e-11 * s;
  for (int i = 0; i < 3; ++i)
    if (std::abs(ta[i]) > ha[i] + A.row(i).dot(hb) + std::abs(da[i]) + g) return true;
  for (int j = 0; j < 3; ++j)
    if (std::abs(tb[j]) > hb[j] + A.col(j).dot(ha) + std::abs(db[j]) + g) return true;
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      // L = a_i x b_j, in a's frame: (0, ...) with t.L = t[i2] C(i1, j) - t[i1] C(i2, j).
      const double dist = std::abs(ta[i2] * C(i1, j) - ta[i1] * C(i2, j));
      const double sweep = std::abs(da[i2] * C(i1, j) - da[i1] * C(i2, j));
      const double ra = ha[i1] * A(i2, j) + ha[i2] * A(i1, j);
      const double rb = hb[j1] * A(i, j2) + hb[j2] * A(i, j1);
      if (dist > ra + rb + sweep + g) return true;
    }
  }
  return false;
}

// The traversals' oriented-box test of a node pair (the god node's box posed
// and swept, the obstacle node): run only where one of the two boxes is under
// half its axis-aligned one (PosedObb::pays, BvhNode::obb_pays), since where
// both are about as tight as their axis-aligned boxes (a bunny's compact
// nodes, the flat fans of an axis-aligned face) the 15-axis test costs more
// than it saves.
GAUSS6_ALWAYS_INLINE bool node_pair_separated(const PosedObb& god_node, const BvhNode& obstacle_node) {
  return (god_node.pays || obstacle_node.obb_pays) && obb_separated(god_node, obstacle_node.obb);
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
// leaf pair being visited are not all visited.
template <class GodNodeBox, class GodFaceBox, class Visit, class Separated>
TraversalStatus resume_candidate_pairs([[maybe_unused]] const TriangleMesh& god_mesh, const Bvh& god,
                                       const TriangleMesh& obs_mesh, const Bvh& obs, const GodNodeBox& god_node_box,
                                       const GodFaceBox& god_face_box, double margin, BvhStack* stack, int* pending,
                                       long budget, Visit&& visit, int* num_node_pairs, const Separated& separated) {
  const int capacity = static_cast<int>(stack->items.size());
  auto* items = stack->items.data();
  int size = *pending;
  const auto leave = [&](TraversalStatus status) {
    *pending = size;
    return status;
  };
  while (size > 0) {
    if (budget-- <= 0) return leave(TraversalStatus::kPaused);
    const auto [gi, oi] = items[--size];
    const BvhNode& gn = god.nodes[gi];
    const BvhNode& on = obs.nodes[oi];
    ++*num_node_pairs;
    const Aabb gw = god_node_box(gi);
    if (!overlap(gw, inflate(on.box, margin)) || separated(gi, oi)) continue;
    if (gn.count > 0 && on.count > 0) {
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

// ---------------------------------------------------------------------------
// Mesh-level CCD step.
// ---------------------------------------------------------------------------

// A mesh and its BVH (built from that mesh). Obstacles: world frame; god-object:
// body frame.
struct CcdBody {
  const TriangleMesh* mesh = nullptr;
  const Bvh* bvh = nullptr;
};

struct CcdStepSettings {
  CcdSettings narrow;                      // tolerances and min_separation of every pair test
  int max_sub_intervals = 16;              // u-ranges whose swept boxes are computed separately
  double sub_interval_angle = 0.1;         // radians of rotation per sub-interval (at most)
  double sub_interval_travel = 0.25;       // travel of G per sub-interval, in god-object radii (at most)
  long cache_fill_budget = 0;              // node pairs per step that refill the cache in the background
                                           // (0: no background fill)
  double cache_margin = 0;                 // coherence between steps: keep the pairs within the reach plus this
                                           // (scene units) at a pose in contact, and take a later step's candidates
                                           // from them while no point has moved farther than this from that pose
                                           // (CcdStepWorkspace::ProximityCache; 0: off; the runtime uses 64 delta)
  double cache_margin_max = 0;             // a list's margin grows up to this (>= cache_margin) to span about six
                                           // steps like the last one (0: every list's margin is cache_margin)
  double near_distance = 0;                // also list the triangle pairs that may come within this (>=
                                           // min_separation) by the stop pose: the near pairs (CcdStepResult)
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
  int num_axis_culls = 0;                  // triangle pairs dropped whole by a separating-axis time bound (no pair test)
  int num_feature_culls = 0;               // feature pairs dropped by their own time bound (no pair test)
  long num_box_iterations = 0;             // narrow-phase boxes, all tests together
  // Near pairs (settings.near_distance > 0): when num_near_pairs >= 0, ws->candidates[0 .. num_near_pairs)
  // hold every triangle pair that can come within near_reach (= max(min_separation, near_distance)) of
  // each other under the exact motion at any u in [near_u0, u_hit] (the last sub-interval searched), so
  // the contact generation at the stop pose can test those instead of descending the trees again (with
  // the stop pose's deviation taken off near_reach). -1: no such list (the step stopped before any
  // descent, or the candidate buffer overflowed).
  int num_near_pairs = -1;
  double near_u0 = 0, near_reach = 0;
  bool cache_filled = false;               // the proximity cache was (re)filled at X0 (CcdStepWorkspace)
  bool cache_refilled = false;             // a background fill of the cache was completed and put in use
  int num_fill_node_pairs = 0;             // node pairs that the cache's fills (at once or in the background) tested
  double u_cached = 0;                     // [0, u_cached] searched from the proximity cache (0: not used)
};

// Everything ccd_step needs, allocated once.
// World boxes of god nodes, faces and vertices over the current sub-interval
// (ccd_step keeps node and face boxes grown by min_separation, vertex boxes as
// they are) and the nodes' posed oriented boxes, so each is computed once per
// sub-interval however many obstacle nodes it meets: direct-mapped caches
// (index & mask -> entry; a collision just recomputes), of fixed size, so any
// mesh fits without allocation. Entries are valid while their stamp equals
// `stamp` (next_interval() invalidates them all in O(1)).
struct SweptBoxCache {
  template <class T>
  struct Entry {
    T value;
    int32_t key = -1;
    uint32_t stamp = 0;
  };
  template <class T>
  using Table = std::vector<Entry<T>>;
  explicit SweptBoxCache(int capacity_log2 = 12)
      : nodes(size_t{1} << std::clamp(capacity_log2, 0, 24)), faces(nodes.size()), vertices(nodes.size()),
        node_obbs(nodes.size()) {}
  void next_interval() {
    if (++stamp != 0) return;
    // Wrapped around (every 2^32 sub-intervals).
    for (auto& e : nodes) e.stamp = 0;
    for (auto& e : faces) e.stamp = 0;
    for (auto& e : vertices) e.stamp = 0;
    for (auto& e : node_obbs) e.stamp = 0;
    stamp = 1;
  }
  // The cached value of `index` in `table`, computed by make() when missing.
  template <class T, class Make>
  const T& get(Table<T>& table, int index, const Make& make) {
    Entry<T>& e = table[static_cast<size_t>(index) & (table.size() - 1)];
    if (e.key != index || e.stamp != stamp) {
      e.value = make();
      e.key = index;
      e.stamp = stamp;
    }
    return e.value;
  }
  Table<Aabb> nodes, faces, vertices;  // god BVH nodes, faces, vertices (by mesh index)
  Table<PosedObb> node_obbs;           // god BVH nodes
  uint32_t stamp = 0;
};

struct CcdStepWorkspace {
  explicit CcdStepWorkspace(int box_capacity = 1 << 14, int stack_capacity = 1024, int candidate_capacity = 1 << 14)
      : narrow(box_capacity),
        stack(stack_capacity),
        candidates(static_cast<size_t>(std::max(candidate_capacity, 0))),
        cache(std::max(candidate_capacity, 0), stack_capacity) {}
  // A candidate triangle pair of one sub-interval and a lower bound of its first contact parameter.
  struct Candidate {
    double earliest;
    int32_t god_face, obstacle_face, obstacle;
  };
  // Coherence between steps (CcdStepSettings::cache_margin). pairs[0 ..
  // num_pairs) hold every triangle pair not proven farther than reach + margin
  // apart with the god-object at the exact pose ref: so at any god pose whose
  // every point lies within `margin` of its place at ref, every pair that may
  // lie within `reach` is among them. A pose of the god-object in contact
  // hardly moves from one step to the next (resting, or pressed into an edge
  // and stopped at once): while a step's motion keeps within the margin of ref,
  // ccd_step takes its candidates from here instead of descending the trees.
  // ccd_step refills it (at the step's start) when it cannot serve the step
  // and a fresh one could (see ccd_step). It is keyed by the god-object's and the obstacles' meshes and
  // BVHs (pointers), the reach and the settings' margins; clear() it when a
  // mesh behind the same pointers changes. Each list has its own margin
  // (CcdStepSettings::cache_margin_max).
  struct ProximityCache {
    ProximityCache(int capacity, int stack_capacity)
        : pairs(static_cast<size_t>(capacity)), fill(capacity, stack_capacity) {}
    // gap: a lower bound of the pair's distance at ref; radius: the largest
    // |r_B| of the god triangle's corners. A step whose points move at most
    // shift + turn |r_B| from ref keeps the pair farther apart than
    // gap - shift - turn radius.
    struct Pair {
      double gap, radius;
      int32_t god_face, obstacle_face, obstacle;
    };
    std::vector<Pair> pairs;
    int num_pairs = -1;            // -1: empty (never filled, or the pairs did not fit)
    Pose ref;
    double reach = 0, margin = 0;  // margin: this list's
    double margin_min = 0, margin_max = 0;  // the settings it was filled under (keys)
    int uses = 0;  // later steps served since the fill
    int rest = 0;  // chances to refill still to pass over (see ccd_step)
    CcdBody god;
    std::vector<CcdBody> obstacles;  // grows (allocates) only when a fill sees more obstacles than ever before
    // A fill in progress (CcdStepSettings::cache_fill_budget): the same kind
    // of list for the pose `ref` (where the god-object is heading: ccd_step)
    // and its own margin, built a budget of node pairs per step in the
    // background while the list above still serves, then swapped in;
    // finished at once when a step needs it first. Same keys as the list above.
    struct Fill {
      Fill(int capacity, int stack_capacity) : pairs(static_cast<size_t>(capacity)), stack(stack_capacity) {}
      std::vector<Pair> pairs;
      int num_pairs = 0;
      Pose ref;
      double margin = 0;
      CcdMotion motion;  // still at ref (or the step it started in, when ref is that step's start)
      BvhStack stack;    // the descent's pending node pairs: stack.items[0 .. pending)
      int pending = 0;
      int obstacle = 0;  // the obstacle being descended
      long cost = 0;     // node pairs tested so far
      bool active = false, complete = false;
    } fill;
    long fill_cost = 0;  // node pairs of the last fill completed
    Pose last_x0;        // the start of the last step (for the background fill's pose)
    bool has_last = false;
    void clear() {
      num_pairs = -1;
      fill.active = false;
    }
  };
  // The triangle pair that stopped the last step run in this workspace
  // (coherence): when it is among a step's hints it is searched first. A
  // god-object pressed into a corner is stopped by the same pair step after
  // step, at once; found first, its hit ends the searches of the sliding
  // contacts there, where each would otherwise search the whole step (a
  // hundred narrow-phase boxes or more each).
  FeaturePair last_hit;
  CcdWorkspace narrow;
  BvhStack stack;
  std::vector<Candidate> candidates;  // tested earliest-first; overflow is tested in traversal order
  SweptBoxCache swept;                // god boxes of the current sub-interval
  ProximityCache cache;
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
//
// hints[0 .. num_hints): feature pairs likely to touch first (the runtime
// passes the contacts at X0); their triangle pairs are tested over the whole
// step before the descent (and not again after it). A pair pressed against an
// obstacle then gives a hit near u = 0 at once, and the descent searches only
// up to it, with boxes swept over that short range: the peg pressed into the
// hole's rim, commanded a millimetre into it, no longer sweeps that millimetre
// through the hole. Any hint is a real pair, so the answer's guarantee is the
// same with or without them; out-of-range hints are ignored.
//
// With settings.cache_margin > 0, ws->cache carries candidates from one step
// to the next (CcdStepWorkspace::ProximityCache): the same answer as a fresh
// descent, for a fraction of its cost while the god-object stays near a pose.
// With settings.cache_fill_budget > 0 as well, the next list is filled that
// many node pairs per step, at the pose the god-object is heading for, while
// the list in use serves.
void ccd_step(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const Pose& X0, const Pose& X1,
              const CcdStepSettings& settings, CcdStepWorkspace* ws, CcdStepResult* result,
              const FeaturePair* hints = nullptr, int num_hints = 0);

}  // namespace gauss6
