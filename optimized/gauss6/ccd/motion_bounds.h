// Motion bounds of the collision pipeline: how far the god-object's points
// can move over a range of the motion parameter u, and the conservative
// volumes and time bounds built on that (METHOD.md section 4): swept
// axis-aligned boxes (swept_box), oriented boxes posed and swept over a
// sub-interval (PosedObb, SweptObbFrame, obb_separated, node_pair_separated),
// the per-sub-interval cache of the god-object's swept boxes (SweptBoxCache),
// the time before a moving triangle can come within reach of a fixed one
// (TriangleMotion, triangle_time_lower_bound), and in `detail` the machinery
// of the CCD step: the god-object's frame at a sub-interval's start with its
// bounds (StartFrame) and the displacement between two poses (Displacement).
//
// Frames: the god-object's body frame B (origin at G) and the world frame W,
// in which the obstacles and every swept volume lie. Every bound holds for
// the exact motion, rounding included. No allocation, no locks, no exceptions
// (SweptBoxCache allocates once, at construction).
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "gauss6/geometry/aabb.h"
#include "gauss6/geometry/bvh.h"
#include "gauss6/ccd/ccd.h"
#include "gauss6/geometry/distance.h"
#include "gauss6/numeric/error_allowances.h"
#include "gauss6/geometry/pose.h"

namespace gauss6 {

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
// u1^2 |g|^2 + (tau 2 |g|)^2 / 6 (detail::StartFrame below).
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
// the largest such time over the axes (and `extra`:
// for_each_separating_axis), or 0 when none proves g > reach; +inf when an
// axis proves a gap that the motion never closes. Returns as soon as one axis
// proves more than `enough`. Rounding: a.v is within kAxisVelocityRounding
// |a|_1 |v|_inf of the exact one; a.(omega x r) = r.(a x omega), within
// kAxisProductRounding |a|_1 |omega|_inf |r|_inf (error_allowances.h); the
// rest is rounded the safe way. Inline: the mesh step calls it for every
// candidate triangle pair and feature pair.
// Two forms: this one takes the sides prepared (sat_side; a god face's:
// StartFrame::posed_face) with r[k] = A's corner k less m.centre and r_inf
// the largest |coordinate| of those of A's Shape (corner_offsets); the one
// below takes the corners and prepares them.
template <Shape ShapeA = Shape::kTriangle, Shape ShapeB = Shape::kTriangle>
inline double triangle_time_lower_bound(const SatSide& A, const Vec3 r[3], double r_inf, const SatSide& B,
                                        const TriangleMotion& m, double reach, double enough,
                                        const Vec3* extra = nullptr) {
  constexpr int na = static_cast<int>(ShapeA);  // A's distinct corners
  const double v_inf = m.v.cwiseAbs().maxCoeff(), omega_inf = m.omega.cwiseAbs().maxCoeff();
  double best = 0;
  for_each_separating_axis<ShapeA, ShapeB>(A, B, [&](const Vec3& a, double g, double side) GAUSS6_ALWAYS_INLINE_LAMBDA {
    const Lower clear = Lower{g} - Upper{reach};
    if (!(clear.v > 0)) return false;
    const double a_1 = a.cwiseAbs().sum();
    const double along_v = side * a.dot(m.v);
    double approach = along_v, slack = kAxisVelocityRounding * a_1 * v_inf;
    if (omega_inf > 0) {
      const Vec3 c = a.cross(m.omega);  // r.(a x omega) = a.(omega x r)
      approach = -std::numeric_limits<double>::infinity();
      for (int k = 0; k < na; ++k) {
        const double b = side * r[k].dot(c);
        approach = std::max(approach, along_v + b + m.lag * std::max(0.0, -b));
      }
      slack += kAxisProductRounding * a_1 * omega_inf * r_inf;
    }
    const Upper toward = max(Upper{0.0}, round_up(approach)) + Upper{slack};
    // |a| from below, > 0 (Upper / Lower needs a positive divisor's double): an
    // axis too short to bound it proves nothing.
    const Lower a_norm = norm_down(a.norm(), kRelativeRoundingWide);
    if (!(a_norm.v > 0)) return false;
    const Upper speed = toward / a_norm + Upper{m.w};
    const double t = speed.v > 0 ? (clear / speed).v : std::numeric_limits<double>::infinity();
    if (!(t <= std::numeric_limits<double>::infinity())) return false;  // NaN
    best = std::max(best, t);
    return best > enough;
  }, extra);
  return best;
}
// r and r_inf of A's corners about `centre`.
template <Shape ShapeA = Shape::kTriangle>
GAUSS6_ALWAYS_INLINE double corner_offsets(const Vec3 A[3], const Vec3& centre, Vec3 r[3]) {
  double r_inf = 0;
  for (int k = 0; k < 3; ++k) r[k] = A[k] - centre;
  for (int k = 0; k < static_cast<int>(ShapeA); ++k) r_inf = std::max(r_inf, r[k].cwiseAbs().maxCoeff());
  return r_inf;
}
template <Shape ShapeA = Shape::kTriangle, Shape ShapeB = Shape::kTriangle>
inline double triangle_time_lower_bound(const Vec3 A[3], const Vec3 B[3], const TriangleMotion& m, double reach,
                                        double enough, const Vec3* extra = nullptr) {
  Vec3 r[3];
  const double r_inf = corner_offsets<ShapeA>(A, m.centre, r);
  return triangle_time_lower_bound<ShapeA, ShapeB>(sat_side<ShapeA>(A), r, r_inf, sat_side<ShapeB>(B), m, reach,
                                                   enough, extra);
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
// where Xd = p + R r_B is its double position at u0 (detail::StartFrame below:
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
  bool still = true;              // half_step is exactly zero (a fixed pose: the proximity cache's fills)
};

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
//
// The rotation R is set with set_rotation, which checks it once at
// kObbRotationTight: pose() then skips the frame check of R A for the nodes
// whose axes passed at kObbAxesTight (BvhNode::obb_tight), since the product
// passes it (proofs/ObbFrameProduct.v posed_frame_check).
class SweptObbFrame {
 public:
  void set_rotation(const Mat3& rotation) {
    R_ = rotation;
    rotation_tight_ = near_orthonormal(R_, kObbRotationTight);
  }
  const Mat3& rotation() const { return R_; }
  Vec3 p = Vec3::Zero();
  Vec3 step = Vec3::Zero();  // world translation of G over the sub-interval (its midpoint)
  Vec3 spin = Vec3::Zero();  // directional: the turn's first order over the sub-interval (zero: isotropic)
  double grow = 0;           // static_error + d + (u1 - u0) |dp - dp_mid| (any point)
  double turn = 0;           // times |r_B| for a point's turn (isotropic) or its rest (directional)
  double spread = 0;         // directional: >= |spin| (times |half|)
  // A BVH node's box: the frame check of R A is skipped when both R and the
  // node's axes passed the tight checks.
  PosedObb pose(const BvhNode& node) const { return pose_checked(node.obb, !(rotation_tight_ && node.obb_tight)); }
  // Any box: R A is checked.
  PosedObb pose(const Obb& b) const { return pose_checked(b, true); }

 private:
  Mat3 R_ = Mat3::Identity();
  bool rotation_tight_ = true;  // R_ passes near_orthonormal at kObbRotationTight (the identity does)

  PosedObb pose_checked(const Obb& b, bool check_frame) const {
    PosedObb out;
    out.axes = R_ * b.axes;
    const Vec3 c = R_ * b.center;
    out.center = c + p;
    out.half = b.half;
    // |r_B| <= |center| + |half| for every point of the box, each norm bounded
    // with its floor (norm_up: the squares may underflow).
    const Upper radius = norm_up(b.center.norm(), kRelativeRoundingWide) + norm_up(b.half.norm(), kRelativeRoundingWide);
    out.grow = turn > 0 ? (Upper{grow} + Upper{turn} * radius).v : grow;
    if (spread > 0) {
      const Vec3 node_step = step + spin.cross(c);
      out.half_step = 0.5 * node_step;
      // The spread; the roundings of c (as R r_B's), the cross product and the sum.
      const double rounding = kSpinRounding * (spin.cwiseAbs().maxCoeff() * radius.v + step.cwiseAbs().maxCoeff());
      const Upper half = norm_up(b.half.norm(), kRelativeRounding);
      out.grow = (Upper{out.grow} + (Upper{spread} * half + Upper{rounding})).v;
    } else {
      out.half_step = 0.5 * step;
    }
    // The 15-axis test holds for axes orthonormal to within kObbFrameTolerance
    // (proofs/ObbSeparation.v); a posed box whose axes are not (R far from a
    // rotation) gets an infinite grow, which no axis separates. Unchecked
    // (check_frame false) only where R and b.axes passed the tight checks,
    // which prove R A passes this one (ObbFrameProduct.v posed_frame_check).
    if (!(out.grow < std::numeric_limits<double>::infinity()) || (check_frame && !near_orthonormal(out.axes)))
      out.grow = std::numeric_limits<double>::infinity();
    out.still = (out.half_step.array() == 0).all();
    out.pays = obb_volume_ratio(b.half, out.axes.cwiseAbs() * b.half) < 0.5;
    return out;
  }
};

// True when a separating axis among the 15 of the two boxes (Gottschalk, Lin
// and Manocha 1996) proves the swept posed god box `a` (see above) apart from
// the obstacle's box `b` (world frame). Rounding: |C| + kObbAxisRounding and
// grow + kObbSeparationRounding s, s the largest coordinate, extent or step
// involved (error_allowances.h). False on NaN.
// kMoving false: the form for a box that does not sweep (a.half_step exactly
// zero, PosedObb::still), the same test with the step's terms left out (each
// is an exact zero there, so the answer is the same bit for bit).
template <bool kMoving>
GAUSS6_ALWAYS_INLINE bool obb_separated_as(const PosedObb& a, const Obb& b) {
  const Mat3 C = a.axes.transpose() * b.axes;  // C(i, j) = a_i . b_j
  Mat3 A = C.cwiseAbs();
  A.array() += kObbAxisRounding;
  const Vec3 t_w = kMoving ? Vec3(b.center - (a.center + a.half_step)) : Vec3(b.center - a.center);
  const Vec3 ta = a.axes.transpose() * t_w, tb = b.axes.transpose() * t_w;
  Vec3 da, db;  // the half step in each frame (moving only)
  if constexpr (kMoving) {
    da = a.axes.transpose() * a.half_step;
    db = b.axes.transpose() * a.half_step;
  }
  const Vec3 &ha = a.half, &hb = b.half;
  double s = std::max({ha.maxCoeff(), hb.maxCoeff(), t_w.cwiseAbs().maxCoeff(), a.center.cwiseAbs().maxCoeff(),
                       b.center.cwiseAbs().maxCoeff(), a.grow});
  if constexpr (kMoving) s = std::max(s, a.half_step.cwiseAbs().maxCoeff());
  const double g = a.grow + kObbSeparationRounding * s;
  // Each reach sums as (extents + sweep) + g, the sweep's term only when moving.
  for (int i = 0; i < 3; ++i) {
    double reach = ha[i] + A.row(i).dot(hb);
    if constexpr (kMoving) reach += std::abs(da[i]);
    if (std::abs(ta[i]) > reach + g) return true;
  }
  for (int j = 0; j < 3; ++j) {
    double reach = hb[j] + A.col(j).dot(ha);
    if constexpr (kMoving) reach += std::abs(db[j]);
    if (std::abs(tb[j]) > reach + g) return true;
  }
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      // L = a_i x b_j, in a's frame: (0, ...) with t.L = t[i2] C(i1, j) - t[i1] C(i2, j).
      const double dist = std::abs(ta[i2] * C(i1, j) - ta[i1] * C(i2, j));
      const double ra = ha[i1] * A(i2, j) + ha[i2] * A(i1, j);
      const double rb = hb[j1] * A(i, j2) + hb[j2] * A(i, j1);
      double reach = ra + rb;
      if constexpr (kMoving) reach += std::abs(da[i2] * C(i1, j) - da[i1] * C(i2, j));
      if (dist > reach + g) return true;
    }
  }
  return false;
}
GAUSS6_ALWAYS_INLINE bool obb_separated(const PosedObb& a, const Obb& b) {
  return a.still ? obb_separated_as<false>(a, b) : obb_separated_as<true>(a, b);
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

// World boxes of god nodes, faces and vertices over the current sub-interval
// (ccd_step keeps node and face boxes grown by min_separation, vertex boxes as
// they are) and the nodes' posed oriented boxes, so each is computed once per
// sub-interval however many obstacle nodes it meets: direct-mapped caches
// (index & mask -> entry; a collision just recomputes), of fixed size, so any
// mesh fits without allocation. Entries are valid while their stamp equals
// `stamp` (next_interval() invalidates them all in O(1)).
struct SweptBoxCache {
  // A god face at the sub-interval's start: its corners in doubles
  // (StartFrame::pose) prepared for the separating axes (side.P), their
  // offsets r from G and the largest |coordinate| of those (r_inf: for
  // triangle_time_lower_bound), and a bound on each one's |r_B|
  // (StartFrame::radius).
  struct PosedFace {
    SatSide side;
    Vec3 r[3];
    double r_inf;
    double radius[3];
  };
  template <class T>
  struct Entry {
    T value;
    int32_t key = -1;
    uint32_t stamp = 0;
  };
  template <class T>
  using Table = std::vector<Entry<T>>;
  // posed_faces_log2: the posed faces' table apart (a user that never poses
  // faces, the contact generation, keeps one entry, not 2^12 of ~300 bytes).
  explicit SweptBoxCache(int capacity_log2 = 12, int posed_faces_log2 = 12)
      : nodes(size_t{1} << std::clamp(capacity_log2, 0, 24)), faces(nodes.size()), vertices(nodes.size()),
        node_obbs(nodes.size()), posed_faces(size_t{1} << std::clamp(posed_faces_log2, 0, 24)) {}
  void next_interval() {
    if (++stamp != 0) return;
    // Wrapped around (every 2^32 sub-intervals).
    for (auto& e : nodes) e.stamp = 0;
    for (auto& e : faces) e.stamp = 0;
    for (auto& e : vertices) e.stamp = 0;
    for (auto& e : node_obbs) e.stamp = 0;
    for (auto& e : posed_faces) e.stamp = 0;
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
  Table<PosedFace> posed_faces;        // god faces (StartFrame::posed_face)
  uint32_t stamp = 0;
};

namespace detail {

// The god-object at a sub-interval's start u0 in doubles (X = p + R r_B), and
// bounds on how far the exactly moving point p(u) + R(u) r_B, for u in [u0, u1]
// and |r_B| <= the god radius rho, can lie from the double X:
//   - static_error: the stop pose's deviation (make_stop_pose: double pose vs
//     exact motion) plus the double evaluation of R(q) r_B + p: kPoseRounding
//     (|p|_inf + rho) (proofs/PoseAllowances.v). The projections n.X of the
//     double points on a separating axis round under kAxisProductRounding, at
//     for_each_separating_axis (proofs/AxisAllowances.v axis_gap_rounding);
//   - the motion: p(u) - p(u0) = (u - u0) dp, with dp within drift of its
//     midpoint dp_mid, and R(u) R(u0)^T is the turn about g by 2 (atan(u |g|) -
//     atan(u0 |g|)) <= 2 (u - u0) |g| (atan is 1-Lipschitz), so a body point r_B
//     moves by at most (u - u0)(|dp_mid| + drift + turn_rate |r_B|), turn_rate
//     = 2 |g| (speed: that for |r_B| = rho), and along a direction n by at most
//     (u - u0)(|n.dp_mid| + drift + turn_rate |r_B|).
struct StartFrame {
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero(), dp_mid = Vec3::Zero();
  double u0 = 0, static_error = 0, speed = 0, drift = 0, turn_rate = 0, rho = 0;
  double dp_max = 0;  // |dp| for every dp in the motion's enclosure (rounded up)
  // The turn: R(u) R(u0)^T turns about the exact g by at most 2 (u - u0) |g|;
  // omega = 2 g_mid (g's midpoint), within omega_error of 2 g for every g in
  // its enclosure, and omega2 >= |2 g|^2.
  Vec3 omega = Vec3::Zero();
  double omega_error = 0, omega2 = 0;
  double omega_norm = 0;  // >= |omega|
  double g2 = 0;          // >= |g|^2
  void set(const CcdMotion& m, double u, double rho_in);

  // How far the turn by phi over [u0, u0 + tau], tau <= tau_max, may fall
  // behind tau omega (TriangleMotion::lag): phi = 2 (atan(u |g|) - atan(u0 |g|))
  // lies between 2 tau |g| / (1 + u1^2 |g|^2) and 2 tau |g| (u1 = u0 + tau_max),
  // and sin(phi) >= phi (1 - phi^2 / 6); so sin(phi) / (2 tau |g|) >= 1 - u1^2
  // |g|^2 - (2 tau |g|)^2 / 6. At most 1.
  double lag(double tau_max) const {
    const Upper u1 = min(Upper{1.0}, Upper{u0} + Upper{tau_max});
    const Upper a = Upper{tau_max} * Upper{turn_rate};
    const Upper l = sqr(u1) * Upper{g2} + sqr(a) / 6;
    return l.v < 1 ? l.v : 1.0;  // also NaN
  }

  // The oriented-box frame of the sub-interval [u0, u1] (PosedObb, SweptObbFrame:
  // directional), grown by the distance sought d. A point at
  // offset r (exact, at u0) from G moves by tau dp + (lambda tau 2 g) x r +
  // (1 - cos(phi)) e x (e x r), tau = u - u0 <= span, lambda in [1 - lag, 1]:
  // that is tau (dp_mid + omega x r) plus at most span (drift + (omega_error +
  // lag |omega| + span omega2 / 2) |r|) (the lag, 2 g's distance from omega,
  // 1 - cos(phi) <= phi^2 / 2); with r taken from the double pose, within 2
  // static_error of the exact one, plus span (turn_rate + |omega|) 2
  // static_error.
  SweptObbFrame obb_frame(double u1, double d) const;

  // A lower bound of the first u >= u0 at which the god triangle gf can come
  // within min_separation d of the obstacle triangle `of` (u0 when unknown). At
  // u the god-object's points are within static_error of their double positions
  // X = p + R r_B at u0 moved as above; so a separating axis of the double
  // triangles (triangle_time_lower_bound: face normals, and edge cross products,
  // which separate a long side strip of the peg from the wide fan triangles
  // around the hole's rim where no face normal does) with gap g, along which the
  // triangle approaches at most at |n.dp_mid| + drift plus its turn about G
  // (TriangleMotion: the directional part from omega, the rest in w), keeps
  // every feature pair farther than d until (g - static_error - d) / that. The
  // search stops once the bound passes u_limit, and the bound is used for
  // u <= u_limit only: the turn's second-order term is taken for tau_max =
  // u_limit - u0. w, for r the largest |r_B| of the triangle's corners (>= that
  // of any of its points): drift; (omega_error + tau_max omega2 / 2) r (the
  // exact turn rate's distance from omega, and the second-order term);
  // turn_rate (static_error + kCornerOffsetRounding r) (the double corners'
  // offsets from G are within static_error of the exact ones, and their
  // subtraction rounds).
  // The god face comes posed (posed_face, cached per sub-interval in a
  // SweptBoxCache: a god face meets several obstacle faces).
  double earliest(const SweptBoxCache::PosedFace& g, const TriangleMesh& om, int of, double d,
                  double u_limit) const {
    Vec3 Y[3];
    place(om, of, Y);
    // |r_B| of any point of the triangle <= that of its farthest corner.
    const double r = std::max({g.radius[0], g.radius[1], g.radius[2]});
    TriangleMotion m;
    Upper tau_max;
    if (!motion(r, u_limit, &m, &tau_max)) return u0;
    const Upper reach = Upper{static_error} + Upper{d};
    return after(triangle_time_lower_bound(g.side, g.r, g.r_inf, sat_side(Y), m, reach.v, tau_max.v));
  }
  // The same for a god triangle X (its corners at u0, doubles; r >= the
  // largest |r_B| of them) and an obstacle triangle Y, either possibly
  // degenerate (a feature of the given Shapes: see for_each_separating_axis),
  // `extra` an axis to try first.
  template <Shape ShapeX = Shape::kTriangle, Shape ShapeY = Shape::kTriangle>
  double earliest(const Vec3 X[3], const Vec3 Y[3], double r, double d, double u_limit,
                  const Vec3* extra = nullptr) const {
    TriangleMotion m;
    Upper tau_max;
    if (!motion(r, u_limit, &m, &tau_max)) return u0;
    const Upper reach = Upper{static_error} + Upper{d};
    return after(triangle_time_lower_bound<ShapeX, ShapeY>(X, Y, m, reach.v, tau_max.v, extra));
  }

  // A lower bound of the distance of the god triangle gf at u0 (exact) from
  // the obstacle triangle `of`: the separating-axis bound of the double
  // triangles less static_error (0 when none proves more), computed until it
  // exceeds `enough`; *radius: the largest |r_B| of gf's corners.
  double gap(const SweptBoxCache::PosedFace& g, const TriangleMesh& om, int of, double enough, double* r) const {
    Vec3 Y[3];
    place(om, of, Y);
    *r = std::max({g.radius[0], g.radius[1], g.radius[2]});
    const double b = triangle_gap_lower_bound(g.side, sat_side(Y), (Upper{static_error} + Upper{enough}).v);
    return std::max(0.0, (Lower{b} - Upper{static_error}).v);
  }

  // A body point's double position at u0.
  Vec3 pose(const Vec3& r_B) const { return R * r_B + p; }
  // A bound >= sqrt(r2) and <= rho (every body point's |r_B| is).
  double radius(double r2) const { return std::min(rho, norm_up(std::sqrt(r2), kRelativeRounding).v); }
  // The god face gf at u0 (pose, radius), from `cache` when posed there in
  // this sub-interval.
  const SweptBoxCache::PosedFace& posed_face(const TriangleMesh& gm, int gf, SweptBoxCache* cache) const {
    return cache->get(cache->posed_faces, gf, [&] {
      SweptBoxCache::PosedFace f;
      Vec3 X[3];
      for (int k = 0; k < 3; ++k) {
        const Vec3 r_B = gm.V.row(gm.F(gf, k)).transpose();
        X[k] = pose(r_B);
        f.radius[k] = radius(r_B.squaredNorm());
      }
      f.side = sat_side(X);
      f.r_inf = corner_offsets(X, p, f.r);
      return f;
    });
  }

 private:
  // The motion of a god triangle whose corners' |r_B| are <= r, as
  // triangle_time_lower_bound takes it, for u in [u0, u_limit] (tau_max =
  // u_limit - u0); false when its speed bound w is not finite.
  bool motion(double r, double u_limit, TriangleMotion* m, Upper* tau_max) const {
    *tau_max = Upper{u_limit} - Lower{u0};
    m->v = dp_mid;
    m->omega = omega;
    m->centre = p;
    m->lag = lag(tau_max->v);
    const Upper second = 0.5 * (*tau_max * Upper{omega2});
    const Upper offsets = Upper{turn_rate} * round_up(static_error + kCornerOffsetRounding * r);
    m->w = ((Upper{drift} + (Upper{omega_error} + second) * Upper{r}) + offsets).v;
    return m->w < std::numeric_limits<double>::infinity();
  }
  // The u a time bound tau from u0 gives (u0 when it is not positive).
  double after(double tau) const { return tau > 0 ? (Lower{u0} + Lower{tau}).v : u0; }
  // The obstacle triangle's corners.
  static void place(const TriangleMesh& om, int of, Vec3 Y[3]) {
    for (int k = 0; k < 3; ++k) Y[k] = om.V.row(om.F(of, k)).transpose();
  }
};

// How far any point r_B of a body lies at pose b from where it lies at pose
// a, both exact (p + R(q) r_B, R(q) the rotation of the unit quaternion
// q / |q|): at most shift + turn |r_B|, with shift >= |p_b - p_a| and turn >=
// |R(q_b) - R(q_a)|: for unit quaternions R(a)^T R(b) = R(conj(a) b) turns by
// theta with |vec(conj(a) b)| = sin(theta / 2), and a turn by theta moves a
// point by at most 2 sin(theta / 2) |r_B|. In doubles: kQuaternionTurnRounding
// covers the two normalisations and the product, kRelativeRounding the
// rounding of |p_b - p_a|. Infinite on non-finite input.
struct Displacement {
  double shift = 0, turn = 0;
  Displacement(const Pose& a, const Pose& b);
  // Grown by a motion from b over [0, u] (StartFrame at 0: |dp| <= dp_max, and
  // R(u) R(0)^T turns by at most u turn_rate).
  void add(const StartFrame& f, double u) {
    shift = (Upper{shift} + u * Upper{f.dp_max}).v;
    turn = (Upper{turn} + u * Upper{f.turn_rate}).v;
  }
  double bound(double radius) const { return (Upper{shift} + Upper{turn} * Upper{radius}).v; }
};

}  // namespace detail

}  // namespace gauss6
