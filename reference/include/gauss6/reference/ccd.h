// Exact continuous collision detection: the reference of METHOD.md section 4.
//
// Every answer is exact for the exact meaning of the inputs: doubles are taken
// as the rationals they denote, poses as in METHOD.md section 1 (R(q) is the
// rational quaternion rotation over |q|^2), and the in-between motion is the
// Cayley motion of METHOD.md section 4, built in exact arithmetic from the two
// poses' doubles. Times of impact are algebraic numbers, isolated exactly
// (CGAL's Algebraic_kernel_d_1 over GMP integers); contact tests at those times
// are exact sign evaluations of polynomials at algebraic numbers.
//
// Contact means distance exactly zero: a vertex in the closed triangle, or two
// closed segments sharing a point. Degenerate inputs (coplanar motion, parallel
// or zero-length edges, collinear triangles, contact at u = 0) are handled.
//
// Polynomial degrees (checked by the tests): a body point moves on
// x(u) = N(u) / W(u), N cubic, W(u) = |q0|^2 (s^2 + u^2 |v|^2) > 0 (qr = (s, v));
// after the positive factors W are divided out, every vertex/face and edge/edge
// coplanarity condition is a polynomial of degree <= 3 in u.
//
// Slow by design (GMP, CGAL): for checks, tests and certificates, not for the
// real-time loops. Functions allocate and may throw.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <gmpxx.h>

#include "gauss6/geometry/aabb.h"
#include "gauss6/io/ccd_queries.h"
#include "gauss6/geometry/feature_ids.h"
#include "gauss6/geometry/mesh.h"
#include "gauss6/geometry/pose.h"

namespace gauss6::reference {

// ---------------------------------------------------------------------------
// Exact time of impact.

// u* in [0, 1] when hit. u* is the unique root in [isolating_lower,
// isolating_upper] of the square-free integer polynomial `poly` (poly[i] is the
// coefficient of u^i); isolating_lower == isolating_upper when u* is rational.
// Double bracket: lower <= u* <= upper, with either lower == upper == u*
// exactly, or upper = nextafter(lower, 2) and lower < u* < upper (the tightest
// possible), so that compare_toi(toi, u) is exact for every double u.
struct ExactToi {
  bool hit = false;
  double lower = 0, upper = 0;
  std::vector<mpz_class> poly;
  mpq_class isolating_lower, isolating_upper;
};

// Exact sign of u - u* (-1, 0, +1). A miss counts as u* = +infinity (-1).
inline int compare_toi(const ExactToi& toi, double u) {
  if (!toi.hit || u < toi.lower) return -1;
  if (u > toi.upper) return +1;
  if (toi.lower == toi.upper) return 0;  // u* is the double lower itself
  return u == toi.lower ? -1 : +1;       // lower < u* < upper, adjacent doubles
}
// Exact sign of a* - b*; a miss counts as +infinity (two misses compare equal).
int compare_toi(const ExactToi& a, const ExactToi& b);

// ---------------------------------------------------------------------------
// Linear per-vertex motion x(t) = x0 + t (x1 - x0), t in [0, 1] (the query files).

using ExactPoint = std::array<mpq_class, 3>;

// The optimized linear queries (gauss6/ccd/ccd.h) with exact points and no window:
// index [0] is the position at t = 0, [1] at t = 1.
// Vertex/face: contact when the vertex lies on the closed triangle face[.][0..2].
struct LinearVertexFaceQuery {
  std::array<ExactPoint, 2> vertex;
  std::array<std::array<ExactPoint, 3>, 2> face;
};
// Edge/edge: edge_a[time][endpoint], edge_b[time][endpoint].
struct LinearEdgeEdgeQuery {
  std::array<std::array<ExactPoint, 2>, 2> edge_a, edge_b;
};
ExactToi ccd_linear_vertex_face(const LinearVertexFaceQuery& q);
ExactToi ccd_linear_edge_edge(const LinearEdgeEdgeQuery& q);
// A query of the shared file format (gauss6/io/ccd_queries.h), by its kind.
ExactToi query_toi(const CcdQuery& query);
ExactPoint to_exact(const RationalPoint& p);

// ---------------------------------------------------------------------------
// Cayley rigid motion of a body from X0 = (p0, q0) to X1 = (p1, q1) (world frame).

// Exact data of the motion. The quaternions are kept as integers scaled by
// powers of two, which changes neither R(q0) nor g = v / s.
struct ExactCayleyMotion {
  Pose X0, X1;                    // the input doubles
  std::array<mpz_class, 4> q0;    // (w, x, y, z) of q0, times 2^a
  mpz_class s;                    // scalar part of qr = q1 conj(q0) (times 2^b), s > 0
  std::array<mpz_class, 3> v;     // vector part of qr (times 2^b): g = v / s
};

// Throws std::domain_error when a quaternion is zero, a coordinate is not
// finite, or the relative rotation is exactly a half turn (scalar(qr) == 0: no
// finite Gibbs vector; split the step).
ExactCayleyMotion make_exact_cayley_motion(const Pose& X0, const Pose& X1);

// Exact world position at rational u of the body point r_B: p(u) + C(u g) R(q0) r_B.
ExactPoint motion_point_exact(const ExactCayleyMotion& m, const mpq_class& u, const Vec3& r_B);
// Exact world position under the static pose X (METHOD.md section 1).
ExactPoint transform_point_exact(const Pose& X, const Vec3& r_B);

// The optimized rigid queries (gauss6/ccd/ccd.h), exactly: the body (the god-object)
// moves, the obstacle is static; body features in the body frame (B), obstacle
// features in the world frame (W). Only contacts at u <= u_end are looked for
// (u_end in (0, 1], a double taken exactly; std::invalid_argument otherwise): a
// miss then means no contact in [0, u_end]. The window always starts at u = 0.

// The god-object's vertex moving, the obstacle face static.
struct RigidVertexFaceQuery {
  const ExactCayleyMotion* motion = nullptr;
  Vec3 vertex_B;
  std::array<Vec3, 3> face_W;
  double u_end = 1;
};
// The obstacle's vertex static, the god-object's face moving.
struct RigidFaceVertexQuery {
  const ExactCayleyMotion* motion = nullptr;
  Vec3 vertex_W;
  std::array<Vec3, 3> face_B;
  double u_end = 1;
};
// The god-object's edge moving, the obstacle edge static.
struct RigidEdgeEdgeQuery {
  const ExactCayleyMotion* motion = nullptr;
  std::array<Vec3, 2> edge_B, edge_W;
  double u_end = 1;
};
ExactToi ccd_rigid_vertex_face(const RigidVertexFaceQuery& q);
ExactToi ccd_rigid_face_vertex(const RigidFaceVertexQuery& q);
ExactToi ccd_rigid_edge_edge(const RigidEdgeEdgeQuery& q);

// Degree of the query's coplanarity polynomial after removing the positive
// factors W, -1 when it is identically zero (u_end plays no part; for tests and
// documentation).
int coplanarity_degree(const RigidVertexFaceQuery& q);
int coplanarity_degree(const RigidFaceVertexQuery& q);
int coplanarity_degree(const RigidEdgeEdgeQuery& q);

// ---------------------------------------------------------------------------
// Mesh level: a moving god-object mesh (body frame B) against a static obstacle
// mesh (world frame W). The moving body of the primitives above is the
// god-object: the god side of the shared PairKind and FeaturePair
// (gauss6/geometry/feature_pair.h). Boxes are the shared gauss6::Aabb (gauss6/geometry/aabb.h).

// Bounding-box tree over items (triangles, vertices or edges). Node i has box
// box[i]; an inner node has children child[i] and child[i] + 1; a leaf has
// child[i] = -1 and items item[first[i] .. first[i] + count[i]).
struct AabbTree {
  std::vector<Aabb> box;
  std::vector<int32_t> child, first, count, item;
};

// Everything that depends only on the two meshes, built once.
struct ExactMeshPair {
  TriangleMesh god;                               // god-object, body frame
  TriangleMesh obstacle;                          // static, world frame
  std::vector<std::array<int32_t, 2>> god_edges, obstacle_edges;  // unique, sorted
  AabbTree obstacle_faces, obstacle_vertices, obstacle_edge_tree;  // exact boxes (doubles)
  // God-object faces in groups of kFaceGroup consecutive items of the tree's item
  // order (nearby faces): group g's box holds the boxes of faces item[g * kFaceGroup ..].
  static constexpr int kFaceGroup = 8;
  AabbTree god_faces;                        // body frame, exact boxes
  std::vector<Aabb> god_face_groups;         // body frame
  double god_radius = 0;  // max |r_B| over god-object vertices (rounded up)
};

// Throws std::invalid_argument on an empty mesh or an index out of range.
ExactMeshPair make_exact_mesh_pair(const TriangleMesh& god_B, const TriangleMesh& obstacle_W);
// Unique undirected edges (i < j), sorted.
std::vector<std::array<int32_t, 2>> mesh_edges(const TriangleMesh& m);

struct MeshContact {
  ExactToi toi;                        // first contact over all feature pairs
  std::vector<FeaturePairIds> pairs;   // every pair touching exactly at u* (empty on a miss), in
                                       // canonical ids (gauss6/geometry/feature_ids.h)
  int64_t num_candidate_pairs = 0;     // pairs whose swept boxes overlap
  int64_t num_filtered_pairs = 0;      // of those, ruled out by the interval filter (no exact arithmetic)
  int64_t num_exact_pairs = 0;         // of those, solved exactly (root isolation)
};

// Exact first contact over u in [0, 1] of the Cayley motion X0 -> X1: minimum
// over god vertex/obstacle face, obstacle vertex/god face and edge/edge
// pairs (the kinds of kPairKinds, in its order). Culling is conservative: a
// pair is skipped only when the swept box of the god-object's feature
// (provably containing its whole path) misses the obstacle feature's box.
// Filtered (the default), as CGAL's filtered kernels: each candidate pair's
// coplanarity polynomial is first enclosed in interval arithmetic (Interval_nt)
// and its Bernstein form on [0, 1] checked for a root, the sub-intervals that may
// hold one isolated by subdivision and the contact test evaluated over each in
// intervals; only the pairs this cannot rule out are solved exactly, in order of
// the filter's lower bound on their contact, until that bound passes the best
// contact found. The answer (u*, its touching pairs) is the same exact answer as
// unfiltered (filtered = false: every candidate solved exactly; for tests).
// Throws as make_exact_cayley_motion.
MeshContact mesh_first_contact(const ExactMeshPair& meshes, const Pose& X0, const Pose& X1, bool filtered = true);

// Exact first contact over u in [0, u_max] of one feature pair (any vertices
// of the two meshes: an edge id need not be a mesh edge) under the motion.
// Throws std::invalid_argument when the ids' features do not match the kind
// (kPairKinds) or an index is out of range.
ExactToi feature_pair_first_contact(const ExactMeshPair& meshes, const ExactCayleyMotion& motion,
                                    const FeaturePairIds& pair, double u_max = 1.0);

// Number of (god triangle, obstacle triangle) pairs that intersect (share at
// least a point) with the god-object at pose X, exactly. Pairs are culled on boxes
// that contain the exact posed triangles (groups of god-object faces against a walk
// of the obstacle's face tree), then decided by CGAL's filtered predicate:
// interval arithmetic on enclosures of the exact posed vertices, Gmpq on the exact ones when the intervals
// cannot decide. Throws std::domain_error on a zero quaternion or a non-finite
// coordinate.
int64_t count_intersecting_pairs(const ExactMeshPair& meshes, const Pose& X);

struct ExactSeparation {
  bool within = false;         // some triangle pair is at distance <= max_distance
  mpq_class squared_distance;  // exact minimum squared distance (when within)
  double lower = 0, upper = 0; // bracket of the distance: lower <= d <= upper
  int32_t god_face = -1, obstacle_face = -1;  // a pair achieving it
};
// Exact minimum triangle/triangle distance between the god-object at pose X and the
// obstacle, over pairs whose boxes are within max_distance (>= 0); within ==
// false when every pair is farther than max_distance.
// Same culling; each pair's squared distance is first enclosed in interval
// arithmetic, and only the pairs that can still be the minimum are evaluated
// in Gmpq.
ExactSeparation separation_distance(const ExactMeshPair& meshes, const Pose& X, double max_distance);

// Whether the exact minimum triangle/triangle distance between the god-object at
// pose X and the obstacle is <= max_distance (>= 0, finite), the question of
// property 6, without computing the minimum: separation_bracket's two passes
// (boxes, then each candidate pair's squared distance enclosed in interval
// arithmetic) decide it when an enclosure lies below max_distance^2; only when
// none does are the pairs whose lower bound does not rule them out evaluated in
// Gmpq. Far faster than separation_distance where faces slide parallel at the
// contact distance (its exact pass then visits every such pair).
struct SeparationBound {
  bool within = false;  // the exact minimum distance is <= max_distance
  double upper = 0;     // when within: a certified upper bound of that minimum
  bool exact = false;   // decided with Gmpq (the intervals could not decide)
};
SeparationBound separation_within(const ExactMeshPair& meshes, const Pose& X, double max_distance);

// A certified bracket lower <= d <= upper of the minimum distance d between the god-object at
// pose X and the obstacle, from separation_distance's first two passes only (boxes, then
// interval arithmetic on enclosures of the exact posed vertices; no Gmpq): enough to decide
// d against a threshold outside the bracket, far cheaper than the exact value. When every
// pair is farther than max_distance, lower = max_distance and upper = +infinity (upper is
// also +infinity when no enclosure was finite).
struct SeparationBracket {
  double lower = 0, upper = 0;
};
SeparationBracket separation_bracket(const ExactMeshPair& meshes, const Pose& X, double max_distance);

}  // namespace gauss6::reference
