// The simulated device: an impedance-type handle (6-DoF mass-spring-damper)
// held by a virtual user whose hand follows a scripted trajectory.
//
// Model, world frame, the scene's units (metres, kilograms, seconds in the
// generated scenes). The handle has position p, velocity v, orientation q and
// angular velocity w (world frame). The hand pose X_WA(t) comes from the script
// (keyframes: linear in position, slerp in rotation; held before the first and
// after the last). While gripped, a grip spring-damper pulls the handle to the hand:
//   f_grip = k (p_A - p) + c (v_A - v),  tau_grip = kr log(q_A q^*) + cr (w_A - w)
// and the rendered wrench (f_r, tau_r) from write() acts back on it (closed loop):
//   m dv/dt = f_grip + f_r - b v,        I dw/dt = tau_grip + tau_r - br w
// with an isotropic rotational inertia I (so there is no gyroscopic term).
// After the script's let-go time the grip is off: only the rendered wrench and
// the damping act, and DeviceState::gripped is false.
//
// Integration: semi-implicit Euler (v then p; w then q = exp(w h) q), with the
// rendered wrench held constant between write() calls, in equal substeps no
// longer than the stability limit of the parameters. Deterministic: the result
// depends only on the sequence of (t, F) calls, which in lockstep runs the
// caller gives (time is never read from a clock).
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "gauss6/runtime/device_port.h"
#include "gauss6/geometry/pose.h"

namespace gauss6 {

struct HandKeyframe {
  double t = 0;      // s
  Pose X_WA;         // pose of the hand (A) in the world at time t
};

// A named part of a scripted interaction (e.g. the paper's phases a-e); the
// runtime records the phases in the trace's metadata and as events.
struct HandPhase {
  std::string name;
  double start = 0;  // s
};

struct HandScript {
  std::vector<HandKeyframe> keys;   // at least one, strictly increasing times
  double let_go_time = -1;          // s; < 0: the user never lets go
  double end_time = -1;             // s; read() returns kEnded after it; < 0: the last key's time
  std::vector<HandPhase> phases;    // non-decreasing start times (may be empty)
};

// Throws std::invalid_argument naming the problem (load time).
void validate_hand_script(const HandScript& script);

// A script from JSON text: {"keys": [{"t": 0, "p": [x, y, z], "q": [w, x, y, z]}, ...],
// "let_go_time": 3.5, "end_time": 6, "phases": [{"name": "a", "start": 0}, ...]}
// (let_go_time, end_time, phases, q and a "description" string optional; any
// other key is an error). Throws std::invalid_argument naming `origin` (e.g.
// the file name), the key's path (keys[3].p) and the problem.
HandScript hand_script_from_json(const std::string& text, const std::string& origin = "hand script");

// The hand's pose and velocity (linear, angular; world frame) at time t.
struct HandSample {
  Pose X_WA;
  Vec6 V_WA = Vec6::Zero();
};
HandSample sample_hand(const HandScript& script, double t);

struct SimulatedHandleParams {
  double mass = 0.1;                      // kg: handle and the user's hand's effective mass
  double inertia = 1e-4;                  // kg m^2, isotropic
  double damping = 1.0;                   // N s/m: handle against the ground
  double angular_damping = 1e-3;          // N m s/rad
  double grip_stiffness = 500;            // N/m: k
  double grip_damping = 5;                // N s/m: c
  double grip_angular_stiffness = 1;      // N m/rad: kr
  double grip_angular_damping = 0.01;     // N m s/rad: cr
  double rate_hz = 1000;                  // the haptic loop's rate with this device
  double max_force = 20;                  // N, reported in DeviceInfo
  double max_torque = 1;                  // N m
  double max_substep = 0;                 // s; 0: 0.1 over the fastest time constant's rate
};

class SimulatedDevice final : public Device {
 public:
  // Throws std::invalid_argument on a bad script or parameters (load time).
  SimulatedDevice(HandScript script, const SimulatedHandleParams& params = {}, std::string name = "simulated");

  const DeviceInfo& info() const override { return info_; }
  // Advances the handle from the last read's time to t (t >= that time) and samples it.
  // kEnded after the script's end time (the state stays valid: the hand holds still);
  // kError if t goes backwards or is not finite (the state is left unchanged).
  DeviceStatus read(double t, DeviceState* state) override;
  // Holds F (world frame, torque about the handle's point) until the next write().
  // kError (F ignored) if F is not finite.
  DeviceStatus write(double t, const Vec6& F) override;
  // From any thread (the runtime's watchdog): the handle feels no force from now
  // until the next write(). kOk.
  DeviceStatus halt_force() noexcept override;
  bool halted() const { return halted_.load(std::memory_order_acquire); }

  // Puts the handle on the hand at time t0, at rest relative to it, with no force.
  void reset(double t0 = 0);

  const HandScript& script() const { return script_; }
  const SimulatedHandleParams& params() const { return params_; }
  const Pose& handle_pose() const { return X_WH_; }
  Vec6 handle_velocity() const;                    // (v, w), world frame
  double substep() const { return max_substep_; }  // s, the largest substep used

 private:
  void step(double t, double h);  // one semi-implicit Euler substep from time t

  HandScript script_;
  SimulatedHandleParams params_;
  DeviceInfo info_;
  double max_substep_ = 0;
  double end_time_ = 0;
  double time_ = 0;
  Pose X_WH_;
  Vec3 v_ = Vec3::Zero();
  Vec3 w_ = Vec3::Zero();
  Vec6 F_ = Vec6::Zero();
  std::atomic<bool> halted_{false};  // halt_force(): F_ is not applied until the next write()
};

}  // namespace gauss6
