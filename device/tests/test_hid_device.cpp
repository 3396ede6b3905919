// HID driver: report parsing per profile, rate integration, the unplug/re-plug
// state machine (fake backend), and a run against a real device when one is present.
#include <catch2/catch.hpp>

#include <deque>
#include <iostream>
#include <map>
#include <thread>

#include "gauss6/hid_device.h"

using namespace gauss6;

namespace {

// A scripted HID backend: a list of present devices, queued reports per path,
// and unplug/re-plug events. Handles are indices into `opened`.
class FakeBackend final : public HidBackend {
 public:
  struct Unit {
    HidDeviceEntry entry;
    bool present = true;
    std::deque<std::vector<uint8_t>> reports;
  };
  std::vector<Unit> units;
  std::vector<std::pair<size_t, bool>> opened;  // unit index, still open
  int num_enumerations = 0;

  std::vector<HidDeviceEntry> enumerate() override {
    ++num_enumerations;
    std::vector<HidDeviceEntry> out;
    for (const Unit& u : units)
      if (u.present) out.push_back(u.entry);
    return out;
  }
  Handle open(const std::string& path) override {
    for (size_t i = 0; i < units.size(); ++i)
      if (units[i].present && units[i].entry.path == path) {
        opened.push_back({i, true});
        return reinterpret_cast<Handle>(opened.size());  // 1-based: never nullptr
      }
    return nullptr;
  }
  int read_timeout(Handle h, uint8_t* buf, size_t len, int) override {
    const auto& [unit, open] = opened.at(reinterpret_cast<size_t>(h) - 1);
    if (!open || !units[unit].present) return -1;  // unplugged: hidraw read fails
    auto& q = units[unit].reports;
    if (q.empty()) return 0;
    const std::vector<uint8_t> r = q.front();
    q.pop_front();
    const size_t n = std::min(len, r.size());
    std::copy(r.begin(), r.begin() + n, buf);
    return static_cast<int>(n);
  }
  int write(Handle, const uint8_t*, size_t len) override { return static_cast<int>(len); }
  void close(Handle h) override { opened.at(reinterpret_cast<size_t>(h) - 1).second = false; }

  size_t num_open() const {
    size_t n = 0;
    for (const auto& o : opened) n += o.second;
    return n;
  }
};

std::vector<uint8_t> report(uint8_t id, std::initializer_list<int> values) {
  std::vector<uint8_t> r = {id};
  for (int v : values) {
    const auto u = static_cast<uint16_t>(static_cast<int16_t>(v));
    r.push_back(static_cast<uint8_t>(u & 0xff));
    r.push_back(static_cast<uint8_t>(u >> 8));
  }
  return r;
}

HidDeviceEntry entry(uint16_t vid, uint16_t pid, const std::string& path, const std::string& serial) {
  return {path, vid, pid, serial, "3Dconnexion", "SpaceMouse", 0};
}

}  // namespace

TEST_CASE("every profile parses its motion and button reports", "[device][hid]") {
  REQUIRE(hid_profiles().size() >= 10);
  for (const HidProfile& p : hid_profiles()) {
    INFO(p.name);
    CHECK(find_hid_profile(p.vendor_id, p.product_id) == &p);
    CHECK((p.vendor_id == 0x046d || p.vendor_id == 0x256f));
    CHECK_FALSE(p.renders_force);
    SpaceMouseAxes axes;
    if (p.layout == HidReportLayout::kSplit) {
      CHECK(parse_spacemouse_report(p, report(1, {100, -200, 350}).data(), 7, &axes) == kReportTranslation);
      CHECK(parse_spacemouse_report(p, report(2, {-1, 32767, -32768}).data(), 7, &axes) == kReportRotation);
    } else {
      const auto r = report(1, {100, -200, 350, -1, 32767, -32768});
      CHECK(parse_spacemouse_report(p, r.data(), r.size(), &axes) == (kReportTranslation | kReportRotation));
    }
    CHECK(axes.translation[0] == 100);
    CHECK(axes.translation[1] == -200);
    CHECK(axes.translation[2] == 350);
    CHECK(axes.rotation[0] == -1);
    CHECK(axes.rotation[1] == 32767);
    CHECK(axes.rotation[2] == -32768);
    // Buttons: little-endian bitmask masked to the profile's count.
    const uint8_t buttons[] = {3, 0x03, 0xff, 0xff, 0xff};
    CHECK(parse_spacemouse_report(p, buttons, sizeof buttons, &axes) == kReportButtons);
    const uint32_t mask = p.num_buttons >= 32 ? 0xffffffffu : (1u << p.num_buttons) - 1u;
    CHECK(axes.buttons == (0xffffff03u & mask));
    // Short and unknown reports change nothing.
    const SpaceMouseAxes before = axes;
    const uint8_t shortr[] = {2, 1, 2, 3};
    const uint8_t led[] = {4, 1};
    CHECK(parse_spacemouse_report(p, shortr, sizeof shortr, &axes) == 0);
    CHECK(parse_spacemouse_report(p, led, sizeof led, &axes) == 0);
    CHECK(parse_spacemouse_report(p, led, 0, &axes) == 0);
    CHECK(axes.rotation[0] == before.rotation[0]);
    CHECK(axes.buttons == before.buttons);
  }
  CHECK(find_hid_profile(0x046d, 0xc077) == nullptr);  // a Logitech mouse
}

TEST_CASE("a SpaceMouse integrates its deflection into the handle pose", "[device][hid]") {
  auto fake = std::make_shared<FakeBackend>();
  fake->units.push_back({entry(0x256f, 0xc635, "/dev/hidraw3", "SN1"), true, {}});
  HidDeviceSettings s;
  s.linear_speed = 0.2;   // m/s at full deflection
  s.angular_speed = 1.0;  // rad/s
  HidDevice dev(fake, {0x256f, 0xc635, "", ""}, s);
  REQUIRE(dev.connection() == HidConnection::kConnected);
  CHECK(dev.info().name == "3Dconnexion SpaceMouse Compact");
  CHECK_FALSE(dev.info().renders_force);
  DeviceState st;
  CHECK(dev.read(0.0, &st) == DeviceStatus::kOk);
  // Half deflection along x (175 of 350 counts), a quarter about z, held 1 s at 1 kHz.
  fake->units[0].reports.push_back(report(1, {175, 0, 3}));   // z = 3: inside the deadzone (5)
  fake->units[0].reports.push_back(report(2, {0, 0, 87}));
  for (int i = 1; i <= 1000; ++i) REQUIRE(dev.read(i * 1e-3, &st) == DeviceStatus::kOk);
  // p = k_lin (175/350) t = 0.1 m; angle = k_ang (87/350) t (87: integer counts).
  CHECK(st.X_WH.p.x() == Approx(0.1).epsilon(1e-12));
  CHECK(st.X_WH.p.z() == 0.0);
  CHECK(quat_log(st.X_WH.q).z() == Approx(87.0 / 350.0).epsilon(1e-12));
  // Buttons come through.
  const std::vector<uint8_t> b = {3, 0x02};
  fake->units[0].reports.push_back(b);
  dev.read(1.001, &st);
  CHECK(st.buttons == 2u);
  // The wrench is recorded, sent nowhere.
  Vec6 F = Vec6::Constant(0.5);
  CHECK(dev.write(1.001, F) == DeviceStatus::kOk);
  CHECK(dev.applied_force() == F);
}

TEST_CASE("HID state machine: unplug, force zeroed, re-plug, same unit", "[device][hid]") {
  auto fake = std::make_shared<FakeBackend>();
  fake->units.push_back({entry(0x046d, 0xc626, "/dev/hidraw0", "A"), true, {}});
  fake->units.push_back({entry(0x046d, 0xc626, "/dev/hidraw1", "B"), true, {}});
  HidDevice dev(fake, {0x046d, 0xc626, "B", ""}, {});
  REQUIRE(dev.connection() == HidConnection::kConnected);
  CHECK(dev.entry().serial == "B");
  DeviceState st;
  Vec6 F = Vec6::Constant(1.0);
  fake->units[1].reports.push_back(report(1, {350, 0, 0}));
  REQUIRE(dev.read(0.0, &st) == DeviceStatus::kOk);
  REQUIRE(dev.read(0.1, &st) == DeviceStatus::kOk);
  REQUIRE(dev.write(0.1, F) == DeviceStatus::kOk);
  CHECK(dev.applied_force() == F);
  const double x_before = st.X_WH.p.x();
  CHECK(x_before > 0);

  // Unplug: the next read fails, the device is lost, the force is zero.
  fake->units[1].present = false;
  CHECK(dev.read(0.2, &st) == DeviceStatus::kNotConnected);
  CHECK(dev.connection() == HidConnection::kLost);
  CHECK(dev.applied_force().isZero());
  CHECK(dev.write(0.2, F) == DeviceStatus::kNotConnected);
  CHECK(dev.applied_force().isZero());
  CHECK(st.X_WH.p.x() == x_before);  // the pose holds, no drift
  const int enumerations = fake->num_enumerations;
  for (int i = 0; i < 10; ++i) dev.read(0.2 + i * 1e-3, &st);
  CHECK(fake->num_enumerations == enumerations);  // read() never enumerates

  // Re-enumeration while it is away: the lost handle is closed, unit A is not taken.
  CHECK(dev.poll_connection() == HidConnection::kReconnecting);
  CHECK(fake->num_open() == 0);
  CHECK(dev.poll_connection() == HidConnection::kReconnecting);

  // Re-plug (on another path, as hidraw numbering goes): found again by its serial.
  fake->units[1].present = true;
  fake->units[1].entry.path = "/dev/hidraw7";
  CHECK(dev.poll_connection() == HidConnection::kConnected);
  CHECK(dev.entry().path == "/dev/hidraw7");
  CHECK(dev.entry().serial == "B");
  CHECK(dev.read(0.3, &st) == DeviceStatus::kOk);
  CHECK(st.X_WH.p.x() == x_before);  // the deflection was reset while away
  CHECK(dev.write(0.3, F) == DeviceStatus::kOk);
  CHECK(dev.applied_force() == F);
}

TEST_CASE("HID device absent at start: reconnecting until it appears (helper thread)", "[device][hid]") {
  auto fake = std::make_shared<FakeBackend>();
  HidDeviceSettings s;
  s.reconnect_period = 0.01;
  HidDevice dev(fake, {}, s);
  DeviceState st;
  CHECK(dev.connection() == HidConnection::kReconnecting);
  CHECK(dev.read(0.0, &st) == DeviceStatus::kNotConnected);
  CHECK(std::string(st.message).find("not connected") != std::string::npos);
  // An unknown HID device is not taken.
  fake->units.push_back({entry(0x046d, 0xc077, "/dev/hidraw0", ""), true, {}});
  CHECK(dev.poll_connection() == HidConnection::kReconnecting);
  CHECK_THROWS_AS(HidDevice(fake, {0x046d, 0xc077, "", ""}, s), std::invalid_argument);
  // Note: the fake backend is not thread-safe, so the unit is added before the thread starts.
  fake->units.push_back({entry(0x256f, 0xc62e, "/dev/hidraw1", ""), true, {}});
  dev.start_reconnect_thread();
  for (int i = 0; i < 200 && dev.connection() != HidConnection::kConnected; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  dev.stop_reconnect_thread();
  CHECK(dev.connection() == HidConnection::kConnected);
  CHECK(dev.profile()->product_id == 0xc62e);
}

TEST_CASE("a real SpaceMouse, when one is plugged in", "[device][hid][hardware]") {
  auto backend = make_hidapi_backend();
  bool found = false;
  for (const HidDeviceEntry& e : list_hid_devices(*backend))
    found |= find_hid_profile(e.vendor_id, e.product_id) != nullptr;
  if (!found) {
    WARN("SKIPPED: no supported HID device found by hid_enumerate (no SpaceMouse plugged in, or no hidraw access)");
    std::cout << "SKIPPED: real-device test: no supported HID device found\n";
    return;
  }
  HidDevice dev(backend, {}, {});
  REQUIRE(dev.connection() == HidConnection::kConnected);
  DeviceState st;
  for (int i = 0; i < 200; ++i) {
    REQUIRE(dev.read(i * 1e-3, &st) == DeviceStatus::kOk);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  CHECK(is_valid_pose(st.X_WH));
}
