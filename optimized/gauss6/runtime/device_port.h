// The device port of the runtime: the one Device interface of gauss6, a haptic
// handle that reports its pose and buttons and takes a wrench. It belongs to the
// core, which consumes it (the haptic loop, runtime.h); the drivers in device/
// implement it. Virtual dispatch lives here, at the device boundary, and nowhere
// else. Implementations: simulated (device/src/simulated_device.cpp), replay of a
// recorded trace (device/src/replay_device.cpp), HID through hidapi (device/src/hid_device.cpp).
//
// Real-time contract: read() and write() are called from the haptic loop at the
// device's rate; they allocate nothing, take no lock that a non-real-time thread
// may hold for long, and throw nothing: failures come back as a DeviceStatus.
// halt_force() alone may be called from another thread (the watchdog's).
#pragma once

#include <cstdint>
#include <string>

#include "gauss6/geometry/pose.h"

namespace gauss6 {

enum class DeviceStatus {
  kOk = 0,
  kNotConnected,   // never opened, or unplugged: the loop zeroes the force and reports it
  kTimeout,        // no fresh sample within the device's period
  kEnded,          // a replay or a script reached its end
  kError,          // anything else; DeviceState::message says what
};
const char* to_string(DeviceStatus s);

// What a device can do, fixed when it opens.
struct DeviceInfo {
  std::string name;            // e.g. "simulated: peg_in_hole", "3Dconnexion SpaceMouse Compact"
  double rate_hz = 1000;       // the haptic loop's rate with this device
  double max_force = 20;       // N: larger forces are clamped before write()
  double max_torque = 1;       // N m
  bool renders_force = true;   // false: input-only (the force is recorded, not sent)
};

// One sample of the handle, world frame (the scene's units).
struct DeviceState {
  double time = 0;             // s, the device's clock (virtual in lockstep runs)
  Pose X_WH;                   // pose of the handle: the god-object's target xh
  uint32_t buttons = 0;        // bit i: button i pressed
  bool gripped = true;         // false once the user lets go of the handle
  DeviceStatus status = DeviceStatus::kOk;
  const char* message = "";    // static text for status != kOk
};

class Device {
 public:
  virtual ~Device() = default;
  virtual const DeviceInfo& info() const = 0;
  // Samples the handle at time t (s since the run started). Never throws.
  virtual DeviceStatus read(double t, DeviceState* state) = 0;
  // Applies the wrench F = (force, torque about the handle's point), world frame,
  // already clamped to info()'s limits and finite. Input-only devices ignore it.
  virtual DeviceStatus write(double t, const Vec6& F) = 0;
  // The one call that may come from another thread, while read() or write() is
  // blocked in the haptic thread: the runtime's watchdog (kHapticStalled) asks the
  // device to stop rendering force now, without waiting for the blocked call
  // (an amplifier disable, or an atomic flag the driver's rendering checks); the
  // next write() renders again. Returns kOk when no force is rendered any more.
  // The default serves input-only devices (nothing rendered: kOk); a device that
  // renders force and cannot do this returns kError, and the watchdog says so.
  virtual DeviceStatus halt_force() noexcept { return info().renders_force ? DeviceStatus::kError : DeviceStatus::kOk; }
};

}  // namespace gauss6
