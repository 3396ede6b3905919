// The narrow phase's linear queries (ccd.h: ccd_linear_vertex_face,
// ccd_linear_edge_edge): every point moves on a line. The enclosure of F over
// a box from its corners (make_linear_points, enclose_linear: the rounding
// bound proved in proofs/Allowances.v), and the routing: a short box bisection
// (bisection.h), then the u-filter with its cubics and the guides
// (u_filter.h) where it does not decide.
#include "gauss6/ccd/ccd.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "gauss6/ccd/bisection.h"
#include "gauss6/ccd/u_filter.h"
#include "gauss6/geometry/distance.h"  // closest points: the guides' separating axes
#include "gauss6/numeric/error_allowances.h"

namespace gauss6 {

using namespace ccd_detail;  // the narrow phase's shared machinery (bisection.h, u_filter.h)

// ---------------------------------------------------------------------------
// Linear trajectories. Each coordinate of F is multilinear in (u, a, b): every
// product term has degree <= 1 in each variable (terms u, a, b, ua, ub). A
// multilinear function is affine along each axis, so its extremes over a box are
// at the box's 8 corners; the hull of the corners' enclosures encloses F.
// ---------------------------------------------------------------------------

namespace {

// Four linearly moving points in plain doubles, and a bound on the rounding
// error of any corner value of F computed from them as in the enclosures below:
// kLinearCornerRounding M + kLinearCornerUnderflow, M the largest input
// coordinate (error_allowances.h derives it along this evaluation).
// The multilinear argument above then bounds F over the box by the corners'
// min and max widened by this bound (the widening itself rounded outward).
struct LinearPoints {
  std::array<std::array<double, 3>, 4> x0, dx;
  Upper error;
};
LinearPoints make_linear_points(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end) {
  LinearPoints p;
  double M = 0;
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 3; ++i) {
      p.x0[k][i] = start[k][i];
      p.dx[k][i] = end[k][i] - start[k][i];
      M = std::max({M, std::abs(start[k][i]), std::abs(end[k][i])});
    }
  p.error = kLinearCornerRounding * Upper{M} + Upper{kLinearCornerUnderflow};
  return p;
}

// Encloses F = w + a ea - b eb over a box, where at each u the points are
// p_k = x0_k + u dx_k and w = p_w0 - p_w1, ea = p_a0 - p_a1, eb = p_b0 - p_b1
// (indices into the four points): the corners' min and max widened by
// pts.error. (Negating ea or swapping a difference's order is exact, so the
// error bound above holds for both feature kinds.) Inputs are finite and
// bounded (validated), so no NaN reaches min/max.
struct LinearDifference {
  int w0, w1, a0, a1, b0, b1;
};
void enclose_linear(const LinearPoints& pts, const LinearDifference& ix, const Box& box, Corners* K) {
  IVec3* F = &K->c[0];
  K->n = 1;  // the hull alone (the corners' values are not kept)
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
  for (double u : box.u) {
    for (int i = 0; i < 3; ++i) {
      double p[4];
      for (int k = 0; k < 4; ++k) p[k] = pts.x0[k][i] + u * pts.dx[k][i];
      const double w = p[ix.w0] - p[ix.w1], ea = p[ix.a0] - p[ix.a1], eb = p[ix.b0] - p[ix.b1];
      // The corner values c = (w + a ea) - b eb over the four (a, b) corners,
      // without evaluating all four: rounding is monotone (fl(x + y) never
      // decreases with x or y, fl(x - y) never decreases with x nor increases
      // with y), so the smallest computed c is the one at the a with the
      // smallest computed a ea and the b with the largest computed b eb (and
      // vice versa for the largest): the same values as the corner loop.
      const double pa0 = box.a[0] * ea, pa1 = box.a[1] * ea, pb0 = box.b[0] * eb, pb1 = box.b[1] * eb;
      lo[i] = std::min(lo[i], (w + std::min(pa0, pa1)) - std::max(pb0, pb1));
      hi[i] = std::max(hi[i], (w + std::max(pa0, pa1)) - std::min(pb0, pb1));
    }
  }
  for (int i = 0; i < 3; ++i) (*F)[i] = widen({lo[i], hi[i]}, pts.error);
}

}  // namespace

// ---------------------------------------------------------------------------
// Linear trajectories, the queries a short bisection does not decide: the
// u-filter (a certified isolation of the coplanarity cubic's roots) and the
// guides of the rigid queries, for points moving on lines.
//
// Every point moves on a line, x_k(u) = X_k + u DX_k, so a difference of two
// points is linear in u, d(u) = d0 + u d1, and for three such differences
//   A.(B x C) = A0.N0 + u (A0.N1 + A1.N0) + u^2 (A0.N2 + A1.N1) + u^3 A1.N2,
//   B x C = N0 + u N1 + u^2 N2,
// a cubic whose coefficients are enclosed from the input doubles (outward
// rounded intervals: the exact cubic of the input lies in them).
// (1) Coplanarity. Vertex/face: P = (v - f0).((f1 - f0) x (f2 - f0)) is |n(u)|
//     times the vertex's signed distance from the face's plane; edge/edge:
//     P = (a0 - b0).(ea x eb) is |n(u)| times the lines' signed distance (at
//     most the segments'). A contact within d at u needs |P(u)| <= d |n(u)| <=
//     d Nmax, Nmax = |N0| + |N1| + |N2| >= |n(u)| on [0, 1]. With d = 0 this is
//     P(u) = 0: filtered_bisect()'s 1-D subdivision with positive_on() (P's
//     Bernstein coefficients on each u-interval, rounding bounded) drops every
//     u-interval on which P is proven nonzero and narrows the rest to
//     time_tolerance around P's roots, in increasing u; the bisection then
//     decides each of those narrow intervals. A vertex sliding along a face at a
//     gap, or an edge along a nearly parallel one at a gap, has no root there: it
//     is dropped whole, without a box.
// (2) Slabs along fixed axes (stage 2). For any double vector m, a point within
//     d of a feature projects on m within d |m| of the feature's projection (the
//     hull of its corners'). Vertex/face: with m_k an inward edge normal of the
//     face at the window's middle (nominal doubles: any vector is valid),
//     (v - f_j).m_k < -d |m_k| for the three corners j (linear in u) excludes.
//     Edge/edge: the rigid queries' end slabs, (a_k - b0).eb < -d Emax for both
//     ends k of A (quadratic: eb moves too; Emax >= |eb(u)| on [0, 1]), and the
//     three others alike.
// Guides (the bisection's, see bisect()): the features' nominal closest points
// at u, and separated(n, U): the corners' projections on n relative to a corner
// R of the second feature, (x_k - R).n = (X_k - R0).n + u (DX_k - DR).n, linear
// in u, so enclosed over U by its values at U's ends (a translation common to
// both features does not widen it); apart by more than d |n| excludes U.
//
// Routing. A plain bisection of kLinearBisectionBudget boxes runs first: it
// decides most queries in a few boxes (the median query of the shared data: 3), with the same answers as
// use_u_filter = false. The rest (sliding contacts, nearly parallel edges)
// continue from where it stopped (everything before is settled: no contact)
// with the filter and the guides.
// ---------------------------------------------------------------------------

namespace {

// The first bisection's boxes, and the filter's evaluations after it: a
// subdivision that has not isolated P's roots in 64 evaluations faces a P that
// is nearly zero over a range (features sliding in a common plane), where the
// bisection and the guides, not the cubic, decide.
constexpr int kLinearBisectionBudget = 64, kLinearFilterEvaluations = 64;

enum class LinearFeatures { kVertexFace, kEdgeEdge };

// A difference of two linearly moving points, d(u) = d0 + u d1, enclosed.
struct LinearVector {
  IVec3 d0, d1;
};
LinearVector operator-(const LinearVector& a, const LinearVector& b) { return {a.d0 - b.d0, a.d1 - b.d1}; }

// The cubic A.(B x C) of three linear vectors, and *n_max >= |B x C| on [0, 1].
Cubic triple_product(const LinearVector& A, const LinearVector& B, const LinearVector& C, Upper* n_max) {
  const IVec3 N0 = cross(B.d0, C.d0), N1 = cross(B.d0, C.d1) + cross(B.d1, C.d0), N2 = cross(B.d1, C.d1);
  *n_max = norm_upper(N0) + norm_upper(N1) + norm_upper(N2);
  return {{dot(A.d0, N0), dot(A.d0, N1) + dot(A.d1, N0), dot(A.d0, N2) + dot(A.d1, N1), dot(A.d1, N2)}};
}
// The quadratic A.B of two linear vectors.
Cubic inner_product(const LinearVector& A, const LinearVector& B) {
  return {{dot(A.d0, B.d0), dot(A.d0, B.d1) + dot(A.d1, B.d0), dot(A.d1, B.d1), Interval::point(0)}};
}
// The linear m.A for a double vector m.
Cubic projection(const Vec3& m, const LinearVector& A) {
  return {{along(m, A.d0), along(m, A.d1), Interval::point(0), Interval::point(0)}};
}

// x0, x1: the four points at u = 0 and u = 1, vertex/face (v, f0, f1, f2) or
// edge/edge (a0, a1, b0, b1); enclose: F's enclosure (as for bisect()).
template <class Enclose>
void linear_search(LinearFeatures kind, const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1,
                   const Enclose& enclose, const Scales& sc, double u_begin, double u_end, const CcdSettings& s,
                   CcdWorkspace* ws, CcdResult* r) {
  const bool vf = kind == LinearFeatures::kVertexFace;
  CcdSettings first = s;
  first.max_iterations = std::min(s.max_iterations, kLinearBisectionBudget);
  bisect(enclose, /*triangle=*/vf, sc, u_begin, u_end, first, ws, r);
  if (r->status != CcdStatus::kMaxIterations || s.max_iterations <= kLinearBisectionBudget) return;
  const double from = r->u_hit;  // everything before is settled: no contact
  const int spent = r->iterations;
  // The points relative to R = f0 (vertex/face) or b0 (edge/edge).
  const int ref = vf ? 1 : 2;
  LinearVector P[4];
  for (int k = 0; k < 4; ++k) {
    P[k].d0 = to_interval(x0[k]) - to_interval(x0[ref]);
    P[k].d1 = (to_interval(x1[k]) - to_interval(x0[k])) - (to_interval(x1[ref]) - to_interval(x0[ref]));
  }
  const double d = s.min_separation;
  UFilter filter;  // no motion: D(u) = 1, no axis test
  Upper n_max;
  const Cubic coplanar = vf ? triple_product(P[0], P[2], P[3], &n_max) : triple_product(P[0], P[1] - P[0], P[3], &n_max);
  const double dL = (d * n_max).v;
  filter.at_most(coplanar, dL);
  filter.at_least(coplanar, dL);
  const auto add_more = [&](UFilter* f) {
    if (vf) {
      const double um = 0.5 * (from + u_end);
      Vec3 t[3];
      for (int k = 0; k < 3; ++k) t[k] = x0[k + 1] + um * (x1[k + 1] - x0[k + 1]);
      const Vec3 nm = (t[1] - t[0]).cross(t[2] - t[0]);
      for (int k = 0; k < 3; ++k) {
        const Vec3 m = nm.cross(t[(k + 1) % 3] - t[k]);
        const double rm = (d * norm_upper(to_interval(m))).v;
        for (int j = 0; j < 3; ++j) f->at_least(projection(m, P[0] - P[j + 1]), rm, /*join=*/j > 0);
      }
      return;
    }
    const LinearVector ea = P[1] - P[0], eb = P[3];
    const double rb = (d * (norm_upper(eb.d0) + norm_upper(eb.d1))).v;
    const double ra = (d * (norm_upper(ea.d0) + norm_upper(ea.d1))).v;
    for (int k = 0; k < 2; ++k) f->at_least(inner_product(P[k], eb), rb, /*join=*/k > 0);
    for (int k = 0; k < 2; ++k) f->at_most(inner_product(P[k] - P[3], eb), rb, /*join=*/k > 0);
    for (int k = 0; k < 2; ++k) f->at_least(inner_product(P[2 + k] - P[0], ea), ra, /*join=*/k > 0);
    for (int k = 0; k < 2; ++k) f->at_most(inner_product(P[2 + k] - P[1], ea), ra, /*join=*/k > 0);
  };
  const auto at = [&](double u) {
    Guide g;
    Vec3 X[4];
    for (int k = 0; k < 4; ++k) X[k] = x0[k] + u * (x1[k] - x0[k]);
    if (vf) {
      const Vec3 c = closest_point_on_triangle(X[0], X[1], X[2], X[3]);
      triangle_parameters(c, X[1], X[2], X[3], &g.a, &g.b);
      g.axis = X[0] - c;
      g.valid = true;
    } else {
      closest_segment_parameters(X[0], X[1], X[2], X[3], &g.a, &g.b);
      g.valid = g.a >= 0 && g.a <= 1 && g.b >= 0 && g.b <= 1;  // false for NaN or out of range
      g.axis = (X[0] + g.a * (X[1] - X[0])) - (X[2] + g.b * (X[3] - X[2]));
    }
    return g;
  };
  const auto separated = [&](const Vec3& n, double u0, double u1) {
    const Interval U{u0, u1};
    const auto proj = [&](int k) { return along(n, P[k].d0) + U * along(n, P[k].d1); };
    const int split = vf ? 1 : 2;  // the first feature's corners: [0, split), the second's: [split, 4)
    Interval first_hull = proj(0), second_hull = proj(split);
    for (int k = 1; k < split; ++k) first_hull = hull(first_hull, proj(k));
    for (int k = split + 1; k < 4; ++k) second_hull = hull(second_hull, proj(k));
    const Interval grown = widen(second_hull, d * norm_upper(to_interval(n)));
    return first_hull.lo > grown.hi || first_hull.hi < grown.lo;
  };
  CcdSettings rest = s;
  rest.max_iterations = s.max_iterations - spent;
  filtered_bisect(enclose, /*triangle=*/vf, sc, filter, add_more, Guides<decltype(at), decltype(separated)>{at, separated},
                  from, u_end, rest, ws, r, kLinearFilterEvaluations);
  r->iterations += spent;
}

}  // namespace

void ccd_linear_vertex_face(const LinearVertexFaceQuery& q, const CcdSettings& s, CcdWorkspace* ws,
                            CcdResult* r) {
  bool ok = valid_settings(s) && valid_window(q.u_begin, q.u_end) && ws != nullptr;
  for (int t = 0; t < 2; ++t) {
    ok = ok && bounded_coordinates(q.vertex[t]);
    for (int k = 0; k < 3; ++k) ok = ok && bounded_coordinates(q.face[t][k]);
  }
  if (!ok) return refuse(q.u_end, r);
  // Heuristic scales: motion, edge lengths, coordinates.
  Scales sc{0, 0, 0, 0};
  double move_v = max_abs(q.vertex[1] - q.vertex[0]), move_f = 0, len_a = 0, len_b = 0;
  for (int k = 0; k < 3; ++k) {
    move_f = std::max(move_f, max_abs(q.face[1][k] - q.face[0][k]));
  }
  for (int t = 0; t < 2; ++t) {
    len_a = std::max(len_a, max_abs(q.face[t][1] - q.face[t][0]));
    len_b = std::max(len_b, max_abs(q.face[t][2] - q.face[t][0]));
    sc.coordinate = std::max(sc.coordinate, max_abs(q.vertex[t]));
    for (int k = 0; k < 3; ++k) sc.coordinate = std::max(sc.coordinate, max_abs(q.face[t][k]));
  }
  sc.u = move_v + move_f;
  sc.a = len_a;
  sc.b = len_b;
  // Corner values in plain doubles (points: vertex, f0, f1, f2), widened by
  // the static error bound of make_linear_points().
  const LinearPoints pts = make_linear_points({q.vertex[0], q.face[0][0], q.face[0][1], q.face[0][2]},
                                              {q.vertex[1], q.face[1][0], q.face[1][1], q.face[1][2]});
  // F = (v - f0) - a (f1 - f0) - b (f2 - f0): w = p0 - p1, ea = p1 - p2, eb = p3 - p1.
  auto enclose = [&](const Box& box, Corners* K) { enclose_linear(pts, {0, 1, 1, 2, 3, 1}, box, K); };
  if (!s.use_u_filter) return bisect(enclose, /*triangle=*/true, sc, q.u_begin, q.u_end, s, ws, r);
  const std::array<Vec3, 4> x0 = {q.vertex[0], q.face[0][0], q.face[0][1], q.face[0][2]};
  const std::array<Vec3, 4> x1 = {q.vertex[1], q.face[1][0], q.face[1][1], q.face[1][2]};
  linear_search(LinearFeatures::kVertexFace, x0, x1, enclose, sc, q.u_begin, q.u_end, s, ws, r);
}

void ccd_linear_edge_edge(const LinearEdgeEdgeQuery& q, const CcdSettings& s, CcdWorkspace* ws,
                          CcdResult* r) {
  bool ok = valid_settings(s) && valid_window(q.u_begin, q.u_end) && ws != nullptr;
  for (int t = 0; t < 2; ++t)
    for (int k = 0; k < 2; ++k) ok = ok && bounded_coordinates(q.edge_a[t][k]) && bounded_coordinates(q.edge_b[t][k]);
  if (!ok) return refuse(q.u_end, r);
  Scales sc{0, 0, 0, 0};
  double move_a = 0, move_b = 0;
  for (int k = 0; k < 2; ++k) {
    move_a = std::max(move_a, max_abs(q.edge_a[1][k] - q.edge_a[0][k]));
    move_b = std::max(move_b, max_abs(q.edge_b[1][k] - q.edge_b[0][k]));
  }
  for (int t = 0; t < 2; ++t) {
    sc.a = std::max(sc.a, max_abs(q.edge_a[t][1] - q.edge_a[t][0]));
    sc.b = std::max(sc.b, max_abs(q.edge_b[t][1] - q.edge_b[t][0]));
    for (int k = 0; k < 2; ++k)
      sc.coordinate = std::max({sc.coordinate, max_abs(q.edge_a[t][k]), max_abs(q.edge_b[t][k])});
  }
  sc.u = move_a + move_b;
  const LinearPoints pts = make_linear_points({q.edge_a[0][0], q.edge_a[0][1], q.edge_b[0][0], q.edge_b[0][1]},
                                              {q.edge_a[1][0], q.edge_a[1][1], q.edge_b[1][0], q.edge_b[1][1]});
  // F = (a0 - b0) + a (a1 - a0) - b (b1 - b0): w = p0 - p2, ea = p1 - p0, eb = p3 - p2.
  auto enclose = [&](const Box& box, Corners* K) { enclose_linear(pts, {0, 2, 1, 0, 3, 2}, box, K); };
  if (!s.use_u_filter) return bisect(enclose, /*triangle=*/false, sc, q.u_begin, q.u_end, s, ws, r);
  const std::array<Vec3, 4> x0 = {q.edge_a[0][0], q.edge_a[0][1], q.edge_b[0][0], q.edge_b[0][1]};
  const std::array<Vec3, 4> x1 = {q.edge_a[1][0], q.edge_a[1][1], q.edge_b[1][0], q.edge_b[1][1]};
  linear_search(LinearFeatures::kEdgeEdge, x0, x1, enclose, sc, q.u_begin, q.u_end, s, ws, r);
}

}  // namespace gauss6
