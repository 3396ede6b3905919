// The replay device: plays back the handle poses (xh) of a recorded trace at
// their times, so that a run can be repeated against a new build of the
// renderer. Between two recorded ticks the pose is interpolated (linear in
// position, slerp in rotation); before the first tick it holds the first pose;
// after the last it holds the last pose and read() returns kEnded. Buttons and
// the grip come from the earlier of the two ticks. write() keeps the last wrench
// for inspection and sends it nowhere (renders_force is false).
#pragma once

#include <string>
#include <vector>

#include "gauss6/runtime/device_port.h"
#include "gauss6/trace.h"

namespace gauss6 {

struct ReplaySample {
  double t = 0;                 // s, strictly increasing
  Pose X_WH;
  uint32_t buttons = 0;
  bool gripped = true;
};

class ReplayDevice final : public Device {
 public:
  // Throws std::invalid_argument on no samples, times not strictly increasing
  // or invalid poses (load time).
  explicit ReplayDevice(std::vector<ReplaySample> samples, std::string name = "replay");
  // The ticks of a trace (read_trace()); `name` defaults to "replay: <trace path>".
  static ReplayDevice from_trace(const Trace& trace, std::string name = "replay");

  const DeviceInfo& info() const override { return info_; }
  DeviceStatus read(double t, DeviceState* state) override;
  DeviceStatus write(double t, const Vec6& F) override;

  const Vec6& last_force() const { return last_F_; }
  double end_time() const { return samples_.back().t; }
  size_t num_samples() const { return samples_.size(); }

 private:
  std::vector<ReplaySample> samples_;
  DeviceInfo info_;
  size_t cursor_ = 0;           // last segment used: reads move forward in O(1)
  Vec6 last_F_ = Vec6::Zero();
};

}  // namespace gauss6
