// Conservative narrow-phase CCD (vertex/face, edge/edge) over linear and Cayley
// rigid trajectories: interval enclosures of the feature difference F(u, a, b)
// and a bisection that visits boxes in increasing u. See ccd.h for the
// guarantee and the rounding argument.
#include "gauss6/ccd/ccd.h"

#include <array>
#include <cmath>
#include <limits>

#include "gauss6/numeric/bernstein.h"  // the u-filter's positivity tests
#include "gauss6/geometry/distance.h"  // closest points: the separating axes of the u-filter
#include "gauss6/numeric/error_allowances.h"

namespace gauss6 {

const char* to_string(CcdStatus s) {
  switch (s) {
    case CcdStatus::kOk: return "ok";
    case CcdStatus::kMaxIterations: return "max_iterations: gave up, hit reported conservatively";
    case CcdStatus::kWorkspaceFull: return "workspace_full: box queue full, hit reported conservatively";
    case CcdStatus::kInvalidInput: return "invalid_input: non-finite or huge coordinate, or bad window/settings";
    case CcdStatus::kHalfTurn: return "half_turn: relative rotation near 180 degrees, split the step";
  }
  return "unknown";
}

CcdWorkspace::CcdWorkspace(int capacity) : boxes_(static_cast<size_t>(std::max(capacity, 16))) {}

namespace {

using Box = CcdWorkspace::Box;

bool valid_window(double u0, double u1) { return 0 <= u0 && u0 <= u1 && u1 <= 1; }
bool valid_settings(const CcdSettings& s) {
  return s.time_tolerance > 0 && s.distance_tolerance > 0 && s.min_separation >= 0 &&
         std::isfinite(s.min_separation) && std::isfinite(s.distance_tolerance) && s.max_iterations > 0;
}


// Heuristic weights of the three box dimensions: how much F can change across
// the full range of each (scene units). They steer the splitting only.
struct Scales { double u, a, b, coordinate; };

// The bisection: an outer depth-first search over u-intervals, left half first,
// so u-intervals are settled in increasing u; for each u-interval U an inner
// depth-first search over the feature parameters decides whether U may hold a
// contact. The inner search of U starts from the parameter boxes its parent
// interval could not exclude (its "front"), not from the whole domain: a box
// excluded over a u-interval is excluded over every part of it.
//
// Proof of the guarantee. Let (u*, a*, b*) be a first contact (|F|_2 <= d with
// d = min_separation). A parameter box P is dropped by an inner search only if
// (i) the enclosure of F over U x P proves |F|_2 > d on all of U x P (and so on
// every sub-interval of U): see excludes() (vertex/face, rigid: over U x (P cut
// by the triangle), the only part of P that can hold a contact), or
// (ii) (vertex/face) a_lo + b_lo > 1 in floating point, which implies the exact
// sum exceeds 1 (1 is a double and rounding is monotone): P lies outside the
// triangle, or
// (iii) the projections of F on an axis n (any nonzero vector of doubles) lie
// beyond d |n| on one side: |F|_2 >= |n.F| / |n| > d. For fixed u, F is affine
// in the feature parameters, so n.F over P lies between its values at P's
// corners (vertex/face, rigid: at the points whose hull holds P cut by the
// triangle, see rigid_vertex_face()), and each corner's value over U lies
// in n . (the corner's enclosure): the hull of those scalar intervals encloses
// n.F on U x P. (The
// axis-aligned hull of F loses up to a factor sqrt(3) on a diagonal n: a pair
// 1.1 d apart along (1, 1, 1) is never excluded by (i), whatever the split.)
// Splits share the double midpoint, so children cover their parent
// exactly, and a front passed to the halves of U is every box of U's search not
// dropped. Hence a u-interval is dropped only when it holds no contact. The
// outer search visits u-intervals in increasing order and stops at the first
// one it accepts (or gives up at), so the interval holding u* is never passed:
// u_hit = U.lo <= u*.
//
// Guide (rigid queries). The axis of (iii) is re-chosen for each u-interval U:
// the difference of the features' nominal closest points at U.lo (the
// direction conservative advancement would use; it separates the two convex
// features at U.lo, and stays separating over a U short enough). Before its
// inner search, U is dropped whole when the u-filter's separating-axis test
// (UFilter, (2)) with this axis proves the features' projections more than
// d |n| apart over U: the same test as (iii) for all parameters at once, with
// the motion projected on n before it is enclosed over U, so a motion sliding
// across n does not widen it (a corner's box over U would). With
// early_hit, the outer search also accepts U.lo at once when F at U.lo and
// those closest parameters is proven within d + distance_tolerance (the
// acceptance rule of filtered_bisect()'s early hit): everything before U.lo is
// settled, so u_hit = U.lo <= u* still holds (reported with
// time_tolerance_reached = 0: the distance bound holds at u_hit itself).
//
// Accuracy. A u-interval is accepted when it is at most time_tolerance wide and
// the inner search found a parameter box on which F is not excluded and cannot
// usefully be refined (its parameter widths move F by less than the u-width
// does, or by less than distance_tolerance). Every point of that box satisfies
// |F|_inf <= max |F's bounds|, reported as distance_reached (Euclidean, at
// u = u_hit and the box's corner (a_lo, b_lo), a valid feature point).
//
// Memory: the workspace array is a stack of blocks, one per pending u-interval
// (LIFO, as the outer search is depth-first): a header box (u: the interval;
// b[0]: the index of the header below) followed by the interval's front.
// True when the enclosure F proves |F|_2 > d on its whole box: either one
// coordinate misses [-d, d] (then |F|_2 >= |F|_inf > d), or the sum of the
// squared distances of the intervals from 0, rounded down, exceeds d^2 rounded
// up. False for NaN bounds (every comparison with NaN is false).
inline bool excludes(const IVec3& F, double d) {
  Lower sum{0};
  for (const Interval& c : F) {
    if (c.lo > d || c.hi < -d) return true;
    const double m = c.lo > 0 ? c.lo : (c.hi < 0 ? -c.hi : 0.0);  // distance of [lo, hi] from 0
    sum = sum + sqr(Lower{m});
  }
  return sum > sqr(Upper{d});
}

// n . x for a double vector n and an interval vector x, outward rounded.
GAUSS6_ALWAYS_INLINE Interval along(const Vec3& n, const IVec3& x) {
  return n[0] * x[0] + n[1] * x[1] + n[2] * x[2];
}

// Enclosures of F at the corners of a parameter box (up to 5: see
// rigid_vertex_face()), each over the box's whole u-range; F over the box
// lies in their hull (see bisect()).
struct Corners {
  IVec3 c[5];
  int n = 0;
  IVec3 hull() const {
    IVec3 h = c[0];
    for (int k = 1; k < n; ++k)
      for (int i = 0; i < 3; ++i) h[i] = {std::min(h[i].lo, c[k][i].lo), std::max(h[i].hi, c[k][i].hi)};
    return h;
  }
};

// The features' nominal closest points at some u (heuristic, from the double
// motion): the axis F points along there (zero when unknown) and the feature
// parameters (a, b) of the pair (valid feature points).
struct Guide {
  bool valid = false;
  Vec3 axis = Vec3::Zero();
  double a = 0, b = 0;
};
// A query's guides: at(u), the nominal closest pair at u, and separated(n, u0,
// u1), true when the projections of the two features on the axis n are proven
// more than d |n| apart for every u in [u0, u1] (the u-filter's separating-axis
// test, with this axis).
template <class At, class Separated>
struct Guides {
  At at;
  Separated separated;
};
struct NoGuide {
  Guide at(double) const { return {}; }
  bool separated(const Vec3&, double, double) const { return false; }
};

// Exclusion (iii) of bisect(): true when every corner's projection on the axis
// lies beyond `reach` = d |axis| (rounded up) on the same side.
GAUSS6_ALWAYS_INLINE bool axis_excludes(const Corners& K, const Vec3& axis, double reach) {
  Interval p = along(axis, K.c[0]);
  for (int k = 1; k < K.n; ++k) p = hull(p, along(axis, K.c[k]));
  return p.lo > reach || p.hi < -reach;
}

// Scales a guide's axis to unit length (any nonzero vector is valid; unit
// length keeps d |axis| ~ d); false when the guide has no usable axis.
inline bool unit_axis(Guide* g) {
  const double n = g->axis.norm();
  if (!(g->valid && n > 0 && std::isfinite(n))) return false;
  g->axis /= n;
  return true;
}

template <class Enclose, class GuideT = NoGuide>
void bisect(const Enclose& enclose, bool triangle, const Scales& sc, double u_begin, double u_end,
            const CcdSettings& s, CcdWorkspace* ws, CcdResult* r, const GuideT& guides = NoGuide{}) {
  const double d = s.min_separation;
  // Rounding noise makes F's enclosure a few ulps of the coordinates wide: a
  // distance tolerance below that could never be met.
  const double tol_d = std::max(s.distance_tolerance, kDistanceToleranceFloor * sc.coordinate);
  const int capacity = ws->capacity();
  Box* arena = ws->data();
  *r = CcdResult{};
  r->u_hit = u_end;
  const auto give_up = [&](CcdStatus status, double u0, double u1) {
    // Everything before u0 is settled (no contact): stop at u0.
    r->status = status;
    r->hit = true;
    r->u_hit = u0;
    r->time_tolerance_reached = u1 - u0;
    r->distance_reached = std::numeric_limits<double>::infinity();
  };
  int top = 0;
  arena[top++] = Box{{u_begin, u_end}, {0, 0}, {0, 0}};
  arena[top++] = Box{{u_begin, u_end}, {0, 1}, {0, 1}};
  int header = 0;
  // The guide of the current u-interval's start (recomputed when U.lo changes:
  // a left half keeps its parent's start, hence its guide and probe outcome).
  Guide guide;
  double guide_u = std::numeric_limits<double>::quiet_NaN();
  double reach = 0;  // d |axis|, rounded up
  Corners K;
  while (top > 0) {
    // Pop the interval on top: its header and front are arena[header .. top).
    const double u0 = arena[header].u[0], u1 = arena[header].u[1];
    const int front_begin = header + 1;
    const int saved_header_link = static_cast<int>(arena[header].b[0]);  // previous block's header
    const double wu = u1 - u0;
    if (!(u0 == guide_u)) {
      guide_u = u0;
      guide = guides.at(u0);
      if (unit_axis(&guide)) {
        reach = (d * norm_upper(to_interval(guide.axis))).v;
        if (s.early_hit) {
          // Everything before u0 is settled: accept u0 when a pair there is proven within d + tol_d.
          enclose(Box{{u0, u0}, {guide.a, guide.a}, {guide.b, guide.b}}, &K);
          const double dist = norm_upper(K.c[0]).v;
          if (dist <= d + tol_d) {
            ++r->iterations;
            r->status = CcdStatus::kOk;
            r->hit = true;
            r->u_hit = u0;
            r->time_tolerance_reached = 0;
            r->distance_reached = dist;
            return;
          }
        }
      } else {
        guide.axis = Vec3::Zero();
      }
    }
    const bool use_axis = guide.axis != Vec3::Zero();
    if (use_axis && guides.separated(guide.axis, u0, u1)) {
      // (iii) for the whole features at once, the u-dependence projected first
      // (no wrapping of a sliding motion into the axis): no contact in U.
      ++r->iterations;
      top = header;
      header = saved_header_link;
      continue;
    }
    // Parameter refinement pays only while it shrinks F more than the u-width
    // blurs it: measure that blur on one parameter point.
    enclose(Box{{u0, u1}, {0, 0}, {0, 0}}, &K);
    const IVec3 F_point = K.c[0];
    double blur = 0;
    for (const Interval& c : F_point) blur = std::max(blur, c.hi - c.lo);
    if (!(blur < std::numeric_limits<double>::infinity())) blur = wu * sc.u;  // NaN or inf: fall back
    const double enough = std::max({tol_d, wu * sc.u, blur});
    // Inner search: the front is the initial stack, at arena[front_begin .. top).
    bool maybe = false;
    Box found{};
    IVec3 F_maybe{};
    while (top > front_begin) {
      if (r->iterations >= s.max_iterations) return give_up(CcdStatus::kMaxIterations, u0, u1);
      Box P = arena[--top];
      P.u[0] = u0;
      P.u[1] = u1;
      ++r->iterations;
      if (triangle && P.a[0] + P.b[0] > 1) continue;  // (ii)
      enclose(P, &K);
      const IVec3 F = K.hull();
      if (excludes(F, d)) continue;                               // (i)
      if (use_axis && axis_excludes(K, guide.axis, reach)) continue;  // (iii)
      const double wa = P.a[1] - P.a[0], wb = P.b[1] - P.b[0];
      const double ma = 0.5 * (P.a[0] + P.a[1]), mb = 0.5 * (P.b[0] + P.b[1]);
      // A dimension whose midpoint equals an end cannot be split (one float wide).
      const bool can_a = P.a[0] < ma && ma < P.a[1], can_b = P.b[0] < mb && mb < P.b[1];
      if ((!can_a && !can_b) || wa * sc.a + wb * sc.b <= enough) {
        maybe = true;
        found = P;
        F_maybe = F;
        break;
      }
      if (top + 2 > capacity) return give_up(CcdStatus::kWorkspaceFull, u0, u1);
      Box lo = P, hi = P;
      if (can_a && (!can_b || wa * sc.a >= wb * sc.b)) {
        lo.a[1] = ma;
        hi.a[0] = ma;
      } else {
        lo.b[1] = mb;
        hi.b[0] = mb;
      }
      arena[top++] = hi;
      arena[top++] = lo;
    }
    const double mu = 0.5 * (u0 + u1);
    if (maybe && (wu <= s.time_tolerance || !(u0 < mu && mu < u1))) {
      // Accepted: the earliest u-interval that may hold a contact.
      r->hit = true;
      r->u_hit = u0;
      r->time_tolerance_reached = wu;
      r->distance_reached = norm_upper(F_maybe).v;
      return;
    }
    if (!maybe) {
      // No contact in U: drop its block; the previous block is on top.
      top = header;
      header = saved_header_link;
      continue;
    }
    // Split U. The new front = the found box + the boxes left on the stack
    // (arena[front_begin .. top)); both halves get a copy: right below, left on top.
    arena[top++] = found;
    const int n_front = top - front_begin;
    if (top + 1 + n_front > capacity) return give_up(CcdStatus::kWorkspaceFull, u0, u1);
    // Reuse the current block for the right half.
    arena[header].u[0] = mu;
    // The left half's block: header then a copy of the front.
    const int left_header = top;
    arena[top++] = Box{{u0, mu}, {0, 0}, {static_cast<double>(header), 0}};
    for (int i = 0; i < n_front; ++i) arena[top++] = arena[front_begin + i];
    header = left_header;
  }
  // Every u-interval dropped: no contact in the window.
  r->hit = false;
  r->u_hit = u_end;
}

void refuse(double u_end, CcdResult* r) {
  *r = CcdResult{};
  r->status = CcdStatus::kInvalidInput;
  r->hit = false;
  r->u_hit = u_end;
}


double max_abs(const Vec3& v) { return v.cwiseAbs().maxCoeff(); }

}  // namespace

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
void triangle_parameters(const Vec3& c, const Vec3& t0, const Vec3& t1, const Vec3& t2, double* a, double* b) {
  const Vec3 e1 = t1 - t0, e2 = t2 - t0, w = c - t0;
  const double d11 = e1.dot(e1), d12 = e1.dot(e2), d22 = e2.dot(e2), w1 = w.dot(e1), w2 = w.dot(e2);
  const double det = d11 * d22 - d12 * d12;
  double x = 0, y = 0;
  if (det > 0 && std::isfinite(det)) {
    x = (w1 * d22 - w2 * d12) / det;
    y = (w2 * d11 - w1 * d12) / det;
  }
  x = std::isfinite(x) ? std::clamp(x, 0.0, 1.0) : 0.0;
  y = std::isfinite(y) ? std::clamp(y, 0.0, 1.0 - x) : 0.0;
  *a = x;
  *b = y;
}

// Axis first. The separating axis needs none of the cubics' set-up and often
// clears the whole window alone: when the filter, holding only the axis so far,
// excludes [u_begin, u_end], *r is the no-hit answer filtered_bisect() would give
// and the caller returns at once (the same exclusion, found earlier).
bool axis_clears(const UFilter& filter, double u_begin, double u_end, CcdResult* r) {
  if (filter.axis.num_corners == 0 || !filter.excludes(u_begin, u_end)) return false;
  *r = CcdResult{};
  r->status = CcdStatus::kOk;
  r->hit = false;
  r->u_hit = u_end;
  r->filter_intervals = 1;  // the whole window, once
  return true;
}

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
  const IVec3 a0W = mul(m.R0, a0), eaW = mul(m.R0, ea), Q = m.p0 - b0;
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
  const IVec3 T0 = cross(eaW, eb), T1 = cross(ca.c1, eb), T2 = cross(ca.c2, eb), Z = cross(a0W, eaW);
  const Cubic P{{dot(Q, T0) + dot(Z, eb), (dot(Q, T1) + dot(m.dp, T0)) - dot(Z, cb.c1),
                 (dot(Q, T2) + dot(m.dp, T1)) + dot(Z, cb.c2), dot(m.dp, T2)}};
  // L >= |C ea' x eb| on the window: |ea' x eb| + 2 u_end |g| |ea| |eb|.
  const Upper g_norm = sqrt(Upper{m.g2.hi});
  const Upper turn = (2 * q.u_end) * g_norm * (norm_upper(ea) * norm_upper(eb));
  const double dL = (d * (norm_upper(T0) + turn)).v;
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
    // The lines' distance (4): S = P^2 - d^2 |N|^2, N = T0 + u T1 + u^2 T2.
    {
      Sextic q6;
      for (int i = 0; i < 4; ++i) {
        q6.k[2 * i] = q6.k[2 * i] + sqr(P.k[i]);
        for (int j = i + 1; j < 4; ++j) q6.k[i + j] = q6.k[i + j] + 2.0 * (P.k[i] * P.k[j]);
      }
      const Interval d2 = sqr(Interval::point(d));
      for (int c = 0; c < 3; ++c) {
        const Interval n[3] = {T0[c], T1[c], T2[c]};
        for (int i = 0; i < 3; ++i) {
          q6.k[2 * i] = q6.k[2 * i] - d2 * sqr(n[i]);
          for (int j = i + 1; j < 3; ++j) q6.k[i + j] = q6.k[i + j] - d2 * (2.0 * (n[i] * n[j]));
        }
      }
      f->set_lines(q6);
    }
  }, Guides<decltype(guide_at), decltype(separated)>{guide_at, separated}, q.u_begin, q.u_end, s, ws, r);
}

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
