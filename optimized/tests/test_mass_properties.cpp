// Tests of mass_properties.h against closed forms: box, tetrahedron, regular
// prism (exact) and its convergence to the cylinder, icospheres converging to the
// ball, invariance under rigid motions, and refusal of open or inside-out meshes.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "gauss6/geometry/mass_properties.h"
#include "mesh_shapes.h"

using namespace gauss6;
using gauss6::test::flipped;
using gauss6::test::make_box;
using gauss6::test::make_icosphere;
using gauss6::test::make_prism;
using gauss6::test::make_unit_tetrahedron;

namespace {

MassProperties mass_properties_or_fail(const TriangleMesh& m, double density) {
  MassProperties mp;
  std::string error;
  INFO(m.source);
  REQUIRE(compute_mass_properties(m, density, &mp, &error));
  CHECK(error.empty());
  return mp;
}

// |a - b| / |b| in the Frobenius norm.
double relative_error(const Mat3& a, const Mat3& b) { return (a - b).norm() / b.norm(); }

// Closed form of the prism over the regular n-gon (circumradius r, height h,
// centred): with t = 2 pi / n, the n-gon has area A = n r^2 sin(t) / 2 and polar
// moment J = int (x^2 + y^2) dA = n r^4 sin(t) (2 + cos(t)) / 12 (each of its n
// triangles (0, p, q) has int |x|^2 = area (|p|^2 + |q|^2 + p.q) / 6), isotropic
// in the plane for n >= 3. Then m = rho A h, Izz = rho h J,
// Ixx = Iyy = rho (h J / 2 + A h^3 / 12).
Mat3 prism_inertia(int n, double r, double h, double rho, double* mass) {
  const double t = 2.0 * M_PI / n;
  const double A = n * r * r * std::sin(t) / 2.0;
  const double J = n * std::pow(r, 4) * std::sin(t) * (2.0 + std::cos(t)) / 12.0;
  *mass = rho * A * h;
  const double ixx = rho * (h * J / 2.0 + A * h * h * h / 12.0);
  return Eigen::Vector3d(ixx, ixx, rho * h * J).asDiagonal();
}

}  // namespace

TEST_CASE("Box a x b x c: exact volume, centre and inertia", "[mass]") {
  // Awkward sides (1/3, 2/7, 5) and an off-origin centre. The divergence-theorem
  // sums are exact for a box up to rounding: relative tolerance 1e-12 (about
  // 5000 ulps, the sums have tens of terms of mixed sign).
  const double a = 1.0 / 3.0, b = 2.0 / 7.0, c = 5.0, rho = 2.5;
  const Vec3 center(1.25, -3.0, 0.1);
  const MassProperties mp = mass_properties_or_fail(make_box(a, b, c, center), rho);
  const double m = rho * a * b * c;
  CHECK(mp.volume == Approx(a * b * c).epsilon(1e-12));
  CHECK(mp.mass == Approx(m).epsilon(1e-12));
  CHECK((mp.center_of_mass - center).norm() < 1e-12 * center.norm());
  const Mat3 expected =
      Eigen::Vector3d(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12)
          .asDiagonal();
  CHECK(relative_error(mp.inertia, expected) < 1e-12);
}

TEST_CASE("Unit tetrahedron: inertia about its centroid by hand", "[mass]") {
  // Corners 0, e1, e2, e3: V = 1/6, centroid (1/4, 1/4, 1/4), int x^2 = 1/60,
  // int xy = 1/120, so about the origin Ixx = 1/30, Ixy = -1/120; shifted to the
  // centroid: Ixx = 1/30 - V (1/16 + 1/16) = 1/80, Ixy = -1/120 + V / 16 = 1/480.
  const MassProperties mp = mass_properties_or_fail(make_unit_tetrahedron(), 1.0);
  CHECK(mp.volume == Approx(1.0 / 6.0).epsilon(1e-14));
  CHECK((mp.center_of_mass - Vec3::Constant(0.25)).norm() < 1e-15);
  Mat3 expected;
  expected << 1.0 / 80, 1.0 / 480, 1.0 / 480,  //
      1.0 / 480, 1.0 / 80, 1.0 / 480,          //
      1.0 / 480, 1.0 / 480, 1.0 / 80;
  CHECK(relative_error(mp.inertia, expected) < 1e-14);  // a handful of roundings on O(1) values
}

TEST_CASE("Regular prism: exact n-gon closed form, O(1/n^2) to the cylinder", "[mass]") {
  const double r = 0.7, h = 1.9, rho = 3.0;
  SECTION("exact for the polygonal prism") {
    for (int n : {3, 5, 17, 100}) {
      INFO("n = " << n);
      double m = 0;
      const Mat3 expected = prism_inertia(n, r, h, rho, &m);
      const MassProperties mp = mass_properties_or_fail(make_prism(n, r, h), rho);
      CHECK(mp.mass == Approx(m).epsilon(1e-12));
      CHECK(mp.center_of_mass.norm() < 1e-13);  // symmetric about the origin
      // Tolerance 1e-12 relative: the closed form itself uses sin/cos of 2 pi / n
      // and the mesh's vertices are rounded cos/sin values, both within 1e-15.
      CHECK(relative_error(mp.inertia, expected) < 1e-12);
    }
  }
  SECTION("converges to the smooth cylinder like 1/n^2") {
    // Smooth: m = rho pi r^2 h, Izz = m r^2 / 2. Series of the closed form in
    // t = 2 pi / n: volume ratio sin(t)/t = 1 - t^2/6 + ..., Izz ratio
    // sin(t)(2 + cos(t)) / (3t) = 1 - t^2/3 + ..., so n^2 times the relative
    // error tends to 2 pi^2 / 3 (volume) and 4 pi^2 / 3 (Izz), from below.
    for (int n : {32, 64, 128, 256}) {
      INFO("n = " << n);
      const MassProperties mp = mass_properties_or_fail(make_prism(n, r, h), rho);
      const double m_smooth = rho * M_PI * r * r * h;
      const double izz_smooth = m_smooth * r * r / 2;
      const double n2_volume_error = n * n * (1.0 - mp.mass / m_smooth);
      const double n2_izz_error = n * n * (1.0 - mp.inertia(2, 2) / izz_smooth);
      // The next terms are O(t^2) relative: within 1% of the limit for n >= 32.
      CHECK(n2_volume_error > 0.99 * 2 * M_PI * M_PI / 3);
      CHECK(n2_volume_error < 2 * M_PI * M_PI / 3);
      CHECK(n2_izz_error > 0.99 * 4 * M_PI * M_PI / 3);
      CHECK(n2_izz_error < 4 * M_PI * M_PI / 3);
    }
  }
}

TEST_CASE("Icospheres: isotropic inertia, converging to the ball", "[mass]") {
  const double r = 1.3, rho = 0.8;
  const double ball_volume = 4.0 / 3.0 * M_PI * r * r * r;
  double previous_volume = 0, previous_error = 0;
  for (int level = 0; level <= 5; ++level) {
    INFO("level " << level);
    const MassProperties mp = mass_properties_or_fail(make_icosphere(level, r), rho);
    // Icosahedral symmetry forces I = (trace / 3) Id exactly; rounding only.
    const double iso = mp.inertia.trace() / 3.0;
    CHECK((mp.inertia - iso * Mat3::Identity()).norm() < 1e-13 * iso);
    CHECK(mp.center_of_mass.norm() < 1e-14);
    // Inscribed polyhedra, each containing the last: volume increases below the ball's.
    CHECK(mp.volume > previous_volume);
    CHECK(mp.volume < ball_volume);
    previous_volume = mp.volume;
    // I / (m r^2) tends to 2/5 from below; the error shrinks by a factor tending
    // to 4 per level (edge length halves, error O(h^2)): measured 3.78, 3.94,
    // 3.99, 4.00 for levels 2..5.
    const double error = 0.4 - iso / (mp.mass * r * r);
    CHECK(error > 0);
    if (level >= 2) {
      CHECK(previous_error / error > 3.75);
      CHECK(previous_error / error < 4.05);
    }
    previous_error = error;
  }
  // Level 5 (20480 triangles): measured 1.442e-4; bounds catch a change either way.
  CHECK(previous_error > 1.3e-4);
  CHECK(previous_error < 1.6e-4);
}

TEST_CASE("Mass properties follow rigid motions", "[mass]") {
  // A body without symmetry: an icosphere scaled anisotropically and sheared
  // (a linear map with positive determinant: still closed and outward).
  TriangleMesh body = make_icosphere(2, 1.0);
  body.V = body.V * Eigen::Vector3d(1.0, 0.6, 0.3).asDiagonal();
  body.V.col(0) += 0.2 * body.V.col(1);  // shear: off-diagonal inertia
  const MassProperties mp0 = mass_properties_or_fail(body, 1.7);

  std::mt19937 rng(12345);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
    const Mat3 R = q.toRotationMatrix();
    const Vec3 t(10 * normal(rng), 10 * normal(rng), 10 * normal(rng));
    TriangleMesh moved = body;
    moved.V = (body.V * R.transpose()).rowwise() + t.transpose();
    const MassProperties mp = mass_properties_or_fail(moved, 1.7);
    // Rounding of the moved vertices (|t| ~ 10, size ~ 1) perturbs every moment by
    // about 1e-15 |t| relative: tolerances 1e-12 leave a wide margin.
    CHECK(mp.mass == Approx(mp0.mass).epsilon(1e-12));
    CHECK((mp.center_of_mass - (R * mp0.center_of_mass + t)).norm() < 1e-12 * (1 + t.norm()));
    CHECK(relative_error(mp.inertia, R * mp0.inertia * R.transpose()) < 1e-12);
  }
  // The shear made the tensor non-diagonal, so the rotation test was not vacuous.
  CHECK(std::abs(mp0.inertia(0, 1)) > 1e-3 * mp0.inertia.norm());
}

TEST_CASE("Open, inside-out or bad input is refused with a reason", "[mass]") {
  MassProperties mp;
  std::string error;
  const TriangleMesh box = make_box(1, 2, 3);

  CHECK_FALSE(compute_mass_properties(flipped(box), 1.0, &mp, &error));
  CHECK(error.find("inside out") != std::string::npos);

  TriangleMesh open = box;
  open.F.conservativeResize(11, 3);
  CHECK_FALSE(compute_mass_properties(open, 1.0, &mp, &error));
  CHECK(error.find("not closed") != std::string::npos);

  TriangleMesh one_flipped = box;
  std::swap(one_flipped.F(0, 1), one_flipped.F(0, 2));
  CHECK_FALSE(compute_mass_properties(one_flipped, 1.0, &mp, &error));

  CHECK_FALSE(compute_mass_properties(box, 0.0, &mp, &error));
  CHECK_FALSE(compute_mass_properties(box, std::nan(""), &mp, &error));
  CHECK(error.find("density") != std::string::npos);

  TriangleMesh bad_index = box;
  bad_index.F(3, 0) = 8;
  CHECK_FALSE(compute_mass_properties(bad_index, 1.0, &mp, &error));
  CHECK_FALSE(compute_mass_properties(TriangleMesh{}, 1.0, &mp, &error));
}

TEST_CASE("mass_matrix is diag(m I3, R I R^T), symmetric positive definite", "[mass]") {
  MassProperties mp;
  std::string error;
  REQUIRE(compute_mass_properties(make_box(1, 2, 3), 2.0, &mp, &error));
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, -1).normalized()).toRotationMatrix();
  const Mat6 M = mass_matrix(mp, R);
  CHECK(M.topLeftCorner<3, 3>() == mp.mass * Mat3::Identity());
  CHECK(M.topRightCorner<3, 3>().isZero(0.0));
  CHECK(M.bottomLeftCorner<3, 3>().isZero(0.0));
  CHECK(relative_error(M.bottomRightCorner<3, 3>(), R * mp.inertia * R.transpose()) < 1e-15);
  CHECK(M == M.transpose());
  CHECK(Eigen::LLT<Mat6>(M).info() == Eigen::Success);
}
