// The scene's vocabulary (the names of roles, surface and device kinds) and the
// rules its settings must meet (check_gains() and the others, scene.h), stated
// once in the core: the scene loader applies them at each key's line, and the
// runtime model applies the same rules to a scene built in code.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "gauss6/contact/coupling.h"
#include "gauss6/io/scene.h"

namespace gauss6 {

const char* to_string(BodyRole r) { return r == BodyRole::kObstacle ? "obstacle" : "god_object"; }
const char* to_string(DeviceKind k) {
  switch (k) {
    case DeviceKind::kSimulated: return "simulated";
    case DeviceKind::kReplay: return "replay";
    case DeviceKind::kHid: return "hid";
  }
  return "unknown";
}

namespace {

// x is finite and above lo (below hi): NaN and infinities break every settings rule.
bool finite_above(double x, double lo) { return std::isfinite(x) && x > lo; }
bool finite_below(double x, double hi) { return std::isfinite(x) && x < hi; }

// A length for a message: six significant digits, any magnitude.
std::string format_number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", x);
  return text;
}

}  // namespace

SettingsProblem check_gains(const Gains& g) {
  if (!(finite_above(g.ks, 0) && g.ks <= 1)) return {"gains", "ks", "must be in (0, 1]"};
  if (!valid_coupling_gain(g.kh)) return {"gains", "kh", "must be > 0"};
  return {};
}

SettingsProblem check_contact_parameters(const ContactParameters& c) {
  if (!finite_above(c.delta, 0)) return {"contact", "delta", "must be > 0"};
  if (!finite_below(c.offset_eps, 0)) return {"contact", "offset_eps", "must be < 0"};
  if (!finite_above(c.offset_time, 0)) return {"contact", "offset_time", "must be > 0"};
  return {};
}

SettingsProblem check_surface_settings(const SurfaceSettings& s) {
  if (s.kind != SurfaceKind::kTexture) return {};
  if (!finite_above(s.amplitude, 0)) return {"surface", "amplitude", "must be > 0"};
  if (!finite_above(s.wavelength, 0)) return {"surface", "wavelength", "must be > 0"};
  if (s.axis < 0 || s.axis > 2) return {"surface", "axis", "must be x, y or z"};
  if (s.texture == TextureKind::kSine) return {};
  if (s.axis_v < 0 || s.axis_v > 2 || s.axis_v == s.axis)
    return {"surface", "axis_v", "must be x, y or z, and not axis"};
  if (!s.origin.allFinite()) return {"surface", "origin", "must be finite"};
  if (s.texture != TextureKind::kHeightMap) return {};
  const HeightMapImage& h = s.height_map;
  if (h.width < 2 || h.height < 2 || h.values.size() != static_cast<size_t>(h.width) * h.height)
    return {"surface", "image", "must be an image of at least 2 x 2 pixels"};
  for (float v : h.values)
    if (!(v >= 0 && v <= 1)) return {"surface", "image", "values must be in [0, 1]"};
  return {};
}

SettingsProblem check_crease_angle(double degrees) {
  if (!(std::isfinite(degrees) && degrees >= 0 && degrees <= 180))
    return {"obstacle", "crease_angle", "must be in [0, 180] (degrees)"};
  return {};
}

double scene_extent(const Scene& scene) {
  double extent = 0;
  const auto reach = [&](const Body& b) {
    const double r = b.mesh.V.rows() ? b.mesh.V.rowwise().norm().maxCoeff() : 0.0;  // rotations keep norms
    extent = std::max(extent, b.pose.p.norm() + r);
  };
  for (const Body& b : scene.obstacles) reach(b);
  reach(scene.god_object);
  return extent;
}

SettingsProblem check_delta_scale(const Scene& scene) {
  static_assert(kMinDeltaPerExtent == 1e-6 && kMaxDeltaPerExtent == 1e-2 && kMinDelta == 1e-150,
                "the messages below state them");
  const double extent = scene_extent(scene), delta = scene.contact.delta;
  const std::string where = " of the scene's extent (" + format_number(extent) + ", the farthest vertex from the origin)";
  if (!(delta >= kMinDelta && delta >= kMinDeltaPerExtent * extent))
    return {"contact", "delta",
            "must be at least 1e-6" + where + " and at least 1e-150: smaller, the rounding of squared "
            "coordinates nears delta^2 and the god-object stops sliding along surfaces"};
  if (!(delta <= kMaxDeltaPerExtent * extent))
    return {"contact", "delta",
            "must be at most 1e-2" + where + ": larger, the contact band swallows the scene"};
  return {};
}

SettingsProblem check_device_settings(const DeviceSettings& d) {
  if (!(std::isfinite(d.rate_hz) && d.rate_hz >= 100 && d.rate_hz <= 10000))
    return {"device", "rate_hz", "must be in [100, 10000]"};
  if (!finite_above(d.max_force, 0)) return {"device", "max_force", "must be > 0"};
  if (!finite_above(d.max_torque, 0)) return {"device", "max_torque", "must be > 0"};
  return {};
}

}  // namespace gauss6
