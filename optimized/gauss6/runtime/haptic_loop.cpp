// The haptic loop: device read, force, safety stage, device write
// (haptic_loop.h).
#include "gauss6/runtime/haptic_loop.h"

#include <cmath>

#include "runtime_detail.h"

namespace gauss6 {

using namespace detail;  // the loops' shared machinery (runtime_detail.h)

// ---------------------------------------------------------------------------
// Haptic loop.
// ---------------------------------------------------------------------------

namespace {

bool all_finite(const Vec6& v) { return v.allFinite(); }

}  // namespace

Vec6 make_safe_wrench(const Vec6& F, double max_force, double max_torque, uint32_t* events) noexcept {
  // A limit that is not >= 0 (negative or NaN) would reverse the wrench into the
  // obstacle: no force, as for a non-finite wrench.
  if (!all_finite(F) || !(max_force >= 0) || !(max_torque >= 0)) {
    *events |= event_bit(RuntimeEventKind::kNonFiniteForce);
    return Vec6::Zero();
  }
  // Scale each part down to its limit (direction kept). A finite part whose
  // norm overflows (components near 1e154 and above) is divided by its largest
  // component first, so it is clamped to the limit, not to 0.
  Vec6 out = F;
  const auto clamp_part = [events](auto part, double limit) {
    const double n = part.norm();
    if (std::isfinite(n)) {
      if (n > limit) part *= limit / n, *events |= event_bit(RuntimeEventKind::kForceClamped);
      return;
    }
    part /= part.cwiseAbs().maxCoeff();
    part *= limit / part.norm();
    *events |= event_bit(RuntimeEventKind::kForceClamped);
  };
  clamp_part(out.head<3>(), max_force);
  clamp_part(out.tail<3>(), max_torque);
  if (!all_finite(out)) {  // only when a limit itself is not finite
    *events |= event_bit(RuntimeEventKind::kNonFiniteForce);
    return Vec6::Zero();
  }
  return out;
}

namespace {

constexpr uint32_t kZeroForceEvents =
    event_bit(RuntimeEventKind::kInvalidHandlePose) | event_bit(RuntimeEventKind::kDeviceTimeout) |
    event_bit(RuntimeEventKind::kSimStalled) | event_bit(RuntimeEventKind::kCouplingStalled) |
    event_bit(RuntimeEventKind::kDeviceEnded) | event_bit(RuntimeEventKind::kDeviceNotConnected);

// The smaller of the scene's limit and the device's; a device limit that is not a
// positive number (unset, NaN) leaves the scene's, which the model checked is > 0.
double lower_limit(double scene_limit, double device_limit) {
  return device_limit > 0 && device_limit < scene_limit ? device_limit : scene_limit;
}

}  // namespace

WrenchLimits resolve_wrench_limits(const RuntimeModel& model, const DeviceInfo& device) {
  return {lower_limit(model.device.max_force, device.max_force), lower_limit(model.device.max_torque, device.max_torque),
          /*resolved=*/true};
}

bool haptic_tick(const RuntimeModel& model, double t, Device* device, RuntimeChannels* channels, HapticState* h,
                 CouplingState* coupling, const RuntimeObserver& observer, RuntimeStats* stats) noexcept {
  const Clock::time_point start = Clock::now();
  const RuntimeSettings& settings = model.settings;
  uint32_t events = 0;
  ++h->tick;

  // 1. Read the device; publish a good xh.
  const DeviceStatus status = device->read(t, &h->device);
  if (status == DeviceStatus::kOk) {
    // A handle beyond the scene's coordinates (1e12) would make au reach the
    // range where the projection's rows lose their digits (|au| ~ 1e155 reports
    // optimal while violating one): refused at the entry, as a non-finite pose.
    if (is_valid_pose(h->device.X_WH) && h->device.X_WH.p.cwiseAbs().maxCoeff() <= kMaxSceneCoordinate) {
      h->xh = h->device.X_WH;
      h->has_handle = true;
      h->last_good_time = t;
      HandleSample sample;
      sample.time = t;
      sample.tick = h->tick;
      store_pose(h->xh, sample.p, sample.q);
      channels->handle.write(sample);
    } else {
      events |= event_bit(RuntimeEventKind::kInvalidHandlePose);
    }
  } else if (status == DeviceStatus::kEnded) {
    events |= event_bit(RuntimeEventKind::kDeviceEnded);
    h->ended = true;
  } else if (status == DeviceStatus::kNotConnected) {
    events |= event_bit(RuntimeEventKind::kDeviceNotConnected);  // zero force now (device_port.h), not after the timeout
  } else {
    events |= event_bit(RuntimeEventKind::kDeviceError);
  }

  // 2. The force: the coupling step in this tick, or the coupling loop's Fc.
  Vec6 F = Vec6::Zero();
  double god_time = -1, force_time = t;
  if (coupling) {
    const CouplingStepInfo& info = coupling_step(model, t, channels, coupling);
    stats->coupling.add_start(t);
    stats->coupling.work.add(info.force_seconds);
    if (projection_failed(info.projection)) events |= event_bit(RuntimeEventKind::kProjectionFailed);
    if (observer.on_coupling_step) observer.on_coupling_step(observer.user, info);
    F = info.Fc;
    god_time = info.god_time;
  } else if (channels->wrench.try_read(&h->wrench)) {
    F = Eigen::Map<const Vec6>(h->wrench.F);
    god_time = h->wrench.god_time;
    force_time = h->wrench.time;
  } else {
    force_time = 0;  // nothing published yet (the run started at 0)
  }

  // 3. Safety: watchdogs, then finiteness and limits.
  if (t - h->last_good_time > settings.device_timeout) events |= event_bit(RuntimeEventKind::kDeviceTimeout);
  if (t - (god_time >= 0 ? god_time : 0.0) > settings.sim_timeout) events |= event_bit(RuntimeEventKind::kSimStalled);
  if (!coupling && t - force_time > settings.coupling_timeout) events |= event_bit(RuntimeEventKind::kCouplingStalled);
  const Vec6 F_computed = F;
  if (events & kZeroForceEvents) F.setZero();
  // The device's info() is the one source of what it can render; a scene may only lower it.
  if (!h->limits.resolved) h->limits = resolve_wrench_limits(model, device->info());
  F = make_safe_wrench(F, h->limits.max_force, h->limits.max_torque, &events);

  // 4. Write the device. A failed write may leave the last force rendered: zero
  // is written at once, and if that fails too the device is asked to halt.
  DeviceStatus written = device->write(t, F);
  if (written != DeviceStatus::kOk) {
    events |= event_bit(RuntimeEventKind::kDeviceWriteFailed);
    F.setZero();
    if (device->write(t, F) != DeviceStatus::kOk) device->halt_force();
  }

  // Events (onsets), statistics, record. The detail is the read's status, or
  // the failed write's when the read was good.
  const int detail = static_cast<int>(status != DeviceStatus::kOk ? status : written);
  report_onsets(events, &h->events, settings.event_interval, t, h->tick, observer, &stats->haptic, detail);
  stats->haptic.work.add(seconds_since(start));
  HapticTickRecord& rec = h->record;
  rec.tick = h->tick;
  rec.time = t;
  rec.device_status = status;
  rec.xh = h->xh;
  rec.buttons = h->device.buttons;
  rec.gripped = h->device.gripped;
  rec.F_computed = F_computed;
  rec.F_sent = F;
  rec.active_events = events;
  if (observer.on_haptic_tick) observer.on_haptic_tick(observer.user, rec);
  return !h->ended;
}

}  // namespace gauss6
