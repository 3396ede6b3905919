// Conservative continuous collision detection (CCD) of METHOD.md section 4,
// narrow phase: one feature pair along a linear motion or the Cayley motion of
// motion.h (the mesh-level step over whole meshes: step/ccd_step.h).
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
// same filters and guides (sliding contacts, nearly parallel edges: linear_queries.cpp); with early_hit the
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

#include "gauss6/ccd/motion.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/numeric/rounding.h"

namespace gauss6 {

// ---------------------------------------------------------------------------
// Requests and results.
// ---------------------------------------------------------------------------

enum class CcdStatus {
  kOk = 0,          // the search finished: hit or no hit is decided within the tolerances
  kMaxIterations,   // gave up after max_iterations boxes: hit reported conservatively
  kWorkspaceFull,   // box stack full: hit reported conservatively
  kInvalidInput,    // a non-finite or huge coordinate, or an empty window
  kHalfTurn,        // mesh step only: relative rotation near 180 degrees, split the step in halves
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

}  // namespace gauss6
