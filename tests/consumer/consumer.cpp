// A program of an engine using the installed gauss6 library: a unit cube falling
// onto a slab, one CCD step from G at height 1.5 down to -1.5, checked against the
// exact first contact (the bottom face at z = G - 1/2 reaches z = 0 at u = 1/3).
#include <cmath>
#include <cstdio>
#include <vector>

#include "gauss6/geometry/bvh.h"
#include "gauss6/step/ccd_step.h"
#include "gauss6/geometry/mesh.h"
#include "gauss6/geometry/pose.h"

using gauss6::Vec3;

// Axis-aligned box of sides a x b x c about `center`, 12 outward triangles.
static gauss6::TriangleMesh box(double a, double b, double c, const Vec3& center) {
  gauss6::TriangleMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    m.V.row(i) = (center + Vec3((i & 1) ? a / 2 : -a / 2, (i & 2) ? b / 2 : -b / 2, (i & 4) ? c / 2 : -c / 2))
                     .transpose();
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  m.F.resize(12, 3);
  for (int k = 0; k < 6; ++k) {
    const int* q = quads[k];
    m.F.row(2 * k) << q[0], q[1], q[2];
    m.F.row(2 * k + 1) << q[0], q[2], q[3];
  }
  m.source = "consumer box";
  return m;
}

int main() {
  const gauss6::TriangleMesh god = box(1, 1, 1, Vec3::Zero());           // body frame about G
  const gauss6::TriangleMesh slab = box(4, 4, 1, Vec3(0, 0, -0.5));      // world frame, top at z = 0
  const gauss6::Bvh god_bvh = gauss6::build_bvh(god), slab_bvh = gauss6::build_bvh(slab);
  const gauss6::CcdBody obstacle{&slab, &slab_bvh}, body{&god, &god_bvh};
  gauss6::CcdStepSettings settings;
  gauss6::CcdStepWorkspace ws;
  gauss6::CcdStepResult r;
  gauss6::ccd_step(&obstacle, 1, body, {{Vec3(0.1, 0.2, 1.5), gauss6::Quat{}}, {Vec3(0.1, 0.2, -1.5), gauss6::Quat{}}},
                   settings, &ws, &r);
  const double u_star = 1.0 / 3;
  // Conservative (never past the contact) and close to it: time tolerance 1e-6 at speed 3.
  const bool ok = r.status == gauss6::CcdStatus::kOk && r.hit && r.u_hit <= u_star && u_star - r.u_hit <= 1e-5;
  std::printf("gauss6 %s: first contact at u = %.12f (exact 1/3): %s\n", GAUSS6_PACKAGE_VERSION, r.u_hit,
              ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
}
