// Tests of runtime.h and shared_state.h: the three loops on a box god-object
// (10 cm, 1 kg) pressed onto a box obstacle (top face z = 0) by a scripted test
// device, in lockstep runs (exact, repeatable) and threaded runs (sanity only:
// no assertion on durations). Checked against the analytic answers of this
// geometry: the god-object never goes below the plane z = delta, the force is
// kh m ks (xs_z - xh_z) straight up, nothing in free space or along the surface.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <climits>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "gauss6/geometry/mass_properties.h"
#include "gauss6/runtime/runtime.h"
#include "mesh_shapes.h"
#include "runtime_fixtures.h"

using namespace gauss6;
using gauss6::test::make_box;
using Vec2 = Eigen::Vector2d;

using namespace gauss6::test;

namespace {

// A god-object on its tip over a convex crease. The obstacle's top is flat
// (z = 0) for x <= 0 and slopes down by kCreaseAngle for x >= 0 (a prism along y
// over the pentagon (-0.5, -0.3), (-0.5, 0), (0, 0), (0.5, -0.5 tan), (0.5, -0.3)
// of the xz-plane, y in [-0.5, 0.5]). The god-object is the regular octahedron
// with vertices at kHalf on the axes (density 1000: m = 0.167 kg, felt
// stiffness kh m ks = 83 N/m); its tip (0, 0, -kHalf) touches the surface, and
// on the flat part its row has no angular part, so pressing does not tip it.
constexpr double kCreaseAngle = 20 * M_PI / 180;
const Vec3 kSlopeNormal(std::sin(kCreaseAngle), 0, std::cos(kCreaseAngle));  // outward, through the origin

Scene make_crease_scene() {
  Scene sc = make_scene();
  const double t = std::tan(kCreaseAngle);
  const std::vector<Vec2> profile = {{-0.5, -0.3}, {-0.5, 0}, {0, 0}, {0.5, -0.5 * t}, {0.5, -0.3}};  // (x, z)
  const int n = static_cast<int>(profile.size());
  std::vector<Eigen::Vector3d> V;
  for (double y : {-0.5, 0.5})
    for (const Vec2& q : profile) V.emplace_back(q.x(), y, q.y());
  std::vector<std::array<int, 3>> F;
  for (int k = 1; k + 1 < n; ++k) {
    F.push_back({0, k + 1, k});          // y = -0.5 cap, normal -y
    F.push_back({n, n + k, n + k + 1});  // y = +0.5 cap, normal +y
  }
  for (int k = 0; k < n; ++k) gauss6::test::add_quad(&F, k, (k + 1) % n, n + (k + 1) % n, n + k);  // sides, outward
  const std::vector<Eigen::Vector3d> octa = {{kHalf, 0, 0}, {-kHalf, 0, 0}, {0, kHalf, 0},
                                             {0, -kHalf, 0}, {0, 0, kHalf}, {0, 0, -kHalf}};
  std::vector<std::array<int, 3>> octa_faces;
  for (int sx = 0; sx < 2; ++sx)
    for (int sy = 0; sy < 2; ++sy)
      for (int sz = 0; sz < 2; ++sz) {
        const int a = sx, b = 2 + sy, c = 4 + sz;  // vertex of each axis on its side (0: +, 1: -)
        // (x, y, z) is counter-clockwise from outside in the octants with an even number of minus signs.
        if ((sx + sy + sz) % 2 == 0) octa_faces.push_back({a, b, c});
        else octa_faces.push_back({a, c, b});
      }
  sc.god_object.mesh = gauss6::test::make_mesh(octa, octa_faces, "octahedron");
  build_adjacency(&sc.god_object.mesh);
  compute_vertex_normals(&sc.god_object.mesh);
  std::string error;
  REQUIRE(compute_mass_properties(sc.god_object.mesh, 1000, &sc.god_mass.mass, &error));
  REQUIRE(sc.god_mass.mass.mass == Approx(1000 * 4.0 / 3 * kHalf * kHalf * kHalf).epsilon(1e-12));
  Body wedge;
  wedge.name = "crease";
  wedge.mesh = gauss6::test::make_mesh(V, F, "crease");
  build_adjacency(&wedge.mesh);
  compute_vertex_normals(&wedge.mesh);
  sc.obstacles = {wedge};
  sc.name = "box_over_crease";
  return sc;
}

// Height of the god-object above the crease's top: min over its vertices of the
// larger of the two top planes' signed distances (z and kSlopeNormal . x). The
// wedge is convex, so a vertex is inside it only if both are <= 0; outside, its
// distance to the wedge is at least this, and at most this / cos(angle / 2)
// (the worst case: a point above the crease line, between the two normals).
double height_over_crease(const RuntimeModel& model, const Pose& x) {
  double h = INFINITY;
  for (int v = 0; v < model.god_mesh_B.V.rows(); ++v) {
    const Vec3 w = transform_point(x, model.god_mesh_B.V.row(v).transpose());
    h = std::min(h, std::max(w.z(), kSlopeNormal.dot(w)));
  }
  return h;
}

// Tolerance of Fc . ac = 0 relative to |Fc| |au| (|ac| <= |au| in the M-norm:
// the natural scale of both factors): the projection meets complementarity to
// ~1e-13 relative (feasibility_tol); 1e-9 leaves room for the 6x6 products and
// still fails on any real tangential component.
constexpr double kOrthogonalityTol = 1e-9;

}  // namespace

TEST_CASE("runtime: model built once, refused settings and surfaces", "[runtime]") {
  const Scene sc = make_scene();
  const RuntimeModel model(sc, RuntimeSettings{});
  REQUIRE(model.obstacles.size() == 1);
  // The slab's mesh was moved to the world once (identity pose here) and its
  // top face is at z = 0.
  CHECK(model.obstacle_meshes_W[0].V.col(2).maxCoeff() == 0.0);
  CHECK(model.settings.ccd.narrow.min_separation == kDelta);
  CHECK(model.mass == Approx(1.0).epsilon(1e-12));
  // M at a quarter turn: the cube's inertia is isotropic (m s^2 / 6), so M is diagonal.
  const Mat6 M = mass_matrix_at(model, quat_exp(Vec3(0, 0, M_PI / 2)));
  CHECK((M - Mat6(Vec6(1, 1, 1, kSide * kSide / 6, kSide * kSide / 6, kSide * kSide / 6).asDiagonal())).norm() <
        1e-12);
  // Force shading is rendered (surface.h): the model builds its shading normals once;
  // a crease angle outside [0, 180] degrees is refused by its rule.
  Scene shaded = sc;
  shaded.surface.kind = SurfaceKind::kForceShading;
  {
    const RuntimeModel shaded_model(shaded, RuntimeSettings{});
    CHECK(shaded_model.surface.shading);
    CHECK_FALSE(shaded_model.surface.texture);
    CHECK(shaded_model.surface.obstacles.size() == 1);
  }
  shaded.obstacles[0].crease_angle = 200;
  CHECK_THROWS_AS(RuntimeModel(shaded, RuntimeSettings{}), RuntimeError);
  RuntimeSettings bad;
  bad.gap_factor = 1.0;  // not below contact_factor
  CHECK_THROWS_AS(RuntimeModel(sc, bad), RuntimeError);
  RuntimeSettings bad_cache;
  bad_cache.cache_margin = -1;
  CHECK_THROWS_AS(RuntimeModel(sc, bad_cache), RuntimeError);
  RuntimeSettings bad_tolerance;
  bad_tolerance.ccd_distance_tolerance = 0;
  CHECK_THROWS_AS(RuntimeModel(sc, bad_tolerance), RuntimeError);
}

// A scene built in code meets the same rules as a scene file (check_gains and
// the others, scene.h): the runtime refuses what the loader would, with the
// rule's own message.
TEST_CASE("runtime: a scene built in code meets the scene file's rules", "[runtime]") {
  const Scene sc = make_scene();
  const auto refusal = [](const Scene& scene) -> std::string {
    try {
      RuntimeModel model(scene, RuntimeSettings{});
    } catch (const RuntimeError& e) {
      return e.what();
    }
    return "";
  };
  CHECK(refusal(sc).empty());
  Scene no_kh = sc;
  no_kh.gains.kh = 0;  // the loader requires kh > 0
  CHECK_THAT(refusal(no_kh), Catch::Matchers::Contains("gains.kh: must be > 0"));
  Scene slow = sc;
  slow.device.rate_hz = 50;  // the loader requires [100, 10000]
  CHECK_THAT(refusal(slow), Catch::Matchers::Contains("device.rate_hz: must be in [100, 10000]"));
  Scene offsets = sc;
  offsets.contact.offset_eps = 0;  // must be < 0
  CHECK_THAT(refusal(offsets), Catch::Matchers::Contains("contact.offset_eps: must be < 0"));
  Scene texture = sc;
  texture.surface.kind = SurfaceKind::kTexture;
  texture.surface.wavelength = -1;
  CHECK_THAT(refusal(texture), Catch::Matchers::Contains("surface.amplitude: must be > 0"));
}

// The CCD settings relative to the scene's scale are stated in units of delta
// (RuntimeSettings) and resolved once into scene units.
TEST_CASE("runtime: delta-scaled settings resolve into the CCD's", "[runtime]") {
  const Scene sc = make_scene();
  RuntimeSettings s;
  s.cache_margin = 10;
  s.cache_margin_max = 40;
  s.cache_fill_budget = 7;
  s.ccd_distance_tolerance = 0.3;
  s.near_slack = 0.5;
  const EffectiveSettings e = resolve_runtime_settings(sc, s);
  const double d = sc.contact.delta;
  CHECK(e.runtime.ccd.narrow.min_separation == d);
  CHECK(e.runtime.ccd.narrow.distance_tolerance == 0.3 * d);
  CHECK(e.runtime.ccd.cache.margin == 10 * d);
  CHECK(e.runtime.ccd.cache.margin_max == 40 * d);
  CHECK(e.runtime.ccd.cache.fill_budget == 7);
  CHECK(e.contact_generation.distance == d * (1 + s.contact_factor));
  CHECK(e.runtime.ccd.near_distance == e.contact_generation.distance + 0.5 * d);
}

TEST_CASE("runtime: a box pressed onto a box never penetrates, the force is up, kh m ks deep", "[runtime]") {
  // Handle from G = 0.2 down to 0.03 at 0.2 m/s (2 cm deeper than resting, at
  // t = 0.85 s), held until 1.2 s. One sim step per haptic tick.
  ScriptedDevice device(press_script(0.2, 0.03, 0.2));
  Run r;
  run(&r, make_scene(), RuntimeSettings{}, &device, 1200);
  REQUIRE(r.rec.sims.size() == 1200);
  REQUIRE(r.rec.ticks.size() == 1200);
  REQUIRE(r.rec.events.empty());

  // Never penetrates: every pose keeps the lowest corner at least delta above
  // the plane, up to make_stop_pose's deviation and rounding (1e-3 delta = 1e-8,
  // far above both, far below a real penetration). Never stops far away either:
  // once resting, the gap stays below delta (1 + contact_factor) + 1e-3 delta.
  double min_gap = INFINITY;
  int num_contact_steps = 0;
  for (const SimStepInfo& s : r.rec.sims) {
    const double gap = lowest_z(*r.model, s.xs);
    min_gap = std::min(min_gap, gap);
    if (s.num_contacts > 0) {
      ++num_contact_steps;
      CHECK(gap <= kDelta * 1.501);
    }
  }
  CHECK(min_gap >= kDelta * (1 - 1e-3));
  CHECK(num_contact_steps > 300);

  // Forces: zero in free space, straight up and equal to kh m ks (xs_z - xh_z)
  // in contact (the four corner rows [0 0 1, r_y, -r_x, 0] give ac_z = 0, no
  // rotation), non-decreasing while the handle goes deeper.
  double last_Fz = 0;
  int num_free = 0, num_pressed = 0;
  for (size_t k = 0; k < r.rec.ticks.size(); ++k) {
    const HapticTickRecord& tick = r.rec.ticks[k];
    const CouplingStepInfo& c = r.rec.couplings[k];
    const SimStepInfo& s = r.rec.sims[k];  // the sim step of this tick (before it)
    const Vec6& F = tick.F_sent;
    const double depth = kHalf - tick.xh.p.z();  // handle below its resting height
    if (c.num_rows == 0) {
      ++num_free;
      CHECK(F.norm() == 0.0);  // ac = au exactly without rows
      continue;
    }
    if (depth < 1e-3) continue;  // approach: contact set just forming
    ++num_pressed;
    // Tolerance 1e-9 N: the force is 5-10 N; the rows are exact axis-aligned
    // normals, so only rounding (~1e-15 relative) separates F from the formula.
    const double expected = kKh * r.model->mass * kKs * (s.xs.p.z() - tick.xh.p.z());
    CHECK(std::abs(F[2] - expected) <= 1e-9);
    CHECK(std::abs(F[0]) <= 1e-9);
    CHECK(std::abs(F[1]) <= 1e-9);
    CHECK(F.tail<3>().norm() <= 1e-9);
    CHECK(F[2] >= last_Fz - 1e-9);  // grows with the penetration (held: constant)
    last_Fz = F[2];
    // Orthogonality Fc . ac = 0.
    CHECK(std::abs(c.Fc.dot(c.ac)) <= kOrthogonalityTol * c.Fc.norm() * c.au.norm());
  }
  CHECK(num_free > 500);
  CHECK(num_pressed > 300);
  // Held 2 cm deep: 500 N/m x 2 cm = 10 N, up to the resting gap (1.5 delta x 500 N/m < 1e-2 N).
  CHECK(std::abs(last_Fz - 10.0) < 1e-2);
}

TEST_CASE("runtime: sliding along the top, the force stays normal and the god-object follows", "[runtime]") {
  // Pressed 1 cm deep, then slid 4 cm along +x (over the slab's diagonal edge)
  // at 0.1 m/s, then held.
  auto script = [](double t) {
    const double z = std::max(0.04, 0.2 - 0.4 * t);
    const double x = t < 0.5 ? 0.0 : std::min(0.04, 0.1 * (t - 0.5));
    return Pose{Vec3(x, 0.001, z), Quat{}};
  };
  ScriptedDevice device(script);
  Run r;
  run(&r, make_scene(), RuntimeSettings{}, &device, 1000);
  REQUIRE(r.rec.events.empty());
  int num_sliding = 0, num_offsets_started = 0;
  for (size_t k = 0; k < r.rec.ticks.size(); ++k) {
    const HapticTickRecord& tick = r.rec.ticks[k];
    const CouplingStepInfo& c = r.rec.couplings[k];
    CHECK(lowest_z(*r.model, r.rec.sims[k].xs) >= kDelta * (1 - 1e-3));
    if (tick.time <= 0.5) continue;
    num_offsets_started += c.num_new_offsets;
    ++num_sliding;
    const Vec6& F = tick.F_sent;
    // Pressing 1 cm: 5 N up.
    CHECK(F[2] > 4.9);
    // No tangential component: Fc . (1, 0, 0, 0, 0, 0) and Fc . (0, 1, 0, ...)
    // vanish up to rounding (1e-9 of the 5 N force: the contact normals are
    // exactly +z, nothing else can put force along x or y).
    CHECK(std::abs(F[0]) <= 1e-9 * F.norm());
    CHECK(std::abs(F[1]) <= 1e-9 * F.norm());
    CHECK(std::abs(c.Fc.dot(c.ac)) <= kOrthogonalityTol * c.Fc.norm() * c.au.norm());
  }
  CHECK(num_sliding > 400);
  // The rows carried over from snapshot to snapshot are recognised as the same
  // constraints: no offset restarts while sliding across triangles.
  CHECK(num_offsets_started == 0);
  // The god-object slid with the handle: within one sim step's lag (v dt = 1e-4 m)
  // plus margin, no sticking.
  const Pose& xs = r.data->sim.xs;
  CHECK(std::abs(xs.p.x() - 0.04) < 1e-3);
  CHECK(std::abs(xs.p.y() - 0.001) < 1e-3);
}

TEST_CASE("runtime: a new contact with the handle already deep starts small and ramps (offsets)", "[runtime]") {
  // Handle held 1 cm above the resting height, then 1.5 cm below it in one tick
  // at t = 0.1 s: the first contact set arrives with d_k = ks (-1.5 cm) = -7.5 mm
  // < eps = -1e-4: offset rows, ramped back to 0 in T = 0.05 s.
  const double T = 0.05;
  auto script = [](double t) { return Pose{Vec3(0, 0, t < 0.1 ? kHalf + 0.01 : kHalf - 0.015), Quat{}}; };
  ScriptedDevice device(script);
  Run r;
  run(&r, make_scene(/*offset_eps=*/-1e-4, /*offset_time=*/T), RuntimeSettings{}, &device, 300);
  const double full = kKh * 1.0 * kKs * 0.015;  // 7.5 N (up to the resting gap, < 1e-2 N)
  // The first tick with contacts.
  size_t first = 0;
  while (first < r.rec.couplings.size() && r.rec.couplings[first].num_rows == 0) ++first;
  REQUIRE(first < r.rec.couplings.size());
  CHECK(r.rec.couplings[first].num_new_offsets == 4);  // the four corners
  const double t0 = r.rec.ticks[first].time;
  // Starts small: the offset rows admit au exactly (f_k(0) = d_k), so Fc = 0.
  CHECK(r.rec.ticks[first].F_sent.norm() < 1e-9 * full);
  double last = -1;
  for (size_t k = first; k < r.rec.ticks.size(); ++k) {
    const double Fz = r.rec.ticks[k].F_sent[2];
    const double dt = r.rec.ticks[k].time - t0;
    CHECK(Fz >= last - 1e-9);  // ramps up, never down
    last = Fz;
    // The ramp follows the smoothstep f_k(dt) = d_k (1 - s(dt / T)): the force
    // is full * s(dt / T) (1e-2 N: the resting gap's share).
    const double u = std::min(1.0, dt / T);
    CHECK(std::abs(Fz - full * (3 * u * u - 2 * u * u * u)) < 1e-2);
    if (dt > T) CHECK(r.rec.couplings[k].num_offset_rows == 0);
  }
  CHECK(std::abs(last - full) < 1e-2);
}

TEST_CASE("runtime: safety: NaN from the device, device timeout, sim stall, force limits", "[runtime]") {
  const Scene sc = make_scene();
  SECTION("a non-finite handle pose gives zero force and one event; then the force returns") {
    ScriptedDevice device(press_script(0.2, 0.04, 0.4));
    device.nan_from = 0.6;
    device.nan_to = 0.6035;  // four ticks: 0.600 .. 0.603
    Run r;
    run(&r, sc, RuntimeSettings{}, &device, 700);
    CHECK(r.rec.count(RuntimeEventKind::kInvalidHandlePose) == 1);
    REQUIRE(r.rec.events.size() == 1);
    CHECK(r.rec.events[0].time == Approx(0.6).margin(1e-12));
    int zeroed = 0;
    for (const HapticTickRecord& t : r.rec.ticks) {
      CHECK(t.F_sent.allFinite());
      if (t.time > 0.5 && t.time < 0.5995) CHECK(t.F_sent[2] > 4.9);  // pressing 1 cm: 5 N
      if (t.time >= 0.5995 && t.time < 0.6035) {
        CHECK(t.F_sent.norm() == 0.0);
        ++zeroed;
      }
      if (t.time > 0.605) CHECK(t.F_sent[2] > 4.9);
    }
    CHECK(zeroed == 4);
    // The device saw exactly these forces.
    REQUIRE(device.writes.size() == r.rec.ticks.size() + 1);  // + the final zero
    for (size_t k = 0; k < r.rec.ticks.size(); ++k) CHECK(device.writes[k].F == r.rec.ticks[k].F_sent);
    CHECK(device.writes.back().F.norm() == 0.0);
  }
  SECTION("a device that stops answering: force kept for device_timeout, then zero, watchdog event") {
    ScriptedDevice device(press_script(0.2, 0.04, 0.4));
    device.timeout_from = 0.6;
    RuntimeSettings settings;
    settings.device_timeout = 0.0055;  // not a multiple of the period: no tie to round
    Run r;
    run(&r, sc, settings, &device, 700);
    CHECK(r.rec.count(RuntimeEventKind::kDeviceError) == 1);
    CHECK(r.rec.count(RuntimeEventKind::kDeviceTimeout) == 1);
    // Last good sample at 0.599; the watchdog fires when t - 0.599 > 0.0055.
    for (const HapticTickRecord& t : r.rec.ticks) {
      if (t.time > 0.5 && t.time < 0.6045) CHECK(t.F_sent[2] > 4.9);
      if (t.time > 0.6045) CHECK(t.F_sent.norm() == 0.0);
    }
    for (const RuntimeEvent& e : r.rec.events)
      if (e.kind == RuntimeEventKind::kDeviceTimeout) CHECK(e.time == Approx(0.605).margin(1e-12));
  }
  SECTION("a stalled sim loop zeroes the force") {
    // One sim step every 0.2 s; the force is zeroed when its snapshot is older
    // than sim_timeout = 0.05 s.
    ScriptedDevice device(press_script(0.2, 0.04, 0.4));
    RuntimeSettings settings;
    settings.lockstep_sim_period = 200;
    settings.sim_timeout = 0.05;
    Run r;
    run(&r, sc, settings, &device, 1000);
    CHECK(r.rec.count(RuntimeEventKind::kSimStalled) == 5);  // once per 0.2 s gap
    for (const HapticTickRecord& t : r.rec.ticks) {
      const double since_sim = std::fmod(t.time + 1e-9, 0.2);
      if (since_sim > 0.0505) CHECK(t.F_sent.norm() == 0.0);
    }
  }
  SECTION("the device's info() limits the force; the scene's limits only lower them") {
    // Pressing 1 cm gives 5 N (the NaN section above); a device that renders at
    // most 3 N gets at most 3 N (and one clamp event), while the scene says 20 N.
    ScriptedDevice device(press_script(0.2, 0.04, 0.4));
    device.set_limits(3, 1);
    Run r;
    run(&r, sc, RuntimeSettings{}, &device, 700);
    CHECK(r.rec.count(RuntimeEventKind::kForceClamped) == 1);
    double max_sent = 0;
    for (const HapticTickRecord& t : r.rec.ticks) max_sent = std::max(max_sent, t.F_sent.head<3>().norm());
    // Clamping scales the force to exactly the limit, up to rounding (1e-12 N).
    CHECK(max_sent <= 3 + 1e-12);
    CHECK(max_sent >= 3 - 1e-12);
    // A device limit above the scene's leaves the scene's (20 N: no clamp at 5 N);
    // one that is not a positive number (unset, NaN) is ignored.
    for (double device_limit : {1000.0, 0.0, std::nan("")}) {
      ScriptedDevice roomy(press_script(0.2, 0.04, 0.4));
      roomy.set_limits(device_limit, device_limit);
      Run q;
      run(&q, sc, RuntimeSettings{}, &roomy, 700);
      CHECK(q.rec.count(RuntimeEventKind::kForceClamped) == 0);
      CHECK(q.rec.ticks.back().F_sent[2] > 4.9);
    }
  }
  SECTION("the safety stage: limits keep the direction, non-finite becomes zero") {
    uint32_t events = 0;
    Vec6 F;
    F << 30, 40, 0, 0, 0, 0.5;  // |force| = 50 N > 20 N
    const Vec6 safe = make_safe_wrench(F, 20, 1, &events);
    CHECK((safe.head<3>() - Vec3(12, 16, 0)).norm() < 1e-12);
    CHECK(safe[5] == 0.5);
    CHECK(events == 1u << static_cast<int>(RuntimeEventKind::kForceClamped));
    events = 0;
    F[3] = INFINITY;
    CHECK(make_safe_wrench(F, 20, 1, &events).norm() == 0.0);
    CHECK(events == 1u << static_cast<int>(RuntimeEventKind::kNonFiniteForce));
  }
}

TEST_CASE("runtime: lockstep runs are repeatable bit for bit", "[runtime]") {
  // A pressing, sliding and twisting handle: edge contacts, rotations, offsets.
  auto script = [](double t) {
    const double z = std::max(0.035, 0.2 - 0.5 * t);
    const double s = std::max(0.0, t - 0.35);
    return Pose{Vec3(0.05 * std::sin(3 * s), 0.03 * s, z), quat_exp(Vec3(0.2 * s, 0.1 * s, 0.8 * s))};
  };
  RuntimeSettings settings;
  settings.lockstep_sim_period = 3;
  auto run_once = [&](Run* r, ScriptedDevice* device) { run(r, make_scene(-1e-4, 0.05), settings, device, 800); };
  ScriptedDevice d1(script), d2(script);
  Run r1, r2;
  run_once(&r1, &d1);
  run_once(&r2, &d2);
  REQUIRE(d1.writes.size() == d2.writes.size());
  REQUIRE(d1.writes.size() == 801);
  int differing = 0;
  double max_force = 0;
  for (size_t k = 0; k < d1.writes.size(); ++k) {
    differing += std::memcmp(d1.writes[k].F.data(), d2.writes[k].F.data(), sizeof(double) * 6) != 0;
    max_force = std::max(max_force, d1.writes[k].F.head<3>().norm());
  }
  CHECK(differing == 0);
  CHECK(max_force > 1);  // the run did press: the comparison is not of zeros
  REQUIRE(r1.rec.sims.size() == r2.rec.sims.size());
  for (size_t k = 0; k < r1.rec.sims.size(); ++k) {
    const Pose &a = r1.rec.sims[k].xs, &b = r2.rec.sims[k].xs;
    CHECK(std::memcmp(a.p.data(), b.p.data(), sizeof(double) * 3) == 0);
    CHECK((a.q.w == b.q.w && a.q.x == b.q.x && a.q.y == b.q.y && a.q.z == b.q.z));
    CHECK(lowest_z(*r1.model, a) >= kDelta * (1 - 1e-3));
  }
}

// The lowest height_over_crease of the god-object over the straight motion
// between two poses of the same orientation (a pure translation, as every
// motion of these tests: the Cayley motion between them). Per vertex, the
// height max(z, n . x) along the segment is convex and piecewise linear in u:
// its minimum is at an end or where the two planes' distances are equal. The
// octahedron's tip is its lowest point and the crease's top falls at most 20
// degrees, less than its faces' 45, so the tip outside the wedge keeps the
// whole body outside: > 0 means the motion is free of contact.
double lowest_over_crease_along(const RuntimeModel& model, const Pose& a, const Pose& b) {
  REQUIRE((a.q.w == b.q.w && a.q.x == b.q.x && a.q.y == b.q.y && a.q.z == b.q.z));
  double h = INFINITY;
  for (int v = 0; v < model.god_mesh_B.V.rows(); ++v) {
    const Vec3 r = model.god_mesh_B.V.row(v).transpose();
    const Vec3 wa = transform_point(a, r), wb = transform_point(b, r);
    auto height = [&](double u) {
      const Vec3 w = wa + u * (wb - wa);
      return std::max(w.z(), kSlopeNormal.dot(w));
    };
    h = std::min({h, height(0), height(1)});
    const double fa = wa.z() - kSlopeNormal.dot(wa), fb = wb.z() - kSlopeNormal.dot(wb);
    if (fa * fb < 0) h = std::min(h, height(fa / (fa - fb)));
  }
  return h;
}

// Step 4 on a sim loop's state, as sim_step runs it (sim_loop.cpp's advance_by).
static void step4_on(const RuntimeModel& model, const Pose& x_start, const Pose& x_target, const Vec6& residual, SimState* s,
                     SimStepInfo* info) {
  advance_god_object(model, x_start, x_target, residual, s->M, &s->contacts, &s->step4, info);
  s->xs = info->xs;
  s->M = mass_matrix_at(model, s->xs.q);
}

TEST_CASE("runtime: step 4's paths: settle, refused settle, shortening, keep_a_contact, graze lift", "[runtime]") {
  // Each path of step 4 (docs/sim-step.md), named by the section that takes it
  // and checked by what it is for (each fails with its path removed). The tip
  // rests on the flat part, kDelta (1 + gap_factor) above it, before the
  // crease; the step slides it along +x (the command projected on the flat
  // face's contact), over the slope and out of the contact band.
  const RuntimeModel model(make_crease_scene(), RuntimeSettings{});
  const double gap = kDelta * (1 + model.settings.gap_factor);
  const Vec6 pressing = (Vec6() << 0, 0, -0.005, 0, 0, 0).finished();  // what the flat face's rows withheld
  SimState s(model);
  SimStepInfo info;
  auto start_at = [&](const Pose& x0) {  // in contact with the flat face at x0
    step4_on(model, x0, x0, Vec6::Zero(), &s, &info);
    REQUIRE(info.status == SimStepStatus::kFree);
    REQUIRE(info.num_contacts > 0);
  };

  SECTION("nothing withheld: the god-object ends in free space (no settling)") {
    const Pose x0{Vec3(-0.001, 0, kHalf + gap), Quat{}};
    const Pose x1{x0.p + Vec3(0.003, 0, 0), Quat{}};
    start_at(x0);
    step4_on(model, x0, x1, Vec6::Zero(), &s, &info);
    CHECK(info.status == SimStepStatus::kFree);
    CHECK_FALSE(info.settled);
    CHECK(s.step4.paths.settles == 0);
    CHECK(info.num_contacts == 0);
    CHECK(s.xs.p.x() == Approx(x1.p.x()).margin(1e-12));
    CHECK(height_over_crease(model, s.xs) > 50 * kDelta);
  }
  SECTION("settle: the pressing part withheld, a short step settles on the slope in the same step") {
    // 1 delta before the crease, 4 delta along: 2.5 delta from the slope at
    // the first leg's end (out of the band, 1.5 delta); the settled end is 0.4
    // delta below the flat part's plane, and the direct motion to it passes
    // about 0.9 delta over the crease.
    const Pose x0{Vec3(-kDelta, 0, kHalf + gap), Quat{}};
    const Pose x1{x0.p + Vec3(4 * kDelta, 0, 0), Quat{}};
    start_at(x0);
    step4_on(model, x0, x1, pressing, &s, &info);
    CHECK(info.settled);
    CHECK(info.num_shortenings == 0);
    CHECK(s.step4.paths.settles == 1);
    CHECK(s.step4.paths.refused == 0);
    CHECK(info.status == SimStepStatus::kContact);
    CHECK(info.ccd == CcdStatus::kOk);
    CHECK(info.num_contacts > 0);
    CHECK(info.num_contacts <= 4);  // the tip against the slope: its four faces' corner, merged or not
    // Recorded inputs.
    CHECK(info.x_start.p == x0.p);
    CHECK(info.x_target.p == x1.p);
    CHECK(info.residual == pressing);
    // The settling leg only went down (-z) from the first leg's end.
    CHECK(s.xs.p.x() == Approx(x1.p.x()).margin(1e-12));
    CHECK(s.xs.p.z() < x1.p.z() - kDelta);
    // Stopped delta before the slope: at least delta (1 - 1e-3) (stop-pose
    // rounding), and in the contact band; the tip is the nearest point, over
    // the slope, so the plane distance is the exact distance there.
    const double h = height_over_crease(model, s.xs);
    CHECK(h >= kDelta * (1 - 1e-3));
    CHECK(h <= kDelta * (1 + model.settings.contact_factor));
    for (int k = 0; k < s.contacts.num_contacts; ++k)
      CHECK(s.contacts.contacts[k].normal.dot(kSlopeNormal) == Approx(1).margin(1e-12));
    // Property 5: the motion between the step's two poses is free of contact.
    CHECK(lowest_over_crease_along(model, x0, s.xs) > 0.5 * kDelta);
  }
  SECTION("refused settle, shortening: a long step's settled end is refused (the direct motion cuts the crease)") {
    // 1 mm before the crease, 3 mm along: the first leg ends 0.73 mm (73 delta)
    // over the slope; settling there would put the tip 2 mm along the slope,
    // and the straight motion from x0 to it passes 0.23 mm (23 delta) under the
    // crease: each leg is free, the motion between the published poses is not.
    // Halved twice, the slide (0.75 mm) stays on the flat part, in contact
    // with it: no settling, no dropout.
    const Pose x0{Vec3(-0.001, 0, kHalf + gap), Quat{}};
    const Pose x1{x0.p + Vec3(0.003, 0, 0), Quat{}};
    start_at(x0);
    step4_on(model, x0, x1, pressing, &s, &info);
    CHECK(info.settled);
    CHECK(info.num_shortenings == 2);
    CHECK(s.step4.paths.refused == 2);
    CHECK(s.step4.paths.keep_halvings == 0);
    CHECK(info.status == SimStepStatus::kFree);
    CHECK(info.num_contacts > 0);
    CHECK(s.xs.p.x() == Approx(x0.p.x() + 0.003 / 4).margin(1e-12));
    // Property 5, the check that failed before the refusal (-23 delta: through the crease).
    CHECK(lowest_over_crease_along(model, x0, s.xs) > 0.5 * kDelta);
    // The shortened tries' contacts came from the first leg's near pairs, kept
    // before the settling legs ran (GodObjectStep::proven_near): the same set as a
    // full descent at the published pose.
    CHECK(s.step4.leg.near.pairs == s.step4.proven_near.data());
    CHECK(s.step4.leg.near.num_pairs > 0);
    ContactSet full(s.capacity);
    ContactWorkspace full_ws(model.god_mesh_B);
    REQUIRE(generate_contacts(model.obstacles.data(), static_cast<int>(model.obstacles.size()), model.god, s.xs,
                              model.contact_generation, &full_ws, &full) == ContactStatus::kOk);
    REQUIRE(full.num_contacts == s.contacts.num_contacts);
    for (int k = 0; k < full.num_contacts; ++k) {
      int same = 0;
      for (int j = 0; j < s.contacts.num_contacts; ++j)
        same += s.contacts.contacts[j].features == full.contacts[k].features &&
                s.contacts.contacts[j].separation == full.contacts[k].separation;
      CHECK(same == 1);
    }
  }
  SECTION("keep_a_contact: every settle refused, the first leg halved on until its end keeps a contact") {
    // 1 mm before the crease, 12 mm along: the first leg's end at 1, 1/2, 1/4
    // and 1/8 of the slide lies 11 to 0.5 mm past the crease, out of the
    // band, and each settled end is refused (the direct motion to the slope
    // dips under the crease's top); at 1/16 (0.75 mm) the tip is still on the
    // flat part, in contact. Without the halvings the step would publish an
    // empty set while the user presses (a force dropout).
    const Pose x0{Vec3(-0.001, 0, kHalf + gap), Quat{}};
    const Pose x1{x0.p + Vec3(0.012, 0, 0), Quat{}};
    start_at(x0);
    step4_on(model, x0, x1, pressing, &s, &info);
    CHECK(info.settled);
    CHECK(info.num_shortenings == kMaxSettleShortenings);
    CHECK(s.step4.paths.refused == kMaxSettleShortenings + 1);
    CHECK(s.step4.paths.keep_halvings == 1);
    CHECK_FALSE(s.step4.paths.stayed);
    CHECK(info.num_contacts > 0);
    CHECK(s.xs.p.x() == Approx(x0.p.x() + 0.012 / 16).margin(1e-12));
    CHECK(lowest_over_crease_along(model, x0, s.xs) > 0.5 * kDelta);
  }
  SECTION("graze lift: a contact left in the CCD's band does not hold the god-object back") {
    // The tip 1.05 delta over the flat part (inside the CCD's band, delta to
    // 1.1 delta), sliding 1 mm along it and closing in by 0.15 delta: the CCD
    // accepts the pair it starts with at once (u_hit 0), though the tip would
    // reach delta only a third of the way along. Lifted to delta (1 +
    // gap_factor) first, the leg slides until the tip comes back into the
    // band, 43-71% of the way; that end is kept, the direct motion from x0
    // being free.
    const Pose x0{Vec3(-0.004, 0, kHalf + 1.05 * kDelta), Quat{}};
    const Pose x1{x0.p + Vec3(0.001, 0, -0.15 * kDelta), Quat{}};
    start_at(x0);
    step4_on(model, x0, x1, Vec6::Zero(), &s, &info);
    CHECK(s.step4.paths.grazed);
    CHECK(s.step4.paths.lifted);
    CHECK(s.xs.p.x() - x0.p.x() > 0.0004);  // without the lift: u_hit 0
    CHECK(height_over_crease(model, s.xs) >= kDelta * (1 - 1e-3));
    CHECK(info.num_contacts > 0);
    CHECK(lowest_over_crease_along(model, x0, s.xs) > 0.5 * kDelta);
  }
}

TEST_CASE("runtime: step 4 splits an update's work units by path", "[runtime][budget]") {
  // The settle of the paths test above under a count that never runs out: its
  // units go to the first leg, the settling leg and the check of its direct
  // motion (StepPaths), and add up to the update's; without a budget nothing
  // is counted.
  const Pose x0{Vec3(-kDelta, 0, kHalf + kDelta * (1 + RuntimeSettings{}.gap_factor)), Quat{}};
  const Pose x1{x0.p + Vec3(4 * kDelta, 0, 0), Quat{}};
  const Vec6 pressing = (Vec6() << 0, 0, -0.005, 0, 0, 0).finished();
  for (const bool counted : {true, false}) {
    RuntimeSettings settings;
    if (counted) settings.budget.work_units = LONG_MAX / 4;
    const RuntimeModel model(make_crease_scene(), settings);
    SimState s(model);
    SimStepInfo info;
    step4_on(model, x0, x0, Vec6::Zero(), &s, &info);
    REQUIRE(info.num_contacts > 0);
    step4_on(model, x0, x1, pressing, &s, &info);
    REQUIRE(s.step4.paths.settles == 1);
    REQUIRE(s.step4.paths.refused == 0);
    const StepPaths& p = s.step4.paths;
    CHECK(p.first_leg_units + p.check_units + p.detour_units == info.work_units);
    if (counted) {
      CHECK(p.first_leg_units > 0);
      CHECK(p.check_units > 0);
      CHECK(p.detour_units > 0);
    } else {
      CHECK(info.work_units == 0);
      CHECK(p.first_leg_units == 0);
      CHECK(p.check_units == 0);
      CHECK(p.detour_units == 0);
    }
  }
}

TEST_CASE("runtime: sliding over a convex crease, the force never drops out", "[runtime]") {
  // Pressed 2 cm deep on the flat part (1.7 N), then slid along +x over the
  // crease at 0.1 m/s, the handle following the surface 2 cm below it, so the
  // user keeps pressing throughout. Each step's motion, tangent to the contact
  // it starts with, lifts off where the surface turns down (1e-4 m x sin 20 deg
  // = 3.4 delta per step, beyond the band); the settling leg puts it back.
  auto surface = [](double x) { return x <= 0 ? 0.0 : -x * std::tan(kCreaseAngle); };
  auto script = [&](double t) {
    const double x = -0.05 + (t < 0.5 ? 0.0 : std::min(0.15, 0.1 * (t - 0.5)));
    const double z = std::max(kHalf + surface(x) - 0.02, 0.2 - 0.4 * t);
    return Pose{Vec3(x, 0.001, z), Quat{}};
  };
  ScriptedDevice device(script);
  Run r;
  run(&r, make_crease_scene(), RuntimeSettings{}, &device, 2200);
  REQUIRE(r.rec.events.empty());
  const RuntimeModel& model = *r.model;
  int num_sliding = 0, num_dropouts = 0, num_settled = 0, max_contacts = 0;
  double max_rel_dot = 0, min_force = INFINITY;
  const double cos_half = std::cos(kCreaseAngle / 2);
  for (size_t k = 1; k < r.rec.sims.size(); ++k) {
    const SimStepInfo& sim = r.rec.sims[k];
    const CouplingStepInfo& c = r.rec.couplings[k];
    // Never into the wedge: see height_over_crease (rounding margin 1e-3).
    CHECK(height_over_crease(model, sim.xs) >= kDelta * cos_half * (1 - 1e-3));
    num_settled += sim.settled;
    max_contacts = std::max(max_contacts, sim.num_contacts);
    if (sim.time < 0.5) continue;  // landing (and its offset ramp) done by then
    ++num_sliding;
    // A dropout: the set empties (the coupling then sends no force) while the
    // handle is 2 cm inside.
    if (r.rec.sims[k - 1].num_contacts > 0 && sim.num_contacts == 0) ++num_dropouts;
    min_force = std::min(min_force, r.rec.ticks[k].F_sent.head<3>().norm());
    if (c.num_offset_rows == 0 && c.Fc.norm() > 0)
      max_rel_dot = std::max(max_rel_dot, std::abs(c.Fc.dot(c.ac)) / (c.Fc.norm() * c.au.norm()));
  }
  CHECK(num_sliding > 1600);
  CHECK(num_dropouts == 0);
  // 83 N/m x 2 cm = 1.7 N on the flat part; less on the slope, where part of
  // the depth is tangential and the tip's row has an angular part (the god-
  // object turns about its tip: a lower effective stiffness); measured minimum
  // 0.54 N. A dropout sends 0.
  CHECK(min_force > 0.3);
  CHECK(num_settled > 0);       // the crease was crossed: the settling leg ran
  CHECK(max_contacts <= 4);     // the tip: its faces' corner, merged or not
  CHECK(max_rel_dot <= kOrthogonalityTol);
  // The god-object went over: its x near the handle's end, on the slope.
  CHECK(r.data->sim.xs.p.x() > 0.09);
}

TEST_CASE("runtime: a run's recorded CCD inputs replay its collision work exactly", "[runtime]") {
  // Sliding over the crease and turning: settling legs, hits and free steps.
  auto script = [](double t) {
    const double x = -0.05 + (t < 0.5 ? 0.0 : 0.1 * (t - 0.5));
    return Pose{Vec3(x, 0.001, std::max(0.03 - std::max(0.0, x) * std::tan(kCreaseAngle), 0.2 - 0.4 * t)),
                quat_exp(Vec3(0, 0.05 * std::max(0.0, t - 0.5), 0))};
  };
  ScriptedDevice device(script);
  Run r;
  run(&r, make_crease_scene(), RuntimeSettings{}, &device, 1500);
  const RuntimeModel& model = *r.model;
  SimState replay(model);
  SimStepInfo info;
  int num_replayed = 0, num_settled = 0, num_hits = 0, num_settling_legs = 0;
  for (size_t k = 0; k < r.rec.sims.size(); ++k) {
    const SimStepInfo& sim = r.rec.sims[k];
    if (sim.status == SimStepStatus::kNoHandle) {
      CHECK(sim.x_start.p == sim.xs.p);
      continue;
    }
    // The inputs are those of the step: it started where the last one ended,
    // its target is xs (+) ac, its residual au - ac (0 after an empty set).
    const Pose& before = k > 0 ? r.rec.sims[k - 1].xs : model.initial_pose;
    CHECK(std::memcmp(sim.x_start.p.data(), before.p.data(), sizeof(double) * 3) == 0);
    const Pose target = pose_update(sim.x_start, sim.ac);
    CHECK(std::memcmp(sim.x_target.p.data(), target.p.data(), sizeof(double) * 3) == 0);
    const bool had_contacts = k > 0 && r.rec.sims[k - 1].num_contacts > 0;
    CHECK(sim.residual == (had_contacts ? Vec6(sim.au - sim.ac) : Vec6::Zero()));
    // Replayed on a fresh state: the same pose (bit for bit) and contacts.
    step4_on(model, sim.x_start, sim.x_target, sim.residual, &replay, &info);
    CHECK(std::memcmp(replay.xs.p.data(), sim.xs.p.data(), sizeof(double) * 3) == 0);
    CHECK((replay.xs.q.w == sim.xs.q.w && replay.xs.q.x == sim.xs.q.x && replay.xs.q.y == sim.xs.q.y &&
           replay.xs.q.z == sim.xs.q.z));
    CHECK(info.num_contacts == sim.num_contacts);
    CHECK(info.settled == sim.settled);
    // Only the step's first leg goes on with the proximity cache's background
    // fill (its budget is per sim step): an accepted settling leg, the last
    // leg run, filled only if it refilled the list at once or finished a
    // fill it needed.
    const CcdStepResult& last = replay.step4.leg.ccd;  // the leg the step ended on
    if (info.settled && info.num_shortenings == 0 && last.motion.nominal.p0 != sim.x_start.p && !last.cache_filled &&
        !last.cache_refilled) {
      CHECK(last.num_fill_node_pairs == 0);
      ++num_settling_legs;
    }
    ++num_replayed;
    num_settled += sim.settled;
    num_hits += sim.status == SimStepStatus::kContact;
  }
  CHECK(num_replayed > 1400);
  CHECK(num_settled > 0);
  CHECK(num_settling_legs > 0);
  CHECK(num_hits > 0);
}

TEST_CASE("shared state: a seqlock read under a concurrent writer is never torn", "[runtime][threaded]") {
  // Every write fills all words with one counter value; a torn read would mix two.
  struct Payload {
    uint64_t words[300];
  };
  static SeqLock<Payload> lock;
  std::atomic<bool> done{false};
  constexpr uint64_t kWrites = 200000;
  std::thread writer([&] {
    static Payload p;
    for (uint64_t i = 1; i <= kWrites; ++i) {
      std::fill(std::begin(p.words), std::end(p.words), i);
      lock.write(p);
    }
    done.store(true);
  });
  long reads = 0, torn = 0, backwards = 0;
  uint64_t last = 0;
  Payload got;
  while (!done.load() || reads == 0) {
    if (!lock.try_read(&got)) continue;
    ++reads;
    for (uint64_t w : got.words) torn += w != got.words[0];
    backwards += got.words[0] < last;
    last = got.words[0];
  }
  writer.join();
  REQUIRE(lock.try_read(&got));
  CHECK(got.words[0] == kWrites);
  CHECK(lock.num_writes() == kWrites);
  CHECK(reads > 0);
  CHECK(torn == 0);
  CHECK(backwards == 0);
}

TEST_CASE("shared state: the god-object channel of a runtime capacity, whole and never torn", "[runtime][threaded]") {
  // A channel for 300 contacts (SeqLockBuffer underneath): writes of 0 to 300
  // rows, plain and shaded, each filled with its write number; a reader sees
  // whole snapshots only (every value one number, the row count the one written
  // with it), in order. A reader with less room than the channel is refused.
  constexpr int kCap = 300;
  static GodObjectChannel channel(kCap);
  GodObjectSnapshot small(kCap - 1);
  GodObjectSnapshot got(kCap);
  CHECK(!channel.try_read(&got));  // nothing written yet
  std::atomic<bool> done{false};
  constexpr uint64_t kWrites = 20000;
  std::thread writer([&] {
    static GodObjectSnapshot g(kCap);
    for (uint64_t i = 1; i <= kWrites; ++i) {
      const double v = static_cast<double>(i);
      g.sequence = i;
      g.time = v;
      g.num_contacts = static_cast<int32_t>(i % (kCap + 1));
      g.shaded = static_cast<int32_t>(i % 2);
      std::fill(std::begin(g.M), std::end(g.M), v);
      for (auto* a : {&g.J, &g.point, &g.normal, &g.separation, &g.Js, &g.shaded_normal})
        std::fill(a->begin(), a->end(), v);
      channel.write(g);
    }
    done.store(true);
  });
  long reads = 0, torn = 0, backwards = 0;
  uint64_t last = 0;
  while (!done.load() || reads == 0) {
    if (!channel.try_read(&got)) continue;
    ++reads;
    const double v = static_cast<double>(got.sequence);
    const int m = got.num_contacts;
    torn += got.time != v || got.M[35] != v || m != static_cast<int>(got.sequence % (kCap + 1)) ||
            got.shaded != static_cast<int>(got.sequence % 2);
    for (int k = 0; k < m; ++k)
      torn += got.J[6 * k + 5] != v || got.point[3 * k] != v || got.normal[3 * k + 2] != v ||
              got.separation[k] != v || (got.shaded && (got.Js[6 * k] != v || got.shaded_normal[3 * k + 1] != v));
    backwards += got.sequence < last;
    last = got.sequence;
  }
  writer.join();
  REQUIRE(channel.try_read(&got));
  CHECK(got.sequence == kWrites);
  CHECK(got.num_contacts == static_cast<int>(kWrites % (kCap + 1)));
  CHECK(channel.num_writes() == kWrites);
  CHECK(reads > 0);
  CHECK(torn == 0);
  CHECK(backwards == 0);
  CHECK(!channel.try_read(&small));
}

TEST_CASE("runtime: threaded runs give sane forces (both force sources)", "[runtime][threaded]") {
  for (const ForceSource source : {ForceSource::kHapticTick, ForceSource::kCouplingLoop}) {
    // Pressed 1 cm deep. The run stops once 50 successive ticks sent more than
    // 4 N, or after 5 s of wall time (a loaded machine only makes it slower).
    ScriptedDevice device(press_script(0.2, 0.04, 1.0));
    RuntimeSettings settings;
    settings.force_source = source;
    settings.coupling_min_period = 1e-4;  // leave the two cores some room
    settings.sim_timeout = 1.0;
    settings.coupling_timeout = 0.05;
    const RuntimeModel model(make_scene(), settings);
    auto data = std::make_unique<RuntimeData>(model);
    Recorder rec;
    rec.ticks.reserve(10000);
    rec.sims.reserve(20000);
    rec.couplings.reserve(200000);
    int pressed_in_a_row = 0;
    rec.on_tick = [&](const HapticTickRecord& t) {
      pressed_in_a_row = t.F_sent[2] > 4 ? pressed_in_a_row + 1 : 0;
      if (pressed_in_a_row >= 50) rec.stop.store(true);
    };
    RuntimeObserver observer = rec.observer();
    observer.on_coupling_step = nullptr;  // the coupling thread would race with the haptic thread's vector
    run_threaded(model, &device, 5.0, &rec.stop, observer, data.get());
    INFO("force source " << static_cast<int>(source));
    CHECK(rec.stop.load());
    REQUIRE(!device.writes.empty());
    for (const auto& w : device.writes) {
      CHECK(w.F.allFinite());
      CHECK(w.F.head<3>().norm() <= 20 * (1 + 1e-15));
      CHECK(w.F.tail<3>().norm() <= 1 * (1 + 1e-15));
      CHECK(w.F[2] >= -1e-9);  // never pulls down into the obstacle
    }
    // The last pressed tick: 5 N up (resting gap: < 1e-2 N), nothing sideways.
    const HapticTickRecord& last = rec.ticks.back();
    CHECK(std::abs(last.F_sent[2] - 5.0) < 1e-2);
    CHECK(last.F_sent.head<2>().norm() < 1e-9);
    for (const SimStepInfo& s : rec.sims) CHECK(lowest_z(model, s.xs) >= kDelta * (1 - 1e-3));
    CHECK(device.writes.back().F.norm() == 0.0);  // released at the end
    CHECK(data->stats.haptic.period.count > 0);
    CHECK(data->stats.sim.work.count > 0);
    CHECK(data->stats.coupling.work.count > 0);
    std::printf("threaded (%s): %ld haptic ticks, period mean %.1f us (max jitter %.1f us, %ld overruns); "
                "%ld sim steps, update mean %.1f us max %.1f us; %ld coupling steps, force mean %.2f us max %.2f us\n",
                source == ForceSource::kHapticTick ? "coupling in the haptic tick" : "coupling thread",
                data->stats.haptic.period.count + 1, 1e6 * data->stats.haptic.period.mean(),
                1e6 * data->stats.haptic.max_jitter, data->stats.haptic.overruns, data->stats.sim.work.count,
                1e6 * data->stats.sim.work.mean(), 1e6 * data->stats.sim.work.max, data->stats.coupling.work.count,
                1e6 * data->stats.coupling.work.mean(), 1e6 * data->stats.coupling.work.max);
  }
}

TEST_CASE("runtime: a pushing hand gets rows and force at every delta down to the floor", "[runtime][delta]") {
  // The box pressed 1 cm (times the scene's scale) onto the slab: 5 N (times
  // the scale; the resting gap adds 1.25 delta) at any delta the model accepts,
  // in metres and in a scene 1000 times larger (millimetres). The CCD stops the
  // god-object within its stop distance, which must stay inside the contact
  // band delta (1 + contact_factor), or the blocked god-object has no rows and
  // the user feels almost nothing (in millimetres, before the step's time
  // tolerance was bounded by delta: 400 delta away, 0 N, from delta 1e-8 down).
  for (const double scale : {1.0, 1000.0}) {
    for (const double delta : {1e-4, 1e-6, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12}) {
      Scene sc = make_scene();
      sc.contact.delta = delta;
      sc.device.max_force = 1e9;
      for (Body* b : {&sc.obstacles[0], &sc.god_object}) b->mesh.V *= scale;
      sc.god_object.pose.p *= scale;
      std::string error;
      REQUIRE(compute_mass_properties(sc.god_object.mesh, 1000 / (scale * scale * scale), &sc.god_mass.mass, &error));
      if (delta < kMinDeltaPerExtent * scene_extent(sc)) {  // 1e-12 in millimetres: refused, by name
        CHECK_THROWS_WITH(RuntimeModel(sc, RuntimeSettings{}), Catch::Contains("contact.delta"));
        continue;
      }
      ScriptedDevice device([scale](double t) { return Pose{scale * Vec3(0, 0, std::max(0.04, 0.2 - 0.4 * t)), Quat{}}; });
      device.set_limits(1e9, 1e9);
      Run r;
      run(&r, sc, RuntimeSettings{}, &device, 700);
      INFO("scale " << scale << ", delta " << delta);
      const SimStepInfo& last = r.rec.sims.back();
      CHECK(last.num_contacts > 0);
      const double expected = 500 * (0.01 * scale + 1.25 * delta);  // kh m ks (depth + resting gap)
      CHECK(r.rec.ticks.back().F_sent[2] == Approx(expected).epsilon(1e-3));
      double lowest = INFINITY;
      for (const SimStepInfo& s : r.rec.sims) lowest = std::min(lowest, lowest_z(*r.model, s.xs));
      CHECK(lowest >= delta * (1 - 1e-3));
      std::printf("scale %g, delta %.0e: %d contacts, %.6f N (expected %.6f), lowest gap %.3e (%.2f delta)\n", scale,
                  delta, last.num_contacts, r.rec.ticks.back().F_sent[2], expected, lowest, lowest / delta);
    }
  }
}

TEST_CASE("runtime: docs/sim-step.md states step 4's constants as the code defines them", "[runtime]") {
  std::ifstream in(std::string(GAUSS6_SOURCE_DIR) + "/docs/sim-step.md");
  REQUIRE(in);
  std::stringstream text;
  text << in.rdbuf();
  const auto stated = [&](const char* name, double value) {
    char line[96];
    std::snprintf(line, sizeof line, "`%s` = %g", name, value);
    INFO(line);
    CHECK(text.str().find(line) != std::string::npos);
  };
  stated("kMaxSettleShortenings", kMaxSettleShortenings);
  stated("kMaxKeepHalvings", kMaxKeepHalvings);
  stated("kSettleLeadSweep", kSettleLeadSweep);
  // Budgeted updates (update_budget.h).
  stated("kRecommendedUpdateCpuSeconds", kRecommendedUpdateCpuSeconds);
  stated("kDefaultBudgetCheckInterval", static_cast<double>(kDefaultBudgetCheckInterval));
  stated("kUpdateOverrunBound", kUpdateOverrunBound);
}
