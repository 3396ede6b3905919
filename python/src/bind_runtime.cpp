// Bindings of the scripted scenarios (gauss6._gauss6.runtime): run a scene with
// its hand script through the runtime and record the trace (device/scenario.h);
// the scene's geometry and mass for the analysis; and the exact
// non-interpenetration check of a list of god-object poses (the reference's
// count_intersecting_pairs: exact, filtered predicates over Gmpq).
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "gauss6/reference/ccd.h"
#include "gauss6/scenario.h"
#include "gauss6/io/scene.h"
#include "module.h"

namespace py = pybind11;

namespace gauss6::python {

namespace {

using MatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using MatrixX3i = Eigen::Matrix<int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;

// A scene's errors reach Python as gauss6.LoadError (bind_core registers it).
Scene load(const std::string& path) { return load_scene_warning(path); }

// The settings a run of the scene uses (resolve_runtime_settings on the default
// RuntimeSettings): what `gauss6 scene info` prints.
py::dict effective_settings(const Scene& scene) {
  const EffectiveSettings e = resolve_runtime_settings(scene, RuntimeSettings{});
  const RuntimeSettings& r = e.runtime;
  const CcdStepSettings& c = r.ccd;
  py::dict d;
  d["delta"] = scene.contact.delta;
  d["ccd"] = py::dict(py::arg("min_separation") = c.narrow.min_separation,
                      py::arg("distance_tolerance") = c.narrow.distance_tolerance,
                      py::arg("time_tolerance") = c.narrow.time_tolerance,
                      py::arg("max_iterations") = c.narrow.max_iterations,
                      py::arg("cache_margin") = c.cache.margin, py::arg("cache_margin_max") = c.cache.margin_max,
                      py::arg("cache_fill_budget") = c.cache.fill_budget, py::arg("near_distance") = c.near_distance,
                      py::arg("max_sub_intervals") = c.max_sub_intervals,
                      py::arg("sub_interval_angle") = c.sub_interval_angle,
                      py::arg("sub_interval_travel") = c.sub_interval_travel);
  d["contacts"] = py::dict(py::arg("distance") = e.contact_generation.distance,
                           py::arg("contact_factor") = r.contact_factor, py::arg("gap_factor") = r.gap_factor);
  d["projection"] = py::dict(py::arg("feasibility_tol") = r.projection.feasibility_tol,
                             py::arg("dependence_tol") = r.projection.dependence_tol,
                             py::arg("max_iterations") = r.projection.max_iterations);
  d["offsets"] = py::dict(py::arg("eps") = scene.contact.offset_eps, py::arg("time") = scene.contact.offset_time);
  // A texture is felt only up to an exploration speed (METHOD.md 6.2): the bound
  // at the default constraint update rate (the model computes it: surface.h).
  if (scene.surface.kind == SurfaceKind::kTexture) {
    const RuntimeModel model(scene, RuntimeSettings{});
    d["texture"] = py::dict(py::arg("shortest_wavelength") = shortest_wavelength(model.surface.field),
                            py::arg("sim_rate_hz") = model.sim_rate_hz,
                            py::arg("max_exploration_speed") = model.texture_max_speed);
  }
  d["gains"] = py::dict(py::arg("ks") = scene.gains.ks, py::arg("kh") = scene.gains.kh);
  d["device"] = py::dict(py::arg("rate_hz") = scene.device.rate_hz, py::arg("max_force") = scene.device.max_force,
                         py::arg("max_torque") = scene.device.max_torque);
  return d;
}

py::dict loop_dict(const LoopStats& s) {
  py::dict d;
  d["nominal_period"] = s.nominal_period;
  d["count"] = s.work.count;
  d["work_mean"] = s.work.mean();
  d["work_max"] = s.work.max;
  d["period_min"] = s.period.min;
  d["period_max"] = s.period.max;
  d["period_mean"] = s.period.mean();
  d["max_jitter"] = s.max_jitter;
  d["overruns"] = s.overruns;
  d["realtime"] = s.realtime;
  d["realtime_priority"] = s.realtime_priority_applied;
  d["pinned_cpu"] = s.pinned_cpu;
  d["pin_error"] = s.pin_error;
  py::dict events;
  for (int k = 0; k < kNumRuntimeEventKinds; ++k)
    if (s.event_counts[k]) events[to_string(static_cast<RuntimeEventKind>(k))] = s.event_counts[k];
  d["events"] = events;
  const BudgetStats& b = s.budget;
  d["budget"] = py::dict(py::arg("updates") = b.updates, py::arg("exhausted") = b.exhausted,
                         py::arg("longest_run") = b.longest_run, py::arg("deferred_max") = b.deferred_max,
                         py::arg("deferred_sum") = b.deferred_sum, py::arg("max_work_units") = b.max_work_units,
                         py::arg("max_cpu") = b.max_cpu);
  return d;
}

// The options of a run from Python: lockstep runs produce rows faster than real
// time (larger rings, frequent flushes); progress(run_time_s) under the GIL.
ScenarioOptions run_options(const std::string& trace_path, bool threaded, double duration, int lockstep_sim_period,
                            const std::string& extra_json, const std::function<void(double)>& progress,
                            int max_contacts) {
  if (max_contacts < 1 || max_contacts > kMaxContactCapacity)
    throw py::value_error("max_contacts must be in [1, " + std::to_string(kMaxContactCapacity) + "]");
  ScenarioOptions options;
  options.runtime.max_contacts = max_contacts;
  options.trace_path = trace_path;
  options.threaded = threaded;
  options.duration = duration;
  options.runtime.lockstep_sim_period = lockstep_sim_period;
  options.extra_json = extra_json;
  options.trace.flush_period = 0.1;
  options.trace.tick_capacity = 1u << 17;
  options.trace.step_capacity = 1u << 15;
  options.trace.contact_capacity = 1u << 19;
  if (progress) {
    options.progress = [progress](double t) {
      py::gil_scoped_acquire gil;
      try {
        progress(t);
      } catch (const py::error_already_set&) {
        // A failing progress display must not abandon the run's threads.
      }
    };
  }
  return options;
}

// Runs `start` without the GIL; its errors reach Python as ValueError.
template <class Start>
ScenarioResult run_released(const Start& start) {
  py::gil_scoped_release release;
  try {
    return start();
  } catch (const std::exception& e) {
    py::gil_scoped_acquire gil;
    throw py::value_error(e.what());
  }
}

py::dict result_dict(const ScenarioResult& r, const std::vector<HandPhase>& phases) {
  py::dict d;
  d["trace"] = r.trace_path;
  d["num_ticks"] = r.num_ticks;
  d["num_sim_steps"] = r.num_sim_steps;
  d["run_time"] = r.run_time;
  d["wall_seconds"] = r.wall_seconds;
  d["max_rel_force_dot_ac"] = r.max_rel_force_dot_ac;
  d["num_orthogonality_checks"] = r.num_orthogonality_checks;
  d["num_offset_steps"] = r.num_offset_steps;
  d["constraint_energy_injected"] = r.constraint_energy_injected;
  d["constraint_energy_removed"] = r.constraint_energy_removed;
  d["port_energy_max"] = r.port_energy_max;
  d["port_energy_final"] = r.port_energy_final;
  d["num_shaded_steps"] = r.num_shaded_steps;
  d["max_rel_constraint_violation"] = r.max_rel_constraint_violation;
  d["num_constraint_checks"] = r.num_constraint_checks;
  d["shading_work_injected"] = r.shading_work_injected;
  d["shading_work_removed"] = r.shading_work_removed;
  d["max_texture_step"] = r.max_texture_step;
  d["rows_written"] = std::vector<uint64_t>(r.trace.written.begin(), r.trace.written.end());
  d["rows_dropped"] = std::vector<uint64_t>(r.trace.dropped.begin(), r.trace.dropped.end());
  d["haptic"] = loop_dict(r.stats.haptic);
  d["coupling"] = loop_dict(r.stats.coupling);
  d["sim"] = loop_dict(r.stats.sim);
  d["watchdog"] = loop_dict(r.stats.watchdog);
  py::list l;
  for (const HandPhase& p : phases) l.append(py::make_tuple(p.name, p.start));
  d["phases"] = l;
  return d;
}

// The scene's hand script, or the file `script` (a .json path; empty: the scene's) in its place,
// which makes the device a simulated one. gauss6.LoadError naming the file and the key.
HandScript scene_script(Scene& scene, const std::string& script) {
  if (!script.empty()) {
    if (script.size() <= 5 || script.compare(script.size() - 5, 5, ".json") != 0)
      throw py::value_error(script + ": a hand script file's name ends in .json");
    scene.device.kind = DeviceKind::kSimulated;
    scene.device.script = std::filesystem::absolute(script).lexically_normal().string();
    scene.device.script_json.clear();
  }
  try {
    return load_scene_script(scene);
  } catch (const ScenarioError& e) {
    throw LoadError(scene.path, e.what());  // a file the scene names: gauss6.LoadError
  }
}

py::dict hand_script(const std::string& scene_path, const std::string& script_path) {
  Scene scene = load(scene_path);
  const HandScript s = scene_script(scene, script_path);
  py::dict d;
  d["origin"] = scene.device.script.empty() ? scene.path + ": device.script" : scene.device.script;
  d["num_keys"] = s.keys.size();
  d["start_time"] = s.keys.front().t;
  d["end_time"] = s.end_time >= 0 ? s.end_time : s.keys.back().t;
  d["let_go_time"] = s.let_go_time;
  py::list l;
  for (const HandPhase& p : s.phases) l.append(py::make_tuple(p.name, p.start));
  d["phases"] = l;
  return d;
}

py::dict run(const std::string& scene_path, const std::string& trace_path, bool threaded, double duration,
             int lockstep_sim_period, const std::string& extra_json, const std::function<void(double)>& progress,
             double rate_hz, int realtime_priority, bool pin_threads, double hold_until, int max_contacts,
             double spin_wait, const std::string& script_path, double budget_seconds, long budget_units) {
  Scene scene = load(scene_path);
  if (rate_hz != 0) {
    if (!(rate_hz >= 1 && rate_hz <= 1e5)) throw py::value_error("rate_hz must be in [1, 1e5] (0: the scene's)");
    scene.device.rate_hz = rate_hz;
  }
  if (realtime_priority < 0 || realtime_priority > 99) throw py::value_error("realtime_priority must be in [0, 99]");
  HandScript script = scene_script(scene, script_path);
  // The hand holds still after its last key until hold_until (s), when later than the script's end.
  if (hold_until > script.end_time) script.end_time = hold_until;
  ScenarioOptions options =
      run_options(trace_path, threaded, duration, lockstep_sim_period, extra_json, progress, max_contacts);
  options.runtime.realtime_priority = realtime_priority;
  options.runtime.pin_threads = pin_threads;
  options.runtime.spin_wait = spin_wait;  // checked by the RuntimeModel ([0, 1] s): a ValueError naming it
  options.runtime.budget.cpu_seconds = budget_seconds;  // (checked likewise: update_budget_settings_problem)
  options.runtime.budget.work_units = budget_units;
  const ScenarioResult r = run_released([&] { return run_scenario(scene, script, options); });
  py::dict d = result_dict(r, script.phases);
  d["let_go_time"] = script.let_go_time;
  d["end_time"] = script.end_time;
  return d;
}

py::dict replay(const std::string& scene_path, const std::string& recording_path, const std::string& trace_path,
                const std::vector<std::pair<std::string, double>>& phase_list, bool threaded, double duration,
                int lockstep_sim_period, const std::string& extra_json, const std::function<void(double)>& progress,
                int max_contacts) {
  const Scene scene = load(scene_path);
  const Trace recording = read_trace(recording_path);  // TraceError: a gauss6.LoadError
  std::vector<HandPhase> phases;
  for (const auto& [name, start] : phase_list) phases.push_back({name, start});
  const ScenarioOptions options =
      run_options(trace_path, threaded, duration, lockstep_sim_period, extra_json, progress, max_contacts);
  return result_dict(run_released([&] { return run_replay(scene, recording, phases, options); }), phases);
}

// The scene's bodies as the runtime sees them: obstacles in the world frame, the
// god-object in its body frame (origin at G), its initial pose, mass and inertia.
py::dict geometry(const std::string& scene_path) {
  const Scene scene = load(scene_path);
  py::list obstacles;
  for (const Body& b : scene.obstacles) {
    TriangleMesh m = b.mesh;
    const Mat3 R = rotation_matrix(b.pose.q);
    for (Eigen::Index v = 0; v < m.V.rows(); ++v) m.V.row(v) = (b.pose.p + R * m.V.row(v).transpose()).transpose();
    obstacles.append(py::make_tuple(b.name, MatrixX3d(m.V), MatrixX3i(m.F)));
  }
  const MassProperties& mp = scene.god_mass.mass;
  const Vec3 c = mp.center_of_mass;
  const Mat3 I_G = mp.inertia + mp.mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
  py::dict d;
  d["name"] = scene.name;
  d["obstacles"] = obstacles;
  d["god_V"] = MatrixX3d(scene.god_object.mesh.V);
  d["god_F"] = MatrixX3i(scene.god_object.mesh.F);
  d["p0"] = Eigen::Vector3d(scene.god_object.pose.p);
  d["q0"] = Eigen::Vector4d(scene.god_object.pose.q.w, scene.god_object.pose.q.x, scene.god_object.pose.q.y,
                            scene.god_object.pose.q.z);
  d["mass"] = mp.mass;
  d["inertia_G_B"] = Eigen::Matrix3d(I_G);
  d["ks"] = scene.gains.ks;
  d["kh"] = scene.gains.kh;
  d["delta"] = scene.contact.delta;
  d["rate_hz"] = scene.device.rate_hz;
  d["max_force"] = scene.device.max_force;
  return d;
}

// Per pose (rows p (3), q (4)): the number of exactly intersecting triangle
// pairs between the god-object and all obstacles (the reference's
// count_intersecting_pairs, summed over the obstacles).
py::dict count_intersecting(const std::string& scene_path, const Eigen::Ref<const Eigen::MatrixXd>& poses,
                            const std::function<void(long)>& progress) {
  if (poses.cols() != 7) throw py::value_error("poses must be N x 7 (p, q)");
  const Scene scene = load(scene_path);
  std::vector<reference::ExactMeshPair> pairs;
  for (const Body& b : scene.obstacles) {
    TriangleMesh m = b.mesh;  // to the world frame, as the runtime places it
    const Mat3 R = rotation_matrix(b.pose.q);
    for (Eigen::Index v = 0; v < m.V.rows(); ++v) m.V.row(v) = (b.pose.p + R * m.V.row(v).transpose()).transpose();
    pairs.push_back(reference::make_exact_mesh_pair(scene.god_object.mesh, m));
  }
  Eigen::VectorXi out = Eigen::VectorXi::Zero(poses.rows());
  const auto start = std::chrono::steady_clock::now();
  auto last = start;
  for (Eigen::Index i = 0; i < poses.rows(); ++i) {
    Pose X;
    X.p = Vec3(poses(i, 0), poses(i, 1), poses(i, 2));
    X.q = Quat{poses(i, 3), poses(i, 4), poses(i, 5), poses(i, 6)};
    {
      py::gil_scoped_release release;
      try {
        int64_t n = 0;
        for (const reference::ExactMeshPair& pair : pairs) n += reference::count_intersecting_pairs(pair, X);
        out[i] = static_cast<int>(n);
      } catch (const std::exception& e) {
        py::gil_scoped_acquire gil;
        throw py::value_error("pose " + std::to_string(i) + ": " + e.what());
      }
    }
    if (progress && std::chrono::steady_clock::now() - last > std::chrono::milliseconds(200)) {
      last = std::chrono::steady_clock::now();
      progress(static_cast<long>(i + 1));
    }
  }
  if (progress) progress(static_cast<long>(poses.rows()));
  py::dict d;
  d["counts"] = out;
  d["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return d;
}

}  // namespace

void bind_runtime(py::module_& parent) {
  py::module_ m = parent.def_submodule("runtime", "Scripted scenarios: the runtime's loops, traces, exact checks");
  m.def("run_scenario", &run, py::arg("scene"), py::arg("trace"), py::arg("threaded") = false,
        py::arg("duration") = -1.0, py::arg("lockstep_sim_period") = 1, py::arg("extra_json") = "{}",
        py::arg("progress") = nullptr, py::arg("rate_hz") = 0.0, py::arg("realtime_priority") = 0,
        py::arg("pin_threads") = false, py::arg("hold_until") = -1.0,
        py::arg("max_contacts") = kDefaultMaxContacts, py::arg("spin_wait") = 0.0, py::arg("script") = "",
        py::arg("budget_seconds") = 0.0, py::arg("budget_units") = 0L,
        "Runs the scene with its hand script (or the JSON file `script` in its place) (lockstep by default, or threaded) and writes the trace. Returns a dict "
        "of run statistics and property checks (orthogonality, constraint energy, passivity observer). "
        "progress(run_time_s) is called about every 0.2 s of wall time. rate_hz overrides the scene's haptic rate "
        "(0: the scene's); realtime_priority and pin_threads are RuntimeSettings' (threaded runs; each loop's "
        "outcome in its dict: realtime 1 applied / 0 not asked / -errno, pinned_cpu, pin_error); hold_until (s): "
        "the hand holds still after the script until then. max_contacts: RuntimeSettings::max_contacts, the "
        "contact capacity of the loops (a larger set is truncated and reported as contact_overflow). spin_wait (s, "
        "in [0, 1]): RuntimeSettings::spin_wait, the haptic loop's busy wait before each tick (threaded runs). budget_seconds, "
        "budget_units: RuntimeSettings::budget, each god-object update's CPU time and work units (0: none; "
        "update_budget.h); its statistics in the sim loop's dict (budget).");
  m.def("hand_script", &hand_script, py::arg("scene"), py::arg("script") = "",
        "The hand script a run of the scene follows (the scene's, or the JSON file `script`): a dict of origin (the "
        "file, or the scene's [device.script] table), num_keys, start_time, end_time, let_go_time (< 0: none) and "
        "phases [(name, start)]. Raises LoadError naming the file and the key.");
  m.def("replay", &replay, py::arg("scene"), py::arg("recording"), py::arg("trace"),
        py::arg("phases") = std::vector<std::pair<std::string, double>>{}, py::arg("threaded") = false,
        py::arg("duration") = -1.0, py::arg("lockstep_sim_period") = 1, py::arg("extra_json") = "{}",
        py::arg("progress") = nullptr, py::arg("max_contacts") = kDefaultMaxContacts,
        "Replays a recorded session: the handle poses of the trace `recording` drive the scene's runtime through "
        "the replay device, and the run is written to `trace`. phases: (name, start) pairs to mark. Returns the "
        "dict of run_scenario.");
  m.def("effective_settings", &effective_settings, py::arg("scene"),
        "The settings a run of the scene uses: the scene's values and the defaults, with the CCD and contact "
        "distances derived from delta (resolve_runtime_settings, runtime_model.h). Raises LoadError.");
  m.def("scene_geometry", &geometry, py::arg("scene"),
        "Obstacles (world frame: list of (name, V, F)), god_V/god_F (body frame, origin at G), p0, q0, mass, "
        "inertia_G_B, ks, kh, delta, rate_hz, max_force.");
  m.def("count_intersecting_pairs", &count_intersecting, py::arg("scene"), py::arg("poses"),
        py::arg("progress") = nullptr,
        "Exact check of god-object poses (rows p, q: N x 7) against the scene's obstacles "
        "(reference::count_intersecting_pairs: box culling, interval filter, Gmpq when the filter cannot decide): "
        "dict with counts (per pose, the number of intersecting triangle pairs, touching included) and seconds "
        "(wall time of the check). progress(num_done) is called about every 0.2 s.");
}

}  // namespace gauss6::python
