// Exact vertex/face and edge/edge continuous collision primitives (linear and
// Cayley motions): coplanarity polynomials over the integers, exact root
// isolation in [0, 1] (CGAL Algebraic_kernel_d_1, MPFI), and exact contact
// tests at the roots by signs of polynomials at algebraic numbers.
// See gauss6/reference/ccd.h.
#include "gauss6/reference/ccd.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <CGAL/Algebraic_kernel_d_1.h>
#include <CGAL/Gmpz.h>

namespace gauss6::reference {
namespace {

using AK = CGAL::Algebraic_kernel_d_1<CGAL::Gmpz>;
using Alg = AK::Algebraic_real_1;
using CPoly = AK::Polynomial_1;
using Bound = AK::Bound;  // CGAL::Gmpq

// ---------------------------------------------------------------------------
// Dense integer polynomials: c[i] is the coefficient of u^i; no trailing zero
// coefficient, so the zero polynomial is empty and degree = size - 1.

using ZPoly = std::vector<mpz_class>;
using ZVec = std::array<ZPoly, 3>;

void trim(ZPoly* p) {
  while (!p->empty() && p->back() == 0) p->pop_back();
}

ZPoly constant(const mpz_class& c) { return c == 0 ? ZPoly{} : ZPoly{c}; }

ZPoly add(const ZPoly& a, const ZPoly& b) {
  ZPoly r(std::max(a.size(), b.size()));
  for (size_t i = 0; i < a.size(); ++i) r[i] += a[i];
  for (size_t i = 0; i < b.size(); ++i) r[i] += b[i];
  trim(&r);
  return r;
}

ZPoly sub(const ZPoly& a, const ZPoly& b) {
  ZPoly r(std::max(a.size(), b.size()));
  for (size_t i = 0; i < a.size(); ++i) r[i] += a[i];
  for (size_t i = 0; i < b.size(); ++i) r[i] -= b[i];
  trim(&r);
  return r;
}

ZPoly mul(const ZPoly& a, const ZPoly& b) {
  if (a.empty() || b.empty()) return {};
  ZPoly r(a.size() + b.size() - 1);
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = 0; j < b.size(); ++j) r[i + j] += a[i] * b[j];
  trim(&r);
  return r;
}

int degree(const ZPoly& p) { return int(p.size()) - 1; }

// Divides out the positive content (gcd of the coefficients): the sign at every
// u is unchanged, the numbers get smaller.
void make_primitive(ZPoly* p) {
  if (p->empty()) return;
  mpz_class g = 0;
  for (const auto& c : *p) mpz_gcd(g.get_mpz_t(), g.get_mpz_t(), c.get_mpz_t());
  if (g > 1)
    for (auto& c : *p) mpz_divexact(c.get_mpz_t(), c.get_mpz_t(), g.get_mpz_t());
}

// If the primitive polynomial d divides f, sets *q = f / d (integral by
// Gauss's lemma) and returns true. Integer long division: no rationals.
bool divide_exact(const ZPoly& f, const ZPoly& d, ZPoly* q) {
  if (f.empty() || degree(f) < degree(d)) return false;
  const int n = degree(d);
  ZPoly r = f;
  q->assign(f.size() - d.size() + 1, mpz_class(0));
  for (int i = degree(f) - n; i >= 0; --i) {
    if (!mpz_divisible_p(r[i + n].get_mpz_t(), d.back().get_mpz_t())) return false;
    mpz_divexact((*q)[i].get_mpz_t(), r[i + n].get_mpz_t(), d.back().get_mpz_t());
    for (int j = 0; j <= n; ++j) r[i + j] -= (*q)[i] * d[j];
  }
  for (const auto& c : r)
    if (c != 0) return false;
  trim(q);
  return true;
}

// Removes every factor w (a polynomial that is positive on R) from p.
void strip_factor(ZPoly* p, ZPoly w) {
  make_primitive(p);
  if (degree(w) < 1) return;
  make_primitive(&w);
  ZPoly q;
  while (divide_exact(*p, w, &q)) *p = q;
}

CPoly to_cgal(const ZPoly& p) {
  std::vector<CGAL::Gmpz> c;
  c.reserve(p.size());
  for (const auto& x : p) c.emplace_back(x.get_mpz_t());
  return CPoly(c.begin(), c.end());
}

ZPoly from_cgal(const CPoly& p) {
  ZPoly r;
  for (int i = 0; i <= p.degree(); ++i) r.emplace_back(p[i].mpz());
  trim(&r);
  return r;
}

const AK& kernel() {
  static const AK ak;
  return ak;
}

int sign_of(const mpz_class& x) { return sgn(x); }

// Exact sign of p at the algebraic number a.
int sign_at(const ZPoly& p, const Alg& a) {
  if (p.empty()) return 0;
  if (p.size() == 1) return sign_of(p[0]);
  return int(kernel().sign_at_1_object()(to_cgal(p), a));
}

// True when p has no root in [0, b] (b > 0), by the signs of the Bernstein
// coefficients of p(b t) on t in [0, 1]: with b = N / D and times n! D^n,
// B_k = sum_{i<=k} C(k,i) i! (n-i)! a_i N^i D^(n-i), all of one strict sign.
bool no_root_in(const ZPoly& p, const mpq_class& b) {
  const int n = degree(p);
  if (n < 0) return false;
  std::vector<mpz_class> fact(n + 1, 1), scaled(n + 1);
  for (int i = 1; i <= n; ++i) fact[i] = fact[i - 1] * i;
  for (int i = 0; i <= n; ++i) {
    mpz_class num_pow, den_pow;
    mpz_pow_ui(num_pow.get_mpz_t(), b.get_num_mpz_t(), i);
    mpz_pow_ui(den_pow.get_mpz_t(), b.get_den_mpz_t(), n - i);
    scaled[i] = p[i] * num_pow * den_pow * fact[i] * fact[n - i];
  }
  int common = 0;
  for (int k = 0; k <= n; ++k) {
    mpz_class sum = 0, binom = 1;  // binom = C(k, i)
    for (int i = 0; i <= k; ++i) {
      sum += binom * scaled[i];
      binom = binom * (k - i) / (i + 1);
    }
    const int s = sgn(sum);
    if (s == 0 || (common != 0 && s != common)) return false;
    common = s;
  }
  return true;
}

bool less(const Alg& a, const Alg& b) { return kernel().compare_1_object()(a, b) == CGAL::SMALLER; }

// The distinct real roots of p in [0, u_max], increasing (0 < u_max <= 1).
std::vector<Alg> roots_in(const ZPoly& p, const mpq_class& u_max) {
  if (degree(p) < 1 || no_root_in(p, u_max)) return {};
  std::vector<Alg> all, in;
  kernel().solve_1_object()(to_cgal(p), /*known_to_be_square_free=*/false, std::back_inserter(all));
  const auto compare = kernel().compare_1_object();
  for (const Alg& a : all)
    if (compare(a, Bound(0)) != CGAL::SMALLER && compare(a, Bound(u_max.get_mpq_t())) != CGAL::LARGER)
      in.push_back(a);
  std::sort(in.begin(), in.end(), less);
  return in;
}

// ---------------------------------------------------------------------------
// Points moving on x(u) = N(u) / W(u)^k, k in {0, 1}, W > 0 on R (W = 1 for
// linear motion). Only signs are ever read, so every quantity is kept as the
// numerator of a fraction whose denominator is a positive power of W.

struct WPoint {
  ZVec x;
  int k = 0;
};

struct Weight {
  ZPoly w{mpz_class(1)};  // W(u)
  ZPoly strip;            // a factor of W that is positive on R (empty: none)
};

ZVec lift(const ZVec& x, int times, const Weight& w) {
  ZVec r = x;
  for (int t = 0; t < times; ++t)
    for (auto& c : r) c = mul(c, w.w);
  return r;
}

WPoint minus(const WPoint& a, const WPoint& b, const Weight& w) {
  const int k = std::max(a.k, b.k);
  const ZVec xa = lift(a.x, k - a.k, w), xb = lift(b.x, k - b.k, w);
  return {{sub(xa[0], xb[0]), sub(xa[1], xb[1]), sub(xa[2], xb[2])}, k};
}

WPoint cross(const WPoint& a, const WPoint& b) {
  return {{sub(mul(a.x[1], b.x[2]), mul(a.x[2], b.x[1])), sub(mul(a.x[2], b.x[0]), mul(a.x[0], b.x[2])),
           sub(mul(a.x[0], b.x[1]), mul(a.x[1], b.x[0]))},
          a.k + b.k};
}

// Numerator of a . b (its denominator W^(ka + kb) is positive).
ZPoly dot(const WPoint& a, const WPoint& b) {
  return add(add(mul(a.x[0], b.x[0]), mul(a.x[1], b.x[1])), mul(a.x[2], b.x[2]));
}

// Polynomials deciding "p lies on the closed segment [a, b]" (at a time where
// the test is asked).
struct SegmentTest {
  ZVec d, e, c;      // b - a, p - a, (b - a) x (p - a)
  ZPoly dot_a, dot_b;  // (p - a).(b - a), (p - b).(a - b)

  SegmentTest(const WPoint& p, const WPoint& a, const WPoint& b, const Weight& w) {
    // Signs only: numerators over positive powers of W.
    const WPoint ab = minus(b, a, w), ap = minus(p, a, w), bp = minus(p, b, w);
    const WPoint cr = cross(ab, ap);
    for (int i = 0; i < 3; ++i) {
      d[i] = ab.x[i];
      e[i] = ap.x[i];
      c[i] = cr.x[i];
    }
    dot_a = dot(ap, ab);
    dot_b = sub(ZPoly{}, dot(bp, ab));
  }

  bool holds(const Alg& u) const {
    const bool point_segment = sign_at(d[0], u) == 0 && sign_at(d[1], u) == 0 && sign_at(d[2], u) == 0;
    if (point_segment) return sign_at(e[0], u) == 0 && sign_at(e[1], u) == 0 && sign_at(e[2], u) == 0;
    return sign_at(c[0], u) == 0 && sign_at(c[1], u) == 0 && sign_at(c[2], u) == 0 &&
           sign_at(dot_a, u) >= 0 && sign_at(dot_b, u) >= 0;
  }

  void collect(std::vector<const ZPoly*>* out) const {
    for (int i = 0; i < 3; ++i) out->insert(out->end(), {&d[i], &e[i], &c[i]});
    out->insert(out->end(), {&dot_a, &dot_b});
  }
};

ZPoly primitive(ZPoly p) {
  make_primitive(&p);
  return p;
}

// Everything needed to decide contact of one vertex/face or edge/edge pair.
// The coplanarity polynomial comes first; the polynomials of the planar test
// are built only when it has a root in [0, 1] (or vanishes identically).
struct PairPredicates {
  CcdQuery::Kind kind;
  std::array<WPoint, 4> pts;      // VF: p, a, b, c; EE: a0, a1, b0, b1
  Weight weight;
  ZPoly coplanar;                 // zero exactly when the 4 points are coplanar
  bool complete = false;          // whether the members below are built
  ZVec normal;                    // triangle normal (VF) or da x db (EE)
  std::vector<ZPoly> orient;      // VF: 3 edge sides; EE: o1..o4
  std::vector<SegmentTest> segments;  // the degenerate (collinear) case

  PairPredicates(CcdQuery::Kind k, const std::array<WPoint, 4>& points, const Weight& w)
      : kind(k), pts(points), weight(w) {
    const auto& [p0, p1, p2, p3] = pts;
    if (kind == CcdQuery::kVertexFace)
      coplanar = dot(cross(minus(p2, p1, w), minus(p3, p1, w)), minus(p0, p1, w));
    else
      coplanar = dot(minus(p2, p0, w), cross(minus(p1, p0, w), minus(p3, p2, w)));
    strip_factor(&coplanar, w.strip);
  }

  void build_planar_test() {
    if (complete) return;
    complete = true;
    const Weight& w = weight;
    if (kind == CcdQuery::kVertexFace) {
      const auto& [p, a, b, c] = pts;
      const WPoint ab = minus(b, a, w), bc = minus(c, b, w), ca = minus(a, c, w), ac = minus(c, a, w);
      const WPoint ap = minus(p, a, w), bp = minus(p, b, w), cp = minus(p, c, w);
      const WPoint n = cross(ab, ac);
      for (int i = 0; i < 3; ++i) normal[i] = primitive(n.x[i]);
      // p is on the inner side of each edge, seen along n.
      orient = {primitive(dot(cross(ab, ap), n)), primitive(dot(cross(bc, bp), n)),
                primitive(dot(cross(ca, cp), n))};
      // Collinear triangle: its hull is the longest of its three sides.
      segments = {SegmentTest(p, a, b, w), SegmentTest(p, b, c, w), SegmentTest(p, c, a, w)};
    } else {
      const auto& [a0, a1, b0, b1] = pts;
      const WPoint da = minus(a1, a0, w), db = minus(b1, b0, w);
      const WPoint n = cross(da, db);
      for (int i = 0; i < 3; ++i) normal[i] = primitive(n.x[i]);
      // Coplanar, not parallel: each segment's endpoints are not strictly on one
      // side of the other segment's line.
      orient = {primitive(dot(cross(da, minus(b0, a0, w)), n)), primitive(dot(cross(da, minus(b1, a0, w)), n)),
                primitive(dot(cross(db, minus(a0, b0, w)), n)), primitive(dot(cross(db, minus(a1, b0, w)), n))};
      // Parallel or zero-length: they touch iff an endpoint lies on the other segment.
      segments = {SegmentTest(a0, b0, b1, w), SegmentTest(a1, b0, b1, w), SegmentTest(b0, a0, a1, w),
                  SegmentTest(b1, a0, a1, w)};
    }
  }

  // Contact at u, knowing the 4 points are coplanar at u (build_planar_test() first).
  bool contact(const Alg& u) const {
    const bool nondegenerate =
        sign_at(normal[0], u) != 0 || sign_at(normal[1], u) != 0 || sign_at(normal[2], u) != 0;
    if (nondegenerate) {
      if (kind == CcdQuery::kVertexFace)
        return sign_at(orient[0], u) >= 0 && sign_at(orient[1], u) >= 0 && sign_at(orient[2], u) >= 0;
      return sign_at(orient[0], u) * sign_at(orient[1], u) <= 0 &&
             sign_at(orient[2], u) * sign_at(orient[3], u) <= 0;
    }
    for (const auto& s : segments)
      if (s.holds(u)) return true;
    return false;
  }
};

PairPredicates vertex_face_predicates(const WPoint& p, const WPoint& a, const WPoint& b, const WPoint& c,
                                      const Weight& w) {
  return PairPredicates(CcdQuery::kVertexFace, {p, a, b, c}, w);
}

PairPredicates edge_edge_predicates(const WPoint& a0, const WPoint& a1, const WPoint& b0, const WPoint& b1,
                                    const Weight& w) {
  return PairPredicates(CcdQuery::kEdgeEdge, {a0, a1, b0, b1}, w);
}

// First u in [0, u_max] of contact, exactly.
std::optional<Alg> first_contact(PairPredicates& pr, const mpq_class& u_max) {
  if (!pr.coplanar.empty()) {
    // Contact needs coplanarity: the candidates are the roots of the coplanarity polynomial.
    const std::vector<Alg> roots = roots_in(pr.coplanar, u_max);
    if (roots.empty()) return std::nullopt;
    pr.build_planar_test();
    for (const Alg& u : roots)
      if (pr.contact(u)) return u;
    return std::nullopt;
  }
  pr.build_planar_test();
  // Coplanar all along: the first contact time is 0 or a root of one of the
  // polynomials the planar test reads (the test is a function of their signs,
  // which are constant between consecutive roots).
  std::vector<const ZPoly*> polys;
  for (int i = 0; i < 3; ++i) polys.push_back(&pr.normal[i]);
  for (const auto& o : pr.orient) polys.push_back(&o);
  for (const auto& s : pr.segments) s.collect(&polys);
  std::vector<Alg> candidates{Alg(0)};
  for (const ZPoly* p : polys)
    for (const Alg& u : roots_in(*p, u_max)) candidates.push_back(u);
  std::sort(candidates.begin(), candidates.end(), less);
  const auto compare = kernel().compare_1_object();
  candidates.erase(std::unique(candidates.begin(), candidates.end(),
                               [&](const Alg& a, const Alg& b) { return compare(a, b) == CGAL::EQUAL; }),
                   candidates.end());
  for (const Alg& u : candidates)
    if (pr.contact(u)) return u;
  return std::nullopt;
}

// The exact time of impact record of the algebraic number u in [0, 1].
ExactToi make_toi(const Alg& u) {
  ExactToi toi;
  toi.hit = true;
  const CPoly p = kernel().compute_polynomial_1_object()(u);
  toi.poly = from_cgal(p);
  const std::pair<Bound, Bound> iso = kernel().isolate_1_object()(u, p);
  toi.isolating_lower = mpq_class(iso.first.mpq());
  toi.isolating_upper = mpq_class(iso.second.mpq());
  // Largest double d <= u, from a relative approximation, then corrected exactly.
  const auto compare = kernel().compare_1_object();
  const std::pair<Bound, Bound> approx = kernel().approximate_relative_1_object()(u, 64);
  double d = mpq_get_d(approx.first.mpq());  // truncates toward zero
  d = std::clamp(d, 0.0, 1.0);
  while (d > 0 && compare(u, Bound(d)) == CGAL::SMALLER) d = std::nextafter(d, -1.0);
  while (d < 1 && compare(u, Bound(std::nextafter(d, 2.0))) != CGAL::SMALLER) d = std::nextafter(d, 2.0);
  toi.lower = d;
  toi.upper = compare(u, Bound(d)) == CGAL::EQUAL ? d : std::nextafter(d, 2.0);
  return toi;
}

Alg to_algebraic(const ExactToi& t) {
  if (t.isolating_lower == t.isolating_upper) return Alg(Bound(t.isolating_lower.get_mpq_t()));
  return kernel().construct_algebraic_real_1_object()(to_cgal(t.poly), Bound(t.isolating_lower.get_mpq_t()),
                                                      Bound(t.isolating_upper.get_mpq_t()));
}

ExactToi solve(PairPredicates pr, double u_max = 1.0) {
  if (!(u_max > 0 && u_max <= 1)) throw std::invalid_argument("exact CCD: u_end must be in (0, 1]");
  const std::optional<Alg> u = first_contact(pr, mpq_class(u_max));
  return u ? make_toi(*u) : ExactToi{};
}

// ---------------------------------------------------------------------------
// Exact inputs.

// x = m 2^e exactly, m an integer (0 for x == 0).
void dyadic(double x, mpz_class* m, long* e) {
  if (!std::isfinite(x)) throw std::domain_error("non-finite coordinate in an exact query");
  if (x == 0) {
    *m = 0;
    *e = 0;
    return;
  }
  int exponent = 0;
  const double f = std::frexp(x, &exponent);  // x = f 2^exponent, 0.5 <= |f| < 1
  *m = mpz_class(static_cast<long>(std::ldexp(f, 53)));
  *e = exponent - 53;
}

// The doubles xs times one common power of two 2^-E, as integers.
std::vector<mpz_class> scale_to_integers(const std::vector<double>& xs) {
  std::vector<mpz_class> m(xs.size());
  std::vector<long> e(xs.size());
  long emin = 0;
  bool any = false;
  for (size_t i = 0; i < xs.size(); ++i) {
    dyadic(xs[i], &m[i], &e[i]);
    if (m[i] != 0 && (!any || e[i] < emin)) emin = e[i], any = true;
  }
  for (size_t i = 0; i < xs.size(); ++i)
    if (m[i] != 0) mpz_mul_2exp(m[i].get_mpz_t(), m[i].get_mpz_t(), static_cast<mp_bitcnt_t>(e[i] - emin));
  return m;
}

mpq_class exact(double x) {
  if (!std::isfinite(x)) throw std::domain_error("non-finite coordinate in an exact query");
  return mpq_class(x);  // a double is a dyadic rational: exact
}

mpq_class exact(const Rational& r) {
  mpq_class q(mpz_class(r.num), mpz_class(r.den));
  q.canonicalize();
  return q;
}

// Linear motion: scale all 8 points by the lcm of their denominators.
std::array<WPoint, 4> linear_points(const std::array<ExactPoint, 4>& x0, const std::array<ExactPoint, 4>& x1) {
  mpz_class l = 1;
  for (const auto* set : {&x0, &x1})
    for (const auto& p : *set)
      for (const auto& c : p) mpz_lcm(l.get_mpz_t(), l.get_mpz_t(), c.get_den_mpz_t());
  std::array<WPoint, 4> pts;
  for (int i = 0; i < 4; ++i)
    for (int c = 0; c < 3; ++c) {
      const mpq_class a = x0[i][c] * l, b = x1[i][c] * l;  // integers
      pts[i].x[c] = ZPoly{a.get_num(), mpz_class(b.get_num() - a.get_num())};
      trim(&pts[i].x[c]);
    }
  return pts;
}

// Integer data of one Cayley motion and one feature pair: positions scaled by
// a common power of two (a uniform scaling of space, which changes no contact time).
struct CayleyPair {
  Weight weight;
  std::array<std::array<ZPoly, 3>, 3> K;  // W0 I + 2 u s [v]x + 2 u^2 [v]x^2
  std::array<std::array<mpz_class, 3>, 3> R0hat;
  mpz_class n0;   // |q0|^2
  ZVec p_motion;  // W(u) (p0 + u dp)
  std::vector<mpz_class> scaled;  // the feature coordinates, scaled, in the caller's order
};

std::array<std::array<mpz_class, 3>, 3> unnormalised_rotation(const std::array<mpz_class, 4>& q) {
  const mpz_class &w = q[0], &x = q[1], &y = q[2], &z = q[3];
  return {{{w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)},
           {2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)},
           {2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z}}};
}

CayleyPair cayley_pair(const ExactCayleyMotion& m, const std::vector<Vec3>& features) {
  CayleyPair cp;
  std::vector<double> xs;
  for (const Vec3& p : {m.X0.p, m.X1.p})
    for (int c = 0; c < 3; ++c) xs.push_back(p[c]);
  for (const Vec3& p : features)
    for (int c = 0; c < 3; ++c) xs.push_back(p[c]);
  const std::vector<mpz_class> z = scale_to_integers(xs);
  cp.scaled.assign(z.begin() + 6, z.end());

  const mpz_class& s = m.s;
  const auto& v = m.v;
  const mpz_class v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  cp.n0 = m.q0[0] * m.q0[0] + m.q0[1] * m.q0[1] + m.q0[2] * m.q0[2] + m.q0[3] * m.q0[3];
  cp.R0hat = unnormalised_rotation(m.q0);
  const ZPoly W0 = [&] {
    ZPoly w{s * s, mpz_class(0), v2};
    trim(&w);
    return w;
  }();
  cp.weight.w = mul(constant(cp.n0), W0);
  cp.weight.strip = degree(W0) >= 1 ? W0 : ZPoly{};
  // [v]x and [v]x^2 = v v^T - |v|^2 I.
  const mpz_class vx[3][3] = {{0, -v[2], v[1]}, {v[2], 0, -v[0]}, {-v[1], v[0], 0}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const mpz_class vx2 = v[i] * v[j] - (i == j ? v2 : mpz_class(0));
      ZPoly k{mpz_class(0), 2 * s * vx[i][j], 2 * vx2};
      if (i == j) k = add(k, W0);
      trim(&k);
      cp.K[i][j] = k;
    }
  for (int c = 0; c < 3; ++c) {
    ZPoly line{z[c], mpz_class(z[3 + c] - z[c])};  // p0 + u (p1 - p0)
    trim(&line);
    cp.p_motion[c] = mul(cp.weight.w, line);
  }
  return cp;
}

// Body point number i of the scaled features, moving: N(u) = W (p0 + u dp) + K R0hat r.
WPoint moving_point(const CayleyPair& cp, int i) {
  std::array<mpz_class, 3> rotated;
  for (int a = 0; a < 3; ++a) {
    rotated[a] = 0;
    for (int b = 0; b < 3; ++b) rotated[a] += cp.R0hat[a][b] * cp.scaled[3 * i + b];
  }
  WPoint p;
  p.k = 1;
  for (int a = 0; a < 3; ++a) {
    ZPoly x = cp.p_motion[a];
    for (int b = 0; b < 3; ++b) x = add(x, mul(cp.K[a][b], constant(rotated[b])));
    p.x[a] = x;
  }
  return p;
}

WPoint static_point(const CayleyPair& cp, int i) {
  WPoint p;
  for (int a = 0; a < 3; ++a) p.x[a] = constant(cp.scaled[3 * i + a]);
  return p;
}

PairPredicates moving_vertex_face_predicates(const ExactCayleyMotion& m, const Vec3& v_B,
                                             const std::array<Vec3, 3>& f_W) {
  const CayleyPair cp = cayley_pair(m, {v_B, f_W[0], f_W[1], f_W[2]});
  return vertex_face_predicates(moving_point(cp, 0), static_point(cp, 1), static_point(cp, 2),
                                static_point(cp, 3), cp.weight);
}

PairPredicates vertex_moving_face_predicates(const ExactCayleyMotion& m, const Vec3& v_W,
                                             const std::array<Vec3, 3>& f_B) {
  const CayleyPair cp = cayley_pair(m, {v_W, f_B[0], f_B[1], f_B[2]});
  return vertex_face_predicates(static_point(cp, 0), moving_point(cp, 1), moving_point(cp, 2),
                                moving_point(cp, 3), cp.weight);
}

PairPredicates moving_edge_edge_predicates(const ExactCayleyMotion& m, const std::array<Vec3, 2>& e_B,
                                           const std::array<Vec3, 2>& e_W) {
  const CayleyPair cp = cayley_pair(m, {e_B[0], e_B[1], e_W[0], e_W[1]});
  return edge_edge_predicates(moving_point(cp, 0), moving_point(cp, 1), static_point(cp, 2),
                              static_point(cp, 3), cp.weight);
}

}  // namespace

// ---------------------------------------------------------------------------
// Public functions.

int compare_toi(const ExactToi& a, const ExactToi& b) {
  if (!a.hit || !b.hit) return a.hit == b.hit ? 0 : (a.hit ? -1 : +1);
  if (a.upper < b.lower) return -1;
  if (a.lower > b.upper) return +1;
  return int(kernel().compare_1_object()(to_algebraic(a), to_algebraic(b)));
}

ExactPoint to_exact(const RationalPoint& p) { return {exact(p.xyz[0]), exact(p.xyz[1]), exact(p.xyz[2])}; }

ExactToi ccd_linear_vertex_face(const LinearVertexFaceQuery& q) {
  const auto& [v, f] = q;
  const auto pts = linear_points({v[0], f[0][0], f[0][1], f[0][2]}, {v[1], f[1][0], f[1][1], f[1][2]});
  return solve(vertex_face_predicates(pts[0], pts[1], pts[2], pts[3], Weight{}));
}

ExactToi ccd_linear_edge_edge(const LinearEdgeEdgeQuery& q) {
  const auto& [a, b] = q;
  const auto pts = linear_points({a[0][0], a[0][1], b[0][0], b[0][1]}, {a[1][0], a[1][1], b[1][0], b[1][1]});
  return solve(edge_edge_predicates(pts[0], pts[1], pts[2], pts[3], Weight{}));
}

ExactToi query_toi(const CcdQuery& q) {
  // Points in the order v, f0, f1, f2 (vertex/face) or a0, a1, b0, b1 (edge/edge).
  std::array<ExactPoint, 8> x;
  for (int i = 0; i < 8; ++i) x[i] = to_exact(q.points[i]);
  if (q.kind == CcdQuery::kVertexFace)
    return ccd_linear_vertex_face({{x[0], x[4]}, {{{x[1], x[2], x[3]}, {x[5], x[6], x[7]}}}});
  return ccd_linear_edge_edge({{{{x[0], x[1]}, {x[4], x[5]}}}, {{{x[2], x[3]}, {x[6], x[7]}}}});
}

ExactCayleyMotion make_exact_cayley_motion(const Pose& X0, const Pose& X1) {
  ExactCayleyMotion m;
  m.X0 = X0;
  m.X1 = X1;
  for (const Pose* X : {&X0, &X1})
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(X->p[c])) throw std::domain_error("make_exact_cayley_motion: non-finite position");
  const std::vector<mpz_class> a = scale_to_integers({X0.q.w, X0.q.x, X0.q.y, X0.q.z});
  const std::vector<mpz_class> b = scale_to_integers({X1.q.w, X1.q.x, X1.q.y, X1.q.z});
  const bool zero0 = a[0] == 0 && a[1] == 0 && a[2] == 0 && a[3] == 0;
  const bool zero1 = b[0] == 0 && b[1] == 0 && b[2] == 0 && b[3] == 0;
  if (zero0 || zero1) throw std::domain_error("make_exact_cayley_motion: zero quaternion");
  m.q0 = {a[0], a[1], a[2], a[3]};
  // qr = q1 conj(q0), Hamilton product, exactly.
  const mpz_class aw = a[0], ax = -a[1], ay = -a[2], az = -a[3];
  const mpz_class &bw = b[0], &bx = b[1], &by = b[2], &bz = b[3];
  mpz_class s = bw * aw - bx * ax - by * ay - bz * az;
  std::array<mpz_class, 3> v = {bw * ax + bx * aw + by * az - bz * ay, bw * ay - bx * az + by * aw + bz * ax,
                                bw * az + bx * ay - by * ax + bz * aw};
  if (s == 0) throw std::domain_error("make_exact_cayley_motion: relative rotation is a half turn");
  if (s < 0) {  // q and -q are the same rotation: take the short way
    s = -s;
    for (auto& c : v) c = -c;
  }
  m.s = s;
  m.v = v;
  return m;
}

ExactPoint transform_point_exact(const Pose& X, const Vec3& r_B) {
  const std::vector<mpz_class> q = scale_to_integers({X.q.w, X.q.x, X.q.y, X.q.z});
  const auto R = unnormalised_rotation({q[0], q[1], q[2], q[3]});
  const mpq_class n(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (n == 0) throw std::domain_error("transform_point_exact: zero quaternion");
  ExactPoint out;
  for (int a = 0; a < 3; ++a) {
    mpq_class acc = 0;
    for (int b = 0; b < 3; ++b) acc += mpq_class(R[a][b]) * exact(r_B[b]);
    out[a] = exact(X.p[a]) + acc / n;
  }
  return out;
}

ExactPoint motion_point_exact(const ExactCayleyMotion& m, const mpq_class& u, const Vec3& r_B) {
  // Directly from the definition, in rationals: p(u) + C(u g) R(q0) r_B.
  const ExactPoint r0 = [&] {
    Pose at_origin;
    at_origin.q = m.X0.q;
    return transform_point_exact(at_origin, r_B);  // R(q0) r_B
  }();
  const ExactPoint h = {u * mpq_class(m.v[0]) / mpq_class(m.s), u * mpq_class(m.v[1]) / mpq_class(m.s),
                        u * mpq_class(m.v[2]) / mpq_class(m.s)};
  const mpq_class h2 = h[0] * h[0] + h[1] * h[1] + h[2] * h[2];
  const ExactPoint hx = {h[1] * r0[2] - h[2] * r0[1], h[2] * r0[0] - h[0] * r0[2], h[0] * r0[1] - h[1] * r0[0]};
  const ExactPoint hhx = {h[1] * hx[2] - h[2] * hx[1], h[2] * hx[0] - h[0] * hx[2], h[0] * hx[1] - h[1] * hx[0]};
  const mpq_class f = mpq_class(2) / (1 + h2);
  ExactPoint out;
  for (int a = 0; a < 3; ++a) {
    const mpq_class p0 = exact(m.X0.p[a]), p1 = exact(m.X1.p[a]);
    out[a] = p0 + u * (p1 - p0) + r0[a] + f * (hx[a] + hhx[a]);
  }
  return out;
}

ExactToi ccd_rigid_vertex_face(const RigidVertexFaceQuery& q) {
  return solve(moving_vertex_face_predicates(*q.motion, q.vertex_B, q.face_W), q.u_end);
}

ExactToi ccd_rigid_face_vertex(const RigidFaceVertexQuery& q) {
  return solve(vertex_moving_face_predicates(*q.motion, q.vertex_W, q.face_B), q.u_end);
}

ExactToi ccd_rigid_edge_edge(const RigidEdgeEdgeQuery& q) {
  return solve(moving_edge_edge_predicates(*q.motion, q.edge_B, q.edge_W), q.u_end);
}

int coplanarity_degree(const RigidVertexFaceQuery& q) {
  return degree(moving_vertex_face_predicates(*q.motion, q.vertex_B, q.face_W).coplanar);
}

int coplanarity_degree(const RigidFaceVertexQuery& q) {
  return degree(vertex_moving_face_predicates(*q.motion, q.vertex_W, q.face_B).coplanar);
}

int coplanarity_degree(const RigidEdgeEdgeQuery& q) {
  return degree(moving_edge_edge_predicates(*q.motion, q.edge_B, q.edge_W).coplanar);
}

}  // namespace gauss6::reference
