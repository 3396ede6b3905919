// The interval filter of the exact first contact (ccd_filter.h).
//
// The coplanarity condition of a feature pair under the Cayley motion, times
// positive powers of D(u) = 1 + u^2 |g|^2, is a polynomial in u whose
// coefficients are enclosed here in CGAL's Interval_nt from the doubles:
//   a god-object point r moves on x(u) = N(u) / D(u) with, w = R(q0) r and
//   P = p0 + w, N = P + u (dp + 2 g x w) + u^2 (|g|^2 P + 2 g x (g x w)) + u^3 |g|^2 dp;
//   god vertex / obstacle face (a, b, c):  D f = n . (N - D a), n = (b - a) x (c - a)   (degree 3);
//   obstacle vertex o / god face (a, b, c): in the god-object's frame, with
//     y(u) = o - p(u) = Y + u Z, D R(u)^T y = R0^T M(u), M = D y - 2 u g x y + 2 u^2 g x (g x y),
//     D f = (R0 n_B) . M - D (n_B . a_B), n_B = (b_B - a_B) x (c_B - a_B)   (degree 3);
//   god edge (a0, a1) / obstacle edge (b0, b1): D^2 f = (D b0 - N_a0) . (Delta x (b1 - b0)), Delta = N_a1 -
//     N_a0 = D e + 2 u g x e + 2 u^2 g x (g x e), e = R0 (a1_B - a0_B)   (degree 5).
// (Each f is the exact code's coplanarity polynomial up to a factor positive on
// R, so it has the same roots in [0, u_max].) Converted to Bernstein form on
// [0, u_max], a polynomial whose coefficients are all of one strict sign has no
// root there: the pair cannot touch (contact needs coplanarity). Otherwise the
// Bernstein form is subdivided (de Casteljau, in intervals) to isolate the
// sub-intervals that may hold a root, and on each the contact test is
// evaluated with the features' positions enclosed over the whole sub-interval
// (interval boxes, the sides of the edges seen along the normal): a sub-interval
// where it fails for every u holds no contact. The first sub-interval neither
// rules out bounds the pair's first contact from below.
#include "ccd_filter.h"

#include <algorithm>
#include <cmath>

#include <CGAL/Gmpz.h>
#include <CGAL/Interval_nt.h>

namespace gauss6::reference::detail {
namespace {

using I = CGAL::Interval_nt_advanced;  // needs upward rounding: filter_pair sets it

struct IV {
  I x[3];
  I& operator[](int i) { return x[i]; }
  const I& operator[](int i) const { return x[i]; }
};
IV iv(const Vec3& v) { return {{I(v.x()), I(v.y()), I(v.z())}}; }
IV operator+(const IV& a, const IV& b) { return {{a[0] + b[0], a[1] + b[1], a[2] + b[2]}}; }
IV operator-(const IV& a, const IV& b) { return {{a[0] - b[0], a[1] - b[1], a[2] - b[2]}}; }
IV operator*(const I& s, const IV& a) { return {{s * a[0], s * a[1], s * a[2]}}; }
IV operator-(const IV& a) { return {{-a[0], -a[1], -a[2]}}; }
IV cross(const IV& a, const IV& b) {
  return {{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}};
}
I dot(const IV& a, const IV& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
IV mul(const I R[3][3], const IV& v) {
  return {{R[0][0] * v[0] + R[0][1] * v[1] + R[0][2] * v[2], R[1][0] * v[0] + R[1][1] * v[1] + R[1][2] * v[2],
           R[2][0] * v[0] + R[2][1] * v[1] + R[2][2] * v[2]}};
}

bool finite(const I& a) { return std::isfinite(a.inf()) && std::isfinite(a.sup()); }
bool positive(const I& a) { return a.inf() > 0; }
bool negative(const I& a) { return a.sup() < 0; }

I to_interval(const mpz_class& z) {
  const std::pair<double, double> r = CGAL::to_interval(CGAL::Gmpz(z.get_mpz_t()));
  return I(r.first, r.second);
}

constexpr int kMaxDegree = 5;
struct Poly {
  I c[kMaxDegree + 1];  // power basis, c[i] of u^i
  int n = 0;            // degree (the form's; a coefficient may enclose 0)
};

}  // namespace

struct IntervalMotion {
  IV p0, dp, g;
  I G;          // |g|^2
  I R0[3][3];   // R(q0)
  bool valid = false;

  // A god-object point r_B: w = R0 r and the terms of its motion.
  struct Point {
    IV w, gw, ggw;  // R0 r, g x w, g x (g x w)
  };
  Point point(const Vec3& r) const {
    Point p;
    p.w = mul(R0, iv(r));
    p.gw = cross(g, p.w);
    p.ggw = cross(g, p.gw);
    return p;
  }
  // N(u) = D(u) x(u), coefficients of u^0..u^3.
  std::array<IV, 4> numerator(const Point& p) const {
    const IV P = p0 + p.w;
    return {P, dp + I(2) * p.gw, G * P + I(2) * p.ggw, G * dp};
  }
  // x(u) over the interval U of u (one enclosure).
  IV at(const Point& p, const I& U) const {
    const I U2 = CGAL::square(U);
    const I D = 1 + U2 * G;
    return p0 + U * dp + p.w + (I(2) / D) * (U * p.gw + U2 * p.ggw);
  }
};

IntervalMotionPtr::IntervalMotionPtr(const ExactCayleyMotion& m) : motion(new IntervalMotion) {
  CGAL::Protect_FPU_rounding<true> upward;
  IntervalMotion& im = *motion;
  im.p0 = iv(m.X0.p);
  im.dp = iv(m.X1.p) - im.p0;
  const I s = to_interval(m.s);
  for (int i = 0; i < 3; ++i) im.g[i] = to_interval(m.v[i]) / s;
  im.G = dot(im.g, im.g);
  const I w = to_interval(m.q0[0]), x = to_interval(m.q0[1]), y = to_interval(m.q0[2]), z = to_interval(m.q0[3]);
  const I n = w * w + x * x + y * y + z * z;
  im.R0[0][0] = (w * w + x * x - y * y - z * z) / n;
  im.R0[0][1] = 2 * (x * y - w * z) / n;
  im.R0[0][2] = 2 * (x * z + w * y) / n;
  im.R0[1][0] = 2 * (x * y + w * z) / n;
  im.R0[1][1] = (w * w - x * x + y * y - z * z) / n;
  im.R0[1][2] = 2 * (y * z - w * x) / n;
  im.R0[2][0] = 2 * (x * z - w * y) / n;
  im.R0[2][1] = 2 * (y * z + w * x) / n;
  im.R0[2][2] = (w * w - x * x - y * y + z * z) / n;
  bool ok = finite(im.G) && n.inf() > 0;
  for (int i = 0; i < 3; ++i) {
    ok = ok && finite(im.p0[i]) && finite(im.dp[i]) && finite(im.g[i]);
    for (int j = 0; j < 3; ++j) ok = ok && finite(im.R0[i][j]);
  }
  im.valid = ok;
}

IntervalMotionPtr::~IntervalMotionPtr() { delete motion; }

namespace {

// The coplanarity polynomial of the pair (see the top of the file).
Poly coplanarity(const IntervalMotion& m, PairKind kind, const std::array<Vec3, 3>& god,
                 const std::array<Vec3, 3>& obs) {
  Poly f;
  switch (kind) {
    case PairKind::kGodVertexObstacleFace: {
      const IV a = iv(obs[0]), b = iv(obs[1]), c = iv(obs[2]);
      const IV n = cross(b - a, c - a);
      const auto N = m.numerator(m.point(god[0]));
      f.n = 3;
      f.c[0] = dot(n, N[0] - a);
      f.c[1] = dot(n, N[1]);
      f.c[2] = dot(n, N[2] - m.G * a);
      f.c[3] = dot(n, N[3]);
      break;
    }
    case PairKind::kObstacleVertexGodFace: {
      const IV a = iv(god[0]), b = iv(god[1]), c = iv(god[2]);
      const IV nB = cross(b - a, c - a);
      const IV mm = mul(m.R0, nB);
      const I k = dot(nB, a);
      const IV Y = iv(obs[0]) - m.p0, Z = -m.dp;
      const IV gY = cross(m.g, Y), gZ = cross(m.g, Z);
      const IV M0 = Y, M1 = Z - I(2) * gY, M2 = m.G * Y - I(2) * gZ + I(2) * cross(m.g, gY),
               M3 = m.G * Z + I(2) * cross(m.g, gZ);
      f.n = 3;
      f.c[0] = dot(mm, M0) - k;
      f.c[1] = dot(mm, M1);
      f.c[2] = dot(mm, M2) - m.G * k;
      f.c[3] = dot(mm, M3);
      break;
    }
    case PairKind::kEdgeEdge: {
      const IntervalMotion::Point a0 = m.point(god[0]);
      const auto N = m.numerator(a0);
      const IV e = mul(m.R0, iv(god[1]) - iv(god[0]));
      const IV ge = cross(m.g, e);
      const IV db = iv(obs[1]) - iv(obs[0]);
      const IV b0 = iv(obs[0]);
      // Delta_j x db, j = 0..2; A_i = (D b0 - N_a0)_i, i = 0..3.
      const IV Dx[3] = {cross(e, db), cross(I(2) * ge, db), cross(m.G * e + I(2) * cross(m.g, ge), db)};
      const IV A[4] = {b0 - N[0], -N[1], m.G * b0 - N[2], -N[3]};
      f.n = 5;
      for (int k = 0; k <= 5; ++k) f.c[k] = I(0);
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 3; ++j) f.c[i + j] += dot(A[i], Dx[j]);
      break;
    }
  }
  return f;
}

// Bernstein coefficients on [0, T] of f: b_k = sum_{i <= k} C(k, i) / C(n, i) a_i T^i.
void bernstein(const Poly& f, double T, I* b) {
  static constexpr double kBinom[kMaxDegree + 1][kMaxDegree + 1] = {
      {1, 0, 0, 0, 0, 0}, {1, 1, 0, 0, 0, 0}, {1, 2, 1, 0, 0, 0}, {1, 3, 3, 1, 0, 0}, {1, 4, 6, 4, 1, 0},
      {1, 5, 10, 10, 5, 1}};
  const int n = f.n;
  I a[kMaxDegree + 1];
  I Tp = I(1);
  for (int i = 0; i <= n; ++i) {
    a[i] = f.c[i] * Tp;
    Tp = Tp * I(T);
  }
  for (int k = 0; k <= n; ++k) {
    b[k] = I(0);
    for (int i = 0; i <= k; ++i) b[k] += (I(kBinom[k][i]) / I(kBinom[n][i])) * a[i];
  }
}

bool one_sign(const I* b, int n) {
  bool pos = true, neg = true;
  for (int k = 0; k <= n; ++k) {
    pos = pos && positive(b[k]);
    neg = neg && negative(b[k]);
  }
  return pos || neg;
}

bool disjoint(const IV& a_lo_hi_a, const IV& b) {  // boxes as interval vectors
  for (int i = 0; i < 3; ++i)
    if (a_lo_hi_a[i].sup() < b[i].inf() || b[i].sup() < a_lo_hi_a[i].inf()) return true;
  return false;
}

IV hull(const IV& a, const IV& b) {
  IV h;
  for (int i = 0; i < 3; ++i) h[i] = I(std::min(a[i].inf(), b[i].inf()), std::max(a[i].sup(), b[i].sup()));
  return h;
}

bool degenerate(const IV& n) { return n[0].do_overlap(0) && n[1].do_overlap(0) && n[2].do_overlap(0); }

// True when the pair is proven not to touch at any u in U (the contact tests
// of ccd_exact.cpp, each failing over the whole of U).
bool no_contact_over(const IntervalMotion& m, PairKind kind, const std::array<Vec3, 3>& god,
                     const std::array<Vec3, 3>& obs, const I& U) {
  IV p, a, b, c;
  if (kind == PairKind::kGodVertexObstacleFace) {
    p = m.at(m.point(god[0]), U);
    a = iv(obs[0]), b = iv(obs[1]), c = iv(obs[2]);
  } else if (kind == PairKind::kObstacleVertexGodFace) {
    p = iv(obs[0]);
    a = m.at(m.point(god[0]), U), b = m.at(m.point(god[1]), U), c = m.at(m.point(god[2]), U);
  } else {
    const IV a0 = m.at(m.point(god[0]), U), a1 = m.at(m.point(god[1]), U);
    const IV b0 = iv(obs[0]), b1 = iv(obs[1]);
    if (disjoint(hull(a0, a1), hull(b0, b1))) return true;
    const IV da = a1 - a0, db = b1 - b0, n = cross(da, db);
    if (degenerate(n)) return false;  // parallel or zero-length edges: exactly
    const I o1 = dot(cross(da, b0 - a0), n), o2 = dot(cross(da, b1 - a0), n);
    const I o3 = dot(cross(db, a0 - b0), n), o4 = dot(cross(db, a1 - b0), n);
    // Contact needs o1 o2 <= 0 and o3 o4 <= 0.
    return (positive(o1) && positive(o2)) || (negative(o1) && negative(o2)) || (positive(o3) && positive(o4)) ||
           (negative(o3) && negative(o4));
  }
  if (disjoint(p, hull(hull(a, b), c))) return true;
  const IV ab = b - a, bc = c - b, ca = a - c;
  const IV n = cross(ab, c - a);
  if (degenerate(n)) return false;  // collinear triangle: exactly
  // Contact needs p on the inner side of every edge, seen along n.
  return negative(dot(cross(ab, p - a), n)) || negative(dot(cross(bc, p - b), n)) ||
         negative(dot(cross(ca, p - c), n));
}

}  // namespace

FilterVerdict filter_pair(const IntervalMotion& m, PairKind kind, const std::array<Vec3, 3>& god,
                          const std::array<Vec3, 3>& obs, double u_max) {
  if (!m.valid) return {};
  CGAL::Protect_FPU_rounding<true> upward;
  const Poly f = coplanarity(m, kind, god, obs);
  for (int i = 0; i <= f.n; ++i)
    if (!finite(f.c[i])) return {};
  I b[kMaxDegree + 1];
  bernstein(f, u_max, b);
  if (one_sign(b, f.n)) return {true, 0};
  // Subdivision in t = u / u_max, depth first, left first: the candidate
  // sub-intervals come out in increasing order.
  constexpr int kMaxDepth = 14, kMaxNodes = 96;
  struct Node {
    I b[kMaxDegree + 1];
    double t0, t1;
    int depth;
  };
  Node stack[kMaxDepth + 2];
  int top = 0, nodes = 0;
  stack[top] = Node{};
  std::copy(b, b + f.n + 1, stack[top].b);
  stack[top].t0 = 0, stack[top].t1 = 1, stack[top].depth = 0;
  ++top;
  const int n = f.n;
  while (top > 0) {
    const Node node = stack[--top];
    ++nodes;
    if (one_sign(node.b, n)) continue;
    // u over the node: [u_max t0, u_max t1], rounded outward (upward mode: -(-x) rounds down).
    const double lo = -((-u_max) * node.t0), hi = u_max * node.t1;
    const I U(std::max(0.0, lo), std::min(u_max, hi));
    if (node.depth >= kMaxDepth || nodes >= kMaxNodes) {
      if (no_contact_over(m, kind, god, obs, U)) continue;
      return {false, U.inf()};
    }
    if (no_contact_over(m, kind, god, obs, U)) continue;
    // de Casteljau at the midpoint: left and right halves.
    Node left, right;
    I w[kMaxDegree + 1];
    std::copy(node.b, node.b + n + 1, w);
    for (int r = 0; r <= n; ++r) {
      left.b[r] = w[0];
      right.b[n - r] = w[n - r];
      for (int k = 0; k < n - r; ++k) w[k] = (w[k] + w[k + 1]) * I(0.5);
    }
    const double mid = 0.5 * (node.t0 + node.t1);  // exact (a dyadic midpoint)
    left.t0 = node.t0, left.t1 = mid, left.depth = node.depth + 1;
    right.t0 = mid, right.t1 = node.t1, right.depth = node.depth + 1;
    stack[top++] = right;
    stack[top++] = left;
  }
  return {true, 0};
}

}  // namespace gauss6::reference::detail
