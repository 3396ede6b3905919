// The projection's answer does not depend on how its rows are scaled, and its
// "optimal" is a certificate in a scale-free form: the feasible cone
// {a : J a >= b} is the same when a row (J_k, b_k) is multiplied by a positive
// number, so ac must be too, to rounding. Lengths beyond the solver's range
// (quasistatics.h, kBadInput) are refused by name, never answered "optimal";
// lengths below it are answered exactly by scaling (au, b) by a power of two.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "gauss6/io/qp_instances.h"
#include "gauss6/contact/quasistatics.h"

using namespace gauss6;

namespace {

double m_norm(const Mat6& M, const Vec6& x) { return std::sqrt(std::max(x.dot(M * x), 0.0)); }

struct Solved {
  ProjectionStatus status;
  Vec6 ac;
  double kkt_relative;
  std::string problem;
};

Solved solve(const Mat6& M, const Vec6& au, const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>& J,
             const Eigen::VectorXd& b) {
  ProjectionProblem p;
  p.M = &M;
  p.au = au;
  p.J = J.rows() ? J.data() : nullptr;
  p.b = b.size() ? b.data() : nullptr;
  p.num_rows = static_cast<int>(J.rows());
  ProjectionSettings settings;
  settings.warm_start = false;
  ProjectionWorkspace ws(std::max(p.num_rows, 1));
  ProjectionResult r(std::max(p.num_rows, 1));
  const ProjectionStatus status = project(p, settings, &ws, &r);
  return {status, r.ac, r.kkt_relative, r.problem ? r.problem : ""};
}

}  // namespace

TEST_CASE("the projection's answer does not depend on positive row scaling", "[qp][scaling]") {
  // Every instance of the stored families (warm's steps solved cold), its rows
  // and offsets multiplied by factors 10^U(-8, 8), three draws each. Tolerance
  // 1e-12 |au|_M: each answer is the exact projection to a few 1e-14 (the
  // crosscheck against the exact reference), so two of them differ by less. A
  // ratio test that mixed the rows' units (the multipliers' noise floor taken
  // from the largest of r_i over rows of different norms, before this fix)
  // answered "optimal" 4%..97% away on 7 of 1,620 such instances.
  std::mt19937_64 rng(47);
  std::uniform_real_distribution<double> decades(-8, 8);
  double worst = 0;
  int checked = 0;
  for (const std::string name : {"box", "peg", "bunny", "m50", "redundant", "inertia", "offsets", "warm"}) {
    for (const QpInstance& q :
         read_qp_instances(std::string(GAUSS6_SOURCE_DIR) + "/datasets_generated/qp/" + name + ".json")) {
      if (q.J.rows() == 0) continue;
      const Solved plain = solve(q.M, q.au, q.J, q.b);
      for (int draw = 0; draw < 3; ++draw) {
        Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> J = q.J;
        Eigen::VectorXd b = q.b;
        for (int k = 0; k < J.rows(); ++k) {
          const double s = std::pow(10.0, decades(rng));
          J.row(k) *= s;
          if (b.size()) b[k] *= s;
        }
        const Solved scaled = solve(q.M, q.au, J, b);
        INFO(name << " " << q.id << " draw " << draw);
        REQUIRE(scaled.status == plain.status);
        if (plain.status != ProjectionStatus::kOptimal) continue;
        const double err = m_norm(q.M, scaled.ac - plain.ac) / std::max(m_norm(q.M, q.au), 1e-300);
        CHECK(err <= 1e-12);
        worst = std::max(worst, err);
        ++checked;
      }
    }
  }
  std::printf("row scaling: %d instances, max |ac - ac_unscaled|_M / |au|_M = %.3g\n", checked, worst);
}

TEST_CASE("the optimal status is a scale-free KKT certificate", "[qp][scaling]") {
  Mat6 M = Mat6::Identity();
  M.diagonal() << 2, 2, 2, 0.01, 0.02, 0.03;
  Eigen::Matrix<double, 2, 6, Eigen::RowMajor> J;
  J << 0, 0, 1, 0.1, 0, 0,  //
      0, 1, 0, 0, 0, 0.2;
  const Vec6 au = (Vec6() << 0.1, -0.3, -0.2, 0.5, 0.1, -0.4).finished();
  const Eigen::VectorXd b = Eigen::VectorXd::Zero(2);
  const Solved base = solve(M, au, J, b);
  REQUIRE(base.status == ProjectionStatus::kOptimal);
  // At rounding: the same with a row multiplied by 1e40.
  CHECK(base.kkt_relative <= 1e-14);
  Eigen::Matrix<double, 2, 6, Eigen::RowMajor> J2 = J;
  J2.row(0) *= 1e40;
  const Solved scaled = solve(M, au, J2, b);
  CHECK(scaled.status == ProjectionStatus::kOptimal);
  CHECK(scaled.kkt_relative <= 1e-14);
  CHECK(m_norm(M, scaled.ac - base.ac) <= 1e-15 * m_norm(M, au));
  // The status follows the certificate: held to a tolerance under the answer's
  // own rounding, the same solve is not called optimal.
  ProjectionProblem p;
  p.M = &M;
  p.au = au;
  p.J = J.data();
  p.num_rows = 2;
  ProjectionSettings tight;
  tight.certificate_tol = 1e-300;
  ProjectionWorkspace ws(2);
  ProjectionResult r(2);
  const ProjectionStatus status = project(p, tight, &ws, &r);
  CHECK((status == ProjectionStatus::kUncertified || r.kkt_relative <= 1e-300));
  CHECK(r.ac.allFinite());
  CHECK(std::string(to_string(ProjectionStatus::kUncertified)) == "uncertified");
}

TEST_CASE("lengths beyond the projection's range are refused by name", "[qp][scaling][bad_input]") {
  const Mat6 M = Mat6::Identity();
  Eigen::Matrix<double, 1, 6, Eigen::RowMajor> J;
  J << 0, 0, 1, 0, 0, 0;
  const Eigen::VectorXd b0 = Eigen::VectorXd::Zero(1);
  const Vec6 down = (Vec6() << 0.3, 0, -1, 0, 0, 0).finished();
  // |au| of 1e155: its square overflows, and a row's scale with it; the
  // solver answered "optimal" with the row violated. Refused, naming au.
  for (const double size : {1e101, 1e155, 1e300}) {
    const Solved s = solve(M, size * down / down.norm(), J, b0);
    INFO("|au| " << size);
    CHECK(s.status == ProjectionStatus::kBadInput);
    CHECK(s.problem.rfind("au:", 0) == 0);
    CHECK(s.ac.allFinite());
  }
  // |au| below 1e-100 is scaled up (quasistatics.h, "Scale"), unless an
  // offset's distance of 1e-5 beside it makes the lengths span more than 1e200.
  for (const double size : {1e-101, 1e-200, 1e-320}) {
    const Solved s = solve(M, size * down / down.norm(), J, b0);
    INFO("|au| " << size);
    CHECK(s.status == ProjectionStatus::kOptimal);
    Eigen::VectorXd b(1);
    b << -1e-5;
    const Solved spread = solve(M, size * down / down.norm(), J, b);
    if (size < 1e-205) {
      CHECK(spread.status == ProjectionStatus::kBadInput);
      CHECK(spread.problem.rfind("au:", 0) == 0);
    } else {
      CHECK(spread.status == ProjectionStatus::kOptimal);
    }
  }
  // Rows: norms beyond [1e-100, 1e100], including squares that underflow to 0.
  for (const double size : {1e-170, 1e-101, 1e101, 1e160}) {
    const Solved s = solve(M, down, size * J, b0);
    INFO("|J_k| " << size);
    CHECK(s.status == ProjectionStatus::kBadInput);
    CHECK(s.problem.rfind("J:", 0) == 0);
  }
  // An offset whose distance |b_k| / |J_k| is beyond range.
  {
    Eigen::VectorXd b(1);
    b << 1e150;
    const Solved s = solve(M, down, J, b);
    CHECK(s.status == ProjectionStatus::kBadInput);
    CHECK(s.problem.rfind("b:", 0) == 0);
  }
  // Inside the range, the answer is exact at either end: au pushing along -z
  // onto the plane z >= 0 keeps its x part only. Tolerance 4 eps: the answer's
  // x is au's (no arithmetic), z is zero up to the rounding of one projection.
  for (const double length : {1e-99, 1.0, 1e99}) {
    for (const double row : {1e-99, 1.0, 1e99}) {
      const Vec6 au = length * down / down.norm();
      const Solved s = solve(M, au, row * J, b0);
      INFO("|au| " << length << ", |J_k| " << row);
      REQUIRE(s.status == ProjectionStatus::kOptimal);
      CHECK(std::abs(s.ac[0] - au[0]) <= 4 * std::numeric_limits<double>::epsilon() * length);
      CHECK(std::abs(s.ac[2]) <= 4 * std::numeric_limits<double>::epsilon() * length);
    }
  }
  // Zero is no length: au = 0 and a zero row are answered.
  const Solved still = solve(M, Vec6::Zero(), J, b0);
  CHECK(still.status == ProjectionStatus::kOptimal);
  CHECK(still.ac.isZero(0));
  Eigen::Matrix<double, 2, 6, Eigen::RowMajor> with_zero = Eigen::Matrix<double, 2, 6, Eigen::RowMajor>::Zero();
  with_zero.row(0) = J;
  CHECK(solve(M, down, with_zero, Eigen::VectorXd::Zero(2)).status == ProjectionStatus::kOptimal);
}

TEST_CASE("a god-object settling on a resting handle: |au|_M below 1e-100 is answered", "[qp][scaling]") {
  // A hexagonal pin (1 cm across, 7800 kg/m^3) whose centre of mass sits
  // 5.5e-20 m off the handle's start: with ks = 0.5 the sim loop halves that
  // offset every step, so |au|_M passed 1e-100 after ~270 steps at rest and
  // every projection until the handle moved was refused as bad input (2370
  // calls of the sim and coupling loops, reported as projection failures).
  // This is the first refused call, as the runtime made it: no contact rows.
  Mat6 M = Mat6::Zero();
  M(0, 0) = M(1, 1) = M(2, 2) = 0.009727198416000003;
  M(3, 3) = 7.619638831246225e-07;
  M(3, 4) = M(4, 3) = -7.429843071980055e-42;
  M(4, 4) = 7.619638759200001e-07;
  M(5, 5) = 6.484799664462243e-08;
  const Vec6 settling = (Vec6() << 0, 9.32345926809987e-100, 0, 0, 0, 0).finished();
  const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> none(0, 6);
  const Solved free = solve(M, settling, none, Eigen::VectorXd());
  REQUIRE(free.status == ProjectionStatus::kOptimal);
  CHECK(free.ac == settling);  // no row: ac = au exactly

  // With contacts: the 17 rows of the pin's flat end pressed on the torus top
  // (a step of the same run: nearly parallel normals, some repeated), a tiny
  // au made from an ordinary one by 2^-400. The answer, its multipliers and
  // its certificate are those of the ordinary problem times 2^-400: the
  // method commutes with power-of-two scaling (short of underflow), so to a
  // few eps of the ordinary answer's length (bitwise here; the tolerance
  // allows for a change of working set on a tie).
  const double contact[17][2][3] = {
    {{0.029998925402055617, 7.336860439114802e-07, 0.008012516744843075}, {-0.07179208774174689, 0.0414057033745304, 0.9965598144947155}},
    {{0.0299988761197042, 6.483264976094721e-07, 0.008012516741119422}, {-7.555753318974273e-05, -2.5041982540376846e-16, 0.9999999971455296}},
    {{0.02999988171031878, 2.390060732159721e-06, 0.008012516817099368}, {-6.963249721841545e-05, -3.4208207419443893e-06, 0.9999999975698066}},
    {{0.029999999054259503, -4.235164736271502e-22, 0.008012516825965588}, {-7.555753319017641e-05, -4.1041420772988665e-20, 0.9999999971455296}},
    {{0.03000112340724539, 6.491454287989421e-07, 0.008012516910918926}, {-7.55575331897428e-05, 2.50307894256206e-16, 0.9999999971455296}},
    {{0.029998922839745302, 2.5949442852648693e-06, 0.008012516744649473}, {-7.51861637454812e-05, 0.09902500985101723, 0.9950849419878921}},
    {{0.029999999054259503, 2.5949442852648693e-06, 0.008012516825965588}, {-7.555753318974273e-05, 2.5041982540376846e-16, 0.9999999971455296}},
    {{0.02999987157070693, 2.5949442852648693e-06, 0.008012516816333245}, {-7.555753318922222e-05, -3.7118987120784564e-06, 0.9999999971386405}},
    {{0.02999985952993607, 2.838245392529814e-06, 0.008012516815423474}, {-8.258467087561664e-05, -4.057119396591832e-06, 0.9999999965816561}},
    {{0.029855541055084204, 0.002940513999999999, 0.008012505911075489}, {-7.555753319017641e-05, 4.1041420772988665e-20, 0.9999999971455296}},
    {{0.029999999999879838, 2.5949442852648693e-06, 0.008012516826037036}, {-0.13052333339515115, -0.006412191778579105, 0.9914245020353354}},
    {{0.029999999999879838, 2.5949442852648693e-06, 0.008012516826037036}, {0.1305233477673065, 0.006412192484636896, 0.9914245001386413}},
    {{0.02977748907224135, 0.003466696944285265, 0.008012500013660188}, {-7.555753318543074e-05, -1.1207915063263291e-05, 0.9999999970827208}},
    {{0.029855541055084204, -0.002940514000000001, 0.008012505911075489}, {-7.555753319017641e-05, -4.1041420772988665e-20, 0.9999999971455296}},
    {{0.02977825892042848, -0.0034615070557147353, 0.008012500071828018}, {-7.555753318543074e-05, 1.1207915063263291e-05, 0.9999999970827208}},
    {{0.029999999999879838, 2.5949442852648693e-06, 0.008012516826037036}, {-0.1305233477673067, 0.006412192484636905, 0.9914245001386413}},
    {{0.029999999999879838, 2.5949442852648693e-06, 0.008012516826037036}, {0.13052333035118657, -0.006412191629038911, 0.9914245024370476}},
  };
  const Vec3 G(0.02999886663688199, 2.594944285267357e-06, 0.02301251678321998);
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> J(17, 6);
  for (int k = 0; k < 17; ++k) {
    const Vec3 point(contact[k][0][0], contact[k][0][1], contact[k][0][2]);
    const Vec3 normal(contact[k][1][0], contact[k][1][1], contact[k][1][2]);
    J.row(k) << normal.transpose(), (point - G).cross(normal).transpose();
  }
  const Vec6 press = (Vec6() << 1e-4, -3e-5, -5e-4, 2e-3, -1e-3, 4e-4).finished();
  Eigen::VectorXd gaps(17);
  for (int k = 0; k < 17; ++k) gaps[k] = (k % 3 - 1) * 2.5e-7;  // offsets of both signs
  for (const bool offsets : {false, true}) {
    INFO((offsets ? "offsets" : "cone"));
    const Eigen::VectorXd b = offsets ? gaps : Eigen::VectorXd::Zero(17);
    const Solved ordinary = solve(M, press, J, b);
    REQUIRE(ordinary.status == ProjectionStatus::kOptimal);
    Vec6 tiny_au;
    for (int i = 0; i < 6; ++i) tiny_au[i] = std::ldexp(press[i], -400);
    Eigen::VectorXd tiny_b(17);
    for (int k = 0; k < 17; ++k) tiny_b[k] = std::ldexp(b[k], -400);
    REQUIRE(m_norm(M, tiny_au) < 1e-100);
    const Solved tiny = solve(M, tiny_au, J, tiny_b);
    REQUIRE(tiny.status == ProjectionStatus::kOptimal);
    CHECK(tiny.kkt_relative <= 1e-8);
    Vec6 expected;
    for (int i = 0; i < 6; ++i) expected[i] = std::ldexp(ordinary.ac[i], -400);
    CHECK(m_norm(M, tiny.ac - expected) <= 4 * std::numeric_limits<double>::epsilon() * m_norm(M, tiny_au));
  }
}
