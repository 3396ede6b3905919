// HID devices through hidapi: enumeration, device profiles as data, report
// parsing, and a Device with an unplug/re-plug state machine.
//
// Supported today: the 3Dconnexion SpaceMouse family. A SpaceMouse is an
// input-only *rate* device: its cap's deflection (counts) is a velocity, which
// the driver integrates into the handle pose,
//   p += k_lin * (d_t / full_scale) * dt,   q = exp(k_ang * (d_r / full_scale) * dt) q,
// with d_t, d_r the translation and rotation counts mapped to the world by R_WD.
// It renders no force (DeviceInfo::renders_force false): the runtime records
// the wrench in the trace and sends it nowhere.
//
// Reports (from the USB HID reports these devices send, as documented by
// spacenavd/libspnav and observed with usbmon): report 1 = translation
// (x, y, z: int16 little-endian, 6 bytes), report 2 = rotation (rx, ry, rz:
// int16 LE), report 3 = buttons (bitmask, little-endian). Newer models (the
// 0x256f wireless family and the Enterprise) send translation and rotation
// together in report 1 (12 bytes). Each profile names its layout; a report 1 of
// 12 bytes is read as the combined form whatever the profile says.
//
// Hot-plug: kDisconnected -> (open) -> kConnected -> (read error) -> kLost ->
// kReconnecting -> (re-enumeration finds it) -> kConnected. read()/write() never
// enumerate: poll_connection() does, from a helper thread (start_reconnect_thread())
// or from the caller at a low rate. While not connected, read() returns
// kNotConnected with the last pose, and the applied force is zero.
//
// hidapi sits behind HidBackend (enumerate, open, read_timeout, write, close),
// so that the state machine and the parsing are tested with a fake backend.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "gauss6/runtime/device_port.h"
#include "gauss6/geometry/pose.h"

namespace gauss6 {

// One HID interface as enumeration reports it.
struct HidDeviceEntry {
  std::string path;            // platform path (Linux hidraw: /dev/hidrawN)
  uint16_t vendor_id = 0;
  uint16_t product_id = 0;
  std::string serial;          // may be empty
  std::string manufacturer;
  std::string product;
  int interface_number = -1;
};

// The small part of hidapi that the driver uses. Handles are opaque.
class HidBackend {
 public:
  using Handle = void*;
  virtual ~HidBackend() = default;
  virtual std::vector<HidDeviceEntry> enumerate() = 0;                     // not real-time
  virtual Handle open(const std::string& path) = 0;                        // nullptr on failure; not real-time
  // Reads one report into buf (report id first). Returns the number of bytes,
  // 0 when nothing arrived within timeout_ms (0: do not wait), -1 on error
  // (e.g. the device was unplugged). Real-time with timeout_ms == 0.
  virtual int read_timeout(Handle h, uint8_t* buf, size_t len, int timeout_ms) = 0;
  virtual int write(Handle h, const uint8_t* data, size_t len) = 0;        // bytes written or -1
  virtual void close(Handle h) = 0;                                        // not real-time
};

// The hidapi backend (hidapi-hidraw on Linux). One per process is enough.
std::shared_ptr<HidBackend> make_hidapi_backend();

enum class HidReportLayout {
  kSplit,     // report 1: translation (6 bytes), report 2: rotation (6 bytes), report 3: buttons
  kCombined,  // report 1: translation then rotation (12 bytes), report 3: buttons
};

// A device profile: data, not code. Counts to motion: see the file comment.
struct HidProfile {
  uint16_t vendor_id;
  uint16_t product_id;
  const char* name;
  HidReportLayout layout;
  int num_buttons;
  double full_scale;        // counts at full deflection (about 350 for these models)
  bool renders_force;       // false: input-only
};

// Every known profile (the SpaceMouse family).
std::span<const HidProfile> hid_profiles();
// The profile of (vendor, product), or nullptr.
const HidProfile* find_hid_profile(uint16_t vendor_id, uint16_t product_id);

// The latest values of a 6-DoF rate device, in device counts and device axes.
struct SpaceMouseAxes {
  int16_t translation[3] = {0, 0, 0};  // x, y, z
  int16_t rotation[3] = {0, 0, 0};     // rx, ry, rz
  uint32_t buttons = 0;
};

// What one report changed (bit 0 translation, bit 1 rotation, bit 2 buttons).
enum HidReportParts : unsigned { kReportTranslation = 1, kReportRotation = 2, kReportButtons = 4 };
// Parses one report (report id first) into axes; returns the parts it set, 0 for a
// report it does not know or a short one (axes left unchanged). Real-time safe.
unsigned parse_spacemouse_report(const HidProfile& profile, const uint8_t* report, size_t len, SpaceMouseAxes* axes);

// Lists the HID devices the backend sees (all of them, known profile or not).
std::vector<HidDeviceEntry> list_hid_devices(HidBackend& backend);

// Which device to open: the first entry matching every field that is set.
struct HidSelector {
  uint16_t vendor_id = 0;      // 0: any with a known profile
  uint16_t product_id = 0;     // 0: any
  std::string serial;          // empty: any
  std::string path;            // empty: any
};

struct HidDeviceSettings {
  double linear_speed = 0.1;          // scene units/s at full deflection (k_lin)
  double angular_speed = 1.0;         // rad/s at full deflection (k_ang)
  int deadzone = 5;                   // counts: smaller deflections read as 0
  Mat3 R_WD = Mat3::Identity();       // device axes -> world axes (a rotation); default: as reported
  Pose X_WH0;                         // the handle's pose when the run starts
  double rate_hz = 1000;              // the haptic loop's rate with this device
  double reconnect_period = 0.5;      // s between re-enumerations while lost
  int max_reports_per_read = 32;      // reports drained per read(), at most
};

enum class HidConnection { kDisconnected, kConnected, kLost, kReconnecting };
const char* to_string(HidConnection c);

class HidDevice final : public Device {
 public:
  // Tries to open the selected device once; if it is absent the device starts
  // kReconnecting and poll_connection() keeps looking. Throws std::invalid_argument
  // if the selector names a (vendor, product) with no profile (load time).
  HidDevice(std::shared_ptr<HidBackend> backend, HidSelector selector, const HidDeviceSettings& settings = {});
  ~HidDevice() override;

  const DeviceInfo& info() const override { return info_; }
  // Drains the pending reports, integrates the deflection over t - (last read's t).
  DeviceStatus read(double t, DeviceState* state) override;
  // Input-only devices keep F as the applied force while connected (zero otherwise).
  DeviceStatus write(double t, const Vec6& F) override;

  // Not real-time: one step of the reconnection logic (close a lost handle,
  // re-enumerate, reopen). Returns the connection state after it.
  HidConnection poll_connection();
  // Runs poll_connection() every settings.reconnect_period on a helper thread.
  void start_reconnect_thread();
  void stop_reconnect_thread();

  HidConnection connection() const { return state_.load(std::memory_order_acquire); }
  const HidProfile* profile() const { return profile_; }
  const HidDeviceEntry& entry() const { return entry_; }
  const Vec6& applied_force() const { return applied_F_; }
  const SpaceMouseAxes& axes() const { return axes_; }

 private:
  bool try_open();  // enumerate, match, open: not real-time

  std::shared_ptr<HidBackend> backend_;
  HidSelector selector_;
  HidDeviceSettings settings_;
  DeviceInfo info_;
  const HidProfile* profile_ = nullptr;
  HidDeviceEntry entry_;
  // The handle belongs to the real-time side while kConnected and to the
  // reconnecting side otherwise; state_ hands it over (release/acquire).
  HidBackend::Handle handle_ = nullptr;
  std::atomic<HidConnection> state_{HidConnection::kDisconnected};
  std::mutex poll_mutex_;            // poll_connection() against itself; never in read()/write()
  std::thread thread_;
  std::atomic<bool> stop_{false};

  // Real-time side.
  SpaceMouseAxes axes_;
  Pose X_WH_;
  double last_t_ = 0;
  bool have_last_t_ = false;
  Vec6 applied_F_ = Vec6::Zero();
  uint8_t buf_[64] = {};
};

}  // namespace gauss6
