// The simulated device: script following, closed-loop force, let-go, determinism.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <vector>

#include "gauss6/simulated_device.h"

using namespace gauss6;

namespace {

Pose at(double x, double y, double z, const Quat& q = {}) { return {Vec3(x, y, z), q}; }

// The hand moves 0.1 m along x in 1 s, holds until 3 s, while turning 0.5 rad about z.
HandScript ramp_script() {
  HandScript s;
  s.keys = {{0.0, at(0, 0, 0)}, {1.0, at(0.1, 0, 0, quat_exp(Vec3(0, 0, 0.5)))}, {3.0, at(0.1, 0, 0, quat_exp(Vec3(0, 0, 0.5)))}};
  s.phases = {{"approach", 0.0}, {"hold", 1.0}};
  return s;
}

// Runs the device in lockstep at its rate up to t_end with force law F(state), returns the states.
template <class ForceLaw>
std::vector<DeviceState> run(SimulatedDevice& dev, double t_end, ForceLaw force) {
  std::vector<DeviceState> out;
  const int n = static_cast<int>(std::lround(t_end * dev.info().rate_hz));
  for (int i = 0; i <= n; ++i) {
    DeviceState st;
    dev.read(i / dev.info().rate_hz, &st);
    out.push_back(st);
    REQUIRE(dev.write(st.time, force(st)) == DeviceStatus::kOk);
  }
  return out;
}

const auto no_force = [](const DeviceState&) { return Vec6::Zero().eval(); };

}  // namespace

TEST_CASE("simulated device follows its script with the lag of the grip dynamics", "[device][simulated]") {
  const SimulatedHandleParams p;
  SimulatedDevice dev(ramp_script(), p);
  const auto states = run(dev, 3.0, no_force);
  const double v = 0.1, w = 0.5;  // hand speeds on the ramp (m/s, rad/s)
  // Steady lag on a ramp: the ground damping against the grip spring, b v / k
  // (the grip damping acts on the relative velocity, zero at steady state).
  const double lag = p.damping * v / p.grip_stiffness;                           // 2e-4 m
  const double lag_rot = p.angular_damping * w / p.grip_angular_stiffness;       // 5e-4 rad
  const DeviceState& mid = states[500];  // t = 0.5 s: transients decayed as exp(-30 t)
  const HandSample hand = sample_hand(dev.script(), 0.5);
  const double err = (hand.X_WA.p - mid.X_WH.p).x();
  const double err_rot = quat_log(hand.X_WA.q * conjugate(mid.X_WH.q)).z();
  // Characterisation: within 2% of the analytic lag (time discretisation and the
  // exp(-15) transient are far below that; a wrong gain or sign is far above).
  CHECK(err == Approx(lag).epsilon(0.02));
  CHECK(err_rot == Approx(lag_rot).epsilon(0.02));
  // Bound over the whole run: the lag plus the ring-down of a velocity step dv,
  // at most dv / omega_n (omega_n = sqrt(k/m)).
  const double bound = lag + v / std::sqrt(p.grip_stiffness / p.mass);
  double worst = 0;
  for (const DeviceState& st : states)
    worst = std::max(worst, (sample_hand(dev.script(), st.time).X_WA.p - st.X_WH.p).norm());
  CHECK(worst <= bound);
  CHECK(worst >= lag);  // it does lag: the dynamics are not bypassed
  // At rest after 2 s of hold: on the hand to 1e-9 m (the decay is exp(-60)).
  CHECK((states.back().X_WH.p - Vec3(0.1, 0, 0)).norm() < 1e-9);
  CHECK(std::abs(quat_log(states.back().X_WH.q).z() - 0.5) < 1e-9);
  CHECK(states.back().gripped);
}

TEST_CASE("simulated device: a constant rendered wrench displaces the handle by F/k", "[device][simulated]") {
  HandScript s;
  s.keys = {{0.0, at(0, 0, 0)}};
  s.end_time = 5.0;
  const SimulatedHandleParams p;
  SimulatedDevice dev(s, p);
  Vec6 F;
  F << 1.0, -2.0, 0.5, 0.01, 0.0, -0.02;
  const auto states = run(dev, 3.0, [&](const DeviceState&) { return F; });
  const Pose& x = states.back().X_WH;
  // Steady state of spring k against F: F/k exactly; the transient is below exp(-90).
  CHECK((x.p - F.head<3>() / p.grip_stiffness).norm() < 1e-12);
  CHECK((quat_log(x.q) - F.tail<3>() / p.grip_angular_stiffness).norm() < 1e-12);
}

TEST_CASE("simulated device: a virtual wall pushes the handle back (closed loop)", "[device][simulated]") {
  // The hand goes 5 cm into a wall at x = 0.05; the renderer pushes with stiffness kw.
  HandScript s;
  s.keys = {{0.0, at(0, 0, 0)}, {1.0, at(0.1, 0, 0)}};
  s.end_time = 4.0;
  const SimulatedHandleParams p;
  SimulatedDevice dev(s, p);
  const double kw = 2000, wall = 0.05;
  const auto wall_force = [&](const DeviceState& st) {
    Vec6 F = Vec6::Zero();
    if (st.X_WH.p.x() > wall) F[0] = -kw * (st.X_WH.p.x() - wall);
    return F;
  };
  const auto states = run(dev, 4.0, wall_force);
  // Equilibrium of the two springs: x = (k x_hand + kw wall) / (k + kw) = 0.06 m.
  const double k = p.grip_stiffness;
  const double expected = (k * 0.1 + kw * wall) / (k + kw);
  CHECK(states.back().X_WH.p.x() == Approx(expected).margin(1e-9));
  // Without the wall the handle would be on the hand: the force acted.
  CHECK(states.back().X_WH.p.x() < 0.1 - 0.03);
}

TEST_CASE("simulated device: letting go turns the grip off", "[device][simulated]") {
  HandScript s;
  s.keys = {{0.0, at(0, 0, 0)}, {3.0, at(0.3, 0, 0)}};
  s.let_go_time = 1.0;
  const SimulatedHandleParams p;
  SimulatedDevice dev(s, p);
  const auto states = run(dev, 3.0, no_force);
  CHECK(states[999].gripped);
  CHECK_FALSE(states[1000].gripped);
  CHECK_FALSE(states.back().gripped);
  // After the let-go the handle coasts on its damping: from speed v0 it travels
  // v0 m / b (1 - exp(-b t / m)); v0 is the hand's speed, 0.1 m/s.
  const double v0 = 0.1, T = 2.0;
  const double coast = v0 * p.mass / p.damping * (1 - std::exp(-p.damping * T / p.mass));  // 0.01 m
  const double travelled = states.back().X_WH.p.x() - states[1000].X_WH.p.x();
  // 2%: v0 at the let-go differs from the hand's speed by the ring-down, below 1e-6 m/s here.
  CHECK(travelled == Approx(coast).epsilon(0.02));
  // The hand went on to 0.3 m; the handle stayed near 0.11 m.
  CHECK(states.back().X_WH.p.x() < 0.12);
}

TEST_CASE("simulated device is deterministic: two runs are bit-identical", "[device][simulated]") {
  HandScript s = ramp_script();
  s.let_go_time = 2.0;
  auto force = [](const DeviceState& st) {
    Vec6 F = Vec6::Zero();
    F[0] = -1500 * std::max(0.0, st.X_WH.p.x() - 0.07);
    F[5] = -0.3 * quat_log(st.X_WH.q).z();
    return F;
  };
  SimulatedDevice a(s), b(s);
  const auto ra = run(a, 3.0, force), rb = run(b, 3.0, force);
  REQUIRE(ra.size() == rb.size());
  bool identical = true;
  for (size_t i = 0; i < ra.size(); ++i) {
    identical &= std::memcmp(ra[i].X_WH.p.data(), rb[i].X_WH.p.data(), 3 * sizeof(double)) == 0;
    identical &= std::memcmp(&ra[i].X_WH.q, &rb[i].X_WH.q, sizeof(Quat)) == 0;
    identical &= ra[i].gripped == rb[i].gripped;
  }
  CHECK(identical);
  // Reset replays the same run.
  a.reset(0);
  const auto rc = run(a, 3.0, force);
  CHECK(std::memcmp(rc.back().X_WH.p.data(), ra.back().X_WH.p.data(), 3 * sizeof(double)) == 0);
}

TEST_CASE("simulated device: statuses, end of script, bad inputs", "[device][simulated]") {
  SimulatedDevice dev(ramp_script());
  DeviceState st;
  CHECK(dev.read(0.0, &st) == DeviceStatus::kOk);
  CHECK(dev.read(3.0, &st) == DeviceStatus::kOk);
  CHECK(dev.read(3.001, &st) == DeviceStatus::kEnded);
  CHECK(dev.read(2.0, &st) == DeviceStatus::kError);  // time went backwards
  Vec6 bad = Vec6::Zero();
  bad[2] = std::nan("");
  CHECK(dev.write(3.0, bad) == DeviceStatus::kError);
  CHECK(dev.info().renders_force);
  CHECK(dev.substep() <= 1e-3);

  HandScript empty;
  CHECK_THROWS_AS(SimulatedDevice(empty), std::invalid_argument);
  HandScript unordered;
  unordered.keys = {{1.0, at(0, 0, 0)}, {0.5, at(1, 0, 0)}};
  CHECK_THROWS_WITH(SimulatedDevice(unordered), Catch::Contains("increase strictly"));
}

TEST_CASE("hand scripts from JSON, slerp halfway", "[device][simulated]") {
  const HandScript s = hand_script_from_json(R"({
    "keys": [{"t": 0, "p": [0, 0, 0]}, {"t": 2, "p": [1, 2, 3], "q": [0, 0, 0, 1]}],
    "let_go_time": 1.5, "phases": [{"name": "a", "start": 0}, {"name": "b", "start": 1}]})", "test.json");
  REQUIRE(s.keys.size() == 2);
  CHECK(s.let_go_time == 1.5);
  CHECK(s.phases[1].name == "b");
  const HandSample h = sample_hand(s, 1.0);
  CHECK((h.X_WA.p - Vec3(0.5, 1, 1.5)).norm() < 1e-15);
  // Halfway from identity to a half-turn about z: a quarter-turn about z (shortest way).
  CHECK((quat_log(h.X_WA.q) - Vec3(0, 0, M_PI / 2)).norm() < 1e-12);
  CHECK((h.V_WA.tail<3>() - Vec3(0, 0, M_PI / 2)).norm() < 1e-12);
  CHECK_THROWS_WITH(hand_script_from_json(R"({"keys": [{"t": 0}]})", "bad.json"), Catch::Contains("bad.json"));
  CHECK_THROWS_WITH(hand_script_from_json("{", "bad.json"), Catch::Contains("bad.json"));
}
