// Data the benchmark fixtures own, loaded once per process (load time: these
// functions allocate and throw):
//   - the rigid CCD step sets of datasets_generated/ccd/ (README.md there: one
//     obstacle in the world frame, a god-object mesh in its own frame with G at
//     `offset`, poses X0 -> X1 of G), with their meshes and BVHs built at a chosen
//     leaf size. The Python sweeps (python/gauss6/sweeps.py) read the same files,
//     so that speed measured here and error measured there are on the same data;
//   - the scenes of datasets_generated/scenes/ as the runtime builds them
//     (RuntimeModel: obstacles in the world frame, BVHs, the runtime's CCD and
//     contact settings), and the CCD inputs of every sim step of their scripted
//     scenarios (what `gauss6 reproduce` runs), recorded once in lockstep.
#pragma once

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <utility>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gauss6/geometry/bvh.h"
#include "gauss6/step/ccd_step.h"
#include "gauss6/io/mesh_io.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/io/qp_instances.h"
#include "gauss6/contact/quasistatics.h"
#include "gauss6/runtime/runtime.h"
#include "gauss6/scenario.h"
#include "gauss6/io/scene.h"
#include "gauss6/simulated_device.h"

namespace gauss6::bench {

// The repository whose data the fixtures read: GAUSS6_BENCH_DATA_ROOT when set
// (the gate points both revisions' builds at the same data), else the source tree.
inline std::string data_root() {
  const char* env = std::getenv("GAUSS6_BENCH_DATA_ROOT");
  return env && *env ? std::string(env) : std::string(GAUSS6_SOURCE_DIR);
}
inline std::string datasets_dir() { return data_root() + "/datasets_generated"; }
// The shared test data (../shared/data beside the repository).
inline std::string shared_data_dir() { return data_root() + "/../shared/data"; }

// The projection problem of a QP instance (datasets_generated/qp/), viewing its
// arrays (the instance must outlive it), with au as given.
inline ProjectionProblem problem_of(const QpInstance& q, const Vec6& au) {
  ProjectionProblem p;
  p.M = &q.M;
  p.au = au;
  p.J = q.J.rows() ? q.J.data() : nullptr;
  p.b = q.b.size() ? q.b.data() : nullptr;
  p.num_rows = static_cast<int>(q.J.rows());
  return p;
}

// One step of a set: X0 -> X1, poses of G (q as stored: not necessarily unit).
struct CcdSetStep {
  std::string id;
  int pair = 0;  // index into CcdSet::pairs
  Pose x0, x1;
};

// One obstacle (world frame) and one god-object (body frame, origin at G), with BVHs.
struct CcdMeshPair {
  TriangleMesh obstacle, god;
  Bvh obstacle_bvh, god_bvh;
  CcdBody obstacle_body() const { return {&obstacle, &obstacle_bvh}; }
  CcdBody god_body() const { return {&god, &god_bvh}; }
};

struct CcdSet {
  std::string name;
  double delta = 0;  // the set's separation delta (scene units)
  int leaf_size = 4;
  std::vector<std::unique_ptr<CcdMeshPair>> pairs;
  std::vector<CcdSetStep> steps;
};

inline Pose pose_of(const nlohmann::json& p, const nlohmann::json& q) {
  return {Vec3(p[0].get<double>(), p[1].get<double>(), p[2].get<double>()),
          Quat{q[0].get<double>(), q[1].get<double>(), q[2].get<double>(), q[3].get<double>()}};
}

// Reads datasets_generated/ccd/<name>.json; BVHs built with leaf_size.
inline std::unique_ptr<CcdSet> load_ccd_set(const std::string& name, int leaf_size) {
  const std::string path = datasets_dir() + "/ccd/" + name + ".json";
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  const nlohmann::json doc = nlohmann::json::parse(in);
  if (doc.at("format") != "gauss6-ccd-steps" || doc.at("version") != 1)
    throw std::runtime_error(path + ": not a gauss6-ccd-steps version 1 file");
  auto set = std::make_unique<CcdSet>();
  set->name = name;
  set->delta = doc.at("delta").get<double>();
  set->leaf_size = leaf_size;
  std::map<std::string, int> pair_index;  // key: obstacle|god|offset
  for (const auto& s : doc.at("steps")) {
    const std::string key = s.at("obstacle").get<std::string>() + "|" + s.at("god").get<std::string>() + "|" +
                            s.at("offset").dump();
    auto it = pair_index.find(key);
    if (it == pair_index.end()) {
      auto pair = std::make_unique<CcdMeshPair>();
      pair->obstacle = read_mesh(datasets_dir() + "/" + s.at("obstacle").get<std::string>());
      pair->god = read_mesh(datasets_dir() + "/" + s.at("god").get<std::string>());
      const auto& o = s.at("offset");
      const Vec3 offset(o[0].get<double>(), o[1].get<double>(), o[2].get<double>());
      for (Eigen::Index v = 0; v < pair->god.V.rows(); ++v) pair->god.V.row(v) -= offset.transpose();
      pair->obstacle_bvh = build_bvh(pair->obstacle, leaf_size);
      pair->god_bvh = build_bvh(pair->god, leaf_size);
      it = pair_index.emplace(key, static_cast<int>(set->pairs.size())).first;
      set->pairs.push_back(std::move(pair));
    }
    set->steps.push_back({s.at("id").get<std::string>(), it->second, pose_of(s.at("p0"), s.at("q0")),
                          pose_of(s.at("p1"), s.at("q1"))});
  }
  return set;
}

// Cached per (name, leaf size): fixtures share the loaded data within one process.
inline const CcdSet& ccd_set(const std::string& name, int leaf_size = 4) {
  static std::map<std::pair<std::string, int>, std::unique_ptr<CcdSet>> cache;
  auto& slot = cache[{name, leaf_size}];
  if (!slot) slot = load_ccd_set(name, leaf_size);
  return *slot;
}

// ccd_step of one step of a set (its one obstacle against its god-object).
inline void run_set_step(const CcdSet& set, const CcdSetStep& step, const CcdStepSettings& settings,
                         CcdStepWorkspace* ws, CcdStepResult* r) {
  const CcdMeshPair& p = *set.pairs[step.pair];
  const CcdBody obstacle = p.obstacle_body();
  ccd_step(&obstacle, 1, p.god_body(), {step.x0, step.x1}, settings, ws, r);
}

// Runs ccd_step at the set's delta over every step of the set, in order, and
// calls visit(step, result) after each.
template <class Visit>
void for_each_set_step(const CcdSet& set, Visit&& visit) {
  CcdStepSettings settings;
  settings.narrow.min_separation = set.delta;
  CcdStepWorkspace ws;
  CcdStepResult r;
  for (const CcdSetStep& st : set.steps) {
    run_set_step(set, st, settings, &ws, &r);
    visit(st, r);
  }
}

// datasets_generated/scenes/<name>.toml as the runtime builds it, default
// RuntimeSettings (delta from the scene; ccd.narrow.min_separation = delta,
// distance_tolerance = 0.1 delta; contacts within delta (1 + contact_factor)).
// Cached per name; never freed (fixtures hold references).
// The budgets of the budgeted replays (docs/benchmarks.md, "Budgeted updates"):
// none, the recommended CPU time per update, a count of work units, or a
// count that never runs out (the unbudgeted run, bit for bit, its work counted).
enum class Budget { kNone, kCpu, kUnits, kCounted };
inline constexpr long kBenchWorkUnits = 2000;  // about 1.5 M instructions (update_budget.h's ratio)
inline RuntimeSettings budget_settings(Budget b) {
  RuntimeSettings s;
  if (b == Budget::kCpu) s.budget.cpu_seconds = kRecommendedUpdateCpuSeconds;
  if (b == Budget::kUnits) s.budget.work_units = kBenchWorkUnits;
  if (b == Budget::kCounted) s.budget.work_units = std::numeric_limits<long>::max() / 4;
  return s;
}

inline const RuntimeModel& scene_model(const std::string& name, Budget budget = Budget::kNone) {
  static std::map<std::pair<std::string, Budget>, std::unique_ptr<RuntimeModel>> cache;
  auto& slot = cache[{name, budget}];
  if (!slot) slot = std::make_unique<RuntimeModel>(load_scene(datasets_dir() + "/scenes/" + name + ".toml"),
                                                   budget_settings(budget));
  return *slot;
}

// One sim step's collision work as the runtime did it (SimStepInfo): the first
// leg x_start -> x_target and the residual of a settling leg; replay it with
// advance_god_object(model, x_start, x_target, residual, ...).
struct ScenarioStep {
  Pose x_start, x_target;
  Vec6 residual = Vec6::Zero();
};

// Every sim step with a handle sample (kNoHandle steps do no collision work) of
// the scene's scripted scenario (scene.device.script), run to the script's end
// in lockstep (one sim step per haptic tick, as `gauss6 reproduce` runs it) on
// the simulated device with its default parameters, through the runtime API
// with an observer: the same run as run_scenario, without its trace; under
// `budget` (the steps a budgeted run takes: a cut-short update leaves the
// rest of its command to the next ones).
inline std::vector<ScenarioStep> record_scenario_steps(const std::string& scene_name, Budget budget) {
  const Scene scene = load_scene(datasets_dir() + "/scenes/" + scene_name + ".toml");
  const HandScript script = load_scene_script(scene);
  const RuntimeModel& model = scene_model(scene_name, budget);
  SimulatedHandleParams handle;
  handle.rate_hz = scene.device.rate_hz;
  handle.max_force = scene.device.max_force;
  handle.max_torque = scene.device.max_torque;
  SimulatedDevice device(script, handle, "simulated: " + scene.device.script);
  device.reset(0);
  auto data = std::make_unique<RuntimeData>(model);
  const double end = script.end_time >= 0 ? script.end_time : script.keys.back().t;
  const long num_ticks = static_cast<long>(std::floor(end * scene.device.rate_hz + 1e-9)) + 1;
  std::vector<ScenarioStep> steps;
  steps.reserve(static_cast<size_t>(num_ticks));  // at most one sim step per tick: the hook never reallocates
  RuntimeObserver observer;
  observer.user = &steps;
  observer.on_sim_step = [](void* user, const SimStepInfo& info) {
    auto* out = static_cast<std::vector<ScenarioStep>*>(user);
    if (info.status != SimStepStatus::kNoHandle && out->size() < out->capacity())
      out->push_back({info.x_start, info.x_target, info.residual});
  };
  run_lockstep(model, &device, num_ticks, observer, data.get());
  return steps;
}

// Cached per scene name and budget.
inline const std::vector<ScenarioStep>& scenario_steps(const std::string& scene_name,
                                                       Budget budget = Budget::kNone) {
  static std::map<std::pair<std::string, Budget>, std::unique_ptr<std::vector<ScenarioStep>>> cache;
  auto& slot = cache[{scene_name, budget}];
  if (!slot) slot = std::make_unique<std::vector<ScenarioStep>>(record_scenario_steps(scene_name, budget));
  return *slot;
}

}  // namespace gauss6::bench
