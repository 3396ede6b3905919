// The replay device: recorded handle poses played back at their times (replay_device.h).
#include "gauss6/replay_device.h"

#include <cmath>
#include <stdexcept>

namespace gauss6 {

ReplayDevice::ReplayDevice(std::vector<ReplaySample> samples, std::string name) : samples_(std::move(samples)) {
  if (samples_.empty()) throw std::invalid_argument("replay device: no samples");
  for (size_t i = 0; i < samples_.size(); ++i) {
    // Same rotation, rescaled by a power of two when its size is out of range (pose.h).
    samples_[i].X_WH.q = rescaled(samples_[i].X_WH.q);
    if (!std::isfinite(samples_[i].t) || !is_valid_pose(samples_[i].X_WH))
      throw std::invalid_argument("replay device: sample " + std::to_string(i) +
                                  ": time or pose not finite, or a zero quaternion");
    if (i > 0 && !(samples_[i].t > samples_[i - 1].t))
      throw std::invalid_argument("replay device: sample " + std::to_string(i) + ": times must increase strictly");
  }
  info_.name = std::move(name);
  // The recorded rate: the mean tick spacing (1 kHz for a single sample).
  const double span = samples_.back().t - samples_.front().t;
  info_.rate_hz = samples_.size() > 1 && span > 0 ? (samples_.size() - 1) / span : 1000.0;
  info_.renders_force = false;
}

ReplayDevice ReplayDevice::from_trace(const Trace& trace, std::string name) {
  std::vector<ReplaySample> samples;
  samples.reserve(trace.ticks.num_rows());
  for (size_t i = 0; i < trace.ticks.num_rows(); ++i) {
    const TraceTick tick = trace_tick(trace, i);
    samples.push_back({tick.t, tick.X_WH, tick.buttons, (tick.flags & kTickGripped) != 0});
  }
  return ReplayDevice(std::move(samples), std::move(name));
}

DeviceStatus ReplayDevice::read(double t, DeviceState* state) {
  if (!std::isfinite(t)) {
    state->status = DeviceStatus::kError;
    state->message = "replay device: time is not finite";
    return state->status;
  }
  const size_t n = samples_.size();
  state->time = t;
  state->status = DeviceStatus::kOk;
  state->message = "";
  if (t <= samples_.front().t || n == 1) {
    const ReplaySample& s = t <= samples_.front().t ? samples_.front() : samples_.back();
    state->X_WH = s.X_WH, state->buttons = s.buttons, state->gripped = s.gripped;
    if (t > samples_.back().t) state->status = DeviceStatus::kEnded, state->message = "replay device: end of the trace";
    return state->status;
  }
  if (t > samples_.back().t) {
    const ReplaySample& s = samples_.back();
    state->X_WH = s.X_WH, state->buttons = s.buttons, state->gripped = s.gripped;
    state->status = DeviceStatus::kEnded;
    state->message = "replay device: end of the trace";
    return state->status;
  }
  // Segment [i, i+1] with samples_[i].t < t <= samples_[i+1].t: walk from the
  // last one (forward in a run; backwards only after a jump back).
  size_t i = cursor_ < n - 1 ? cursor_ : n - 2;
  while (samples_[i + 1].t < t) ++i;
  while (i > 0 && samples_[i].t >= t) --i;
  cursor_ = i;
  const ReplaySample& a = samples_[i];
  const ReplaySample& b = samples_[i + 1];
  const double u = (t - a.t) / (b.t - a.t);
  if (t == b.t) {  // on a recorded tick: exactly its pose
    state->X_WH = b.X_WH, state->buttons = b.buttons, state->gripped = b.gripped;
    return state->status;
  }
  state->X_WH.p = a.X_WH.p + u * (b.X_WH.p - a.X_WH.p);
  const Quat qa = normalized(a.X_WH.q);
  state->X_WH.q = normalized(quat_exp(u * quat_log(normalized(b.X_WH.q) * conjugate(qa))) * qa);
  state->buttons = a.buttons;
  state->gripped = a.gripped;
  return state->status;
}

DeviceStatus ReplayDevice::write(double /*t*/, const Vec6& F) {
  if (!F.allFinite()) return DeviceStatus::kError;
  last_F_ = F;
  return DeviceStatus::kOk;
}

}  // namespace gauss6
