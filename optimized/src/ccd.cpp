// Conservative narrow-phase CCD (vertex/face, edge/edge) over linear and Cayley
// rigid trajectories: interval enclosures of the feature difference F(u, a, b)
// and a bisection that visits boxes in increasing u. See ccd.h for the
// guarantee and the rounding argument.
#include "gauss6/ccd.h"

#include <cmath>

#include "gauss6/contacts.h"  // closest points: the separating axes of the u-filter

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

// Coordinates beyond this are refused: with degree <= 6 products of inputs and
// of the Gibbs vector (|g| <= 12), no intermediate can overflow.
constexpr double kMaxCoordinate = 1e30;

bool bounded(const Vec3& v) {
  return std::abs(v.x()) <= kMaxCoordinate && std::abs(v.y()) <= kMaxCoordinate &&
         std::abs(v.z()) <= kMaxCoordinate;  // false for NaN
}
bool valid_window(double u0, double u1) { return 0 <= u0 && u0 <= u1 && u1 <= 1; }
bool valid_settings(const CcdSettings& s) {
  return s.time_tolerance > 0 && s.distance_tolerance > 0 && s.min_separation >= 0 &&
         std::isfinite(s.min_separation) && std::isfinite(s.distance_tolerance) && s.max_iterations > 0;
}

IVec3 operator+(const IVec3& a, const IVec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
IVec3 operator-(const IVec3& a, const IVec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
IVec3 operator*(double s, const IVec3& a) { return {s * a[0], s * a[1], s * a[2]}; }
IVec3 hull(const IVec3& a, const IVec3& b) { return {hull(a[0], b[0]), hull(a[1], b[1]), hull(a[2], b[2])}; }

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
// every sub-interval of U): see excludes(), or
// (ii) (vertex/face) a_lo + b_lo > 1 in floating point, which implies the exact
// sum exceeds 1 (1 is a double and rounding is monotone): P lies outside the
// triangle. Splits share the double midpoint, so children cover their parent
// exactly, and a front passed to the halves of U is every box of U's search not
// dropped. Hence a u-interval is dropped only when it holds no contact. The
// outer search visits u-intervals in increasing order and stops at the first
// one it accepts (or gives up at), so the interval holding u* is never passed:
// u_hit = U.lo <= u*.
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
  double sum = 0;
  for (const Interval& c : F) {
    if (c.lo > d || c.hi < -d) return true;
    const double m = c.lo > 0 ? c.lo : (c.hi < 0 ? -c.hi : 0.0);  // distance of [lo, hi] from 0
    sum = next_down(sum + next_down(m * m));
  }
  return sum > next_up(d * d);
}

template <class Enclose>
void bisect(const Enclose& enclose, bool triangle, const Scales& sc, double u_begin, double u_end,
            const CcdSettings& s, CcdWorkspace* ws, CcdResult* r) {
  const double d = s.min_separation;
  // Rounding noise makes F's enclosure at least ~1e-15 of the coordinates wide:
  // a distance tolerance below that could never be met.
  const double tol_d = std::max(s.distance_tolerance, 1e-12 * sc.coordinate);
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
  while (top > 0) {
    // Pop the interval on top: its header and front are arena[header .. top).
    const double u0 = arena[header].u[0], u1 = arena[header].u[1];
    const int front_begin = header + 1;
    const int saved_header_link = static_cast<int>(arena[header].b[0]);  // previous block's header
    const double wu = u1 - u0;
    // Parameter refinement pays only while it shrinks F more than the u-width
    // blurs it: measure that blur on one parameter point.
    IVec3 F_point;
    enclose(Box{{u0, u1}, {0, 0}, {0, 0}}, &F_point);
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
      IVec3 F;
      enclose(P, &F);
      if (excludes(F, d)) continue;  // (i)
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
      double m2 = 0;
      for (const Interval& c : F_maybe) {
        const double m = std::max(std::abs(c.lo), std::abs(c.hi));
        m2 = next_up(m2 + next_up(m * m));
      }
      r->distance_reached = next_up(std::sqrt(m2));
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
// error of any corner value of F computed from them as in the enclosures below.
//
// Static error bound. Let M bound every input coordinate and r = 2^-53 the unit
// roundoff; u, a, b lie in [0, 1]. Each rounded operation adds at most r times
// the magnitude of its result (plus 2^-1075 if it underflows). Bounding the
// magnitudes and accumulating the errors along the evaluation:
//   dx = x1 - x0          |dx| <= 2M    error <= 2rM
//   p = x0 + u dx         |p|  <= 3M    error <= 2rM + 2rM + 3rM = 7rM
//   w, e1, e2 = p - p'    |.|  <= 6M    error <= 14rM + 6rM = 20rM
//   a e1, b e2            |.|  <= 6M    error <= 20rM + 6rM = 26rM
//   (w - a e1) - b e2     |.|  <= 18M   error <= 20 + 26 + 12 + 26 + 18 = 102rM
// so 128 r M + 64 * 2^-1074 (underflows) bounds the error of every corner value.
// (A fused multiply-add, if a compiler contracted one, rounds once instead of
// twice: its error is within the same bound.)
// The multilinear argument above then bounds F over the box by the corners'
// min and max widened by this bound (the widening itself rounded outward).
struct LinearPoints {
  std::array<std::array<double, 3>, 4> x0, dx;
  double error = 0;
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
  const double r = std::ldexp(1.0, -53);
  p.error = next_up(next_up(128 * r * M) + 64 * std::numeric_limits<double>::denorm_min());
  return p;
}

}  // namespace

void ccd_linear_vertex_face(const LinearVertexFaceQuery& q, const CcdSettings& s, CcdWorkspace* ws,
                            CcdResult* r) {
  bool ok = valid_settings(s) && valid_window(q.u_begin, q.u_end) && ws != nullptr;
  for (int t = 0; t < 2; ++t) {
    ok = ok && bounded(q.vertex[t]);
    for (int k = 0; k < 3; ++k) ok = ok && bounded(q.face[t][k]);
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
  auto enclose = [&](const Box& box, IVec3* F) {
    // Inputs are finite and bounded (validated), so no NaN reaches min/max.
    constexpr double kInf = std::numeric_limits<double>::infinity();
    double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
    for (double u : box.u) {
      for (int i = 0; i < 3; ++i) {
        // F = (v - f0) - a (f1 - f0) - b (f2 - f0) at this u.
        const double p0 = pts.x0[0][i] + u * pts.dx[0][i], p1 = pts.x0[1][i] + u * pts.dx[1][i];
        const double p2 = pts.x0[2][i] + u * pts.dx[2][i], p3 = pts.x0[3][i] + u * pts.dx[3][i];
        const double w = p0 - p1, e1 = p2 - p1, e2 = p3 - p1;
        for (double a : box.a)
          for (double b : box.b) {
            const double c = (w - a * e1) - b * e2;
            lo[i] = std::min(lo[i], c);
            hi[i] = std::max(hi[i], c);
          }
      }
    }
    for (int i = 0; i < 3; ++i) (*F)[i] = {next_down(lo[i] - pts.error), next_up(hi[i] + pts.error)};
  };
  bisect(enclose, /*triangle=*/true, sc, q.u_begin, q.u_end, s, ws, r);
}

void ccd_linear_edge_edge(const LinearEdgeEdgeQuery& q, const CcdSettings& s, CcdWorkspace* ws,
                          CcdResult* r) {
  bool ok = valid_settings(s) && valid_window(q.u_begin, q.u_end) && ws != nullptr;
  for (int t = 0; t < 2; ++t)
    for (int k = 0; k < 2; ++k) ok = ok && bounded(q.edge_a[t][k]) && bounded(q.edge_b[t][k]);
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
  auto enclose = [&](const Box& box, IVec3* F) {
    // Inputs are finite and bounded (validated), so no NaN reaches min/max.
    constexpr double kInf = std::numeric_limits<double>::infinity();
    double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
    for (double u : box.u) {
      for (int i = 0; i < 3; ++i) {
        // F = (a0 - b0) + a (a1 - a0) - b (b1 - b0) at this u.
        const double p0 = pts.x0[0][i] + u * pts.dx[0][i], p1 = pts.x0[1][i] + u * pts.dx[1][i];
        const double p2 = pts.x0[2][i] + u * pts.dx[2][i], p3 = pts.x0[3][i] + u * pts.dx[3][i];
        const double w = p0 - p2, ea = p1 - p0, eb = p3 - p2;
        for (double a : box.a)
          for (double b : box.b) {
            const double c = (w + a * ea) - b * eb;
            lo[i] = std::min(lo[i], c);
            hi[i] = std::max(hi[i], c);
          }
      }
    }
    for (int i = 0; i < 3; ++i) (*F)[i] = {next_down(lo[i] - pts.error), next_up(hi[i] + pts.error)};
  };
  bisect(enclose, /*triangle=*/false, sc, q.u_begin, q.u_end, s, ws, r);
}

// ---------------------------------------------------------------------------
// The Cayley motion, enclosed.
// ---------------------------------------------------------------------------

namespace {

// The rational rotation R(q) of pose.h, every entry enclosed; nullopt-like
// false when |q|^2 is not safely positive.
bool rational_rotation(const Quat& q, IMat3* R) {
  const Interval w = Interval::point(q.w), x = Interval::point(q.x), y = Interval::point(q.y),
                 z = Interval::point(q.z);
  const Interval ww = sqr(w), xx = sqr(x), yy = sqr(y), zz = sqr(z);
  const Interval n = ww + xx + yy + zz;
  if (!(n.lo > 0)) return false;
  const Interval xy = x * y, xz = x * z, yz = y * z, wx = w * x, wy = w * y, wz = w * z;
  const Interval e[9] = {ww + xx - yy - zz, 2.0 * (xy - wz),   2.0 * (xz + wy),
                         2.0 * (xy + wz),   ww - xx + yy - zz, 2.0 * (yz - wx),
                         2.0 * (xz - wy),   2.0 * (yz + wx),   ww - xx - yy + zz};
  for (int i = 0; i < 9; ++i) {
    const Interval v = div_positive(e[i], n);
    (*R)[i] = {std::max(v.lo, -1.0), std::min(v.hi, 1.0)};  // exact R is orthogonal
  }
  return true;
}

}  // namespace

MotionStatus make_ccd_motion(const Pose& x0, const Pose& x1, CcdMotion* m) {
  CayleyMotion nominal;
  const MotionStatus st = make_cayley_motion(x0, x1, &nominal);
  if (st != MotionStatus::kOk) return st;
  if (!bounded(x0.p) || !bounded(x1.p)) return MotionStatus::kInvalidPose;
  CcdMotion out;
  out.nominal = nominal;
  if (!rational_rotation(x0.q, &out.R0)) return MotionStatus::kInvalidPose;
  out.p0 = to_interval(x0.p);
  out.dp = to_interval(x1.p) - out.p0;
  // qr = q1 conj(q0), exactly enclosed (Hamilton product), with the same sign
  // choice as make_cayley_motion (decided on the double value).
  const auto I = [](double v) { return Interval::point(v); };
  const Interval aw = I(x1.q.w), ax = I(x1.q.x), ay = I(x1.q.y), az = I(x1.q.z);
  const Interval bw = I(x0.q.w), bx = -I(x0.q.x), by = -I(x0.q.y), bz = -I(x0.q.z);
  Interval rw = aw * bw - ax * bx - ay * by - az * bz;
  Interval rx = aw * bx + ax * bw + ay * bz - az * by;
  Interval ry = aw * by - ax * bz + ay * bw + az * bx;
  Interval rz = aw * bz + ax * by - ay * bx + az * bw;
  const Quat qr_double = x1.q * conjugate(x0.q);
  if (qr_double.w < 0) { rw = -rw; rx = -rx; ry = -ry; rz = -rz; }
  if (!(rw.lo > 0)) return MotionStatus::kHalfTurn;
  out.g = {div_positive(rx, rw), div_positive(ry, rw), div_positive(rz, rw)};
  out.g2 = sqr(out.g[0]) + sqr(out.g[1]) + sqr(out.g[2]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out.K2[3 * i + j] = (i == j) ? sqr(out.g[i]) - out.g2 : out.g[i] * out.g[j];
  *m = out;
  return MotionStatus::kOk;
}

void enclose_motion(const CcdMotion& m, Interval u, MotionEnclosure* out) {
  // C(u g) = I + alpha(u) [g]x + beta(u) [g]x^2, alpha = 2u / (1 + u^2 s),
  // beta = 2u^2 / (1 + u^2 s), s = |g|^2, u >= 0.
  const Interval s = m.g2;
  const auto den_at = [&](double v) { return Interval::point(1) + sqr(Interval::point(v)) * s; };
  const auto alpha_at = [&](double v) { return div_positive(Interval::point(2 * v), den_at(v)); };
  const auto beta_at = [&](double v) { return div_positive(2.0 * sqr(Interval::point(v)), den_at(v)); };
  // beta = 2 / (1/u^2 + s) increases with u: its range is spanned by the ends.
  const Interval beta = hull(beta_at(u.lo), beta_at(u.hi));
  // alpha increases up to u = 1/sqrt(s), where it is 1/sqrt(s), then decreases;
  // alpha <= 2u always. (2 v is exact: a power-of-two scaling of v in [0, 1].)
  Interval alpha = hull(alpha_at(u.lo), alpha_at(u.hi));
  const bool increasing = (sqr(Interval::point(u.hi)) * s).hi < 1;
  const bool decreasing = (sqr(Interval::point(u.lo)) * s).lo > 1;
  if (!increasing && !decreasing) {
    double cap = 2 * u.hi;
    if (s.lo > 0) cap = std::min(cap, next_up(1.0 / next_down(std::sqrt(s.lo))));
    alpha.hi = std::max(alpha.hi, cap);
  }
  // C = I + alpha K + beta K^2, K = [g]x.
  const IVec3& g = m.g;
  const Interval zero = Interval::point(0);
  const IMat3 K = {zero, -g[2], g[1], g[2], zero, -g[0], -g[1], g[0], zero};
  IMat3 C;
  for (int i = 0; i < 9; ++i) {
    C[i] = alpha * K[i] + beta * m.K2[i];
    if (i % 4 == 0) C[i] = Interval::point(1) + C[i];
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Interval e = C[3 * i] * m.R0[j] + C[3 * i + 1] * m.R0[3 + j] + C[3 * i + 2] * m.R0[6 + j];
      out->R[3 * i + j] = {std::max(e.lo, -1.0), std::min(e.hi, 1.0)};
    }
  out->u = u;
  for (int i = 0; i < 3; ++i) out->p[i] = m.p0[i] + u * m.dp[i];
}

IVec3 enclose_point(const MotionEnclosure& e, const IVec3& r) {
  // Point coordinates (the common case: a vertex) take the cheaper scalar product.
  const auto mul = [](Interval R, Interval x) { return x.lo == x.hi ? x.lo * R : R * x; };
  IVec3 w;
  for (int i = 0; i < 3; ++i)
    w[i] = e.p[i] + (mul(e.R[3 * i], r[0]) + mul(e.R[3 * i + 1], r[1]) + mul(e.R[3 * i + 2], r[2]));
  return w;
}

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
// Two necessary conditions for a contact within distance d at parameter u,
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
//     Over U, P is enclosed twice (Horner, and the mean-value form
//     P(m) + P'(U) (U - m), valid as P is smooth) and the two intersected;
//     U is excluded when |P| > d L max_U D on all of it.
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
// Guarantee. A u-interval is dropped only when (1) or (2) proves that no
// contact within d occurs in it; the bisection then runs on the remaining
// windows in increasing u, so its first accepted interval still starts at or
// before u*. Windows are produced by a depth-first left-first 1-D subdivision
// that keeps intervals down to a width of (window)/2^10 (or the time tolerance),
// merged when adjacent; past a fixed number of evaluations the rest of the
// window is kept whole (conservative).
// ---------------------------------------------------------------------------

IVec3 mul(const IMat3& R, const IVec3& v) {
  IVec3 out;
  for (int i = 0; i < 3; ++i) out[i] = R[3 * i] * v[0] + R[3 * i + 1] * v[1] + R[3 * i + 2] * v[2];
  return out;
}
Interval dot(const IVec3& a, const IVec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
IVec3 cross(const IVec3& a, const IVec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
IVec3 scale(Interval s, const IVec3& a) { return {s * a[0], s * a[1], s * a[2]}; }
// Upper bound of the Euclidean norm of every vector in the box v.
double norm_upper(const IVec3& v) {
  double s2 = 0;
  for (const Interval& c : v) {
    const double m = std::max(std::abs(c.lo), std::abs(c.hi));
    s2 = next_up(s2 + next_up(m * m));
  }
  return next_up(std::sqrt(s2));
}
Interval intersect(Interval a, Interval b) { return {std::max(a.lo, b.lo), std::min(a.hi, b.hi)}; }

// Coefficients of Dc(u) v = v + u c1 + u^2 c2.
struct CayleyCoefficients { IVec3 c1, c2; };
CayleyCoefficients cayley_coefficients(const CcdMotion& m, const IVec3& v) {
  const IVec3 gxv = cross(m.g, v);
  const Interval gv = dot(m.g, v);
  const IVec3 c2 = scale(2.0 * gv, m.g) - scale(m.g2, v);
  return {2.0 * gxv, c2};
}

struct UFilter {
  // (1) the cubic and the right-hand side factor d L (>= 0); active when has_cubic.
  bool has_cubic = false;
  Interval k[4];
  double dL = 0;
  // (2) the axis: corners' projection coefficients and the static projection
  // grown by d |n|; active when num_corners > 0.
  int num_corners = 0;
  Interval c0[3], c1[3], c2[3], c3[3];
  Interval static_proj;
  const CcdMotion* motion = nullptr;

  // Adds a body corner w = R0 r_B (world-oriented offset from G) for the axis n.
  void add_corner(const IVec3& w, const IVec3& n) {
    const IVec3 gxw = cross(motion->g, w), ggw = cross(motion->g, gxw);
    const int j = num_corners++;
    c0[j] = dot(n, motion->p0 + w);
    c1[j] = dot(n, motion->dp + 2.0 * gxw);
    c2[j] = dot(n, gxw);
    c3[j] = dot(n, ggw);
  }
  void set_axis_static(Interval proj, const IVec3& n, double d) {
    const double dn = next_up(d * norm_upper(n));
    static_proj = {next_down(proj.lo - dn), next_up(proj.hi + dn)};
  }

  bool excludes(double u0, double u1) const {
    const Interval U{u0, u1};
    const Interval s = motion->g2;
    if (has_cubic) {
      const Interval k1 = k[1], k2 = k[2], k3 = k[3];
      const Interval horner = k[0] + U * (k1 + U * (k2 + U * k3));
      const double mid = 0.5 * (u0 + u1);
      const Interval M = Interval::point(mid);
      const Interval at_mid = k[0] + M * (k1 + M * (k2 + M * k3));
      const Interval slope = k1 + U * (2.0 * k2 + U * (3.0 * k3));
      const Interval P = intersect(horner, at_mid + slope * (U - M));
      const double rhs = (Interval::point(dL) * (Interval::point(1) + sqr(Interval::point(u1)) * s)).hi;
      if (P.lo > rhs || P.hi < -rhs) return true;
    }
    if (num_corners > 0) {
      const auto beta_at = [&](double v) {
        return div_positive(2.0 * sqr(Interval::point(v)), Interval::point(1) + sqr(Interval::point(v)) * s);
      };
      const Interval B = hull(beta_at(u0), beta_at(u1));
      const Interval Gamma{0, (2.0 * (sqr(Interval::point(u1)) * Interval::point(u1)) * s).hi};
      Interval proj{};
      for (int j = 0; j < num_corners; ++j) {
        const Interval pj = c0[j] + U * c1[j] - Gamma * c2[j] + B * c3[j];
        proj = j == 0 ? pj : hull(proj, pj);
      }
      if (proj.lo > static_proj.hi || proj.hi < static_proj.lo) return true;
    }
    return false;
  }
};

// Runs the bisection on the windows of [u_begin, u_end] that the filter cannot
// exclude, in increasing u; the first hit ends the search.
template <class Enclose>
void filtered_bisect(const Enclose& enclose, bool triangle, const Scales& sc, const UFilter& filter, double u_begin,
                     double u_end, const CcdSettings& s, CcdWorkspace* ws, CcdResult* r) {
  constexpr int kMaxEvaluations = 512, kStack = 64;
  const double min_width = std::max(s.time_tolerance, std::ldexp(u_end - u_begin, -10));
  int evaluations = 0, total_iterations = 0;
  bool pending = false;
  double w0 = 0, w1 = 0;  // the pending window
  *r = CcdResult{};
  // Bisection on one window; true when it ends the search (hit or give-up).
  const auto run = [&](double a, double b) {
    CcdSettings sw = s;
    sw.max_iterations = std::max(1, s.max_iterations - total_iterations);
    bisect(enclose, triangle, sc, a, b, sw, ws, r);
    total_iterations += r->iterations;
    r->iterations = total_iterations;
    return r->hit;
  };
  const auto keep = [&](double a, double b) {
    if (pending && a == w1) {
      w1 = b;
      return false;
    }
    const bool done = pending && run(w0, w1);
    pending = true;
    w0 = a;
    w1 = b;
    return done;
  };
  double stack[kStack][2];
  int top = 0;
  stack[top][0] = u_begin;
  stack[top][1] = u_end;
  ++top;
  while (top > 0) {
    --top;
    const double a = stack[top][0], b = stack[top][1];
    if (evaluations >= kMaxEvaluations) {
      // Budget spent: keep the rest whole (everything still on the stack lies
      // to the right of a and ends at u_end).
      if (keep(a, u_end)) return;
      top = 0;
      break;
    }
    ++evaluations;
    if (filter.excludes(a, b)) continue;
    const double m = 0.5 * (a + b);
    if (b - a <= min_width || !(a < m && m < b) || top + 2 > kStack) {
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
  r->status = CcdStatus::kOk;
  r->hit = false;
  r->u_hit = u_end;
  r->iterations = total_iterations;
}

}  // namespace

void ccd_rigid_vertex_face(const RigidVertexFaceQuery& q, const CcdSettings& s, CcdWorkspace* ws,
                           CcdResult* r) {
  bool ok = valid_settings(s) && valid_window(q.u_begin, q.u_end) && ws != nullptr && q.motion != nullptr &&
            bounded(q.vertex);
  for (const Vec3& f : q.face) ok = ok && bounded(f);
  if (!ok) return refuse(q.u_end, r);
  const CachedEnclosure cache{q.motion, {}, -1, -1};
  const IVec3 f0 = to_interval(q.face[0]);
  const IVec3 e1 = to_interval(q.face[1]) - f0, e2 = to_interval(q.face[2]) - f0;
  const IVec3 v = to_interval(q.vertex);
  Scales sc{0, max_abs(q.face[1] - q.face[0]), max_abs(q.face[2] - q.face[0]), 0};
  const double rho = q.vertex_on_body ? q.vertex.norm()
                                      : std::max({q.face[0].norm(), q.face[1].norm(), q.face[2].norm()});
  sc.u = rigid_speed(*q.motion, rho);
  sc.coordinate = std::max({max_abs(q.vertex), max_abs(q.face[0]), max_abs(q.face[1]), max_abs(q.face[2]),
                            max_abs(q.motion->nominal.p0), max_abs(q.motion->nominal.p0 + q.motion->nominal.dp)});
  auto enclose = [&](const Box& box, IVec3* F) {
    const MotionEnclosure& e = cache.at(box);
    bool first = true;
    if (q.vertex_on_body) {
      // F = M(u, v) - (f0 + a e1 + b e2)
      const IVec3 mv = enclose_point(e, v) - f0;
      for (double a : box.a)
        for (double b : box.b) {
          const IVec3 c = mv - a * e1 - b * e2;
          *F = first ? c : hull(*F, c);
          first = false;
        }
    } else {
      // F = v - M(u, f0 + a e1 + b e2)
      for (double a : box.a)
        for (double b : box.b) {
          const IVec3 c = v - enclose_point(e, f0 + a * e1 + b * e2);
          *F = first ? c : hull(*F, c);
          first = false;
        }
    }
  };
  if (!s.use_u_filter) return bisect(enclose, /*triangle=*/true, sc, q.u_begin, q.u_end, s, ws, r);
  // The u-filter (see UFilter): coplanarity cubic and a separating axis.
  const CcdMotion& m = *q.motion;
  const double d = s.min_separation;
  UFilter filter;
  filter.motion = &m;
  filter.has_cubic = true;
  if (q.vertex_on_body) {
    const Vec3 x_begin = motion_point(m.nominal, q.u_begin, q.vertex);  // heuristic only (the axis)
    const IVec3 n = cross(e1, e2), w = mul(m.R0, v);
    const CayleyCoefficients cw = cayley_coefficients(m, w);
    const Interval A = dot(m.p0 - f0, n), E = dot(m.dp, n);
    filter.k[0] = A + dot(w, n);
    filter.k[1] = E + dot(cw.c1, n);
    filter.k[2] = m.g2 * A + dot(cw.c2, n);
    filter.k[3] = m.g2 * E;
    filter.dL = next_up(d * norm_upper(n));
    const Vec3 axis = x_begin - closest_point_on_triangle(x_begin, q.face[0], q.face[1], q.face[2]);
    if (axis != Vec3::Zero() && std::isfinite(axis.squaredNorm())) {
      const IVec3 na = to_interval(axis);
      filter.add_corner(w, na);
      filter.set_axis_static(hull(hull(dot(na, f0), dot(na, f0 + e1)), dot(na, f0 + e2)), na, d);
    }
  } else {
    const IVec3 nB = cross(e1, e2), nW = mul(m.R0, nB), f0W = mul(m.R0, f0);
    const CayleyCoefficients cn = cayley_coefficients(m, nW);
    const IVec3 Y = v - m.p0;
    const Interval F = dot(f0W, nW);
    filter.k[0] = dot(Y, nW) - F;
    filter.k[1] = dot(Y, cn.c1) - dot(m.dp, nW);
    filter.k[2] = (dot(Y, cn.c2) - dot(m.dp, cn.c1)) - m.g2 * F;
    filter.k[3] = -dot(m.dp, cn.c2);
    filter.dL = next_up(d * norm_upper(nB));
    Vec3 corner[3];
    for (int k = 0; k < 3; ++k) corner[k] = motion_point(m.nominal, q.u_begin, q.face[k]);
    const Vec3 axis = q.vertex - closest_point_on_triangle(q.vertex, corner[0], corner[1], corner[2]);
    if (axis != Vec3::Zero() && std::isfinite(axis.squaredNorm())) {
      const IVec3 na = to_interval(axis);
      filter.add_corner(f0W, na);
      filter.add_corner(mul(m.R0, f0 + e1), na);
      filter.add_corner(mul(m.R0, f0 + e2), na);
      filter.set_axis_static(dot(na, v), na, d);
    }
  }
  filtered_bisect(enclose, /*triangle=*/true, sc, filter, q.u_begin, q.u_end, s, ws, r);
}

void ccd_rigid_edge_edge(const RigidEdgeEdgeQuery& q, const CcdSettings& s, CcdWorkspace* ws, CcdResult* r) {
  bool ok = valid_settings(s) && valid_window(q.u_begin, q.u_end) && ws != nullptr && q.motion != nullptr;
  for (int k = 0; k < 2; ++k) ok = ok && bounded(q.edge_body[k]) && bounded(q.edge_world[k]);
  if (!ok) return refuse(q.u_end, r);
  const CachedEnclosure cache{q.motion, {}, -1, -1};
  const IVec3 a0 = to_interval(q.edge_body[0]), ea = to_interval(q.edge_body[1]) - a0;
  const IVec3 b0 = to_interval(q.edge_world[0]), eb = to_interval(q.edge_world[1]) - b0;
  Scales sc{0, max_abs(q.edge_body[1] - q.edge_body[0]), max_abs(q.edge_world[1] - q.edge_world[0]), 0};
  sc.u = rigid_speed(*q.motion, std::max(q.edge_body[0].norm(), q.edge_body[1].norm()));
  sc.coordinate = std::max({max_abs(q.edge_body[0]), max_abs(q.edge_body[1]), max_abs(q.edge_world[0]),
                            max_abs(q.edge_world[1]), max_abs(q.motion->nominal.p0),
                            max_abs(q.motion->nominal.p0 + q.motion->nominal.dp)});
  auto enclose = [&](const Box& box, IVec3* F) {
    const MotionEnclosure& e = cache.at(box);
    // F = M(u, a0 + a ea) - (b0 + b eb)
    const IVec3 pa[2] = {enclose_point(e, a0 + box.a[0] * ea), enclose_point(e, a0 + box.a[1] * ea)};
    const IVec3 pb[2] = {b0 + box.b[0] * eb, b0 + box.b[1] * eb};
    *F = hull(hull(pa[0] - pb[0], pa[0] - pb[1]), hull(pa[1] - pb[0], pa[1] - pb[1]));
  };
  if (!s.use_u_filter) return bisect(enclose, /*triangle=*/false, sc, q.u_begin, q.u_end, s, ws, r);
  // The u-filter (see UFilter): coplanarity cubic and a separating axis.
  const CcdMotion& m = *q.motion;
  const double d = s.min_separation;
  UFilter filter;
  filter.motion = &m;
  filter.has_cubic = true;
  const IVec3 a0W = mul(m.R0, a0), eaW = mul(m.R0, ea), Q = m.p0 - b0;
  const CayleyCoefficients ca = cayley_coefficients(m, eaW), cb = cayley_coefficients(m, eb);
  const IVec3 T0 = cross(eaW, eb), T1 = cross(ca.c1, eb), T2 = cross(ca.c2, eb), Z = cross(a0W, eaW);
  filter.k[0] = dot(Q, T0) + dot(Z, eb);
  filter.k[1] = (dot(Q, T1) + dot(m.dp, T0)) - dot(Z, cb.c1);
  filter.k[2] = (dot(Q, T2) + dot(m.dp, T1)) + dot(Z, cb.c2);
  filter.k[3] = dot(m.dp, T2);
  // L >= |C ea' x eb| on the window: |ea' x eb| + 2 u_end |g| |ea| |eb|.
  const double g_norm = next_up(std::sqrt(m.g2.hi));
  const double turn = next_up(next_up(2 * q.u_end * g_norm) * next_up(norm_upper(ea) * norm_upper(eb)));
  filter.dL = next_up(d * next_up(norm_upper(T0) + turn));
  const Vec3 A0 = motion_point(m.nominal, q.u_begin, q.edge_body[0]);
  const Vec3 A1 = motion_point(m.nominal, q.u_begin, q.edge_body[1]);
  double sa = 0, tb = 0;
  closest_segment_parameters(A0, A1, q.edge_world[0], q.edge_world[1], &sa, &tb);
  const Vec3 axis = (A0 + sa * (A1 - A0)) - (q.edge_world[0] + tb * (q.edge_world[1] - q.edge_world[0]));
  if (axis != Vec3::Zero() && std::isfinite(axis.squaredNorm())) {
    const IVec3 na = to_interval(axis);
    filter.add_corner(a0W, na);
    filter.add_corner(mul(m.R0, a0 + ea), na);
    filter.set_axis_static(hull(dot(na, b0), dot(na, b0 + eb)), na, d);
  }
  filtered_bisect(enclose, /*triangle=*/false, sc, filter, q.u_begin, q.u_end, s, ws, r);
}

StopPose make_stop_pose(const CcdMotion& m, double u, double body_radius) {
  StopPose out;
  out.pose = motion_pose(m.nominal, u);
  MotionEnclosure e;
  enclose_motion(m, Interval::point(u), &e);
  IMat3 Rq;
  if (!rational_rotation(out.pose.q, &Rq)) {
    out.deviation = std::numeric_limits<double>::infinity();
    return out;
  }
  // Per world axis i: |dp_i| + rho sum_j |dR_ij|, all rounded up.
  double sum2 = 0;
  for (int i = 0; i < 3; ++i) {
    const Interval dp = Interval::point(out.pose.p[i]) - e.p[i];
    double row = 0;
    for (int j = 0; j < 3; ++j) {
      const Interval dR = Rq[3 * i + j] - e.R[3 * i + j];
      row = next_up(row + std::max(std::abs(dR.lo), std::abs(dR.hi)));
    }
    const double di = next_up(std::max(std::abs(dp.lo), std::abs(dp.hi)) + next_up(body_radius * row));
    sum2 = next_up(sum2 + next_up(di * di));
  }
  out.deviation = next_up(std::sqrt(sum2));
  return out;
}

}  // namespace gauss6
