// HID devices: the profile table, SpaceMouse report parsing and the hot-plug
// state machine (hid_device.h). The hidapi backend is in hid_backend_hidapi.cpp.
#include "gauss6/hid_device.h"

#include <array>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace gauss6 {

namespace {

// The SpaceMouse family. Vendor 0x046d: Logitech-era 3Dconnexion devices;
// vendor 0x256f: 3Dconnexion's own id. Product ids and report layouts as
// published by spacenavd / libspnav and the 3Dconnexion product pages.
// full_scale: the counts at full deflection (about +-350 on these models).
constexpr std::array<HidProfile, 12> kProfiles = {{
    {0x046d, 0xc626, "3Dconnexion SpaceNavigator", HidReportLayout::kSplit, 2, 350, false},
    {0x046d, 0xc627, "3Dconnexion SpaceExplorer", HidReportLayout::kSplit, 15, 350, false},
    {0x046d, 0xc628, "3Dconnexion SpaceNavigator for Notebooks", HidReportLayout::kSplit, 2, 350, false},
    {0x046d, 0xc629, "3Dconnexion SpacePilot Pro", HidReportLayout::kSplit, 31, 350, false},
    {0x046d, 0xc62b, "3Dconnexion SpaceMouse Pro", HidReportLayout::kSplit, 15, 350, false},
    {0x256f, 0xc62e, "3Dconnexion SpaceMouse Wireless (cable)", HidReportLayout::kCombined, 2, 350, false},
    {0x256f, 0xc62f, "3Dconnexion SpaceMouse Wireless (receiver)", HidReportLayout::kCombined, 2, 350, false},
    {0x256f, 0xc631, "3Dconnexion SpaceMouse Pro Wireless (cable)", HidReportLayout::kCombined, 15, 350, false},
    {0x256f, 0xc632, "3Dconnexion SpaceMouse Pro Wireless (receiver)", HidReportLayout::kCombined, 15, 350, false},
    {0x256f, 0xc633, "3Dconnexion SpaceMouse Enterprise", HidReportLayout::kCombined, 31, 350, false},
    {0x256f, 0xc635, "3Dconnexion SpaceMouse Compact", HidReportLayout::kSplit, 2, 350, false},
    {0x256f, 0xc652, "3Dconnexion Universal Receiver", HidReportLayout::kCombined, 15, 350, false},
}};

int16_t le16(const uint8_t* b) { return static_cast<int16_t>(static_cast<uint16_t>(b[0] | (b[1] << 8))); }

bool matches(const HidSelector& s, const HidDeviceEntry& e) {
  if (s.vendor_id != 0 && e.vendor_id != s.vendor_id) return false;
  if (s.product_id != 0 && e.product_id != s.product_id) return false;
  if (!s.serial.empty() && e.serial != s.serial) return false;
  if (!s.path.empty() && e.path != s.path) return false;
  return find_hid_profile(e.vendor_id, e.product_id) != nullptr;
}

// Deflection in [-1, 1] (may exceed 1 slightly on some units) with the deadzone applied.
double deflection(int16_t counts, int deadzone, double full_scale) {
  return std::abs(counts) <= deadzone ? 0.0 : counts / full_scale;
}

}  // namespace

std::span<const HidProfile> hid_profiles() { return kProfiles; }

const HidProfile* find_hid_profile(uint16_t vendor_id, uint16_t product_id) {
  for (const HidProfile& p : kProfiles)
    if (p.vendor_id == vendor_id && p.product_id == product_id) return &p;
  return nullptr;
}

unsigned parse_spacemouse_report(const HidProfile& profile, const uint8_t* r, size_t len, SpaceMouseAxes* axes) {
  if (len < 1) return 0;
  const size_t payload = len - 1;
  switch (r[0]) {
    case 1:
      // Combined (12 bytes): translation then rotation; split: translation only.
      if (payload >= 12) {
        for (int i = 0; i < 3; ++i) axes->translation[i] = le16(r + 1 + 2 * i);
        for (int i = 0; i < 3; ++i) axes->rotation[i] = le16(r + 7 + 2 * i);
        return kReportTranslation | kReportRotation;
      }
      if (payload >= 6) {
        for (int i = 0; i < 3; ++i) axes->translation[i] = le16(r + 1 + 2 * i);
        return kReportTranslation;
      }
      return 0;
    case 2:
      if (payload < 6) return 0;
      for (int i = 0; i < 3; ++i) axes->rotation[i] = le16(r + 1 + 2 * i);
      return kReportRotation;
    case 3: {
      if (payload < 1) return 0;
      // Little-endian bitmask, up to 32 buttons, masked to the profile's count.
      uint32_t bits = 0;
      for (size_t i = 0; i < payload && i < 4; ++i) bits |= static_cast<uint32_t>(r[1 + i]) << (8 * i);
      const uint32_t mask = profile.num_buttons >= 32 ? 0xffffffffu : ((1u << profile.num_buttons) - 1u);
      axes->buttons = bits & mask;
      return kReportButtons;
    }
    default:
      return 0;  // LED state, battery and other reports: not motion
  }
}

std::vector<HidDeviceEntry> list_hid_devices(HidBackend& backend) { return backend.enumerate(); }

const char* to_string(HidConnection c) {
  switch (c) {
    case HidConnection::kDisconnected: return "disconnected";
    case HidConnection::kConnected: return "connected";
    case HidConnection::kLost: return "lost";
    case HidConnection::kReconnecting: return "reconnecting";
  }
  return "unknown";
}

HidDevice::HidDevice(std::shared_ptr<HidBackend> backend, HidSelector selector, const HidDeviceSettings& settings)
    : backend_(std::move(backend)), selector_(std::move(selector)), settings_(settings) {
  if (!backend_) throw std::invalid_argument("HID device: no backend");
  if (selector_.vendor_id != 0 && selector_.product_id != 0 &&
      !find_hid_profile(selector_.vendor_id, selector_.product_id))
    throw std::invalid_argument("HID device: no profile for vendor " + std::to_string(selector_.vendor_id) +
                                " product " + std::to_string(selector_.product_id));
  if (!(settings_.rate_hz > 0) || !(settings_.reconnect_period > 0) || settings_.max_reports_per_read < 1)
    throw std::invalid_argument("HID device: rate_hz, reconnect_period and max_reports_per_read must be > 0");
  if (!((settings_.R_WD.transpose() * settings_.R_WD - Mat3::Identity()).norm() < 1e-9 &&
        settings_.R_WD.determinant() > 0))
    throw std::invalid_argument("HID device: R_WD must be a rotation");
  X_WH_ = settings_.X_WH0;
  info_.rate_hz = settings_.rate_hz;
  info_.renders_force = false;
  // Connect now if the device is there; otherwise keep looking in poll_connection().
  if (try_open()) {
    state_.store(HidConnection::kConnected, std::memory_order_release);
  } else {
    state_.store(HidConnection::kReconnecting, std::memory_order_release);
  }
  const HidProfile* named = profile_ ? profile_ : find_hid_profile(selector_.vendor_id, selector_.product_id);
  info_.name = named ? named->name : "HID 6-DoF device (SpaceMouse family)";
  info_.renders_force = named ? named->renders_force : false;
}

HidDevice::~HidDevice() {
  stop_reconnect_thread();
  if (handle_) backend_->close(handle_);
}

bool HidDevice::try_open() {
  for (const HidDeviceEntry& e : backend_->enumerate()) {
    if (!matches(selector_, e)) continue;
    // After a first connection, re-plug must find the same unit (serial), not another one.
    if (!entry_.serial.empty() && e.serial != entry_.serial) continue;
    HidBackend::Handle h = backend_->open(e.path);
    if (!h) continue;
    handle_ = h;
    entry_ = e;
    profile_ = find_hid_profile(e.vendor_id, e.product_id);
    return true;
  }
  return false;
}

HidConnection HidDevice::poll_connection() {
  std::lock_guard<std::mutex> g(poll_mutex_);
  HidConnection s = state_.load(std::memory_order_acquire);
  if (s == HidConnection::kLost) {
    // The real-time side let go of the handle when it set kLost.
    if (handle_) backend_->close(handle_);
    handle_ = nullptr;
    s = HidConnection::kReconnecting;
    state_.store(s, std::memory_order_release);
  }
  if (s == HidConnection::kDisconnected || s == HidConnection::kReconnecting) {
    if (try_open()) {
      s = HidConnection::kConnected;
      state_.store(s, std::memory_order_release);
    }
  }
  return s;
}

void HidDevice::start_reconnect_thread() {
  if (thread_.joinable()) return;
  stop_.store(false);
  thread_ = std::thread([this] {
    const auto period = std::chrono::duration<double>(settings_.reconnect_period);
    while (!stop_.load()) {
      poll_connection();
      // Sleep in short slices so that stop_reconnect_thread() returns promptly.
      const auto until = std::chrono::steady_clock::now() + period;
      while (!stop_.load() && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
}

void HidDevice::stop_reconnect_thread() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

DeviceStatus HidDevice::read(double t, DeviceState* state) {
  const double dt = have_last_t_ && t > last_t_ ? t - last_t_ : 0.0;
  last_t_ = t;
  have_last_t_ = true;
  state->time = t;
  state->gripped = true;

  if (state_.load(std::memory_order_acquire) != HidConnection::kConnected) {
    // Not connected: hold the pose, no deflection, no force.
    axes_ = SpaceMouseAxes{};
    applied_F_.setZero();
    state->X_WH = X_WH_;
    state->buttons = 0;
    state->status = DeviceStatus::kNotConnected;
    state->message = "HID device not connected";
    return state->status;
  }

  // Drain what arrived since the last tick (never waits).
  for (int i = 0; i < settings_.max_reports_per_read; ++i) {
    const int n = backend_->read_timeout(handle_, buf_, sizeof buf_, /*timeout_ms=*/0);
    if (n < 0) {
      // Unplugged (or failed): hand the handle over to poll_connection().
      state_.store(HidConnection::kLost, std::memory_order_release);
      axes_ = SpaceMouseAxes{};
      applied_F_.setZero();
      state->X_WH = X_WH_;
      state->buttons = 0;
      state->status = DeviceStatus::kNotConnected;
      state->message = "HID device lost (read error): reconnecting";
      return state->status;
    }
    if (n == 0) break;
    parse_spacemouse_report(*profile_, buf_, static_cast<size_t>(n), &axes_);
  }

  // Rate control: the deflection is a velocity, integrated over dt.
  const double fs = profile_->full_scale;
  const int dz = settings_.deadzone;
  const Vec3 d_t(deflection(axes_.translation[0], dz, fs), deflection(axes_.translation[1], dz, fs),
                 deflection(axes_.translation[2], dz, fs));
  const Vec3 d_r(deflection(axes_.rotation[0], dz, fs), deflection(axes_.rotation[1], dz, fs),
                 deflection(axes_.rotation[2], dz, fs));
  X_WH_.p += (settings_.linear_speed * dt) * (settings_.R_WD * d_t);
  X_WH_.q = normalized(quat_exp((settings_.angular_speed * dt) * (settings_.R_WD * d_r)) * X_WH_.q);

  state->X_WH = X_WH_;
  state->buttons = axes_.buttons;
  state->status = DeviceStatus::kOk;
  state->message = "";
  return state->status;
}

DeviceStatus HidDevice::write(double /*t*/, const Vec6& F) {
  if (state_.load(std::memory_order_acquire) != HidConnection::kConnected) {
    applied_F_.setZero();
    return DeviceStatus::kNotConnected;
  }
  if (!F.allFinite()) return DeviceStatus::kError;
  // Input-only: the wrench is kept (the runtime records it) and sent nowhere.
  applied_F_ = F;
  return DeviceStatus::kOk;
}

}  // namespace gauss6
