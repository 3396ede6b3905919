// The simulated device: scripted hand, grip spring, mass-spring-damper handle
// (simulated_device.h).
#include "gauss6/simulated_device.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace gauss6 {

void validate_hand_script(const HandScript& s) {
  if (s.keys.empty()) throw std::invalid_argument("hand script: keys: no keyframes");
  for (size_t i = 0; i < s.keys.size(); ++i) {
    const HandKeyframe& k = s.keys[i];
    const std::string key = "hand script: keys[" + std::to_string(i) + "]";
    if (!std::isfinite(k.t)) throw std::invalid_argument(key + ".t: time is not finite");
    if (!is_valid_pose(k.X_WA)) throw std::invalid_argument(key + ": invalid pose (p finite, q a non-zero quaternion)");
    if (i > 0 && !(k.t > s.keys[i - 1].t))
      throw std::invalid_argument(key + ".t: times must increase strictly (the previous key's is " +
                                  std::to_string(s.keys[i - 1].t) + ")");
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

namespace {

// Reads the JSON form; every problem names the key's path (keys[3].p) and what is wrong. Unknown keys
// are errors, as in scene files: a misspelt "let_go_time" must not be silently ignored.
class ScriptReader {
 public:
  [[noreturn]] static void fail(const std::string& key, const std::string& what) {
    throw std::invalid_argument("hand script: " + key + ": " + what);
  }
  static void allow_only(const nlohmann::json& object, const std::string& where,
                         std::initializer_list<const char*> keys) {
    for (const auto& item : object.items()) {
      bool known = false;
      std::string list;
      for (const char* k : keys) {
        known |= item.key() == k;
        list += std::string(list.empty() ? "" : ", ") + k;
      }
      if (!known) fail(where + item.key(), "unknown key (allowed here: " + list + ")");
    }
  }
  static double number(const nlohmann::json& v, const std::string& key) {
    if (!v.is_number()) fail(key, "must be a number");
    return v.get<double>();
  }
  static std::vector<double> numbers(const nlohmann::json& v, const std::string& key, size_t n, const char* what) {
    if (!v.is_array() || v.size() != n) fail(key, std::string("must be ") + what);
    std::vector<double> out;
    for (const auto& x : v) out.push_back(number(x, key));
    return out;
  }
};

}  // namespace

HandScript hand_script_from_json(const std::string& text, const std::string& origin) {
  using R = ScriptReader;
  HandScript s;
  try {
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& e) {
      throw std::invalid_argument(std::string("hand script: not valid JSON: ") + e.what());
    }
    if (!j.is_object()) R::fail("(top level)", "must be an object with \"keys\"");
    R::allow_only(j, "", {"description", "keys", "let_go_time", "end_time", "phases"});
    if (!j.contains("keys"))
      R::fail("keys", "missing (the keyframes: [{\"t\": 0, \"p\": [x, y, z], \"q\": [w, x, y, z]}, ...])");
    if (!j["keys"].is_array()) R::fail("keys", "must be an array of keyframes {t, p, q}");
    for (size_t i = 0; i < j["keys"].size(); ++i) {
      const nlohmann::json& k = j["keys"][i];
      const std::string at = "keys[" + std::to_string(i) + "]";
      if (!k.is_object()) R::fail(at, "must be a keyframe {t, p, q}");
      R::allow_only(k, at + ".", {"t", "p", "q"});
      if (!k.contains("t")) R::fail(at + ".t", "missing (the keyframe's time, s)");
      if (!k.contains("p")) R::fail(at + ".p", "missing (the position of G, [x, y, z])");
      HandKeyframe key;
      key.t = R::number(k["t"], at + ".t");
      const auto p = R::numbers(k["p"], at + ".p", 3, "3 numbers [x, y, z]");
      key.X_WA.p = Vec3(p[0], p[1], p[2]);
      if (k.contains("q")) {
        const auto q = R::numbers(k["q"], at + ".q", 4, "4 numbers [w, x, y, z] (a quaternion)");
        key.X_WA.q = normalized(Quat{q[0], q[1], q[2], q[3]});
      }
      s.keys.push_back(key);
    }
    if (j.contains("let_go_time")) s.let_go_time = R::number(j["let_go_time"], "let_go_time");
    if (j.contains("end_time")) s.end_time = R::number(j["end_time"], "end_time");
    if (j.contains("description") && !j["description"].is_string()) R::fail("description", "must be a string");
    if (j.contains("phases")) {
      if (!j["phases"].is_array()) R::fail("phases", "must be an array of {name, start}");
      for (size_t i = 0; i < j["phases"].size(); ++i) {
        const nlohmann::json& p = j["phases"][i];
        const std::string at = "phases[" + std::to_string(i) + "]";
        if (!p.is_object()) R::fail(at, "must be a phase {name, start}");
        R::allow_only(p, at + ".", {"name", "start"});
        if (!p.contains("name") || !p["name"].is_string()) R::fail(at + ".name", "must be a string");
        if (!p.contains("start")) R::fail(at + ".start", "missing (the phase's start time, s)");
        s.phases.push_back({p["name"].get<std::string>(), R::number(p["start"], at + ".start")});
      }
    }
    validate_hand_script(s);
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(origin + ": hand script: " + e.what());
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
