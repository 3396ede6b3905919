// Fault injection in the runtime's loops (runtime.h, issue "reliability"): each
// fault of the device (error, not connected, a failing write, a blocking read,
// a flaky device), each watchdog (device, haptic thread, sim, coupling) and
// each of the loops' own events (clamping, a non-finite force from the
// pipeline, contact overflow, CCD give-up, projection failure, invalid handle
// poses and settings), each with the event it must raise and the safe state it
// must leave: zero force (or a bounded, finite one) while the fault holds, the
// force back once it is gone. The box-on-box fixtures (runtime_fixtures.h):
// pressing 1 cm gives 5 N straight up.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "gauss6/runtime/runtime.h"
#include "mesh_shapes.h"
#include "gauss6/contact/coupling.h"
#include "runtime_fixtures.h"

using namespace gauss6;
using namespace gauss6::test;

namespace {

constexpr double kPressed = 4.9;  // N: pressed 1 cm (5 N) with the resting gap's rounding
constexpr double kInf = std::numeric_limits<double>::infinity();

// Sum of the counts of the reported events of one kind (coalesced events stand for several onsets).
long reported_onsets(const Recorder& rec, RuntimeEventKind k) {
  long n = 0;
  for (const RuntimeEvent& e : rec.events)
    if (e.kind == k) n += e.count;
  return n;
}

long stats_onsets(const RuntimeStats& s, RuntimeEventKind k) {
  const int i = static_cast<int>(k);
  return s.haptic.event_counts[i] + s.sim.event_counts[i] + s.coupling.event_counts[i] + s.watchdog.event_counts[i];
}

// Every wrench sent is finite and within the scene's limits (20 N, 1 N m).
void check_bounded(const ScriptedDevice& device) {
  for (const auto& w : device.writes) {
    REQUIRE(w.F.allFinite());
    REQUIRE(w.F.head<3>().norm() <= 20 * (1 + 1e-15));
    REQUIRE(w.F.tail<3>().norm() <= 1 * (1 + 1e-15));
  }
}

// A god-object whose bottom is an n x n grid of squares (side kSide, at z =
// -kHalf) closed by a pyramid over it: (n + 1)^2 bottom vertices rest on the slab.
Scene make_grid_bottom_scene(int n) {
  Scene sc = make_scene();
  std::vector<Eigen::Vector3d> V;
  std::vector<std::array<int, 3>> F;
  const auto id = [n](int i, int j) { return i * (n + 1) + j; };
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) V.emplace_back(-kHalf + kSide * i / n, -kHalf + kSide * j / n, -kHalf);
  const int apex = static_cast<int>(V.size());
  V.emplace_back(0, 0, kHalf);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) add_quad(&F, id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j));  // normal -z
  // The boundary counter-clockwise seen from above, each edge to the apex.
  std::vector<int> ring;
  for (int i = 0; i < n; ++i) ring.push_back(id(i, 0));
  for (int j = 0; j < n; ++j) ring.push_back(id(n, j));
  for (int i = n; i > 0; --i) ring.push_back(id(i, n));
  for (int j = n; j > 0; --j) ring.push_back(id(0, j));
  for (size_t k = 0; k < ring.size(); ++k) F.push_back({ring[k], ring[(k + 1) % ring.size()], apex});
  sc.god_object.mesh = make_mesh(V, F, "grid pyramid");
  build_adjacency(&sc.god_object.mesh);
  compute_vertex_normals(&sc.god_object.mesh);
  std::string error;
  REQUIRE(compute_mass_properties(sc.god_object.mesh, 1000, &sc.god_mass.mass, &error));
  REQUIRE(sc.god_mass.mass.mass > 0);
  return sc;
}

// A threaded run (1.2 s) in which the first sim step (or coupling step, with
// the coupling thread) after 0.4 s does not return for 0.3 s: the fault is
// injected through the loop's own hook, which runs in that loop's thread.
struct Stall {
  Recorder rec;
  bool coupling = false;
  std::atomic<bool> done{false};
  std::atomic<double> begin{-1}, end{-1};
  void hit(double t) {
    if (t > 0.4 && !done.exchange(true)) {
      begin.store(t);
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
      end.store(t + 0.3);
    }
  }
};

void run_with_stall(const RuntimeSettings& settings, bool coupling, ScriptedDevice* device, Stall* stall) {
  const RuntimeModel model(make_scene(), settings);
  auto data = std::make_unique<RuntimeData>(model);
  stall->rec.ticks.reserve(10000);
  RuntimeObserver observer;
  observer.user = stall;
  observer.on_event = [](void* u, const RuntimeEvent& e) {
    auto* s = static_cast<Stall*>(u);
    std::lock_guard<std::mutex> lock(s->rec.events_mutex);
    s->rec.events.push_back(e);
  };
  observer.on_haptic_tick = [](void* u, const HapticTickRecord& t) { static_cast<Stall*>(u)->rec.ticks.push_back(t); };
  if (coupling)
    observer.on_coupling_step = [](void* u, const CouplingStepInfo& i) { static_cast<Stall*>(u)->hit(i.time); };
  else
    observer.on_sim_step = [](void* u, const SimStepInfo& i) { static_cast<Stall*>(u)->hit(i.time); };
  run_threaded(model, device, 1.2, nullptr, observer, data.get());
}

}  // namespace

TEST_CASE("faults: read() errors, then the device timeout, then recovery", "[runtime][faults]") {
  // kError for 20 ticks from 0.6 s: one device_error onset; the last good pose
  // keeps the force for device_timeout, then zero (device_timeout event); the
  // first good sample brings the force back.
  ScriptedDevice device(press_script(0.2, 0.04, 0.4));
  device.error_from = 0.6, device.error_to = 0.62;
  RuntimeSettings settings;
  settings.device_timeout = 0.0055;
  Run r;
  run(&r, make_scene(), settings, &device, 700);
  CHECK(r.rec.count(RuntimeEventKind::kDeviceError) == 1);
  CHECK(r.rec.count(RuntimeEventKind::kDeviceTimeout) == 1);
  for (const HapticTickRecord& t : r.rec.ticks) {
    if (t.time > 0.5 && t.time < 0.6045) CHECK(t.F_sent[2] > kPressed);  // last good pose at 0.599
    if (t.time > 0.6045 && t.time < 0.6195) CHECK(t.F_sent.norm() == 0.0);
    if (t.time > 0.6195) CHECK(t.F_sent[2] > kPressed);  // recovered at the first good sample (0.620)
  }
  check_bounded(device);
}

TEST_CASE("faults: kNotConnected zeroes the force at once, as device_port.h promises", "[runtime][faults]") {
  ScriptedDevice device(press_script(0.2, 0.04, 0.4));
  device.not_connected_from = 0.6, device.not_connected_to = 0.65;
  Run r;
  run(&r, make_scene(), RuntimeSettings{}, &device, 800);
  CHECK(r.rec.count(RuntimeEventKind::kDeviceNotConnected) == 1);
  CHECK(r.rec.count(RuntimeEventKind::kDeviceError) == 0);
  int zeroed = 0;
  for (const HapticTickRecord& t : r.rec.ticks) {
    if (t.time >= 0.5995 && t.time < 0.6495) {
      CHECK(t.F_sent.norm() == 0.0);  // the first tick already, not after device_timeout
      ++zeroed;
    }
    if (t.time > 0.655) CHECK(t.F_sent[2] > kPressed);
  }
  CHECK(zeroed == 50);
  check_bounded(device);
}

TEST_CASE("faults: a device that ends stops the run, zero force sent, reported", "[runtime][faults][threaded]") {
  // The device's script ends at 0.6 s (kEnded) while the box is pressed (5 N):
  // the tick that reads kEnded sends zero, reports device_ended once and is the
  // run's last, lockstep or threaded (which must not run on to its 5 s).
  for (const bool threaded : {false, true}) {
    DYNAMIC_SECTION((threaded ? "threaded" : "lockstep")) {
      ScriptedDevice device(press_script(0.2, 0.04, 0.4));
      device.end_time = 0.6;
      Run r;
      if (threaded) {
        r.model = std::make_unique<RuntimeModel>(make_scene(), RuntimeSettings{});
        r.data = std::make_unique<RuntimeData>(*r.model);
        r.rec.ticks.reserve(10000);
        r.rec.sims.reserve(20000);
        RuntimeObserver observer = r.rec.observer();
        observer.on_coupling_step = nullptr;
        const auto start = std::chrono::steady_clock::now();
        run_threaded(*r.model, &device, 5.0, nullptr, observer, r.data.get());
        CHECK(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < 4.0);
      } else {
        run(&r, make_scene(), RuntimeSettings{}, &device, 5000);
        CHECK(r.rec.ticks.size() == 601);  // t = 0, 1 ms, ..., 0.6 s: not the 5000 asked for
      }
      REQUIRE(!r.rec.ticks.empty());
      const HapticTickRecord& last = r.rec.ticks.back();
      CHECK(last.device_status == DeviceStatus::kEnded);
      CHECK(last.time >= 0.6);
      CHECK(last.F_sent.norm() == 0.0);
      CHECK(r.rec.count(RuntimeEventKind::kDeviceEnded) == 1);
      int pressed = 0;  // the force was on until then
      for (const HapticTickRecord& t : r.rec.ticks) {
        if (&t != &last) CHECK(t.device_status == DeviceStatus::kOk);
        if (t.time > 0.5 && t.time < 0.599) pressed += t.F_sent[2] > kPressed ? 1 : 0;
      }
      CHECK(pressed > (threaded ? 5 : 90));  // threaded: as many ticks as the machine schedules
      CHECK(device.felt().norm() == 0.0);
      check_bounded(device);
    }
  }
}

TEST_CASE("faults: a failing write() is reported and zero is written at once", "[runtime][faults]") {
  SECTION("zero is accepted: the device renders nothing while its writes fail") {
    ScriptedDevice device(press_script(0.2, 0.04, 0.4));
    device.write_fail_from = 0.6, device.write_fail_to = 0.65;
    Run r;
    r.rec.on_tick = [&](const HapticTickRecord& t) {
      if (t.time >= 0.5995 && t.time < 0.6495) {
        CHECK(device.felt().norm() == 0.0);
        CHECK(t.F_sent.norm() == 0.0);
      }
    };
    run(&r, make_scene(), RuntimeSettings{}, &device, 800);
    // The condition holds for the 50 ticks of the window: one onset.
    CHECK(r.rec.count(RuntimeEventKind::kDeviceWriteFailed) == 1);
    CHECK(r.data->stats.haptic.event_counts[static_cast<int>(RuntimeEventKind::kDeviceWriteFailed)] == 1);
    CHECK(device.halts.load() == 0);
    CHECK(r.rec.ticks.back().F_sent[2] > kPressed);  // back once writes succeed
    CHECK(device.felt()[2] == 0.0);                  // the run's final zero
  }
  SECTION("zero fails too: the device is halted") {
    ScriptedDevice device(press_script(0.2, 0.04, 0.4));
    device.write_fail_from = 0.6, device.write_fail_to = 0.65;
    device.fail_zero_writes = true;
    Run r;
    r.rec.on_tick = [&](const HapticTickRecord& t) {
      if (t.time >= 0.5995 && t.time < 0.6495) CHECK(device.felt().norm() == 0.0);
    };
    run(&r, make_scene(), RuntimeSettings{}, &device, 800);
    CHECK(r.rec.count(RuntimeEventKind::kDeviceWriteFailed) == 1);
    CHECK(device.halts.load() == 50);
    CHECK(!device.halted.load());  // the next good write renders again
  }
}

TEST_CASE("faults: a flaky device's events are coalesced with counts, none lost", "[runtime][faults]") {
  // Every other read fails for 1 s: 500 onsets of device_error, one every 2 ms.
  ScriptedDevice device(press_script(0.2, 0.04, 0.4));
  device.flaky_from = 0.6, device.flaky_to = 1.6;
  RuntimeSettings settings;
  settings.event_interval = 0.1;
  Run r;
  run(&r, make_scene(), settings, &device, 1800);
  const long onsets = r.data->stats.haptic.event_counts[static_cast<int>(RuntimeEventKind::kDeviceError)];
  CHECK(onsets == 500);
  CHECK(reported_onsets(r.rec, RuntimeEventKind::kDeviceError) == onsets);  // nothing lost
  // At most one report per event_interval: 1 s / 0.1 s, plus the first onset and the last pending ones.
  const int reports = r.rec.count(RuntimeEventKind::kDeviceError);
  CHECK(reports >= 10);
  CHECK(reports <= 12);
  double last = -1;
  for (const RuntimeEvent& e : r.rec.events) {
    if (e.kind != RuntimeEventKind::kDeviceError) continue;
    if (last >= 0) CHECK(e.time - last >= 0.1 - 1e-12);
    last = e.time;
  }
  // The good samples in between keep the watchdog quiet and the force on.
  CHECK(r.rec.count(RuntimeEventKind::kDeviceTimeout) == 0);
  for (const HapticTickRecord& t : r.rec.ticks)
    if (t.time > 0.5) CHECK(t.F_sent[2] > kPressed);
  check_bounded(device);
  SECTION("event_interval 0 reports every onset") {
    ScriptedDevice d2(press_script(0.2, 0.04, 0.4));
    d2.flaky_from = 0.6, d2.flaky_to = 1.6;
    settings.event_interval = 0;
    Run q;
    run(&q, make_scene(), settings, &d2, 1800);
    CHECK(q.rec.count(RuntimeEventKind::kDeviceError) == 500);
  }
}

TEST_CASE("faults: watchdogs of the threaded run (haptic thread, sim, coupling)", "[runtime][faults][threaded]") {
  SECTION("a read() that blocks 0.5 s: the watchdog thread halts the device and reports it") {
    ScriptedDevice device(press_script(0.2, 0.04, 1.0));
    device.block_at = 0.4, device.block_seconds = 0.5;
    RuntimeSettings settings;
    settings.device_timeout = 0.02;  // s: well above a loaded machine's scheduling delays
    settings.sim_timeout = 1.0;
    const RuntimeModel model(make_scene(), settings);
    auto data = std::make_unique<RuntimeData>(model);
    Recorder rec;
    rec.ticks.reserve(10000);
    rec.sims.reserve(20000);
    RuntimeObserver observer = rec.observer();
    observer.on_coupling_step = nullptr;
    run_threaded(model, &device, 1.5, nullptr, observer, data.get());
    REQUIRE(device.blocked);
    CHECK(device.halts.load() >= 1);
    // The stall is reported while the read is blocked, device_timeout after the last tick ended.
    bool during_block = false;
    for (const RuntimeEvent& e : rec.events)
      if (e.kind == RuntimeEventKind::kHapticStalled && e.time > 0.4 && e.time < 0.9) {
        during_block = true;
        CHECK(e.detail == static_cast<int>(DeviceStatus::kOk));  // halt_force() succeeded
      }
    CHECK(during_block);
    CHECK(data->stats.watchdog.event_counts[static_cast<int>(RuntimeEventKind::kHapticStalled)] >= 1);
    CHECK(reported_onsets(rec, RuntimeEventKind::kHapticStalled) ==
          data->stats.watchdog.event_counts[static_cast<int>(RuntimeEventKind::kHapticStalled)]);
    // The force is back after the block (pressed 1 cm from 0.16 s on).
    int pressed_after = 0;
    for (const HapticTickRecord& t : rec.ticks)
      if (t.time > 1.0 && t.F_sent[2] > kPressed) ++pressed_after;
    CHECK(pressed_after > 5);
    check_bounded(device);
    CHECK(device.writes.back().F.norm() == 0.0);
  }
  // (spin: the haptic loop waits the last 0.2 ms of each period busily,
  // RuntimeSettings::spin_wait; its watchdog must act the same.)
  for (const auto [coupling_thread, spin] : {std::pair{false, false}, std::pair{true, false}, std::pair{false, true}}) {
    DYNAMIC_SECTION((coupling_thread ? "a coupling thread" : "a sim thread")
                    << " that stalls 0.3 s" << (spin ? ", the haptic loop busy-waiting" : "")
                    << ": the haptic thread's watchdog zeroes the force") {
      RuntimeSettings settings;
      settings.sim_timeout = 0.1;
      if (spin) settings.spin_wait = 2e-4;
      if (coupling_thread) {
        settings.force_source = ForceSource::kCouplingLoop;
        settings.coupling_min_period = 1e-4;
        settings.coupling_timeout = 0.05;
        settings.sim_timeout = 1.0;
      }
      Stall stall;
      ScriptedDevice device(press_script(0.2, 0.04, 1.0));
      run_with_stall(settings, coupling_thread, &device, &stall);
      REQUIRE(stall.done.load());
      CHECK(stall.rec.count(coupling_thread ? RuntimeEventKind::kCouplingStalled : RuntimeEventKind::kSimStalled) >= 1);
      // The last snapshot (Fc) before the stall is at most a min period older than the stall's start.
      const double timeout = coupling_thread ? settings.coupling_timeout : settings.sim_timeout;
      int zeroed = 0;
      for (const HapticTickRecord& t : stall.rec.ticks) {
        if (t.time > stall.begin.load() + timeout + 0.01 && t.time < stall.end.load() - 0.01) {
          CHECK(t.F_sent.norm() == 0.0);
          ++zeroed;
        }
      }
      CHECK(zeroed > 0);  // as many as the machine schedules (a loaded one: a few dozen)
      CHECK(stall.rec.ticks.back().F_sent[2] > kPressed);  // back with the loop
      check_bounded(device);
    }
  }
}

TEST_CASE("faults: the safety stage clamps torque, and overflowing wrenches to the limit, not 0",
          "[runtime][faults]") {
  uint32_t events = 0;
  Vec6 F;
  F << 0.1, 0, 0, 0, 3, 4;  // |torque| = 5 N m > 1 N m
  Vec6 safe = make_safe_wrench(F, 20, 1, &events);
  CHECK(events == 1u << static_cast<int>(RuntimeEventKind::kForceClamped));
  CHECK(safe.tail<3>().norm() == Approx(1).epsilon(1e-15));
  CHECK(safe[4] == Approx(0.6).epsilon(1e-15));
  CHECK(safe.head<3>() == F.head<3>());
  // Finite, but |F| overflows: clamped to the limit along F (was 0 before).
  for (double big : {1e155, 1e200, 1e308, 1.7e308}) {
    events = 0;
    F << big, -big, 0.5 * big, -big, big, 0;
    safe = make_safe_wrench(F, 20, 1, &events);
    INFO("component " << big);
    CHECK(events == 1u << static_cast<int>(RuntimeEventKind::kForceClamped));
    CHECK(safe.head<3>().norm() == Approx(20).epsilon(1e-14));
    CHECK(safe.tail<3>().norm() == Approx(1).epsilon(1e-14));
    CHECK((safe.head<3>().normalized() - Vec3(2, -2, 1) / 3).norm() < 1e-14);
  }
  SECTION("in a run: a device that renders at most 1e-3 N m gets at most that, with one clamp event") {
    // Pressed with the handle turned 0.05 rad about x: the coupling force has a torque.
    ScriptedDevice device([](double t) {
      return Pose{Vec3(0, 0, std::max(0.04, 0.2 - 0.4 * t)), Quat{std::cos(0.025), std::sin(0.025), 0, 0}};
    });
    device.set_limits(20, 1e-3);
    Run r;
    run(&r, make_scene(), RuntimeSettings{}, &device, 700);
    double max_torque_computed = 0, max_torque_sent = 0;
    for (const HapticTickRecord& t : r.rec.ticks) {
      max_torque_computed = std::max(max_torque_computed, t.F_computed.tail<3>().norm());
      max_torque_sent = std::max(max_torque_sent, t.F_sent.tail<3>().norm());
    }
    REQUIRE(max_torque_computed > 2e-3);
    CHECK(max_torque_sent <= 1e-3 * (1 + 1e-12));
    CHECK(max_torque_sent >= 1e-3 * (1 - 1e-12));
    CHECK(r.rec.count(RuntimeEventKind::kForceClamped) >= 1);
  }
}

TEST_CASE("faults: a non-finite force from inside the pipeline is zeroed and reported", "[runtime][faults]") {
  // The coupling loop's channel (kCouplingLoop) carries a NaN wrench: the haptic tick sends 0.
  RuntimeSettings settings;
  settings.force_source = ForceSource::kCouplingLoop;
  const RuntimeModel model(make_scene(), settings);
  auto data = std::make_unique<RuntimeData>(model);
  ScriptedDevice device(press_script(0.2, 0.04, 0.4));
  Recorder rec;
  WrenchSample w;
  w.time = 0;
  w.god_time = 0;
  for (int i = 0; i < 6; ++i) w.F[i] = i == 2 ? std::nan("") : 1.0;
  data->channels.wrench.write(w);
  CHECK(haptic_tick(model, 0.0, &device, &data->channels, &data->haptic, nullptr, rec.observer(), &data->stats));
  CHECK(rec.count(RuntimeEventKind::kNonFiniteForce) == 1);
  REQUIRE(device.writes.size() == 1);
  CHECK(device.writes[0].F.norm() == 0.0);
  // An infinite one too, next tick: the condition still holds, no new onset.
  w.F[2] = INFINITY;
  data->channels.wrench.write(w);
  CHECK(haptic_tick(model, 0.001, &device, &data->channels, &data->haptic, nullptr, rec.observer(), &data->stats));
  CHECK(device.writes[1].F.norm() == 0.0);
  CHECK(data->stats.haptic.event_counts[static_cast<int>(RuntimeEventKind::kNonFiniteForce)] == 1);
  // A finite one: sent as is.
  w.F[2] = 2.0;
  data->channels.wrench.write(w);
  CHECK(haptic_tick(model, 0.002, &device, &data->channels, &data->haptic, nullptr, rec.observer(), &data->stats));
  CHECK(device.writes[2].F[2] == 2.0);
}

TEST_CASE("faults: contact overflow truncates the set, reported, the god-object stays out", "[runtime][faults]") {
  // 121 bottom vertices rest on the slab. A full set is first reduced to its
  // patches' supports (contacts.h: here the bottom's corners, and the closest
  // contact); with room for fewer rows than that support (4), the set still
  // overflows and is truncated.
  const Scene sc = make_grid_bottom_scene(10);
  ScriptedDevice device(press_script(0.2, 0.04, 0.4));
  RuntimeSettings settings;
  settings.max_contacts = 4;
  Run r;
  run(&r, sc, settings, &device, 700);
  CHECK(r.rec.count(RuntimeEventKind::kContactOverflow) >= 1);
  for (const SimStepInfo& s : r.rec.sims) {
    CHECK(s.num_contacts <= settings.max_contacts);
    CHECK(lowest_z(*r.model, s.xs) >= kDelta * (1 - 1e-3));
  }
  check_bounded(device);
  CHECK(r.rec.ticks.back().F_sent[2] > 0);  // still pushed back up
}

TEST_CASE("more than 64 contacts: a capacity of 256 carries them all to the coupling", "[runtime][faults]") {
  // The same 121-vertex grid bottom pressed 1 cm into the slab, with
  // RuntimeSettings::max_contacts = 256: no overflow, sets of more than 64
  // contacts reach the coupling whole (its rows are the snapshot's), and the
  // force is that of a fully blocked body, -kh M au, to 1e-9 relative (rounding
  // of a projection over 121 rows; a wrong or missing row would let the body
  // tip or sink and change it at the 1e-2 level). The
  // coupling's force is also that of a cold projection of the cached snapshot's
  // rows (same answer to 1e-12 relative: warm and cold starts end on the same
  // optimum). Lockstep, so the run is repeatable.
  const Scene sc = make_grid_bottom_scene(10);
  ScriptedDevice device(press_script(0.2, 0.04, 0.4));
  RuntimeSettings settings;
  settings.max_contacts = 256;
  Run r;
  run(&r, sc, settings, &device, 700);
  CHECK(r.rec.count(RuntimeEventKind::kContactOverflow) == 0);
  int most = 0;
  for (const SimStepInfo& s : r.rec.sims) {
    most = std::max(most, s.num_contacts);
    CHECK(lowest_z(*r.model, s.xs) >= kDelta * (1 - 1e-3));
  }
  CHECK(most > 64);
  int most_rows = 0;
  for (const CouplingStepInfo& c : r.rec.couplings) {
    most_rows = std::max(most_rows, c.num_rows);
    if (!c.has_god_object) continue;
    const SimStepInfo& published = r.rec.sims[static_cast<size_t>(c.god_sequence - 1)];
    CHECK(c.num_rows == published.num_contacts);
  }
  CHECK(most_rows > 64);
  check_bounded(device);
  // Pressed straight down on its flat bottom, the god-object is fully blocked:
  // ac = 0, Fc = -kh M au (straight up: the handle is below G), to rounding.
  const CouplingState& cs = r.data->coupling;
  const CouplingStepInfo& c = r.rec.couplings.back();
  const Vec6 blocked = -r.model->gains.kh * (cs.M * c.au);
  CHECK(c.Fc[2] > 1.0);
  CHECK((c.Fc - blocked).norm() <= 1e-9 * blocked.norm());
  CHECK(c.Fc.head<2>().norm() <= 1e-9 * c.Fc[2]);
  CHECK(r.rec.ticks.back().F_sent == c.Fc);
  // The last coupling step again, cold, from the cached snapshot.
  REQUIRE(cs.god.num_contacts > 64);
  ProjectionWorkspace ws(cs.god.num_contacts);
  ProjectionResult res(cs.god.num_contacts);
  ProjectionSettings cold = r.model->settings.projection;
  cold.warm_start = false;
  ProjectionProblem pb;
  pb.M = &cs.M;
  pb.au = c.au;
  pb.J = cs.god.J.data();
  pb.num_rows = cs.god.num_contacts;
  REQUIRE(project(pb, cold, &ws, &res) == ProjectionStatus::kOptimal);
  const Vec6 F = coupling_force(cs.M, c.au, res.ac, r.model->gains.kh);
  CHECK((F - c.Fc).norm() <= 1e-12 * F.norm());
  // A capacity out of [1, kMaxContactCapacity] is refused when the model is built.
  for (const int bad : {0, -1, kMaxContactCapacity + 1}) {
    RuntimeSettings s;
    s.max_contacts = bad;
    CHECK_THROWS_AS(RuntimeModel(sc, s), RuntimeError);
  }
}

TEST_CASE("faults: CCD give-up keeps the hit conservatively, reported", "[runtime][faults]") {
  // A narrow phase allowed one box per pair test, with the bisection alone (no
  // u-filter, no early hit), gives up on every pair it has to search.
  RuntimeSettings settings;
  settings.ccd.narrow.max_iterations = 1;
  settings.ccd.narrow.use_u_filter = false;
  settings.ccd.narrow.early_hit = false;
  ScriptedDevice device(press_script(0.2, 0.04, 0.4));
  Run r;
  run(&r, make_scene(), settings, &device, 700);
  CHECK(r.rec.count(RuntimeEventKind::kCcdGaveUp) >= 1);
  bool gave_up = false;
  for (const SimStepInfo& s : r.rec.sims) {
    gave_up = gave_up || s.ccd == CcdStatus::kMaxIterations;
    CHECK(lowest_z(*r.model, s.xs) >= kDelta * (1 - 1e-3));  // never through the slab
  }
  CHECK(gave_up);
  check_bounded(device);
}

TEST_CASE("faults: projection failure is reported, the force stays finite and bounded", "[runtime][faults]") {
  // An add/drop cap of 0 steps: any active row makes the projection stop at its cap.
  RuntimeSettings settings;
  settings.projection.max_iterations = 0;
  ScriptedDevice device(press_script(0.2, 0.04, 0.4));
  Run r;
  run(&r, make_scene(), settings, &device, 700);
  CHECK(r.rec.count(RuntimeEventKind::kProjectionFailed) >= 1);
  for (const SimStepInfo& s : r.rec.sims) CHECK(lowest_z(*r.model, s.xs) >= kDelta * (1 - 1e-3));
  check_bounded(device);
}

TEST_CASE("faults: invalid handle poses give zero force and an event, invalid settings are refused",
          "[runtime][faults]") {
  for (const Pose& bad : {Pose{Vec3(0, 0, 0.04), Quat{0, 0, 0, 0}}, Pose{Vec3(0, 0, -1e155), Quat{}},
                          Pose{Vec3(2e12, 0, 0), Quat{}}})
  DYNAMIC_SECTION("a zero quaternion, or a handle beyond the scene's coordinates: " << bad.p.transpose()) {
    // A handle at 1e155 would make |au| ~ 1e155, where the projection reports optimal
    // while violating a row: refused at the entry (kMaxSceneCoordinate, 1e12).
    ScriptedDevice device([bad](double t) {
      if (t >= 0.6 && t < 0.603) return bad;
      return Pose{Vec3(0, 0, std::max(0.04, 0.2 - 0.4 * t)), Quat{}};
    });
    Run r;
    run(&r, make_scene(), RuntimeSettings{}, &device, 700);
    CHECK(r.rec.count(RuntimeEventKind::kInvalidHandlePose) == 1);
    for (const HapticTickRecord& t : r.rec.ticks) {
      if (t.time >= 0.5995 && t.time < 0.6025) CHECK(t.F_sent.norm() == 0.0);
      if (t.time > 0.605) CHECK(t.F_sent[2] > kPressed);
    }
  }
  SECTION("timeouts that would switch a watchdog off, and other settings the loops cannot serve") {
    const Scene sc = make_scene();
    const auto refused = [&](auto edit, const char* what) {
      RuntimeSettings s;
      edit(&s);
      INFO(what);
      CHECK_THROWS_AS(RuntimeModel(sc, s), RuntimeError);
    };
    for (double bad : {kInf, std::nan(""), 1e9, 2.0, 0.0, -1.0}) {
      refused([=](RuntimeSettings* s) { s->device_timeout = bad; }, "device_timeout");
      refused([=](RuntimeSettings* s) { s->sim_timeout = bad; }, "sim_timeout");
      refused([=](RuntimeSettings* s) { s->coupling_timeout = bad; }, "coupling_timeout");
    }
    for (double bad : {kInf, std::nan(""), -1.0, 5.0})
      refused([=](RuntimeSettings* s) { s->event_interval = bad; }, "event_interval");
    refused([](RuntimeSettings* s) { s->sim_min_period = INFINITY; }, "sim_min_period infinite");
    refused([](RuntimeSettings* s) { s->sim_min_period = s->sim_timeout; }, "sim_min_period >= sim_timeout");
    refused([](RuntimeSettings* s) { s->coupling_min_period = 1.0; }, "coupling_min_period >= coupling_timeout");
    for (double bad : {kInf, std::nan(""), -1e-6, 1.5})
      refused([=](RuntimeSettings* s) { s->spin_wait = bad; }, "spin_wait");
    // The CCD's own settings (not resolved from delta) enter here too.
    refused([](RuntimeSettings* s) { s->ccd.narrow.time_tolerance = 0; }, "time_tolerance 0");
    refused([](RuntimeSettings* s) { s->ccd.narrow.time_tolerance = std::nan(""); }, "time_tolerance NaN");
    refused([](RuntimeSettings* s) { s->ccd.narrow.time_tolerance = 1; }, "time_tolerance 1");
    refused([](RuntimeSettings* s) { s->ccd.narrow.max_iterations = 0; }, "max_iterations 0");
    refused([](RuntimeSettings* s) { s->ccd.max_sub_intervals = 0; }, "max_sub_intervals 0");
    refused([](RuntimeSettings* s) { s->ccd.sub_interval_angle = INFINITY; }, "sub_interval_angle");
    // The message names the setting.
    RuntimeSettings s;
    s.ccd.narrow.time_tolerance = 0;
    try {
      RuntimeModel m(sc, s);
      FAIL("time_tolerance = 0 accepted");
    } catch (const RuntimeError& e) {
      CHECK(std::string(e.what()).find("time_tolerance") != std::string::npos);
    }
    // An obstacle beyond the CCD's coordinates (a scene built in code: the loader refuses it
    // already), in its own frame or moved there by its pose.
    Scene far = make_scene();
    far.obstacles[0].mesh.V(0, 0) = 2e30;
    CHECK_THROWS_AS(RuntimeModel(far, RuntimeSettings{}), RuntimeError);
    far = make_scene();
    far.obstacles[0].pose.p.x() = 2e30;
    CHECK_THROWS_AS(RuntimeModel(far, RuntimeSettings{}), RuntimeError);
    // A god-object below kMinBodyRadius (the hypothesis of PoseAllowances.v's
    // pose_rounding_stand_at), refused by name.
    Scene speck = make_scene();
    speck.god_object.mesh.V *= 1e-302;
    CHECK_THROWS_WITH(RuntimeModel(speck, RuntimeSettings{}), Catch::Contains("kMinBodyRadius"));
    // A delta the CCD cannot serve: denormal, below kMinDeltaPerExtent of the
    // scene's extent or above kMaxDeltaPerExtent of it.
    const double extent = scene_extent(make_scene());
    for (double bad : {1e-310, 1e-16, 5e-15, 1e-9, 0.9 * kMinDeltaPerExtent * extent,
                       1.1 * kMaxDeltaPerExtent * extent, 0.5, 1e300}) {
      Scene tiny = make_scene();
      tiny.contact.delta = bad;
      INFO("delta " << bad);
      CHECK_THROWS_WITH(RuntimeModel(tiny, RuntimeSettings{}), Catch::Contains("contact.delta"));
    }
    Scene small = make_scene();
    small.contact.delta = 2 * kMinDeltaPerExtent;
    CHECK_NOTHROW(RuntimeModel(small, RuntimeSettings{}));
    small.contact.delta = 0.5 * kMaxDeltaPerExtent;
    CHECK_NOTHROW(RuntimeModel(small, RuntimeSettings{}));
    // Below kMinDelta (1e-150) whatever the scene's size: the whole scene shrunk
    // so that delta is about 2 kMinDeltaPerExtent of its extent; at 1e-145 it is served.
    for (const double d : {1e-160, 1e-145}) {
      Scene shrunk = make_scene();
      const double scale = d / (2 * kMinDeltaPerExtent);
      for (Body& b : shrunk.obstacles) b.mesh.V *= scale, b.pose.p *= scale;
      shrunk.god_object.mesh.V *= scale;
      shrunk.god_object.pose.p *= scale;
      shrunk.contact.delta = d;
      INFO("delta " << d);
      if (d < kMinDelta)
        CHECK_THROWS_WITH(RuntimeModel(shrunk, RuntimeSettings{}), Catch::Contains("contact.delta"));
      else
        CHECK_FALSE(check_delta_scale(shrunk));
    }
    // The limits themselves are accepted.
    RuntimeSettings ok;
    ok.device_timeout = ok.sim_timeout = ok.coupling_timeout = kMaxTimeout;
    ok.event_interval = 0;
    CHECK_NOTHROW(RuntimeModel(sc, ok));
  }
}
