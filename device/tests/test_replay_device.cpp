// The replay device: a simulated run recorded to a trace and played back.
#include <catch2/catch.hpp>

#include <filesystem>

#include "gauss6/replay_device.h"
#include "gauss6/simulated_device.h"
#include "gauss6/trace.h"

using namespace gauss6;

TEST_CASE("replay reproduces a trace's handle poses", "[device][replay]") {
  // Record 2 s of a simulated device (moving and turning, let go at 1.5 s).
  HandScript s;
  s.keys = {{0.0, {Vec3(0, 0, 0), Quat{}}}, {2.0, {Vec3(0.2, -0.1, 0.05), quat_exp(Vec3(0.3, -0.2, 1.0))}}};
  s.let_go_time = 1.5;
  SimulatedDevice sim(s);
  const auto path = (std::filesystem::temp_directory_path() / "gauss6_replay.g6trace").string();
  std::vector<DeviceState> recorded;
  {
    TraceWriterSettings ws;
    ws.background_thread = false;
    TraceWriter w(path, TraceMeta{}, ws);
    for (int i = 0; i <= 2000; ++i) {
      DeviceState st;
      sim.read(i * 1e-3, &st);
      recorded.push_back(st);
      TraceTick tick;
      tick.t = st.time;
      tick.X_WH = st.X_WH;
      tick.flags = st.gripped ? kTickGripped : 0u;
      REQUIRE(w.append(tick));
      if (i % 500 == 0) w.flush();
    }
    w.close();
  }
  ReplayDevice replay = ReplayDevice::from_trace(read_trace(path));
  CHECK(replay.num_samples() == 2001);
  CHECK(replay.info().rate_hz == Approx(1000).epsilon(1e-9));
  CHECK_FALSE(replay.info().renders_force);
  DeviceState st;
  // On the recorded ticks: exactly the recorded poses and grip.
  for (size_t i = 0; i < recorded.size(); i += 7) {
    REQUIRE(replay.read(recorded[i].time, &st) == DeviceStatus::kOk);
    CHECK(st.X_WH.p == recorded[i].X_WH.p);
    CHECK(st.X_WH.q.w == recorded[i].X_WH.q.w);
    CHECK(st.X_WH.q.z == recorded[i].X_WH.q.z);
    CHECK(st.gripped == recorded[i].gripped);
  }
  // Between ticks: between the neighbours (linear in position), so within the
  // distance of one tick of motion (< 1e-3 s * 0.15 m/s) of each.
  REQUIRE(replay.read(0.5005, &st) == DeviceStatus::kOk);
  const Vec3 mid = 0.5 * (recorded[500].X_WH.p + recorded[501].X_WH.p);
  CHECK((st.X_WH.p - mid).norm() < 1e-15);
  CHECK(quat_log(st.X_WH.q * conjugate(recorded[500].X_WH.q)).norm() <
        quat_log(recorded[501].X_WH.q * conjugate(recorded[500].X_WH.q)).norm());
  // Reads may jump back; past the end: the last pose and kEnded.
  CHECK(replay.read(0.1, &st) == DeviceStatus::kOk);
  CHECK(st.X_WH.p == recorded[100].X_WH.p);
  CHECK(replay.read(2.5, &st) == DeviceStatus::kEnded);
  CHECK(st.X_WH.p == recorded.back().X_WH.p);
  CHECK_FALSE(st.gripped);
  Vec6 F = Vec6::Constant(2.0);
  CHECK(replay.write(2.5, F) == DeviceStatus::kOk);
  CHECK(replay.last_force() == F);
  CHECK_THROWS_AS(ReplayDevice(std::vector<ReplaySample>{}), std::invalid_argument);
}
