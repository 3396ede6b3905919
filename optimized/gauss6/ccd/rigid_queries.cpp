// The narrow phase's rigid queries (ccd.h: ccd_rigid_vertex_face,
// ccd_rigid_face_vertex, ccd_rigid_edge_edge): one feature moves with the
// Cayley motion, the other is static. Each encloses F over a box from the
// motion's enclosure and runs the box bisection (bisection.h), behind the
// u-filter with its coplanarity cubic, separating axes and slabs (u_filter.h)
// unless use_u_filter is off.
#include "gauss6/ccd/ccd.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "gauss6/ccd/bisection.h"
#include "gauss6/ccd/u_filter.h"
#include "gauss6/geometry/distance.h"  // closest points: the guides' separating axes

namespace gauss6 {

using namespace ccd_detail;  // the narrow phase's shared machinery (bisection.h, u_filter.h)

// ---------------------------------------------------------------------------
// Rigid trajectories. For fixed u, F is affine in (a, b) (the motion maps body
// points affinely, and the static feature is affine in its parameter), so over a
// box its extremes at that u are at the 4 (a, b) corners; each corner's F over
// the whole u-range is enclosed by the motion enclosure. The hull of the 4
// corner enclosures therefore encloses F over the box.
// ---------------------------------------------------------------------------

namespace {

// Motion enclosure with a one-entry cache: bisection splits a, b far more often
// than u, so consecutive boxes often share their u-range.
struct CachedEnclosure {
  const CcdMotion* motion;
  mutable MotionEnclosure e;
  mutable double u0 = -1, u1 = -1;
  const MotionEnclosure& at(const Box& box) const {
    if (box.u[0] != u0 || box.u[1] != u1) {
      enclose_motion(*motion, {box.u[0], box.u[1]}, &e);
      u0 = box.u[0];
      u1 = box.u[1];
    }
    return e;
  }
};

// Bound on how far F moves over u in [0, 1] for a body feature of radius rho.
double rigid_speed(const CcdMotion& m, double rho) {
  return max_abs(m.nominal.dp) + 2 * m.nominal.g.norm() * rho;
}

// Which side of a rigid vertex/face pair moves with the god-object.
enum class Moving { kVertex, kFace };

// The one vertex/face search under RigidVertexFaceQuery and RigidFaceVertexQuery:
// the moving feature in the body frame (B), the static one in the world frame (W).
struct VertexFacePair {
  const CcdMotion* motion;
  const Vec3& vertex;
  const std::array<Vec3, 3>& face;
  double u_begin, u_end;
};

void rigid_vertex_face(Moving moving, const VertexFacePair& q, const CcdSettings& s, CcdWorkspace* ws,
                       CcdResult* r) {
  const bool vertex_moves = moving == Moving::kVertex;
  bool ok = valid_settings(s) && valid_window(q.u_begin, q.u_end) && ws != nullptr && q.motion != nullptr &&
            bounded_coordinates(q.vertex);
  for (const Vec3& f : q.face) ok = ok && bounded_coordinates(f);
  if (!ok) return refuse(q.u_end, r);
  const CachedEnclosure cache{q.motion, {}, -1, -1};
  const IVec3 f0 = to_interval(q.face[0]);
  const IVec3 e1 = to_interval(q.face[1]) - f0, e2 = to_interval(q.face[2]) - f0;
  const IVec3 v = to_interval(q.vertex);
  Scales sc{0, max_abs(q.face[1] - q.face[0]), max_abs(q.face[2] - q.face[0]), 0};
  const double rho = vertex_moves ? q.vertex.norm()
                                    : std::max({q.face[0].norm(), q.face[1].norm(), q.face[2].norm()});
  sc.u = rigid_speed(*q.motion, rho);
  sc.coordinate = std::max({max_abs(q.vertex), max_abs(q.face[0]), max_abs(q.face[1]), max_abs(q.face[2]),
                            max_abs(q.motion->nominal.p0), max_abs(q.motion->nominal.p0 + q.motion->nominal.dp)});
  auto enclose = [&](const Box& box, Corners* K) {
    const MotionEnclosure& e = cache.at(box);
    // Parameter points whose convex hull holds the part of the box in the
    // triangle (a + b <= 1): the box's corners, its far corner (a1, b1) replaced,
    // when outside, by the points where the line a + b = 1 crosses the edges
    // a = a1 and b = b1, each moved outward along its edge (rounded up from 1 - x).
    // Proof: the box cut by the half-plane is the convex hull of its corners
    // inside it and the line's crossings with its edges; the crossings with
    // a = a0 and b = b0 lie on edges between kept corners, those with a = a1 and
    // b = b1 between a kept corner and a moved point. A box along the
    // hypotenuse thus stops reaching across it, which a feature point near the
    // triangle's edge needs for (iii).
    const double a0 = box.a[0], a1 = box.a[1], b0 = box.b[0], b1 = box.b[1];
    double pa[5] = {a0, a1, a0, a1, a1}, pb[5] = {b0, b0, b1, b1, b1};
    K->n = 4;
    if (a1 + b1 > 1) {
      pb[3] = std::clamp((Upper{1} - Lower{a1}).v, b0, b1);
      pa[4] = std::clamp((Upper{1} - Lower{b1}).v, a0, a1);
      K->n = 5;
    }
    if (vertex_moves) {
      // F = M(u, v) - (f0 + a e1 + b e2)
      const IVec3 mv = enclose_point(e, v) - f0;
      for (int k = 0; k < K->n; ++k) K->c[k] = mv - pa[k] * e1 - pb[k] * e2;
    } else {
      // F = v - M(u, f0 + a e1 + b e2)
      for (int k = 0; k < K->n; ++k) K->c[k] = v - enclose_point(e, f0 + pa[k] * e1 + pb[k] * e2);
    }
  };
  if (!s.use_u_filter) return bisect(enclose, /*triangle=*/true, sc, q.u_begin, q.u_end, s, ws, r);
  // The u-filter (see UFilter). Stage 1: the coplanarity cubic and a separating
  // axis; stage 2: the three edge slabs of the triangle.
  const CcdMotion& m = *q.motion;
  const double d = s.min_separation;
  UFilter filter;
  filter.motion = &m;
  filter.g2 = m.g2;
  const IVec3 corner[3] = {f0, to_interval(q.face[1]), to_interval(q.face[2])};
  const IVec3 n = cross(e1, e2);
  if (vertex_moves) {
    const Vec3 x_begin = motion_point(m.nominal, q.u_begin, q.vertex);  // heuristic only (the axis)
    const IVec3 w = mul(m.R0, v);
    const MovingCorner corner_w(m, w);
    const Vec3 axis = x_begin - closest_point_on_triangle(x_begin, q.face[0], q.face[1], q.face[2]);
    if (axis != Vec3::Zero() && std::isfinite(axis.squaredNorm())) {
      const IVec3 na = to_interval(axis);
      filter.add_corner(corner_w, axis);
      filter.set_axis_static(hull(hull(dot(na, corner[0]), dot(na, corner[1])), dot(na, corner[2])), na, d);
    }
    if (axis_clears(filter, q.u_begin, q.u_end, r)) return;  // before the coplanarity cubic's set-up
    const CayleyCoefficients cw = cayley_coefficients(m, w);
    const Cubic P = body_point_along(m, w, cw, f0, n);
    const double dL = (d * norm_upper(n)).v;
    filter.at_most(P, dL);
    filter.at_least(P, dL);
    // Guide: the face point nearest the vertex's nominal position.
    const auto guide_at = [&](double u) {
      Guide g;
      const Vec3 x = motion_point(m.nominal, u, q.vertex);
      const Vec3 c = closest_point_on_triangle(x, q.face[0], q.face[1], q.face[2]);
      triangle_parameters(c, q.face[0], q.face[1], q.face[2], &g.a, &g.b);
      g.axis = x - c;
      g.valid = true;
      return g;
    };
    const auto separated = [&](const Vec3& axis_u, double u0, double u1) {
      SeparatingAxis sa;
      const IVec3 na = to_interval(axis_u);
      sa.add_corner(corner_w, axis_u);
      sa.set_static(hull(hull(dot(na, corner[0]), dot(na, corner[1])), dot(na, corner[2])), na, d);
      return sa.excludes(m, filter.turns, u0, u1);
    };
    // Edge slabs: m_k = n x (f_k+1 - f_k) points into the triangle; a point
    // within d of it has (x - f_k).m_k >= -d |m_k|.
    filtered_bisect(enclose, /*triangle=*/true, sc, filter, [&](UFilter* f) {
      for (int k = 0; k < 3; ++k) {
        const IVec3 mk = cross(n, corner[(k + 1) % 3] - corner[k]);
        f->at_least(body_point_along(m, w, cw, corner[k], mk), (d * norm_upper(mk)).v);
      }
    }, Guides<decltype(guide_at), decltype(separated)>{guide_at, separated}, q.u_begin, q.u_end, s, ws, r);
    return;
  }
  Vec3 moved[3];
  for (int k = 0; k < 3; ++k) moved[k] = motion_point(m.nominal, q.u_begin, q.face[k]);
  const Vec3 axis = q.vertex - closest_point_on_triangle(q.vertex, moved[0], moved[1], moved[2]);
  const MovingCorner face_corners[3] = {{m, mul(m.R0, corner[0])}, {m, mul(m.R0, corner[1])},
                                        {m, mul(m.R0, corner[2])}};
  if (axis != Vec3::Zero() && std::isfinite(axis.squaredNorm())) {
    const IVec3 na = to_interval(axis);
    for (int k = 0; k < 3; ++k) filter.add_corner(face_corners[k], axis);
    filter.set_axis_static(dot(na, v), na, d);
  }
  if (axis_clears(filter, q.u_begin, q.u_end, r)) return;  // before the coplanarity cubic's set-up
  const IVec3 nW = mul(m.R0, n), f0W = mul(m.R0, f0);
  const CayleyCoefficients cn = cayley_coefficients(m, nW);
  const Cubic P = static_point_along(m, v, f0W, nW, cn);
  const double dL = (d * norm_upper(n)).v;  // |C R0 n| = |n|
  filter.at_most(P, dL);
  filter.at_least(P, dL);
  // Guide: the point of the nominally moved face nearest the vertex.
  const auto guide_at = [&](double u) {
    Guide g;
    Vec3 t[3];
    for (int k = 0; k < 3; ++k) t[k] = motion_point(m.nominal, u, q.face[k]);
    const Vec3 c = closest_point_on_triangle(q.vertex, t[0], t[1], t[2]);
    triangle_parameters(c, t[0], t[1], t[2], &g.a, &g.b);
    g.axis = q.vertex - c;
    g.valid = true;
    return g;
  };
  const auto separated = [&](const Vec3& axis_u, double u0, double u1) {
    SeparatingAxis sa;
    for (int k = 0; k < 3; ++k) sa.add_corner(face_corners[k], axis_u);
    sa.set_static(along(axis_u, v), to_interval(axis_u), d);
    return sa.excludes(m, filter.turns, u0, u1);
  };
  // Edge slabs in the body frame: (y - x_fk(u)).(C m_k') >= -d |m_k|.
  filtered_bisect(enclose, /*triangle=*/true, sc, filter, [&](UFilter* f) {
    for (int k = 0; k < 3; ++k) {
      const IVec3 mk = cross(n, corner[(k + 1) % 3] - corner[k]), mkW = mul(m.R0, mk);
      f->at_least(static_point_along(m, v, mul(m.R0, corner[k]), mkW, cayley_coefficients(m, mkW)),
                  (d * norm_upper(mk)).v);
    }
  }, Guides<decltype(guide_at), decltype(separated)>{guide_at, separated}, q.u_begin, q.u_end, s, ws, r);
}

}  // namespace

void ccd_rigid_vertex_face(const RigidVertexFaceQuery& q, const CcdSettings& s, CcdWorkspace* ws,
                           CcdResult* r) {
  rigid_vertex_face(Moving::kVertex, {q.motion, q.vertex_B, q.face_W, q.u_begin, q.u_end}, s, ws, r);
}

void ccd_rigid_face_vertex(const RigidFaceVertexQuery& q, const CcdSettings& s, CcdWorkspace* ws,
                           CcdResult* r) {
  rigid_vertex_face(Moving::kFace, {q.motion, q.vertex_W, q.face_B, q.u_begin, q.u_end}, s, ws, r);
}

void ccd_rigid_edge_edge(const RigidEdgeEdgeQuery& q, const CcdSettings& s, CcdWorkspace* ws, CcdResult* r) {
  bool ok = valid_settings(s) && valid_window(q.u_begin, q.u_end) && ws != nullptr && q.motion != nullptr;
  for (int k = 0; k < 2; ++k) ok = ok && bounded_coordinates(q.edge_B[k]) && bounded_coordinates(q.edge_W[k]);
  if (!ok) return refuse(q.u_end, r);
  const CachedEnclosure cache{q.motion, {}, -1, -1};
  const IVec3 a0 = to_interval(q.edge_B[0]), ea = to_interval(q.edge_B[1]) - a0;
  const IVec3 b0 = to_interval(q.edge_W[0]), eb = to_interval(q.edge_W[1]) - b0;
  Scales sc{0, max_abs(q.edge_B[1] - q.edge_B[0]), max_abs(q.edge_W[1] - q.edge_W[0]), 0};
  sc.u = rigid_speed(*q.motion, std::max(q.edge_B[0].norm(), q.edge_B[1].norm()));
  sc.coordinate = std::max({max_abs(q.edge_B[0]), max_abs(q.edge_B[1]), max_abs(q.edge_W[0]),
                            max_abs(q.edge_W[1]), max_abs(q.motion->nominal.p0),
                            max_abs(q.motion->nominal.p0 + q.motion->nominal.dp)});
  auto enclose = [&](const Box& box, Corners* K) {
    const MotionEnclosure& e = cache.at(box);
    // F = M(u, a0 + a ea) - (b0 + b eb)
    const IVec3 pa[2] = {enclose_point(e, a0 + box.a[0] * ea), enclose_point(e, a0 + box.a[1] * ea)};
    const IVec3 pb[2] = {b0 + box.b[0] * eb, b0 + box.b[1] * eb};
    K->n = 4;
    K->c[0] = pa[0] - pb[0];
    K->c[1] = pa[0] - pb[1];
    K->c[2] = pa[1] - pb[0];
    K->c[3] = pa[1] - pb[1];
  };
  if (!s.use_u_filter) return bisect(enclose, /*triangle=*/false, sc, q.u_begin, q.u_end, s, ws, r);
  // The u-filter (see UFilter). Stage 1: the coplanarity cubic and a separating
  // axis; stage 2: the four end slabs.
  const CcdMotion& m = *q.motion;
  const double d = s.min_separation;
  UFilter filter;
  filter.motion = &m;
  filter.g2 = m.g2;
  const IVec3 a0W = mul(m.R0, a0), eaW = mul(m.R0, ea);
  const IVec3 a1W = mul(m.R0, a0 + ea);
  const Vec3 A0 = motion_point(m.nominal, q.u_begin, q.edge_B[0]);
  const Vec3 A1 = motion_point(m.nominal, q.u_begin, q.edge_B[1]);
  double sa = 0, tb = 0;
  closest_segment_parameters(A0, A1, q.edge_W[0], q.edge_W[1], &sa, &tb);
  const Vec3 axis = (A0 + sa * (A1 - A0)) - (q.edge_W[0] + tb * (q.edge_W[1] - q.edge_W[0]));
  const MovingCorner ends[2] = {{m, a0W}, {m, a1W}};
  if (axis != Vec3::Zero() && std::isfinite(axis.squaredNorm())) {
    const IVec3 na = to_interval(axis);
    filter.add_corner(ends[0], axis);
    filter.add_corner(ends[1], axis);
    filter.set_axis_static(hull(dot(na, b0), dot(na, b0 + eb)), na, d);
  }
  if (axis_clears(filter, q.u_begin, q.u_end, r)) return;  // before the coplanarity cubic's set-up
  const CayleyCoefficients ca = cayley_coefficients(m, eaW), cb = cayley_coefficients(m, eb);
  const EdgeEdgeCubic ee = edge_edge_cubic(m, a0W, eaW, ca, b0, eb, cb);
  const Cubic& P = ee.P;
  // L >= |C ea' x eb| on the window: |ea' x eb| + 2 u_end |g| |ea| |eb|.
  const Upper g_norm = sqrt(Upper{m.g2.hi});
  const Upper turn = (2 * q.u_end) * g_norm * (norm_upper(ea) * norm_upper(eb));
  const double dL = (d * (norm_upper(ee.T0) + turn)).v;
  filter.at_most(P, dL);
  filter.at_least(P, dL);
  // End slabs. Every point of a segment lies between the planes through its
  // ends normal to it, so segments within d need the other segment to reach
  // within d of that slab: both ends of A beyond b0 (or b1) along eb by more
  // than d |eb| excludes, and both ends of B beyond a0(u) (or a1(u)) along
  // C ea'. Each pair of ends is one group.
  // Guide: the closest points of the nominally moved edge and the static one.
  const auto guide_at = [&](double u) {
    Guide g;
    const Vec3 P0 = motion_point(m.nominal, u, q.edge_B[0]), P1 = motion_point(m.nominal, u, q.edge_B[1]);
    closest_segment_parameters(P0, P1, q.edge_W[0], q.edge_W[1], &g.a, &g.b);
    g.valid = g.a >= 0 && g.a <= 1 && g.b >= 0 && g.b <= 1;  // false for NaN or out of range
    g.axis = (P0 + g.a * (P1 - P0)) - (q.edge_W[0] + g.b * (q.edge_W[1] - q.edge_W[0]));
    return g;
  };
  const IVec3 b1 = b0 + eb;
  const auto separated = [&](const Vec3& axis_u, double u0, double u1) {
    SeparatingAxis sa;
    sa.add_corner(ends[0], axis_u);
    sa.add_corner(ends[1], axis_u);
    sa.set_static(hull(along(axis_u, b0), along(axis_u, b1)), to_interval(axis_u), d);
    return sa.excludes(m, filter.turns, u0, u1);
  };
  filtered_bisect(enclose, /*triangle=*/false, sc, filter, [&](UFilter* f) {
    const CayleyCoefficients c0 = cayley_coefficients(m, a0W), c1 = cayley_coefficients(m, a1W);
    const double rb = (d * norm_upper(eb)).v, ra = (d * norm_upper(ea)).v;
    // Along eb: A's ends (body) against B's ends (static points).
    const Interval E = dot(m.dp, eb), A0 = dot(m.p0 - b0, eb), A1 = dot(m.p0 - b1, eb);
    const CornerAlong k0 = corner_along(a0W, c0, eb), k1 = corner_along(a1W, c1, eb);
    f->at_least(body_point_along(m, A0, E, k0), rb);
    f->at_least(body_point_along(m, A0, E, k1), rb, /*join=*/true);
    f->at_most(body_point_along(m, A1, E, k0), rb);
    f->at_most(body_point_along(m, A1, E, k1), rb, /*join=*/true);
    // Along C ea': B's ends (static points) against A's ends (body points).
    const DirectionAlong D = direction_along(m.dp, eaW, ca), Y0 = direction_along(b0 - m.p0, eaW, ca),
                         Y1 = direction_along(b1 - m.p0, eaW, ca);
    const Interval F0 = dot(a0W, eaW), F1 = dot(a1W, eaW);
    f->at_least(static_point_along(m, Y0, D, F0), ra);
    f->at_least(static_point_along(m, Y1, D, F0), ra, /*join=*/true);
    f->at_most(static_point_along(m, Y0, D, F1), ra);
    f->at_most(static_point_along(m, Y1, D, F1), ra, /*join=*/true);
    f->set_lines(lines_sextic(ee, d));  // the lines' distance (4), tried last
  }, Guides<decltype(guide_at), decltype(separated)>{guide_at, separated}, q.u_begin, q.u_end, s, ws, r);
}

}  // namespace gauss6
