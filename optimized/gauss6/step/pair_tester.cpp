// The CCD step's pair tester (pair_tester.h): per feature pair of a triangle
// pair, a box filter over the sub-interval, a time bound from the god-object's
// frame at u0, then the rigid narrow-phase query on what is left of the window.
#include "pair_tester.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "gauss6/geometry/distance.h"
#include "gauss6/geometry/feature_pair.h"

namespace gauss6::detail {

namespace {

Vec3 vertex(const TriangleMesh& m, int f, int k) { return m.V.row(m.F(f, k)).transpose(); }

}  // namespace

void PairTester::consider(const CcdResult& r, const FeaturePair& p) {
  ++result->num_pair_tests;
  result->num_box_iterations += r.iterations;
  if (r.status == CcdStatus::kInvalidInput) {
    // The pair test refused its input (a coordinate beyond its bound): nothing
    // is known of this pair, so it is a hit at the window's start, and the step
    // says it was refused (never a miss).
    result->status = CcdStatus::kInvalidInput;
    if (result->hit && result->u_hit <= u0) return;
    result->hit = true;
    result->u_hit = u0;
    result->pair = p;
    result->time_tolerance_reached = 0;
    result->distance_reached = INFINITY;
    return;
  }
  if (!r.hit || (result->hit && r.u_hit >= result->u_hit)) return;
  result->hit = true;
  result->u_hit = r.u_hit;
  result->pair = p;
  result->time_tolerance_reached = r.time_tolerance_reached;
  result->distance_reached = r.distance_reached;
  if (r.status != CcdStatus::kOk) result->status = r.status;  // conservative give-up
}

void PairTester::test(const TriangleMesh& gm, const Bvh& gb, int gf, const TriangleMesh& om, const Bvh& ob, int of,
                      int obstacle) {
  CcdResult r;
  const std::array<Vec3, 3> obs_face = {vertex(om, of, 0), vertex(om, of, 1), vertex(om, of, 2)};
  const std::array<Vec3, 3> god_face = {vertex(gm, gf, 0), vertex(gm, gf, 1), vertex(gm, gf, 2)};
  // Feature-level box filter over the sub-interval (conservative: swept boxes
  // enclose the motion, static boxes are grown by min_separation).
  const double margin = settings->narrow.min_separation;
  const auto box_of = [](const Vec3& a, const Vec3& b) { return Aabb{a.cwiseMin(b), a.cwiseMax(b)}; };
  const Aabb obs_face_box = inflate(triangle_box(om, of), margin);
  // Vertex boxes over the sub-interval (cached per mesh vertex). At each u the
  // motion maps body points affinely, so an edge or the face lies in the hull
  // of its vertices' world points, hence in the hull of their swept boxes.
  Aabb god_swept[3], god_edge_swept[3];
  for (int k = 0; k < 3; ++k)
    god_swept[k] = swept->get(swept->vertices, gm.F(gf, k),
                              [&] { return swept_box(*sub, box_of(god_face[k], god_face[k])); });
  const auto hull_of = [](const Aabb& a, const Aabb& b) { return Aabb{a.lo.cwiseMin(b.lo), a.hi.cwiseMax(b.hi)}; };
  for (int k = 0; k < 3; ++k) god_edge_swept[k] = hull_of(god_swept[k], god_swept[(k + 1) % 3]);
  const Aabb god_face_swept = hull_of(god_edge_swept[0], god_swept[2]);
  // Each feature pair's own time bound (StartFrame::earliest on the features
  // as degenerate triangles, the axis between their closest points at u0
  // tried first): a pair sliding along at its gap, or turning across it,
  // needs no test.
  SweptBoxCache::PosedFace posed;  // the god face at u0 (StartFrame::posed_face), a copy
  const Vec3* const X = posed.side.P;
  const double* const rad = posed.radius;
  bool is_posed = false;
  const auto pose_god_face = [&] {  // once, for the first feature past the box filter
    if (is_posed) return;
    is_posed = true;
    posed = start->posed_face(gm, gf, swept);
  };
  const Vec3* Y = obs_face.data();
  // The bound also starts the feature pair's search: nothing comes within
  // reach before it, so the narrow phase searches [from, end()] only (a
  // contact sliding along at its gap is then searched from where the
  // motion can first close it, not across the whole step).
  double from = u0;
  const auto apart = [&](double earliest) {
    from = std::max(u0, earliest);
    if (from <= end()) return false;
    ++result->num_feature_culls;
    return true;
  };
  // k: the god-object's corner (vertex k, or edge k -> k + 1), j: the
  // obstacle's; -1 for a face. end() only shrinks, so once the window is
  // empty it stays empty for every later feature pair.
  for_each_feature_pair(gb.owned[gf], ob.owned[of], [&](PairKind kind, int k, int j) {
    if (!(u0 <= end())) return false;
    switch (kind) {
      case PairKind::kGodVertexObstacleFace: {
        if (!overlap(god_swept[k], obs_face_box)) return true;
        pose_god_face();
        const Vec3 A[3] = {X[k], X[k], X[k]};
        const Vec3 axis = X[k] - closest_point_on_triangle(X[k], Y[0], Y[1], Y[2]);
        if (apart(start->earliest<Shape::kVertex, Shape::kTriangle>(A, Y, rad[k], reach, end(), &axis))) return true;
        RigidVertexFaceQuery q{motion, god_face[k], obs_face, from, end()};
        ccd_rigid_vertex_face(q, settings->narrow, ws, &r);
        break;
      }
      case PairKind::kObstacleVertexGodFace: {
        if (!overlap(god_face_swept, inflate(box_of(obs_face[j], obs_face[j]), margin))) return true;
        pose_god_face();
        const Vec3 B[3] = {Y[j], Y[j], Y[j]};
        const Vec3 axis = closest_point_on_triangle(Y[j], X[0], X[1], X[2]) - Y[j];
        const double radius = std::max({rad[0], rad[1], rad[2]});
        if (apart(start->earliest<Shape::kTriangle, Shape::kVertex>(X, B, radius, reach, end(), &axis))) return true;
        RigidFaceVertexQuery q{motion, obs_face[j], god_face, from, end()};
        ccd_rigid_face_vertex(q, settings->narrow, ws, &r);
        break;
      }
      case PairKind::kEdgeEdge: {
        const int k1 = (k + 1) % 3, j1 = (j + 1) % 3;
        if (!overlap(god_edge_swept[k], inflate(box_of(obs_face[j], obs_face[j1]), margin))) return true;
        pose_god_face();
        const Vec3 A[3] = {X[k], X[k1], X[k1]}, B[3] = {Y[j], Y[j1], Y[j1]};
        double s = 0, t = 0;
        closest_segment_parameters(X[k], X[k1], Y[j], Y[j1], &s, &t);
        const Vec3 axis = (X[k] + s * (X[k1] - X[k])) - (Y[j] + t * (Y[j1] - Y[j]));
        const double radius = std::max(rad[k], rad[k1]);
        if (apart(start->earliest<Shape::kEdge, Shape::kEdge>(A, B, radius, reach, end(), &axis))) return true;
        RigidEdgeEdgeQuery q{motion, {god_face[k], god_face[k1]}, {obs_face[j], obs_face[j1]}, from, end()};
        ccd_rigid_edge_edge(q, settings->narrow, ws, &r);
        break;
      }
    }
    consider(r, {kind, obstacle, gf, k, of, j});
    return true;
  });
}

}  // namespace gauss6::detail
