// Exact rational helpers for the CCD tests (GMP): doubles as exact rationals,
// 3-vectors of rationals with their sums, scalings, dot and cross products, and
// the exact Cayley motion of METHOD.md section 4 from two double poses, so the
// tests can decide contacts exactly, independently of the code under test.
#pragma once

#include <gmpxx.h>

#include "gauss6/geometry/pose.h"

namespace gauss6::test {

inline mpq_class Q(double x) { return mpq_class(x); }  // exact

struct Q3 {
  mpq_class x, y, z;
};
inline Q3 q3(const Vec3& v) { return {Q(v.x()), Q(v.y()), Q(v.z())}; }
inline Q3 operator-(const Q3& a, const Q3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Q3 operator+(const Q3& a, const Q3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Q3 operator*(const mpq_class& s, const Q3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline mpq_class dot(const Q3& a, const Q3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Q3 cross(const Q3& a, const Q3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Vec3 to_double(const Q3& a) { return {a.x.get_d(), a.y.get_d(), a.z.get_d()}; }

// The exact Cayley motion from two double poses: p(u) = p0 + u dp,
// R(u) = C(u g) R(q0) with R(q0) the rational rotation of q0 and g = vec(qr) /
// scalar(qr), qr = q1 conj(q0).
struct ExactMotion {
  Q3 p0, dp, g;
  mpq_class R0[9];
  ExactMotion(const Pose& x0, const Pose& x1) {
    p0 = q3(x0.p);
    dp = q3(x1.p) - p0;
    const mpq_class w = Q(x0.q.w), x = Q(x0.q.x), y = Q(x0.q.y), z = Q(x0.q.z);
    const mpq_class n = w * w + x * x + y * y + z * z;
    const mpq_class e[9] = {w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y),
                            2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x),
                            2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z};
    for (int i = 0; i < 9; ++i) R0[i] = e[i] / n;
    const mpq_class aw = Q(x1.q.w), ax = Q(x1.q.x), ay = Q(x1.q.y), az = Q(x1.q.z);
    const mpq_class bw = w, bx = -x, by = -y, bz = -z;
    const mpq_class rw = aw * bw - ax * bx - ay * by - az * bz;
    const mpq_class rx = aw * bx + ax * bw + ay * bz - az * by;
    const mpq_class ry = aw * by - ax * bz + ay * bw + az * bx;
    const mpq_class rz = aw * bz + ax * by - ay * bx + az * bw;
    g = {rx / rw, ry / rw, rz / rw};  // the sign of qr cancels in the quotient
  }
  // World point at u of the body point r.
  Q3 point(const mpq_class& u, const Q3& r) const {
    const Q3 v{R0[0] * r.x + R0[1] * r.y + R0[2] * r.z, R0[3] * r.x + R0[4] * r.y + R0[5] * r.z,
               R0[6] * r.x + R0[7] * r.y + R0[8] * r.z};
    const Q3 h = u * g;
    const mpq_class hh = dot(h, h);
    const Q3 Cv = (1 / (1 + hh)) * ((((1 - hh) * v) + ((2 * dot(h, v)) * h)) + (mpq_class(2) * cross(h, v)));
    return (p0 + u * dp) + Cv;
  }
};

}  // namespace gauss6::test
