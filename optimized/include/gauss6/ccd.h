// Conservative continuous collision detection (CCD), narrow phase and the
// mesh-level step of METHOD.md section 4.
//
// Guarantee. For every query, u_hit <= u*, the exact first parameter at which
// the two features touch (or, with min_separation > 0, at which their distance
// may fall to min_separation): the god-object is never advanced into or through
// a contact. How far u_hit may lie below u* is what the tolerances trade against
// speed, and every result reports what it reached (time width, distance bound).
//
// Method: inclusion-based bisection over the box (u, a, b) of the motion
// parameter and the two feature parameters, in the spirit of Tight-Inclusion
// (Wang et al. 2021), with an interval enclosure of the feature difference
// F(u, a, b) (vertex minus face point, or point of edge A minus point of edge B)
// whose every floating-point operation is widened outward (see Interval below).
// A box whose enclosure proves |F| > min_separation (the enclosure misses the
// ball of that radius, or, rigid queries, F's projections on a separating axis
// chosen per u-interval from the features' nominal closest points lie beyond
// it) provably contains no contact and is dropped; boxes are explored in increasing u, so the
// first u-interval accepted (at most time_tolerance wide, holding a small
// parameter box that may touch) bounds u* from below. So u_hit <= u*, and at
// u_hit the features are already within distance_reached; if they truly touch
// in the accepted interval, u* - u_hit <= time_tolerance_reached (in practice
// u* - u_hit <= 2 time_tolerance unless the motion grazes: see the tests).
// Rigid queries first drop u-ranges with cheap polynomial filters in Bernstein
// form (the coplanarity cubic, the slabs; edge/edge, also the lines' distance
// as a polynomial of degree 6, which decides a sliding pair whole); linear
// queries that a short bisection (64 boxes) does not decide continue with the
// same filters and guides (sliding contacts, nearly parallel edges: ccd.cpp); with early_hit the
// earliest kept u-interval is accepted without the bisection when a feature
// pair there is proven within min_separation + distance_tolerance (the same
// acceptance rule; everything before it was proven free, so u_hit <= u*).
//
// Two kinds of vertex trajectories:
//   linear: x(u) = x0 + u (x1 - x0) per vertex (the shared test data's form);
//   rigid:  the Cayley motion of motion.h for the god-object's body points r_B,
//           the obstacle static in the world frame.
//
// Real-time rules: queries never allocate (CcdWorkspace is sized once), never
// lock and never throw; bad input is a status.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <bit>
#include <cstdint>
#include <limits>
#include <vector>

#include "gauss6/motion.h"
#include "gauss6/pose.h"
#include "gauss6/rounding.h"

namespace gauss6 {

inline IVec3 to_interval(const Vec3& v) { return {Interval::point(v.x()), Interval::point(v.y()), Interval::point(v.z())}; }

// ---------------------------------------------------------------------------
// The exact Cayley motion, enclosed.
// ---------------------------------------------------------------------------

// Interval enclosure of the exact in-between motion of METHOD.md section 4 from
// two double poses: p0, dp = p1 - p0, R0 = R(q0) (rational form) and the Gibbs
// vector g = vec(qr) / scalar(qr), qr = q1 conj(q0), each enclosing the exact
// rational value computed from the input doubles. `nominal` is the double motion
// of motion.h (the same motion, rounded), used for poses and heuristics.
struct CcdMotion {
  IVec3 p0, dp, g;
  IMat3 R0;
  Interval g2;           // |g|^2
  IMat3 K2;              // [g]x^2 = g g^T - |g|^2 I
  CayleyMotion nominal;
};

// kOk, or the status of make_cayley_motion (invalid pose, half turn). Also
// kHalfTurn when the enclosure of scalar(qr) is not safely positive.
MotionStatus make_ccd_motion(const Pose& x0, const Pose& x1, CcdMotion* motion);

// Enclosure of the motion over a parameter range U = [u0, u1] subset of [0, 1]:
// for every u in U, R(u) is in R and p(u) in p (world frame).
struct MotionEnclosure {
  Interval u;
  IMat3 R;   // entries intersected with [-1, 1] (R(u) is exactly a rotation)
  IVec3 p;
  // R in midpoint-radius form: every entry of R within R_rad of R_mid's
  // (exactly), and R_abs = |R_mid|; for swept_box (motion_bounds.h).
  Mat3 R_mid, R_rad, R_abs;
};
void enclose_motion(const CcdMotion& motion, Interval u, MotionEnclosure* out);
// Enclosure of the world points p(u) + R(u) r_B for u in e.u and r_B in r_B.
IVec3 enclose_point(const MotionEnclosure& e, const IVec3& r_B);

// ---------------------------------------------------------------------------
// Requests and results.
// ---------------------------------------------------------------------------

enum class CcdStatus {
  kOk = 0,          // the search finished: hit or no hit is decided within the tolerances
  kMaxIterations,   // gave up after max_iterations boxes: hit reported conservatively
  kWorkspaceFull,   // box stack full: hit reported conservatively
  kInvalidInput,    // a non-finite or huge coordinate, or an empty window
  kHalfTurn,        // mesh step only: relative rotation near 180 degrees, split_step() it
};
const char* to_string(CcdStatus s);

struct CcdSettings {
  double time_tolerance = 1e-6;       // accept a box at most this wide in u ...
  double distance_tolerance = 1e-9;   // ... holding a feature-parameter box not excluded whose widths move F by
                                      // at most max(this, u-width x speed) (scene units; raised to 1e-12 of the
                                      // largest coordinate, the rounding floor kDistanceToleranceFloor)
  double min_separation = 0;          // report the first u where the distance may be <= this (scene units, >= 0)
  int max_iterations = 200000;        // boxes examined before a conservative give-up
  bool use_u_filter = true;           // rigid queries: drop u-ranges by the coplanarity cubic and a separating
                                      // axis before the bisection; linear queries: the same filter and guides for
                                      // what a 64-box bisection leaves undecided (conservative; false: bisection
                                      // alone)
  bool early_hit = true;              // queries with the u-filter: accept the earliest u-interval the filter
                                      // keeps (at most time_tolerance wide, all before it excluded) without the
                                      // bisection when the features' nominal closest points there are proven within
                                      // min_separation + distance_tolerance at its start (same acceptance rule as
                                      // the bisection; u_hit <= u* holds either way); the bisection applies the
                                      // same test at the start of each u-interval it takes up (all before settled)
};

struct CcdResult {
  CcdStatus status = CcdStatus::kOk;
  bool hit = false;                   // conservative: true on give-up
  double u_hit = 1;                   // first possible contact (<= u*); the window's end when no hit
  double time_tolerance_reached = 0;  // u-width of the accepted (or last) box
  double distance_reached = 0;        // hit: the features are within this distance (Euclidean) at u_hit,
                                      // for some feature parameters; +inf on give-up
  int iterations = 0;                 // boxes examined
  int filter_intervals = 0;           // u-intervals the u-filter examined (filtered queries; at most 256)
};

// Box stack of the bisection (the parameter-box fronts of the pending
// u-intervals), sized once: capacity boxes of 48 bytes.
class CcdWorkspace {
 public:
  explicit CcdWorkspace(int capacity = 1 << 14);
  struct Box { double u[2], a[2], b[2]; };
  int capacity() const { return static_cast<int>(boxes_.size()); }
  Box* data() { return boxes_.data(); }

 private:
  std::vector<Box> boxes_;
};

// Linear per-vertex motion: index [0] is the position at u = 0, [1] at u = 1.
// Vertex/face: contact when the vertex lies on the triangle (face[.][0..2]).
struct LinearVertexFaceQuery {
  std::array<Vec3, 2> vertex;
  std::array<std::array<Vec3, 3>, 2> face;
  double u_begin = 0, u_end = 1;      // search window, 0 <= u_begin <= u_end <= 1
};
// Edge/edge: edge_a[time][endpoint], edge_b[time][endpoint].
struct LinearEdgeEdgeQuery {
  std::array<std::array<Vec3, 2>, 2> edge_a, edge_b;
  double u_begin = 0, u_end = 1;
};

// Rigid motion: one feature on the moving body (the god-object, body frame B,
// moved by *motion), the other static (the obstacle, world frame W). The names
// and fields mirror the exact twins of gauss6/reference/ccd.h.

// The god-object's vertex moving, the obstacle face static.
struct RigidVertexFaceQuery {
  const CcdMotion* motion = nullptr;
  Vec3 vertex_B = Vec3::Zero();
  std::array<Vec3, 3> face_W = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  double u_begin = 0, u_end = 1;      // search window, 0 <= u_begin <= u_end <= 1
};
// The obstacle's vertex static, the god-object's face moving.
struct RigidFaceVertexQuery {
  const CcdMotion* motion = nullptr;
  Vec3 vertex_W = Vec3::Zero();
  std::array<Vec3, 3> face_B = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  double u_begin = 0, u_end = 1;
};
// The god-object's edge moving, the obstacle edge static.
struct RigidEdgeEdgeQuery {
  const CcdMotion* motion = nullptr;
  std::array<Vec3, 2> edge_B;         // moving
  std::array<Vec3, 2> edge_W;         // static
  double u_begin = 0, u_end = 1;
};

void ccd_linear_vertex_face(const LinearVertexFaceQuery& q, const CcdSettings& s, CcdWorkspace* ws, CcdResult* r);
void ccd_linear_edge_edge(const LinearEdgeEdgeQuery& q, const CcdSettings& s, CcdWorkspace* ws, CcdResult* r);
void ccd_rigid_vertex_face(const RigidVertexFaceQuery& q, const CcdSettings& s, CcdWorkspace* ws, CcdResult* r);
void ccd_rigid_face_vertex(const RigidFaceVertexQuery& q, const CcdSettings& s, CcdWorkspace* ws, CcdResult* r);
void ccd_rigid_edge_edge(const RigidEdgeEdgeQuery& q, const CcdSettings& s, CcdWorkspace* ws, CcdResult* r);

// The mesh-level step (BVH traversal, first hit over all feature pairs) is
// ccd_step() in bvh.h.

// ---------------------------------------------------------------------------
// Stop pose.
// ---------------------------------------------------------------------------

// The pose of the motion at u, as doubles, and a bound on how far any body point
// with |r_B| <= body_radius lies from where the exact motion puts it at u:
// |(p + R(q) r_B) - (p(u) + R(u) r_B)| <= deviation. With a CCD run at
// min_separation = d and u = u_hit, the stop pose's exact separation is at least
// d - deviation (and the exact motion on [0, u_hit] keeps a distance >= d).
struct StopPose {
  Pose pose;
  double deviation = 0;   // scene units
};
StopPose make_stop_pose(const CcdMotion& motion, double u, double body_radius);

// A bound on how far apart two Cayley motions keep each body point: the exact
// motion a from a0 to a1, and the exact motion b (from b0, its start pose) over
// [0, ub] run at the same pace (b at u ub when a is at u); for every u in
// [0, 1] and |r_B| <= body_radius, |(p_a(u) + R_a(u) r_B) - (p_b(u ub) +
// R_b(u ub) r_B)| <= the result (infinity when a cannot be made: invalid pose,
// half turn). Why it holds: b over [0, ub] is the Cayley motion of Gibbs vector
// ub g_b; each motion's quaternion (1, u g) (x) q0 / |q0| is affine in u and of
// norm >= 1, and x -> x / |x| is the nearest point of the unit ball for such
// x (a projection on a convex set: it does not lengthen distances), so the unit
// quaternions differ by at most the affine ones' difference, largest at u = 0
// or 1; unit quaternions q, q' turn r_B to within 2 |q - q'| |r_B| of each
// other; the positions are affine in u too. A
// CCD run of b at min_separation d that stopped at ub keeps a distance >= d
// on [0, ub]: when the bound is below d, the motion a is free of contact.
// With ua < 1, a over [0, ua] only (its Cayley motion of Gibbs vector ua g_a,
// run at the same pace: a at u ua when b is at u ub): when the bound is below
// d, a is free of contact on [0, ua].
double motion_distance_bound(const Pose& a0, const Pose& a1, const Pose& b0, const CcdMotion& b, double ub,
                             double body_radius, double ua = 1.0);

}  // namespace gauss6
