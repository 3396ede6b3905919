// The simulated device: scripted hand, grip spring, mass-spring-damper handle
// (simulated_device.h).
#include "gauss6/simulated_device.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace gauss6 {

void validate_hand_script(const HandScript& s) {
  if (s.keys.empty()) throw std::invalid_argument("hand script: no keyframes");
  for (size_t i = 0; i < s.keys.size(); ++i) {
    const HandKeyframe& k = s.keys[i];
    if (!std::isfinite(k.t)) throw std::invalid_argument("hand script: key " + std::to_string(i) + ": time is not finite");
    if (!is_valid_pose(k.X_WA)) throw std::invalid_argument("hand script: key " + std::to_string(i) + ": invalid pose");
    if (i > 0 && !(k.t > s.keys[i - 1].t))
      throw std::invalid_argument("hand script: key " + std::to_string(i) + ": times must increase strictly");
  }
  for (size_t i = 0; i < s.phases.size(); ++i)
    if (!std::isfinite(s.phases[i].start))
      throw std::invalid_argument("hand script: phase '" + s.phases[i].name + "': start is not finite");
  for (size_t i = 1; i < s.phases.size(); ++i)
    if (s.phases[i].start < s.phases[i - 1].start)
      throw std::invalid_argument("hand script: phase '" + s.phases[i].name + "' starts before the previous one");
  if (!std::isfinite(s.let_go_time) || !std::isfinite(s.end_time))
    throw std::invalid_argument("hand script: let_go_time and end_time must be finite (negative: none)");
}

HandScript hand_script_from_json(const std::string& text, const std::string& origin) {
  HandScript s;
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    for (const auto& k : j.at("keys")) {
      HandKeyframe key;
      key.t = k.at("t").get<double>();
      const auto p = k.at("p").get<std::vector<double>>();
      if (p.size() != 3) throw std::invalid_argument("key 'p' must have 3 numbers");
      key.X_WA.p = Vec3(p[0], p[1], p[2]);
      if (k.contains("q")) {
        const auto q = k.at("q").get<std::vector<double>>();
        if (q.size() != 4) throw std::invalid_argument("key 'q' must have 4 numbers (w, x, y, z)");
        key.X_WA.q = normalized(Quat{q[0], q[1], q[2], q[3]});
      }
      s.keys.push_back(key);
    }
    s.let_go_time = j.value("let_go_time", -1.0);
    s.end_time = j.value("end_time", -1.0);
    if (j.contains("phases"))
      for (const auto& p : j.at("phases")) s.phases.push_back({p.at("name").get<std::string>(), p.at("start").get<double>()});
    validate_hand_script(s);
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(origin + ": " + e.what());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(origin + ": " + e.what());
  }
  return s;
}

HandSample sample_hand(const HandScript& s, double t) {
  HandSample out;
  const auto& keys = s.keys;
  // Held (at rest) before the first and after the last keyframe.
  if (t <= keys.front().t) {
    out.X_WA = keys.front().X_WA;
    return out;
  }
  if (t >= keys.back().t) {
    out.X_WA = keys.back().X_WA;
    return out;
  }
  // Segment [k0, k1] with k0.t <= t < k1.t.
  const auto it = std::upper_bound(keys.begin(), keys.end(), t,
                                   [](double time, const HandKeyframe& k) { return time < k.t; });
  const HandKeyframe& k1 = *it;
  const HandKeyframe& k0 = *(it - 1);
  const double T = k1.t - k0.t;
  const double u = (t - k0.t) / T;
  // Linear in position; slerp in rotation, as exp(u log(q1 q0^*)) q0 (shortest way round).
  const Vec3 dp = k1.X_WA.p - k0.X_WA.p;
  const Vec3 rot = quat_log(k1.X_WA.q * conjugate(k0.X_WA.q));
  out.X_WA.p = k0.X_WA.p + u * dp;
  out.X_WA.q = normalized(quat_exp(u * rot) * normalized(k0.X_WA.q));
  out.V_WA.head<3>() = dp / T;
  out.V_WA.tail<3>() = rot / T;
  return out;
}

SimulatedDevice::SimulatedDevice(HandScript script, const SimulatedHandleParams& params, std::string name)
    : script_(std::move(script)), params_(params) {
  validate_hand_script(script_);
  const SimulatedHandleParams& p = params_;
  const double values[] = {p.mass, p.inertia, p.rate_hz, p.max_force, p.max_torque};
  for (double v : values)
    if (!(v > 0 && std::isfinite(v))) throw std::invalid_argument("simulated device: mass, inertia, rate_hz and limits must be > 0");
  const double gains[] = {p.damping, p.angular_damping, p.grip_stiffness, p.grip_damping,
                          p.grip_angular_stiffness, p.grip_angular_damping, p.max_substep};
  for (double v : gains)
    if (!(v >= 0 && std::isfinite(v))) throw std::invalid_argument("simulated device: gains and damping must be >= 0");

  // Substep: a tenth of the fastest time scale, sqrt(m/k) (oscillation) and
  // m/c (damping), in translation and rotation. Semi-implicit Euler is stable
  // for h omega < 2; at 0.1 it is also accurate to about 1%.
  double h = 1.0 / p.rate_hz;
  auto limit = [&h](double scale) {
    if (std::isfinite(scale) && scale > 0) h = std::min(h, 0.1 * scale);
  };
  limit(std::sqrt(p.mass / p.grip_stiffness));
  limit(p.mass / (p.grip_damping + p.damping));
  limit(std::sqrt(p.inertia / p.grip_angular_stiffness));
  limit(p.inertia / (p.grip_angular_damping + p.angular_damping));
  if (p.max_substep > 0) h = std::min(h, p.max_substep);
  max_substep_ = h;

  end_time_ = script_.end_time >= 0 ? script_.end_time : script_.keys.back().t;
  info_.name = name;
  info_.rate_hz = p.rate_hz;
  info_.max_force = p.max_force;
  info_.max_torque = p.max_torque;
  info_.renders_force = true;
  reset(script_.keys.front().t);
}

void SimulatedDevice::reset(double t0) {
  const HandSample hand = sample_hand(script_, t0);
  time_ = t0;
  X_WH_ = hand.X_WA;
  v_ = hand.V_WA.head<3>();
  w_ = hand.V_WA.tail<3>();
  F_.setZero();
}

Vec6 SimulatedDevice::handle_velocity() const {
  Vec6 V;
  V << v_, w_;
  return V;
}

void SimulatedDevice::step(double t, double h) {
  const SimulatedHandleParams& p = params_;
  Vec6 F = F_;
  if (halted_.load(std::memory_order_acquire)) F.setZero();  // halt_force(), until the next write()
  Vec3 f = F.head<3>() - p.damping * v_;
  Vec3 tau = F.tail<3>() - p.angular_damping * w_;
  const bool gripped = script_.let_go_time < 0 || t < script_.let_go_time;
  if (gripped) {
    const HandSample hand = sample_hand(script_, t);
    f += p.grip_stiffness * (hand.X_WA.p - X_WH_.p) + p.grip_damping * (hand.V_WA.head<3>() - v_);
    tau += p.grip_angular_stiffness * quat_log(hand.X_WA.q * conjugate(X_WH_.q)) +
           p.grip_angular_damping * (hand.V_WA.tail<3>() - w_);
  }
  // Semi-implicit Euler: velocities first, then the pose with the new velocities.
  v_ += (h / p.mass) * f;
  w_ += (h / p.inertia) * tau;
  X_WH_.p += h * v_;
  X_WH_.q = normalized(quat_exp(h * w_) * X_WH_.q);
}

DeviceStatus SimulatedDevice::read(double t, DeviceState* state) {
  if (!std::isfinite(t) || t < time_) {
    state->status = DeviceStatus::kError;
    state->message = "simulated device: time is not finite or went backwards";
    return state->status;
  }
  // Equal substeps no longer than max_substep_ from the last read's time to t.
  const double span = t - time_;
  if (span > 0) {
    const double n = std::ceil(span / max_substep_);
    const double h = span / n;
    const double t0 = time_;
    for (double i = 0; i < n; ++i) step(t0 + i * h, h);
  }
  time_ = t;
  state->time = t;
  state->X_WH = X_WH_;
  state->buttons = 0;
  state->gripped = script_.let_go_time < 0 || t < script_.let_go_time;
  state->status = t > end_time_ ? DeviceStatus::kEnded : DeviceStatus::kOk;
  state->message = state->status == DeviceStatus::kEnded ? "simulated device: end of the script" : "";
  return state->status;
}

DeviceStatus SimulatedDevice::write(double /*t*/, const Vec6& F) {
  if (!F.allFinite()) return DeviceStatus::kError;
  F_ = F;
  halted_.store(false, std::memory_order_release);
  return DeviceStatus::kOk;
}

DeviceStatus SimulatedDevice::halt_force() noexcept {
  halted_.store(true, std::memory_order_release);
  return DeviceStatus::kOk;
}

}  // namespace gauss6
