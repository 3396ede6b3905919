// Benchmarks of one sim step's collision work: the mesh-level continuous
// collision detection (ccd_step) along a haptic-size motion, then the contact
// set at the stop pose (generate_contacts), on scripted motions of the
// peg-in-hole and bunnies scenes (datasets_generated/scenes/). Each step is an
// independent call from pose X_k to X_{k+1}; the scripts keep the god-object
// near or in contact (gaps of a few delta to a few tenths of a millimetre),
// moving 0.1-0.5 mm and 0.05-0.1 degree per step, as a god-object does.
// Counters: p50/p99/max per step (ns), hits per step, narrow-phase pair tests
// and boxes per step, candidate triangle pairs and those dropped by the face
// slab bound (no pair test), contacts generated at the stop pose. The
// *_pressing scripts start every step off contact and end it pressed in, so
// each step has a real first contact (the cases that decide the floors); the
// others are sliding near contact or landing.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "gauss6/bvh.h"
#include "gauss6/contacts.h"
#include "gauss6/scene.h"
#include "latency.h"

namespace gauss6::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;
double deg(double d) { return d * kPi / 180; }

// A scene ready for the CCD: obstacles in world coordinates, BVHs built.
struct CcdScene {
  Scene scene;
  std::vector<TriangleMesh> obstacle_meshes;  // world frame
  std::vector<Bvh> obstacle_bvhs;
  Bvh god_bvh;
  std::vector<CcdBody> obstacles;
  CcdBody god;
  double delta = 0;
};

std::unique_ptr<CcdScene> load_ccd_scene(const std::string& name) {
  auto s = std::make_unique<CcdScene>();
  s->scene = load_scene(std::string(GAUSS6_SOURCE_DIR) + "/datasets_generated/scenes/" + name + ".toml");
  s->delta = s->scene.contact.delta;
  for (const Body& b : s->scene.obstacles) {
    TriangleMesh m = b.mesh;
    const Mat3 R = rotation_matrix(b.pose.q);
    for (Eigen::Index v = 0; v < m.V.rows(); ++v) m.V.row(v) = (b.pose.p + R * m.V.row(v).transpose()).transpose();
    s->obstacle_meshes.push_back(std::move(m));
  }
  for (const TriangleMesh& m : s->obstacle_meshes) s->obstacle_bvhs.push_back(build_bvh(m));
  for (size_t i = 0; i < s->obstacle_meshes.size(); ++i)
    s->obstacles.push_back({&s->obstacle_meshes[i], &s->obstacle_bvhs[i]});
  s->god_bvh = build_bvh(s->scene.god_object.mesh);
  s->god = {&s->scene.god_object.mesh, &s->god_bvh};
  return s;
}

CcdScene& scene(const std::string& name) {
  static std::unique_ptr<CcdScene> peg, bunny;
  auto& slot = name == "peg_in_hole" ? peg : bunny;
  if (!slot) slot = load_ccd_scene(name);
  return *slot;
}

// Lowest / highest world z (axis k) of the god-object's vertices at orientation q, relative to G.
double extreme(const TriangleMesh& m, const Quat& q, int k, bool lowest) {
  const Mat3 R = rotation_matrix(q);
  double e = lowest ? 1e300 : -1e300;
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    const double c = (R * m.V.row(v).transpose())[k];
    e = lowest ? std::min(e, c) : std::max(e, c);
  }
  return e;
}

struct Step { Pose x0, x1; };

Pose moved(const Pose& x, const Vec3& dp, const Vec3& rot) { return {x.p + dp, normalized(quat_exp(rot) * x.q)}; }

// Peg lying on the box top (axis along world X), lowest facet 2 delta above the
// top face (z = 0.03), sliding along X and Y at 0.1 mm/step while turning about
// the vertical by 0.05 degree/step: every step grazes the top face.
std::vector<Step> peg_sliding(const CcdScene& s) {
  const Quat q = normalized(Quat{std::cos(-kPi / 4), 0, 0, std::sin(-kPi / 4)});  // mesh Y -> world X
  const TriangleMesh& m = s.scene.god_object.mesh;
  Pose x{Vec3(-0.02, -0.01, 0.03 + 2 * s.delta - extreme(m, q, 2, true)), q};
  std::vector<Step> steps;
  for (int k = 0; k < 200; ++k) {
    const double a = 2 * kPi * k / 200;
    const Pose y = moved(x, 1e-4 * Vec3(std::cos(a), std::sin(a), 0), Vec3(0, 0, deg(0.05) * std::cos(3 * a)));
    steps.push_back({x, y});
    x = y;
  }
  return steps;
}

// Peg upright above the top face, tip descending 0.1 mm/step from 0.45 mm with
// a 0.1 degree tilt per step: the last step of each descent touches.
std::vector<Step> peg_descending(const CcdScene& s) {
  const Pose x0 = s.scene.god_object.pose;
  const TriangleMesh& m = s.scene.god_object.mesh;
  const double tip = extreme(m, x0.q, 2, true);
  std::vector<Step> steps;
  for (int j = 0; j < 20; ++j) {
    const double a = 2 * kPi * j / 20;
    const Vec3 where(0.03 * std::cos(a), 0.02 * std::sin(a), 0);  // over the top face, off the hole's plane
    for (int k = 0; k < 5; ++k) {
      const Pose x{Vec3(where.x(), where.y(), 0.03 - tip + 4.5e-4 - 1e-4 * k), x0.q};
      steps.push_back({x, moved(x, Vec3(0, 0, -1e-4), deg(0.1) * Vec3(std::cos(a), std::sin(a), 0))});
    }
  }
  return steps;
}

// Peg inside the hole (axis along Y), moving along Y by 0.1 mm/step with a
// lateral wobble of 0.02 mm and 0.02 degree about X and Z. The wobble adds up
// (to about 0.16 mm and 0.3 degree), more than the 0.2 mm clearance: most poses
// of this script intersect the box, which a god-object's poses never do (kept
// as the historical case; in_hole_pressing is the god-object-like one).
std::vector<Step> peg_in_hole(const CcdScene&) {
  Pose x{Vec3(0, -0.01, 0), Quat{1, 0, 0, 0}};
  std::vector<Step> steps;
  for (int k = 0; k < 200; ++k) {
    const double a = 2 * kPi * k / 50;
    const Pose y = moved(x, Vec3(2e-5 * std::cos(a), (k < 100 ? 1e-4 : -1e-4), 2e-5 * std::sin(a)),
                         deg(0.02) * Vec3(std::sin(a), 0, std::cos(a)));
    steps.push_back({x, y});
    x = y;
  }
  return steps;
}

// Held bunny (upside down) lowered until its ears are gap above the static one,
// then sliding 0.3 mm/step in a circle with 0.1 degree/step of rotation.
std::vector<Step> bunny_sliding(CcdScene& s, double gap) {
  const Pose top = s.scene.god_object.pose;
  // Find the height of first contact with one long downward CCD step.
  CcdStepSettings cs;
  cs.narrow.min_separation = 0;
  cs.narrow.time_tolerance = 1e-9;
  CcdStepWorkspace ws;
  CcdStepResult r;
  const Pose down = moved(top, Vec3(0, -0.03, 0), Vec3::Zero());
  ccd_step(s.obstacles.data(), static_cast<int>(s.obstacles.size()), s.god, top, down, cs, &ws, &r);
  const double y_contact = top.p.y() - 0.03 * r.u_hit;
  Pose x{Vec3(top.p.x(), y_contact + gap, top.p.z()), top.q};
  std::vector<Step> steps;
  for (int k = 0; k < 100; ++k) {
    const double a = 2 * kPi * k / 100;
    const Pose y = moved(x, 3e-4 * Vec3(std::cos(a), 0, std::sin(a)), deg(0.1) * Vec3(std::sin(a), 0.5, std::cos(a)));
    steps.push_back({x, y});
    x = y;
  }
  return steps;
}

// How far the god-object can move from x along dir (unit) before touching the
// obstacles: one long tight CCD step of length `reach`.
double free_travel(CcdScene& s, const Pose& x, const Vec3& dir, double reach) {
  CcdStepSettings cs;
  cs.narrow.min_separation = 0;
  cs.narrow.time_tolerance = 1e-9;
  CcdStepWorkspace ws;
  CcdStepResult r;
  ccd_step(s.obstacles.data(), static_cast<int>(s.obstacles.size()), s.god, x, {x.p + reach * dir, x.q}, cs, &ws,
           &r);
  return r.hit ? reach * r.u_hit : reach;
}

// Steps that each press into contact from a non-intersecting start, as the sim
// loop's steps do: the pose k is `gap` short of contact along the direction
// dir(k); the step goes to pose k + 1 pressed `press` past its contact.
std::vector<Step> pressing(CcdScene& s, const std::vector<Pose>& poses, const std::vector<Vec3>& dirs, double gap,
                           double press, double reach) {
  std::vector<Pose> touch;
  for (size_t k = 0; k < poses.size(); ++k) {
    const double t = free_travel(s, poses[k], dirs[k], reach);
    touch.push_back({poses[k].p + t * dirs[k], poses[k].q});
  }
  std::vector<Step> steps;
  for (size_t k = 0; k + 1 < poses.size(); ++k)
    steps.push_back({{touch[k].p - gap * dirs[k], touch[k].q}, {touch[k + 1].p + press * dirs[k + 1], touch[k + 1].q}});
  return steps;
}

// Peg inside the hole, pressed sideways against the wall in a direction that
// turns 360 degrees over the script while it slides along Y (0.1 mm/step) and
// tilts by up to 0.05 degree: each step starts 2 delta off the wall and ends
// 0.01 mm into it, so every step has a real first contact.
std::vector<Step> peg_in_hole_pressing(CcdScene& s) {
  std::vector<Pose> poses;
  std::vector<Vec3> dirs;
  for (int k = 0; k <= 200; ++k) {
    const double a = 2 * kPi * k / 200;
    const Vec3 tilt = deg(0.05) * Vec3(std::sin(3 * a), 0, std::cos(3 * a));
    poses.push_back({Vec3(0, -0.01 + 1e-4 * (k < 100 ? k : 200 - k), 0), normalized(quat_exp(tilt))});
    dirs.push_back(Vec3(std::cos(a), 0, std::sin(a)));
  }
  return pressing(s, poses, dirs, 2 * s.delta, 1e-5, 1e-3);
}

// Held bunny's ears on the static bunny's back: each step starts 2 delta above
// the contact and ends 0.01 mm pressed into it, sliding 0.3 mm/step in a circle
// and turning 0.1 degree/step (the scripted bunny scene, in contact).
std::vector<Step> bunny_pressing(CcdScene& s) {
  Pose x = s.scene.god_object.pose;
  std::vector<Pose> poses;
  std::vector<Vec3> dirs;
  for (int k = 0; k <= 100; ++k) {
    const double a = 2 * kPi * k / 100;
    poses.push_back(x);
    dirs.push_back(Vec3(0, -1, 0));
    x = moved(x, 3e-4 * Vec3(std::cos(a), 0, std::sin(a)), deg(0.1) * Vec3(std::sin(a), 0.5, std::cos(a)));
  }
  return pressing(s, poses, dirs, 2 * s.delta, 1e-5, 0.03);
}

void BM_CcdStep(benchmark::State& state, const std::string& scene_name, const std::string& script) {
  CcdScene& s = scene(scene_name);
  std::vector<Step> steps;
  if (script == "sliding") steps = peg_sliding(s);
  if (script == "descending") steps = peg_descending(s);
  if (script == "in_hole") steps = peg_in_hole(s);
  if (script == "near_1mm") steps = bunny_sliding(s, 1e-3);
  if (script == "near_0.2mm") steps = bunny_sliding(s, 2e-4);
  if (script == "in_hole_pressing") steps = peg_in_hole_pressing(s);
  if (script == "ears_pressing") steps = bunny_pressing(s);
  if (steps.empty()) return state.SkipWithError("unknown script");
  CcdStepSettings settings;
  settings.narrow.min_separation = s.delta;
  // Refine feature boxes only to a tenth of delta (the default 1e-9 m is set for
  // unit-size queries): the stop lies delta before contact, so this moves it by
  // at most 0.1 delta while sparing the bisection most of its boxes.
  settings.narrow.distance_tolerance = 0.1 * s.delta;
  ContactSettings cset;
  cset.distance = 1.1 * s.delta;
  CcdStepWorkspace ws;
  ContactWorkspace cws(*s.god.mesh);
  ContactSet set(64);
  CcdStepResult r;
  LatencyRecorder rec;
  size_t i = 0;
  double hits = 0, pair_tests = 0, boxes = 0, calls = 0, tri_pairs = 0, culls = 0, contacts = 0;
  const int num_obstacles = static_cast<int>(s.obstacles.size());
  for (auto _ : state) {
    const Step& st = steps[i++ % steps.size()];
    rec.time(state, [&] {
      ccd_step(s.obstacles.data(), num_obstacles, s.god, st.x0, st.x1, settings, &ws, &r);
      const StopPose stop = make_stop_pose(r.motion, r.hit ? r.u_hit : 1.0, s.god_bvh.radius);
      generate_contacts(s.obstacles.data(), num_obstacles, s.god, stop.pose, cset, &cws, &set);
    });
    benchmark::DoNotOptimize(set.num_contacts);
    hits += r.hit;
    pair_tests += r.num_pair_tests;
    boxes += static_cast<double>(r.num_box_iterations);
    tri_pairs += r.num_triangle_pairs;
    culls += r.num_slab_culls;
    contacts += set.num_contacts;
    calls += 1;
  }
  rec.report(state);
  state.counters["hits_per_step"] = hits / calls;
  state.counters["pair_tests_per_step"] = pair_tests / calls;
  state.counters["boxes_per_step"] = boxes / calls;
  state.counters["triangle_pairs_per_step"] = tri_pairs / calls;
  state.counters["slab_culls_per_step"] = culls / calls;
  state.counters["contacts_per_step"] = contacts / calls;
}

void register_all() {
  struct Case { const char* scene; const char* script; int iterations; };
  for (Case c : {Case{"peg_in_hole", "sliding", 600}, Case{"peg_in_hole", "descending", 600},
                 Case{"peg_in_hole", "in_hole", 600}, Case{"peg_in_hole", "in_hole_pressing", 600},
                 Case{"bunnies", "near_1mm", 300}, Case{"bunnies", "near_0.2mm", 300},
                 Case{"bunnies", "ears_pressing", 300}}) {
    benchmark::RegisterBenchmark((std::string("CcdStep/") + c.scene + "/" + c.script).c_str(), BM_CcdStep,
                                 std::string(c.scene), std::string(c.script))
        ->UseManualTime()
        ->Iterations(c.iterations)
        ->Unit(benchmark::kMicrosecond);
  }
}

const int registered = (register_all(), 0);

}  // namespace
}  // namespace gauss6::bench
