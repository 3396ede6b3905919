// The haptic loop (fixed rate, the device's): its state and its tick.
//
//   haptic_tick(): device read -> Fc -> safety -> device write
//
// The force comes from the coupling step run inside the tick, or from the
// coupling loop's wrench channel. The safety stage (watchdogs, finiteness,
// limits) is make_safe_wrench. Real time: haptic_tick and make_safe_wrench
// allocate nothing, lock nothing and throw nothing. Frames: world frame W.
#pragma once

#include <cstdint>

#include "gauss6/runtime/coupling_loop.h"
#include "gauss6/runtime/device_port.h"
#include "gauss6/runtime/runtime_channels.h"
#include "gauss6/runtime/runtime_events.h"
#include "gauss6/runtime/runtime_model.h"
#include "gauss6/runtime/runtime_stats.h"

namespace gauss6 {

// The force and torque a haptic loop may send: the device's (DeviceInfo, the
// one source of what it can render) lowered by the scene's (model.device). A
// device limit that is not a positive number (unset, NaN) leaves the scene's.
struct WrenchLimits {
  double max_force = 0, max_torque = 0;  // N, N m
  bool resolved = false;                 // set by resolve_wrench_limits
};
WrenchLimits resolve_wrench_limits(const RuntimeModel& model, const DeviceInfo& device);

// Every buffer of the haptic loop.
struct HapticState {
  uint64_t tick = 0;
  DeviceState device;                  // last sample
  Pose xh;                             // last good handle pose
  bool has_handle = false;
  double last_good_time = 0;           // s, time of the last good sample (the run's start at first)
  EventGate events;                    // onsets and their rate limit (runtime_events.h)
  bool ended = false;                  // the device ended
  WrenchSample wrench;                 // kCouplingLoop: last Fc read
  WrenchLimits limits;                 // the device's, resolved at the first tick (a state serves one device)
  HapticTickRecord record;
};

// t is the run's clock (s): virtual in lockstep runs, steady_clock in threads.
// One haptic tick: device read, force (the coupling step when coupling != null,
// else the wrench channel), safety (watchdogs, finiteness, limits), device write.
// Zero force (and an event) on: an invalid pose, kNotConnected, the device,
// sim or coupling watchdog, the device's end; a failed write() is followed by a
// write of zero (Device::halt_force() if that fails too) and reported.
// The limits are the device's (device->info()) lowered by the scene's (model.device),
// resolved once, at the state's first tick (h->limits).
// Writes stats->haptic (and stats->coupling when coupling != null); event onsets
// go to the observer. Returns false when the device ended (zero force written).
bool haptic_tick(const RuntimeModel& model, double t, Device* device, RuntimeChannels* channels,
                 HapticState* h, CouplingState* coupling, const RuntimeObserver& observer, RuntimeStats* stats) noexcept;

// The safety stage alone: returns a finite wrench within the limits; sets the
// bits of *events (1 << RuntimeEventKind) for kNonFiniteForce and kForceClamped.
// A non-finite wrench, or a limit that is not >= 0 (negative or NaN), gives zero
// and kNonFiniteForce.
Vec6 make_safe_wrench(const Vec6& F, double max_force, double max_torque, uint32_t* events) noexcept;

}  // namespace gauss6
