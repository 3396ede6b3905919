// Tests of run_scenario (scenario.h): a cube pressed on and slid along a slab by
// the simulated device's scripted hand, recorded as a trace. Checked: the trace
// round trip (rows, phases, let-go), the force's direction (up, no tangential
// part), orthogonality and the constraint energy, bit-for-bit repeatable
// lockstep runs, and a threaded run.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "../../optimized/tests/mesh_shapes.h"
#include "gauss6/geometry/mass_properties.h"
#include "gauss6/scenario.h"
#include "slab_scene.h"

using namespace gauss6;
using gauss6::test::make_slab_scene;

namespace {

// A hand keyframe at time t (s), position (x, 0, z) (m), identity orientation.
HandKeyframe key(double t, double x, double z) {
  HandKeyframe k;
  k.t = t;
  k.X_WA.p = Vec3(x, 0, z);
  return k;
}

// Down 15 mm (5 mm into the slab) in 0.3 s, slide 2 cm along +x, let go.
HandScript make_press_script() {
  HandScript h;
  h.keys = {key(0, 0, 0.02), key(0.3, 0, 0.005), key(0.6, 0.02, 0.005)};
  h.phases = {{"approach", 0.0}, {"slide", 0.3}};
  h.let_go_time = 0.7;
  h.end_time = 0.9;
  return h;
}

std::string temp_trace(const char* name) {
  return (std::filesystem::temp_directory_path() / (std::string("gauss6_test_scenario_") + name + ".g6trace")).string();
}

}  // namespace

TEST_CASE("run_scenario: lockstep press and slide, recorded and checked", "[scenario]") {
  const Scene scene = make_slab_scene();
  const HandScript script = make_press_script();
  ScenarioOptions options;
  options.trace_path = temp_trace("lockstep");
  const ScenarioResult r = run_scenario(scene, script, options);

  // 0.9 s at 1 kHz: ticks 0 .. 900; the device ends after 0.9 s.
  CHECK(r.num_ticks >= 900);
  CHECK(r.num_ticks <= 901);
  CHECK(r.num_sim_steps == r.num_ticks);
  CHECK(r.trace.dropped == std::array<uint64_t, 4>{});

  const Trace tr = read_trace(options.trace_path);
  REQUIRE(tr.complete);
  CHECK(tr.warnings.empty());
  REQUIRE(tr.ticks.num_rows() == static_cast<size_t>(r.num_ticks));
  CHECK(tr.steps.num_rows() == static_cast<size_t>(r.num_sim_steps));
  CHECK(tr.contacts.num_rows() == r.trace.written[2]);

  // Phases and the let-go appear as events at their times.
  int num_phases = 0, num_let_go = 0;
  for (size_t i = 0; i < tr.events.num_rows(); ++i) {
    const double* e = tr.events.row(i);
    if (e[1] == static_cast<double>(TraceEventCode::kPhase)) {
      CHECK(e[0] == script.phases[static_cast<size_t>(e[2])].start);
      ++num_phases;
    }
    if (e[1] == static_cast<double>(TraceEventCode::kLetGo)) {
      CHECK(e[0] >= script.let_go_time);
      CHECK(e[0] <= script.let_go_time + 0.002);  // within two ticks
      ++num_let_go;
    }
  }
  CHECK(num_phases == 2);
  CHECK(num_let_go == 1);

  // While pressed and sliding (0.35 - 0.6 s): contacts, an upward force of
  // kh ks m * depth = 50 N/m * 5 mm = 0.25 N less the handle's give (grip 500 N/m:
  // about 10 %), so within [0.15, 0.3] N,
  // and no tangential part: contact normals are +Z, so Fx, Fy are rounding only.
  int pressed = 0;
  for (size_t i = 0; i < tr.ticks.num_rows(); ++i) {
    const TraceTick k = trace_tick(tr, i);
    if (k.t < 0.35 || k.t > 0.6) continue;
    ++pressed;
    CHECK(k.num_contacts > 0);
    CHECK(k.F[2] > 0.15);
    CHECK(k.F[2] < 0.3);
    CHECK(std::abs(k.F[0]) <= 1e-9 * k.F[2]);
    CHECK(std::abs(k.F[1]) <= 1e-9 * k.F[2]);
    CHECK(k.force_time > 0);
    CHECK((k.flags & kTickGripped) != 0);
  }
  CHECK(pressed >= 240);
  // The god-object stays on the slab: its bottom (z - 1 cm) never below the top.
  for (size_t i = 0; i < tr.ticks.num_rows(); ++i) CHECK(trace_tick(tr, i).X_WS.p[2] - 0.01 > 0);

  // Orthogonality (projection tolerance: about 1e-12 relative; 1e-9 leaves room
  // for rounding in kh M (ac - au)), and the constraints only remove energy.
  CHECK(r.num_orthogonality_checks > 200);
  CHECK(r.max_rel_force_dot_ac <= 1e-9);
  CHECK(r.constraint_energy_removed > 0);
  CHECK(r.constraint_energy_injected <= 1e-12 * r.constraint_energy_removed);
  std::remove(options.trace_path.c_str());
}

TEST_CASE("run_scenario: lockstep runs repeat bit for bit", "[scenario]") {
  const Scene scene = make_slab_scene();
  const HandScript script = make_press_script();
  ScenarioOptions options;
  options.duration = 0.5;
  options.trace_path = temp_trace("repeat_1");
  run_scenario(scene, script, options);
  const Trace a = read_trace(options.trace_path);
  std::remove(options.trace_path.c_str());
  options.trace_path = temp_trace("repeat_2");
  run_scenario(scene, script, options);
  const Trace b = read_trace(options.trace_path);
  std::remove(options.trace_path.c_str());
  REQUIRE(a.ticks.num_rows() == 501);
  REQUIRE(a.ticks.num_rows() == b.ticks.num_rows());
  // Every column but the force-computation time (wall time) is identical.
  for (size_t i = 0; i < a.ticks.num_rows(); ++i) {
    const TraceTick x = trace_tick(a, i), y = trace_tick(b, i);
    REQUIRE(x.t == y.t);
    REQUIRE(x.X_WH.p == y.X_WH.p);
    REQUIRE(x.X_WS.p == y.X_WS.p);
    REQUIRE(x.X_WS.q.w == y.X_WS.q.w);
    REQUIRE(x.F == y.F);
    REQUIRE(x.num_contacts == y.num_contacts);
  }
  CHECK(a.contacts.num_rows() == b.contacts.num_rows());
}

TEST_CASE("run_scenario: threaded run writes a complete trace", "[scenario][threaded]") {
  const Scene scene = make_slab_scene();
  const HandScript script = make_press_script();
  ScenarioOptions options;
  options.threaded = true;
  options.duration = 0.3;
  options.trace_path = temp_trace("threaded");
  double last_progress = -1;
  options.progress = [&](double t) { last_progress = t; };
  const ScenarioResult r = run_scenario(scene, script, options);
  const Trace tr = read_trace(options.trace_path);
  std::remove(options.trace_path.c_str());
  REQUIRE(tr.complete);
  // 0.3 s at 1 kHz on a loaded 2-core machine: at least half the ticks.
  CHECK(tr.ticks.num_rows() >= 150);
  CHECK(tr.ticks.num_rows() <= 301);
  CHECK(tr.ticks.num_rows() == static_cast<size_t>(r.num_ticks));
  CHECK(r.num_sim_steps > 10);
  CHECK(last_progress > 0.2);
  for (size_t i = 1; i < tr.ticks.num_rows(); ++i) CHECK(tr.ticks.row(i)[0] > tr.ticks.row(i - 1)[0]);
}

TEST_CASE("run_scenario: bad options and scripts are refused before the run", "[scenario]") {
  const Scene scene = make_slab_scene();
  ScenarioOptions options;  // no trace path
  CHECK_THROWS_WITH(run_scenario(scene, make_press_script(), options), Catch::StartsWith("run_scenario: "));
  // Each entry point names itself in the message.
  CHECK_THROWS_WITH(run_replay(scene, Trace{}, {}, options), Catch::StartsWith("run_replay: "));
  options.trace_path = temp_trace("bad");
  HandScript empty;
  CHECK_THROWS_AS(run_scenario(scene, empty, options), ScenarioError);
  Scene no_script = scene;
  no_script.device.script.clear();
  CHECK_THROWS_AS(load_scene_script(no_script), ScenarioError);
  Scene missing = scene;
  missing.path = "/nonexistent/scenes/x.toml";
  CHECK_THROWS_WITH(load_scene_script(missing), Catch::Contains("press_and_slide.json"));
}

TEST_CASE("run_scenario: a face sliding over a sphere keeps its force (rows that change identity are not re-offset)",
          "[scenario]") {
  // A 4 x 4 x 1 cm plate pressed 5 mm onto an icosphere (radius 5 cm, 642 vertices) and slid
  // 3 cm in 0.4 s: at 75 um per step the touching sphere vertex moves in the plate's frame by
  // more than the matching distance (1e-3 of the plate's radius, 29 um), so every contact set's
  // row is "new". Measured against the previous set's rows it needs no offset and the force
  // stays; measured against au (the user is 5 mm deep) it would be offset again at every set
  // and the force would keep collapsing to zero.
  Scene s = make_slab_scene();
  s.obstacles[0].mesh = test::make_icosphere(3, 0.05);
  s.obstacles[0].pose.p = Vec3(0, 0, -0.05);  // top at z = 0
  s.god_object.mesh = test::make_box(0.04, 0.04, 0.01);
  s.god_object.pose.p = Vec3(0, 0, 0.01);
  std::string why;
  REQUIRE(compute_mass_properties(s.god_object.mesh, 1000.0, &s.god_mass.mass, &why));
  s.gains.kh = 100.0 / s.god_mass.mass.mass;
  HandScript h;
  // Touch at G z = 5 mm; the hand goes to 0 (5 mm deep), then slides along x.
  h.keys = {key(0, -0.015, 0.01), key(0.2, -0.015, 0.0), key(0.3, -0.015, 0.0), key(0.7, 0.015, 0.0)};
  h.end_time = 0.7;
  ScenarioOptions options;
  options.trace_path = temp_trace("sphere");
  run_scenario(s, h, options);
  const Trace tr = read_trace(options.trace_path);
  std::remove(options.trace_path.c_str());
  // While sliding (0.35 - 0.7 s), the force is kh ks m * 5 mm = 0.25 N less the handle's give
  // (about 10 %) and the curvature's (the plate tilts by at most 3 cm / 5 cm rad ... but its
  // quasi-static pose follows the hand's, which does not tilt): at least 0.1 N on 95 % of the ticks.
  int sliding = 0, pushed = 0;
  for (size_t i = 0; i < tr.ticks.num_rows(); ++i) {
    const TraceTick k = trace_tick(tr, i);
    if (k.t < 0.35 || k.t > 0.7) continue;
    ++sliding;
    pushed += k.F.head<3>().norm() >= 0.1 ? 1 : 0;
  }
  REQUIRE(sliding >= 340);
  CHECK(pushed >= 0.95 * sliding);
}

namespace {

// A 12-sided prism (circumradius 3 cm, axis Y) and an octahedral probe of 5 mm
// held by its lowest vertex (G at the tip; 0.1 kg, kh m = 1000 N/m), with the
// given surface; the hand slides the tip around the axis 4 mm inside the flats.
Scene make_cylinder_scene(SurfaceKind kind) {
  Scene s;
  s.path = "test_scenario (in code)";
  s.name = "cylinder";
  Body cyl;
  cyl.name = "cylinder";
  cyl.mesh = test::make_prism(12, 0.03, 0.08);
  build_adjacency(&cyl.mesh);
  cyl.pose.q = normalized(Quat{1, 1, 0, 0});  // axis z -> y: the ring in the xz plane
  cyl.crease_angle = 45;
  s.obstacles.push_back(cyl);
  s.god_object.name = "probe";
  s.god_object.role = BodyRole::kGodObject;
  const double r = 0.005;
  s.god_object.mesh = test::make_mesh({{r, 0, r}, {-r, 0, r}, {0, r, r}, {0, -r, r}, {0, 0, 2 * r}, {0, 0, 0}},
                                      {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}},
                                      "probe");
  s.god_object.pose.p = Vec3(0.0386 * std::cos(0.26), 0, 0.0386 * std::sin(0.26));
  s.god_mass.from_density = false;
  s.god_mass.mass.mass = 0.1;
  s.god_mass.mass.center_of_mass = Vec3(0, 0, r);
  s.god_mass.mass.inertia = 1e-4 * Mat3::Identity();
  s.gains.ks = 0.5;
  s.gains.kh = 10000;
  s.contact.delta = 1e-6;
  s.contact.offset_eps = -1e-5;
  s.contact.offset_time = 0.05;
  s.surface.kind = kind;
  s.device.rate_hz = 1000;
  s.device.script = "cylinder_slide";
  return s;
}

HandScript make_cylinder_script() {
  const double inside = 0.03 * std::cos(M_PI / 12) - 0.004, far = 0.0386;
  HandScript h;
  auto at = [](double t, double deg, double radius) {
    HandKeyframe k;
    k.t = t;
    k.X_WA.p = Vec3(radius * std::cos(deg * M_PI / 180), 0, radius * std::sin(deg * M_PI / 180));
    return k;
  };
  h.keys = {at(0, 15, far), at(0.3, 15, inside)};
  for (int deg = 15; deg <= 75; ++deg) h.keys.push_back(at(0.4 + (deg - 15) * 0.02, deg, inside));
  h.phases = {{"approach", 0.0}, {"slide", 0.4}};
  h.end_time = 1.7;
  return h;
}

// The largest angle (radians) between the force directions of successive ticks
// with |F| above 0.5 N, over the slide.
double largest_direction_step(const Trace& tr) {
  double worst = 0;
  Vec3 prev = Vec3::Zero();
  for (size_t i = 0; i < tr.ticks.num_rows(); ++i) {
    const TraceTick k = trace_tick(tr, i);
    const Vec3 f = k.F.head<3>();
    if (k.t < 0.45 || f.norm() < 0.5) {
      prev.setZero();
      continue;
    }
    const Vec3 d = f.normalized();
    if (prev != Vec3::Zero()) worst = std::max(worst, std::acos(std::clamp(d.dot(prev), -1.0, 1.0)));
    prev = d;
  }
  return worst;
}

}  // namespace

// Force shading, both loops (surface.h): property 7 on every sim step, the
// shaded orthogonality Fc . asc = 0 under Js on every coupling step, bit-for-bit
// repeatable lockstep runs, and a smoother force direction than the flat facets.
TEST_CASE("run_scenario: force shading keeps property 7 and the shaded orthogonality", "[scenario][surface]") {
  const HandScript script = make_cylinder_script();
  ScenarioOptions options;
  options.trace_path = temp_trace("shaded_1");
  const ScenarioResult r = run_scenario(make_cylinder_scene(SurfaceKind::kForceShading), script, options);
  const Trace a = read_trace(options.trace_path);
  std::remove(options.trace_path.c_str());
  // Property 7 on every step with a handle: the projection's feasibility
  // tolerance is 1e-13 relative; 1e-9 leaves room for the rows' scale.
  CHECK(r.num_constraint_checks == r.num_sim_steps - 1);  // every step but the first (no handle sample yet)
  CHECK(r.max_rel_constraint_violation <= 1e-9);
  // Every coupling step with a snapshot used the shading rows, and their force is
  // orthogonal to asc (same tolerance as the plain orthogonality above).
  CHECK(r.num_shaded_steps >= r.num_ticks - 2);
  CHECK(r.num_orthogonality_checks > 300);
  CHECK(r.max_rel_force_dot_ac <= 1e-9);
  CHECK(r.constraint_energy_injected <= 1e-12 * r.constraint_energy_removed);
  // The shading's work on the god-object's motion is measured (0 on a plain surface).
  CHECK(std::isfinite(r.shading_work_injected));
  // The probe never ends inside the prism's circumscribed circle less delta... its
  // tip stays outside the flats: |xs| >= apothem (property 7 through the CCD).
  const double apothem = 0.03 * std::cos(M_PI / 12);
  for (size_t i = 0; i < a.ticks.num_rows(); ++i) {
    const Vec3 p = trace_tick(a, i).X_WS.p;
    CHECK(std::hypot(p.x(), p.z()) >= apothem - 1e-12);
  }

  // Repeatable bit for bit.
  options.trace_path = temp_trace("shaded_2");
  run_scenario(make_cylinder_scene(SurfaceKind::kForceShading), script, options);
  const Trace b = read_trace(options.trace_path);
  std::remove(options.trace_path.c_str());
  REQUIRE(a.ticks.num_rows() == b.ticks.num_rows());
  for (size_t i = 0; i < a.ticks.num_rows(); ++i) {
    const TraceTick x = trace_tick(a, i), y = trace_tick(b, i);
    REQUIRE(x.X_WS.p == y.X_WS.p);
    REQUIRE(x.F == y.F);
  }

  // The flat facets turn the force by 30 degrees at each edge within a few
  // ticks; shading spreads it over the facet: its largest step is smaller.
  options.trace_path = temp_trace("flat");
  const ScenarioResult flat = run_scenario(make_cylinder_scene(SurfaceKind::kNone), script, options);
  const Trace c = read_trace(options.trace_path);
  std::remove(options.trace_path.c_str());
  CHECK(flat.num_shaded_steps == 0);
  CHECK(flat.shading_work_injected == 0);
  // The plain rows hold as well, at the same tolerance: measured against |ac| alone, the
  // rounding of a god-object held still against a facet read as 3e-7.
  CHECK(flat.max_rel_constraint_violation <= 1e-9);
  CHECK(largest_direction_step(a) < largest_direction_step(c));
}
