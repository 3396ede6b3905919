// Mass properties of a closed triangle mesh at uniform density, by the divergence
// theorem: the solid is the signed sum of the tetrahedra (r, a, b, c) that join a
// reference point r to each triangle (a, b, c), and each tetrahedron's volume,
// first and second moments have closed forms (exact for polyhedra; see e.g.
// Eberly, "Polyhedral Mass Properties (Revisited)", 2002, or Tonon, J. Math.
// Stat. 1(1), 2004). Load-time code: allocates, never throws.
#include "gauss6/geometry/mass_properties.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace gauss6 {
namespace {

// True when every directed edge (a, b) is matched by as many (b, a): the
// triangles form a closed, consistently oriented surface (a 2-cycle), the
// condition under which the divergence theorem gives the enclosed solid.
bool is_oriented_cycle(const MatrixX3i& F) {
  std::vector<std::pair<int32_t, int32_t>> fwd, rev;
  fwd.reserve(3 * static_cast<size_t>(F.rows()));
  rev.reserve(fwd.capacity());
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int32_t a = F(f, k), b = F(f, (k + 1) % 3);
      fwd.emplace_back(a, b);
      rev.emplace_back(b, a);
    }
  }
  std::sort(fwd.begin(), fwd.end());
  std::sort(rev.begin(), rev.end());
  return fwd == rev;
}

}  // namespace

bool compute_mass_properties(const TriangleMesh& m, double density, MassProperties* out,
                             std::string* error) {
  auto fail = [error](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (!(density > 0.0) || !std::isfinite(density))
    return fail("density must be positive and finite, got " + std::to_string(density));
  const int nv = num_vertices(m), nf = num_triangles(m);
  if (nf == 0) return fail("mesh '" + m.source + "' has no triangles");
  if ((m.F.array() < 0).any() || (m.F.array() >= nv).any())
    return fail("mesh '" + m.source + "' has a vertex index out of range");
  if (!m.V.allFinite()) return fail("mesh '" + m.source + "' has a non-finite vertex coordinate");
  if (!is_oriented_cycle(m.F))
    return fail("mesh '" + m.source +
                "' is not closed and consistently oriented (an edge is not matched by an "
                "opposite edge): its volume is undefined");

  // Reference point r: the mean of the vertices, so that the moments are taken
  // about a nearby point (small cancellation for meshes far from the origin).
  const Vec3 r = m.V.colwise().mean().transpose();

  // Sums over the tetrahedra (r, a, b, c), with d = det[a-r, b-r, c-r] = 6 x signed volume:
  //   volume          V  = sum d / 6
  //   first moment    S1 = sum d / 24 (a + b + c)
  //   second moment   S2 = sum d / 120 (a a^T + b b^T + c c^T + s s^T), s = a + b + c
  // (the fourth corner r is the origin of these local coordinates).
  double six_volume = 0;
  Vec3 s1 = Vec3::Zero();
  Mat3 s2 = Mat3::Zero();
  for (int f = 0; f < nf; ++f) {
    const Vec3 a = m.V.row(m.F(f, 0)).transpose() - r;
    const Vec3 b = m.V.row(m.F(f, 1)).transpose() - r;
    const Vec3 c = m.V.row(m.F(f, 2)).transpose() - r;
    const double d = a.dot(b.cross(c));
    const Vec3 s = a + b + c;
    six_volume += d;
    s1 += d * s;
    s2 += d * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  const double volume = six_volume / 6.0;
  if (!(volume > 0.0) || !std::isfinite(volume))
    return fail("mesh '" + m.source + "' encloses volume " + std::to_string(volume) +
                " <= 0: it is inside out (normals point inwards) or flat");

  // Centre of mass (relative to r), then the second moment about it.
  const Vec3 com_r = (s1 / 24.0) / volume;
  const Mat3 second_r = s2 / 120.0;                                        // int x x^T dV about r
  const Mat3 second_com = second_r - volume * com_r * com_r.transpose();  // about the COM
  Mat3 inertia = density * (second_com.trace() * Mat3::Identity() - second_com);
  inertia = 0.5 * (inertia + inertia.transpose());  // symmetric up to rounding already

  out->volume = volume;
  out->mass = density * volume;
  out->center_of_mass = r + com_r;
  out->inertia = inertia;
  return true;
}

Mat6 mass_matrix(const MassProperties& mp, const Mat3& R_WB) {
  Mat6 M = Mat6::Zero();
  M.topLeftCorner<3, 3>() = mp.mass * Mat3::Identity();
  const Mat3 I_W = R_WB * mp.inertia * R_WB.transpose();
  M.bottomRightCorner<3, 3>() = 0.5 * (I_W + I_W.transpose());  // exactly symmetric
  return M;
}

}  // namespace gauss6
