// The narrow phase's u-filter (private to the library: not installed):
// necessary conditions for a contact, each a polynomial in u enclosed over a
// u-interval (positive_on, bernstein.h) or a separating axis, and
// filtered_bisect(), which runs the box bisection (bisection.h) only on the
// u-intervals the filter cannot exclude, in increasing u. The conditions of
// the rigid queries (the Cayley cubics) are built here; the linear queries
// (linear_queries.cpp) build theirs and share the filter and filtered_bisect().
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "gauss6/ccd/bisection.h"
#include "gauss6/numeric/bernstein.h"  // the u-filter's positivity tests

namespace gauss6::ccd_detail {

// ---------------------------------------------------------------------------
// Cheap u-filters run before the bisection (rigid trajectories).
//
// Necessary conditions for a contact within distance d at parameter u,
// each enclosed over a u-interval U with outward-rounded interval arithmetic
// from the enclosed motion (so they hold for the exact motion of the input
// doubles):
//
// (1) Coplanarity polynomial. With D(u) = 1 + u^2 s, s = |g|^2, and
//     Dc(u) v = D(u) C(u g) v = v + u (2 g x v) + u^2 (2 (g.v) g - s v), the
//     conditions below are cubics P(u) = k0 + k1 u + k2 u^2 + k3 u^3:
//   - body vertex w = R0 r_B, static face (f0, n = (f1 - f0) x (f2 - f0)):
//       P = D (p(u) - f0).n + (Dc(u) w).n = D times (x(u) - f0).n;
//       the vertex is within d of the face only if |P| <= d |n| D.
//   - static vertex y, body face (f0' = R0 f0_B, n' = R0 n_B):
//       P = (y - p(u)).Dc(u) n' - D f0'.n' = D times (y - x_f0(u)).(C n');
//       |C n'| = |n_B|, so the condition is |P| <= d |n_B| D.
//   - body edge (a0' = R0 a0_B, ea' = R0 ea_B), static edge (b0, eb):
//       det[p(u) + C a0' - b0, C ea', eb] = det[p(u) - b0, C ea', eb]
//       + det[a0', ea', C^T eb] (det[C x, C y, z] = det[x, y, C^T z]) and
//       C^T = C(-u g), so P = D det = det[p(u) - b0, Dc(u) ea', eb]
//       + det[a0', ea', Dc(-u) eb]. The lines' distance is |det| / |C ea' x eb|
//       (a lower bound of the segments' distance), and
//       |C ea' x eb| <= |ea' x eb| + |C ea' - ea'| |eb| <= |ea' x eb| + theta |ea| |eb|
//       with theta = 2 atan(u |g|) <= 2 u |g| (a chord is shorter than its arc):
//       contact within d only if |P| <= d L D, L that bound (parallel edges:
//       P = 0, the condition holds and this filter never rejects them).
//     U is excluded when P - d L D > 0 or -P - d L D > 0 on all of U.
// (2) A separating axis. For any fixed vector n, points x, y within d have
//     |n.x - n.y| <= d |n|. The moving feature's points at u are convex
//     combinations of its corners, so their projections lie within the hull of
//     the corners' projections. A body corner's world point is
//       x(u) = p0 + w + u (dp + 2 g x w) - gamma(u) (g x w) + beta(u) g x (g x w),
//     with alpha = 2u / D = 2u - gamma, gamma = 2 u^3 s / D in [0, 2 u^3 s], and
//     beta = 2 u^2 / D increasing in u: its projection over U is enclosed by
//     c0 + U c1 - Gamma c2 + B c3 (scalar intervals). U is excluded when the
//     moving and static projections lie more than d |n| apart. The axis, any
//     vector, is taken from the features' closest points at the window's start
//     (the direction conservative advancement would use); n = 0 disables it.
//
// (3) Slabs. A triangle lies in each slab (x - f_k).m_k >= 0, m_k = n x
//     (f_k+1 - f_k) its inward edge normal, so a point within d of it has
//     (x - f_k).m_k >= -d |m_k|; times D this is a cubic in u, as in (1) (body
//     vertex: static m_k; static vertex: body m_k turned by C). A segment lies
//     between the planes through its ends normal to it: two segments within d
//     need an end of each within d of the other's slab (for the moving edge,
//     along C ea': again cubics), so both ends beyond the same plane by more
//     than d exclude. (Stage 2: added only when (1) and (2) keep the window.)
// (4) The lines' distance (edge/edge). With N(u) = Dc(u) ea' x eb = D C ea' x eb
//     (quadratic in u) the cubic of (1) is P = (x_a0(u) - b0).N, so the lines
//     are more than d apart exactly where S(u) = P^2 - d^2 |N|^2 > 0, a
//     polynomial of degree 6 with no bound L in it. (1)'s L grows with the turn
//     over the whole window: an edge sliding across another at a gap of
//     d (1 + 1e-5) while the step turns by a degree has |P| <= d L D everywhere,
//     and its endpoints swing across the axis of (2) by a thousand times the
//     gap's margin, so neither excluded any u-interval wider than about 1e-4
//     of the window: 256 of them (the cap), the rest left to the bisection
//     (the slowest queries of the shared sets). S decides such a window
//     whole. (Stage 2, tried last: the cheaper tests decide most intervals.)
//     Every condition reads "g(u) > 0 on all of U excludes U", g a cubic whose
//     interval coefficients enclose the exact ones (S: degree 6); positive_on()
//     bounds g from below over U by its Bernstein coefficients' least values
//     over those intervals (in doubles, with a certified rounding bound).
//
// Guarantee. A u-interval is dropped only when (1), (2) (with the window
// start's axis, or the interval's own: filtered_bisect()), (3) or (4) proves that no
// contact within d occurs in it; the bisection then runs on the remaining
// intervals in increasing u, so its first accepted interval still starts at or
// before u*. Intervals come from a depth-first left-first 1-D subdivision down
// to the time tolerance; past a fixed number of evaluations the rest of the
// window is kept whole (conservative).
// ---------------------------------------------------------------------------

GAUSS6_ALWAYS_INLINE IVec3 mul(const IMat3& R, const IVec3& v) {
  IVec3 out;
  for (int i = 0; i < 3; ++i) out[i] = R[3 * i] * v[0] + R[3 * i + 1] * v[1] + R[3 * i + 2] * v[2];
  return out;
}
GAUSS6_ALWAYS_INLINE Interval dot(const IVec3& a, const IVec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
GAUSS6_ALWAYS_INLINE IVec3 cross(const IVec3& a, const IVec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
GAUSS6_ALWAYS_INLINE IVec3 scale(Interval s, const IVec3& a) { return {s * a[0], s * a[1], s * a[2]}; }

// Coefficients of Dc(u) v = v + u c1 + u^2 c2.
struct CayleyCoefficients { IVec3 c1, c2; };
GAUSS6_ALWAYS_INLINE CayleyCoefficients cayley_coefficients(const CcdMotion& m, const IVec3& v) {
  const IVec3 gxv = cross(m.g, v);
  const Interval gv = dot(m.g, v);
  const IVec3 c2 = scale(2.0 * gv, m.g) - scale(m.g2, v);
  return {2.0 * gxv, c2};
}

// A cubic k0 + k1 u + k2 u^2 + k3 u^3 whose coefficients are intervals that
// enclose the exact ones.
struct Cubic {
  Interval k[4];
};

// A polynomial of degree 6 whose interval coefficients enclose the exact ones.
struct Sextic {
  Interval k[7];
};

// The edge/edge coplanarity cubic of (1) for the body edge from a0W along eaW
// (world-oriented offsets at u = 0; ca: eaW's Cayley coefficients) and the
// static edge from b0 along eb (cb: eb's): P(u) = (x_a0(u) - b0).N(u), with
// N(u) = Dc(u) eaW x eb = D(u) (C eaW x eb) = T0 + u T1 + u^2 T2 normal to both
// lines at u (proofs/LinesDistance.v: edge_edge_normal, edge_edge_cubic).
struct EdgeEdgeCubic {
  Cubic P;
  IVec3 T0, T1, T2;
};
GAUSS6_ALWAYS_INLINE EdgeEdgeCubic edge_edge_cubic(const CcdMotion& m, const IVec3& a0W, const IVec3& eaW,
                                                   const CayleyCoefficients& ca, const IVec3& b0, const IVec3& eb,
                                                   const CayleyCoefficients& cb) {
  EdgeEdgeCubic e;
  e.T0 = cross(eaW, eb);
  e.T1 = cross(ca.c1, eb);
  e.T2 = cross(ca.c2, eb);
  const IVec3 Q = m.p0 - b0, Z = cross(a0W, eaW);
  e.P = Cubic{{dot(Q, e.T0) + dot(Z, eb), (dot(Q, e.T1) + dot(m.dp, e.T0)) - dot(Z, cb.c1),
               (dot(Q, e.T2) + dot(m.dp, e.T1)) + dot(Z, cb.c2), dot(m.dp, e.T2)}};
  return e;
}

// The lines' distance (4): the coefficients of S(u) = P(u)^2 - d^2 |N(u)|^2
// (proofs/LinesDistance.v: lines_sextic). S > 0 at u puts the two lines, and
// so the two edges, more than d apart there (lines_filter_sound).
GAUSS6_ALWAYS_INLINE Sextic lines_sextic(const EdgeEdgeCubic& e, double d) {
  Sextic q6;
  for (int i = 0; i < 4; ++i) {
    q6.k[2 * i] = q6.k[2 * i] + sqr(e.P.k[i]);
    for (int j = i + 1; j < 4; ++j) q6.k[i + j] = q6.k[i + j] + 2.0 * (e.P.k[i] * e.P.k[j]);
  }
  const Interval d2 = sqr(Interval::point(d));
  for (int c = 0; c < 3; ++c) {
    const Interval n[3] = {e.T0[c], e.T1[c], e.T2[c]};
    for (int i = 0; i < 3; ++i) {
      q6.k[2 * i] = q6.k[2 * i] - d2 * sqr(n[i]);
      for (int j = i + 1; j < 3; ++j) q6.k[i + j] = q6.k[i + j] - d2 * (2.0 * (n[i] * n[j]));
    }
  }
  return q6;
}

// D(u) (x(u) - f).m for the body point with world-oriented offset w = R0 r_B
// (cw: its Cayley coefficients), a static point f and a static direction m:
// D (p(u) - f).m + (Dc(u) w).m, with D = 1 + s u^2 and Dc(u) w = w + u c1 + u^2 c2.
// Its parts: the direction's (E = dp.m), the static point's (A = (p0 - f).m)
// and the corner's (w.m, c1.m, c2.m), so that the edge/edge slabs, two
// corners against two points along one direction, form each once.
struct CornerAlong {
  Interval w, c1, c2;
};
GAUSS6_ALWAYS_INLINE CornerAlong corner_along(const IVec3& w, const CayleyCoefficients& cw, const IVec3& dir) {
  return {dot(w, dir), dot(cw.c1, dir), dot(cw.c2, dir)};
}
GAUSS6_ALWAYS_INLINE Cubic body_point_along(const CcdMotion& m, Interval A, Interval E, const CornerAlong& c) {
  return {{A + c.w, E + c.c1, m.g2 * A + c.c2, m.g2 * E}};
}
GAUSS6_ALWAYS_INLINE Cubic body_point_along(const CcdMotion& m, const IVec3& w, const CayleyCoefficients& cw, const IVec3& f,
                       const IVec3& dir) {
  return body_point_along(m, dot(m.p0 - f, dir), dot(m.dp, dir), corner_along(w, cw, dir));
}
// D(u) (y - x_f(u)).(C(u) n') for a static point y and the body point f' = R0 f_B
// with body direction n' = R0 n_B (cn: the Cayley coefficients of n'):
// (y - p(u)).Dc(u) n' - D f'.n' (C is a rotation: (C f').(C n') = f'.n').
// Its parts, as above: the direction's (dp.n', dp.c1, dp.c2), the static
// point's (Y.n', Y.c1, Y.c2, Y = y - p0) and the body point's (F = f'.n').
struct DirectionAlong {
  Interval n, c1, c2;
};
GAUSS6_ALWAYS_INLINE DirectionAlong direction_along(const IVec3& v, const IVec3& nW, const CayleyCoefficients& cn) {
  return {dot(v, nW), dot(v, cn.c1), dot(v, cn.c2)};
}
GAUSS6_ALWAYS_INLINE Cubic static_point_along(const CcdMotion& m, const DirectionAlong& Y, const DirectionAlong& D,
                                              Interval F) {
  return {{Y.n - F, Y.c1 - D.n, (Y.c2 - D.c1) - m.g2 * F, -D.c2}};
}
GAUSS6_ALWAYS_INLINE Cubic static_point_along(const CcdMotion& m, const IVec3& y, const IVec3& fW, const IVec3& nW,
                         const CayleyCoefficients& cn) {
  return static_point_along(m, direction_along(y - m.p0, nW, cn), direction_along(m.dp, nW, cn), dot(fW, nW));
}

// A body corner w = R0 r_B of the moving feature, with the terms of its
// motion that no axis changes: p0 + w, dp + 2 g x w, g x w, g x (g x w).
struct MovingCorner {
  IVec3 at0, gxw, ggw, rate;
  MovingCorner(const CcdMotion& m, const IVec3& w)
      : at0(m.p0 + w), gxw(cross(m.g, w)), ggw(cross(m.g, gxw)), rate(m.dp + 2.0 * gxw) {}
};

// The turn's terms of a body corner's projection over [u0, u1] (see (2)
// above): B, the hull of beta(u) = 2 u^2 / D(u) (increasing in u), and Gamma =
// [0, 2 u1^3 s], which holds gamma(u) = 2 u^3 s / D(u). One entry: the
// separating-axis tests of one u-interval (the filter's axis, then the
// interval's own guide) share them. For one motion: a query's (UFilter::turns).
struct TurnTerms {
  mutable double u0 = -1, u1 = -1;
  mutable Interval B{}, Gamma{};
  void at(const CcdMotion& m, double a, double b) const {
    if (a == u0 && b == u1) return;
    u0 = a;
    u1 = b;
    const Interval s = m.g2;
    const auto beta_at = [&](double v) {
      return div_positive(2.0 * sqr(Interval::point(v)), Interval::point(1) + sqr(Interval::point(v)) * s);
    };
    B = hull(beta_at(a), beta_at(b));
    Gamma = {0, (2.0 * (sqr(Interval::point(b)) * Interval::point(b)) * s).hi};
  }
};

// The separating-axis test (2) for one axis n: the moving feature's corners'
// projection coefficients and the static projection grown by d |n|.
struct SeparatingAxis {
  int num_corners = 0;  // active when > 0
  Interval c0[3], c1[3], c2[3], c3[3];
  Interval static_proj;

  // Adds a body corner (MovingCorner) for the axis n (exact doubles: each
  // product is a double times an interval).
  void add_corner(const MovingCorner& k, const Vec3& n) {
    const int j = num_corners++;
    c0[j] = along(n, k.at0);
    c1[j] = along(n, k.rate);
    c2[j] = along(n, k.gxw);
    c3[j] = along(n, k.ggw);
  }
  void set_static(Interval proj, const IVec3& n, double d) {
    static_proj = widen(proj, d * norm_upper(n));
  }
  // True when the projections are proven apart for every u in [u0, u1].
  bool excludes(const CcdMotion& m, const TurnTerms& turns, double u0, double u1) const {
    if (num_corners == 0) return false;
    const Interval U{u0, u1};
    turns.at(m, u0, u1);
    const Interval &B = turns.B, &Gamma = turns.Gamma;
    Interval proj{};
    for (int j = 0; j < num_corners; ++j) {
      const Interval pj = c0[j] + U * c1[j] - Gamma * c2[j] + B * c3[j];
      proj = j == 0 ? pj : hull(proj, pj);
    }
    return proj.lo > static_proj.hi || proj.hi < static_proj.lo;
  }
};

struct UFilter {
  // Exclusion conditions g(u) > 0, in groups: a group excludes U when each of
  // its members is positive on all of U (a single condition is a group of one).
  static constexpr int kMaxConditions = 12;
  LowerCoefficients<3> cond[kMaxConditions];
  bool joins_previous[kMaxConditions] = {};
  int num_conditions = 0;
  LowerCoefficients<6> lines;  // (4), edge/edge (rigid): S(u) = P^2 - d^2 |N|^2, tried last
  bool has_lines = false;
  SeparatingAxis axis;  // (2), with the axis of the window's start (rigid queries)
  const CcdMotion* motion = nullptr;  // the axis test's motion (rigid queries; null: no axis test)
  TurnTerms turns;                    // its turn's terms, shared with the guides' axis tests
  Interval g2{};  // s = |g|^2 of D(u) = 1 + s u^2 (zero for linear motion: D = 1)

  // Q(u) <= r D(u) is necessary for a contact: exclude where Q - r D > 0.
  void at_most(const Cubic& Q, double r, bool join = false) {
    const Interval R = Interval::point(r);
    add({{Q.k[0] - R, Q.k[1], Q.k[2] - R * g2, Q.k[3]}}, join);
  }
  // Q(u) >= -r D(u) is necessary for a contact: exclude where -(Q + r D) > 0.
  void at_least(const Cubic& Q, double r, bool join = false) {
    const Interval R = Interval::point(r);
    add({{-(Q.k[0] + R), -Q.k[1], -(Q.k[2] + R * g2), -Q.k[3]}}, join);
  }
  void add(const Cubic& c, bool join) {
    if (num_conditions == kMaxConditions) return;  // fewer conditions: still conservative
    joins_previous[num_conditions] = join && num_conditions > 0;
    cond[num_conditions++].set(c.k);
  }
  void set_lines(const Sextic& p) {
    lines.set(p.k);
    has_lines = true;
  }
  void add_corner(const MovingCorner& k, const Vec3& n) { axis.add_corner(k, n); }
  void set_axis_static(Interval proj, const IVec3& n, double d) { axis.set_static(proj, n, d); }

  // The cubics' weights are formed once per u-interval for all the
  // conditions; the sextic's only when it is reached.
  bool excludes(double u0, double u1) const {
    if (num_conditions > 0) {
      const BernsteinBasis<3> basis(u0, u1);
      for (int i = 0; i < num_conditions;) {
        bool all = true;
        int j = i;
        do {
          all = all && positive_on(cond[j], basis);
          ++j;
        } while (j < num_conditions && joins_previous[j]);
        if (all) return true;
        i = j;
      }
    }
    if (motion != nullptr && axis.excludes(*motion, turns, u0, u1)) return true;
    return has_lines && positive_on(lines, BernsteinBasis<6>(u0, u1));
  }
};

// Early-hit test of filtered_bisect() on [u0, u1]: encloses F at u0 and the
// feature parameters (a, b) (a valid feature point), and accepts u_hit = u0 when
// the pair is proven within d + tol there (tol: the bisection's distance
// tolerance). iterations: the work already spent, reported on.
template <class Enclose>
bool accept_point(const Enclose& enclose, double u0, double u1, double a, double b, double d, double tol,
                  int iterations, CcdResult* r) {
  Corners K;
  enclose(Box{{u0, u0}, {a, a}, {b, b}}, &K);
  const double dist = norm_upper(K.c[0]).v;  // >= |F| at (u0, a, b)
  if (!(dist <= d + tol)) return false;
  *r = CcdResult{};
  r->status = CcdStatus::kOk;
  r->hit = true;
  r->u_hit = u0;
  r->time_tolerance_reached = u1 - u0;
  r->distance_reached = dist;
  r->iterations = iterations + 1;
  return true;
}

// Parameters (a, b) of the point of triangle (t0, t1, t2) nearest to c, a point
// on it: t0 + a (t1 - t0) + b (t2 - t0), clamped into the triangle (a, b >= 0,
// a + b <= 1 up to one rounding). Heuristic (any triangle point is valid).
void triangle_parameters(const Vec3& c, const Vec3& t0, const Vec3& t1, const Vec3& t2, double* a, double* b);

// Axis first. The separating axis needs none of the cubics' set-up and often
// clears the whole window alone: when the filter, holding only the axis so far,
// excludes [u_begin, u_end], *r is the no-hit answer filtered_bisect() would give
// and the caller returns at once (the same exclusion, found earlier).
bool axis_clears(const UFilter& filter, double u_begin, double u_end, CcdResult* r);

// Runs the bisection on the u-intervals of [u_begin, u_end] that the filter
// cannot exclude, in increasing u; the first hit ends the search. The filter
// first sees the whole window with its cheap conditions (stage 1); if they do
// not exclude it, add_more() adds the rest (stage 2) and a depth-first,
// left-first subdivision narrows the window to intervals at most
// time_tolerance wide, handed to the bisection in order (adjacent ones merged).
// Past max_evaluations evaluations the rest of the window goes to the
// bisection whole (conservative).
//
// Early hit. When an interval [a, b] at most time_tolerance wide survives the
// filter and everything before a is settled (excluded by the filter or by the
// bisection), probe(a, b) may accept it directly: it encloses F at u = a at the
// features' closest parameters (taken from the nominal pose) and accepts when
// that proves a feature pair within min_separation + distance_tolerance at u = a.
// This is the bisection's own acceptance rule (a pair within the distance
// tolerance, in the earliest interval not excluded), reached without the
// (u, a, b) search: u_hit = a <= u* still holds because every earlier interval
// was proven free of contact, and distance_reached is a proven upper bound of
// the distance at u_hit.
template <class Enclose, class AddMore, class GuideT>
void filtered_bisect(const Enclose& enclose, bool triangle, const Scales& sc, UFilter& filter,
                     const AddMore& add_more, const GuideT& guides, double u_begin, double u_end,
                     const CcdSettings& s, CcdWorkspace* ws, CcdResult* r, int max_evaluations = 256) {
  constexpr int kStack = 64;
  int evaluations = 1, total_iterations = 0;
  // Every return below leaves *r final; the count of u-intervals goes in on the way out.
  struct CountIntervals {
    CcdResult* r;
    const int* n;
    ~CountIntervals() { r->filter_intervals = *n; }
  } count_intervals{r, &evaluations};
  const double tol_d = std::max(s.distance_tolerance, kDistanceToleranceFloor * sc.coordinate);  // as in bisect()
  const auto probe = [&](double u0, double u1, int iterations, CcdResult* res) {
    const Guide g = guides.at(u0);
    return g.valid && accept_point(enclose, u0, u1, g.a, g.b, s.min_separation, tol_d, iterations, res);
  };
  // Rigid queries (those with the axis test): the separating-axis test (2)
  // again with the axis of the interval's own start (the bisection's guide,
  // re-chosen per u-interval as there): a pair
  // sliding past a face's edge or along an edge at a gap just over d has its
  // nearest points turning away from the window start's axis, and neither the
  // plane nor a slab alone proves it apart (its distance is the hypotenuse of
  // the two); without it the subdivision spent its budget on such a pair's
  // tolerance-wide intervals and left the rest of the window to the bisection.
  // (Not the linear queries': their 64-box bisection runs first, and there the
  // extra guide per interval made the unit tests' edge/edge pass 3.5x slower.)
  // An interval that starts at the window's start has that axis already: the
  // filter's own axis test (the same nominal closest points, unnormalised).
  const auto separated_from = [&](double u0, double u1) {
    if (filter.motion == nullptr || (u0 == u_begin && filter.axis.num_corners > 0)) return false;
    Guide g = guides.at(u0);
    return unit_axis(&g) && guides.separated(g.axis, u0, u1);
  };
  *r = CcdResult{};
  const auto no_hit = [&] {
    r->status = CcdStatus::kOk;
    r->hit = false;
    r->u_hit = u_end;
    r->iterations = total_iterations;
  };
  if (filter.excludes(u_begin, u_end)) return no_hit();
  add_more(&filter);
  // Bisection on one interval; true when it ends the search (hit or give-up).
  const auto run = [&](double a, double b) {
    CcdSettings sw = s;
    sw.max_iterations = std::max(1, s.max_iterations - total_iterations);
    bisect(enclose, triangle, sc, a, b, sw, ws, r, guides);
    total_iterations += r->iterations;
    r->iterations = total_iterations;
    return r->hit;
  };
  // Adjacent kept intervals are merged into one pending window before the
  // bisection runs on it, so its search fronts carry across them.
  bool pending = false;
  double w0 = 0, w1 = 0;
  const auto keep = [&](double a, double b) {
    if (pending && a == w1) {
      w1 = b;
      return false;
    }
    if (pending && run(w0, w1)) return true;
    // Everything before a is settled: a may be accepted at once.
    if (s.early_hit && b - a <= s.time_tolerance && probe(a, b, total_iterations, r)) return true;
    pending = true;
    w0 = a;
    w1 = b;
    return false;
  };
  double stack[kStack][2];
  int top = 0;
  stack[top][0] = u_begin;
  stack[top][1] = u_end;
  ++top;
  while (top > 0) {
    --top;
    const double a = stack[top][0], b = stack[top][1];
    if (evaluations >= max_evaluations) {
      // Budget spent: everything still on the stack lies right of a and ends at u_end.
      if (keep(a, u_end)) return;
      break;
    }
    ++evaluations;
    if (filter.excludes(a, b) || separated_from(a, b)) continue;
    const double m = 0.5 * (a + b);
    if (b - a <= s.time_tolerance || !(a < m && m < b) || top + 2 > kStack) {
      if (keep(a, b)) return;
      continue;
    }
    stack[top][0] = m;  // right half below, left half on top
    stack[top][1] = b;
    ++top;
    stack[top][0] = a;
    stack[top][1] = m;
    ++top;
  }
  if (pending && run(w0, w1)) return;
  no_hit();
}

}  // namespace gauss6::ccd_detail
