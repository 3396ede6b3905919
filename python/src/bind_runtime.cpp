// Bindings of the scripted scenarios (gauss6._gauss6.runtime): run a scene with
// its hand script through the runtime and record the trace (device/scenario.h);
// the scene's geometry and mass for the analysis; and the exact
// non-interpenetration check of a list of god-object poses (the reference's
// count_intersecting_pairs, Gmpq arithmetic).
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "gauss6/reference/ccd.h"
#include "gauss6/scenario.h"
#include "gauss6/scene.h"
#include "module.h"

namespace py = pybind11;

namespace gauss6::python {

namespace {

using MatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using MatrixX3i = Eigen::Matrix<int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;

Scene load(const std::string& path) {
  try {
    return load_scene(path);
  } catch (const SceneError& e) {
    throw py::value_error(e.what());
  }
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
  py::dict events;
  for (int k = 0; k < kNumRuntimeEventKinds; ++k)
    if (s.event_counts[k]) events[to_string(static_cast<RuntimeEventKind>(k))] = s.event_counts[k];
  d["events"] = events;
  return d;
}

py::dict run(const std::string& scene_path, const std::string& trace_path, bool threaded, double duration,
             int lockstep_sim_period, const std::string& extra_json, const std::function<void(double)>& progress) {
  const Scene scene = load(scene_path);
  HandScript script;
  ScenarioOptions options;
  try {
    script = load_scene_script(scene);
  } catch (const ScenarioError& e) {
    throw py::value_error(e.what());
  }
  options.trace_path = trace_path;
  options.threaded = threaded;
  options.duration = duration;
  options.runtime.lockstep_sim_period = lockstep_sim_period;
  options.extra_json = extra_json;
  // Lockstep runs produce rows faster than real time: larger rings, frequent flushes.
  options.trace.flush_period = 0.1;
  options.trace.tick_capacity = 1u << 17;
  options.trace.step_capacity = 1u << 15;
  options.trace.contact_capacity = 1u << 19;
  if (progress) {
    options.progress = [&progress](double t) {
      py::gil_scoped_acquire gil;
      try {
        progress(t);
      } catch (const py::error_already_set&) {
        // A failing progress display must not abandon the run's threads.
      }
    };
  }
  ScenarioResult r;
  {
    py::gil_scoped_release release;
    try {
      r = run_scenario(scene, script, options);
    } catch (const std::exception& e) {
      py::gil_scoped_acquire gil;
      throw py::value_error(e.what());
    }
  }
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
  d["rows_written"] = std::vector<uint64_t>(r.trace.written.begin(), r.trace.written.end());
  d["rows_dropped"] = std::vector<uint64_t>(r.trace.dropped.begin(), r.trace.dropped.end());
  d["haptic"] = loop_dict(r.stats.haptic);
  d["coupling"] = loop_dict(r.stats.coupling);
  d["sim"] = loop_dict(r.stats.sim);
  d["phases"] = [&] {
    py::list l;
    for (const HandPhase& p : script.phases) l.append(py::make_tuple(p.name, p.start));
    return l;
  }();
  d["let_go_time"] = script.let_go_time;
  d["end_time"] = script.end_time;
  return d;
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

// ---------------------------------------------------------------------------
// Exact non-interpenetration of many poses, fast: a floating-point filter that
// proves a pose free, and the reference's exact count for the poses it cannot.
//
// Filter, per pose: the god-object's vertices are moved to the world frame in
// doubles (p + R(q) r, the pose's rational meaning rounded: error below
// 1e-15 m for scene sizes below 10 m); every triangle's box, grown by kMargin =
// 1e-9 m, is looked up in a uniform grid of the obstacle triangles' grown
// boxes. An exactly intersecting pair has overlapping exact boxes, so it is
// found. Each candidate pair must then be separated by one of the 11 axes of
// the separating-axis theorem (the two face normals, the nine edge cross
// products) with a gap above kMargin |axis|, far above the rounding of the
// projections (about 1e-15 |axis| for coordinates below 10 m). A pose whose
// every candidate pair is so separated has no intersecting pair; any other pose
// goes to reference::count_intersecting_pairs (Gmpq). The god-object keeps
// delta >= 1e-6 m from the obstacles, so the filter decides nearly every pose.
// ---------------------------------------------------------------------------

constexpr double kMargin = 1e-9;  // m

struct ObstacleGrid {
  TriangleMesh mesh;               // world frame
  Eigen::Vector3d lo, hi;          // grown bounding box
  double cell = 0;
  Eigen::Vector3i n;
  std::vector<int32_t> start;      // CSR: triangles of cell c are index[start[c] .. start[c + 1])
  std::vector<int32_t> index;
  std::unique_ptr<reference::ExactMeshPair> exact;  // built on first use

  int cell_of(double x, int axis) const {
    return std::clamp(static_cast<int>(std::floor((x - lo[axis]) / cell)), 0, n[axis] - 1);
  }
};

void triangle_box(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, Eigen::Vector3d* lo,
                  Eigen::Vector3d* hi) {
  *lo = a.cwiseMin(b).cwiseMin(c).array() - kMargin;
  *hi = a.cwiseMax(b).cwiseMax(c).array() + kMargin;
}

std::unique_ptr<ObstacleGrid> make_grid(TriangleMesh mesh) {
  auto g = std::make_unique<ObstacleGrid>();
  g->mesh = std::move(mesh);
  const TriangleMesh& m = g->mesh;
  const Eigen::Index nf = m.F.rows();
  g->lo = m.V.colwise().minCoeff().transpose().array() - kMargin;
  g->hi = m.V.colwise().maxCoeff().transpose().array() + kMargin;
  // Cells of about twice the mean triangle box size, at most 128 per axis.
  double mean_size = 0;
  for (Eigen::Index f = 0; f < nf; ++f) {
    Eigen::Vector3d lo, hi;
    triangle_box(m.V.row(m.F(f, 0)), m.V.row(m.F(f, 1)), m.V.row(m.F(f, 2)), &lo, &hi);
    mean_size += (hi - lo).maxCoeff() / static_cast<double>(nf);
  }
  const Eigen::Vector3d extent = g->hi - g->lo;
  g->cell = std::max(2 * mean_size, extent.maxCoeff() / 128);
  for (int k = 0; k < 3; ++k) g->n[k] = std::max(1, static_cast<int>(std::ceil(extent[k] / g->cell)));
  const size_t num_cells = static_cast<size_t>(g->n[0]) * g->n[1] * g->n[2];
  std::vector<std::vector<int32_t>> cells(num_cells);
  for (Eigen::Index f = 0; f < nf; ++f) {
    Eigen::Vector3d lo, hi;
    triangle_box(m.V.row(m.F(f, 0)), m.V.row(m.F(f, 1)), m.V.row(m.F(f, 2)), &lo, &hi);
    for (int i = g->cell_of(lo[0], 0); i <= g->cell_of(hi[0], 0); ++i)
      for (int j = g->cell_of(lo[1], 1); j <= g->cell_of(hi[1], 1); ++j)
        for (int k = g->cell_of(lo[2], 2); k <= g->cell_of(hi[2], 2); ++k)
          cells[(static_cast<size_t>(i) * g->n[1] + j) * g->n[2] + k].push_back(static_cast<int32_t>(f));
  }
  g->start.assign(num_cells + 1, 0);
  for (size_t c = 0; c < num_cells; ++c) g->start[c + 1] = g->start[c] + static_cast<int32_t>(cells[c].size());
  g->index.reserve(static_cast<size_t>(g->start.back()));
  for (const auto& c : cells) g->index.insert(g->index.end(), c.begin(), c.end());
  return g;
}

// True when one of the 11 separating axes separates triangles A and B with a
// gap above kMargin |axis| (a proof that they do not intersect).
bool certainly_separated(const Eigen::Vector3d A[3], const Eigen::Vector3d B[3]) {
  const Eigen::Vector3d eA[3] = {A[1] - A[0], A[2] - A[1], A[0] - A[2]};
  const Eigen::Vector3d eB[3] = {B[1] - B[0], B[2] - B[1], B[0] - B[2]};
  auto separates = [&](const Eigen::Vector3d& v) {
    const double len = v.norm();
    if (!(len > 1e-300)) return false;
    const double a0 = v.dot(A[0]), a1 = v.dot(A[1]), a2 = v.dot(A[2]);
    const double b0 = v.dot(B[0]), b1 = v.dot(B[1]), b2 = v.dot(B[2]);
    const double gap = std::max(std::min({b0, b1, b2}) - std::max({a0, a1, a2}),
                                std::min({a0, a1, a2}) - std::max({b0, b1, b2}));
    return gap > kMargin * len;
  };
  if (separates(eA[0].cross(eA[1])) || separates(eB[0].cross(eB[1]))) return true;
  for (const auto& a : eA)
    for (const auto& b : eB)
      if (separates(a.cross(b))) return true;
  return false;
}

// True when the filter proves the god-object (body-frame mesh, pose X) free of
// every obstacle; *num_pairs counts the candidate pairs it looked at.
bool pose_certainly_free(const TriangleMesh& god_B, const Pose& X, const std::vector<std::unique_ptr<ObstacleGrid>>& grids,
                         std::vector<Eigen::Vector3d>* V_W, long* num_pairs) {
  const Mat3 R = rotation_matrix(X.q);  // the rational form: R(q) for any |q|
  const Eigen::Index nv = god_B.V.rows();
  V_W->resize(static_cast<size_t>(nv));
  for (Eigen::Index v = 0; v < nv; ++v) (*V_W)[static_cast<size_t>(v)] = X.p + R * god_B.V.row(v).transpose();
  for (const auto& g : grids) {
    const TriangleMesh& m = g->mesh;
    for (Eigen::Index f = 0; f < god_B.F.rows(); ++f) {
      const Eigen::Vector3d A[3] = {(*V_W)[static_cast<size_t>(god_B.F(f, 0))], (*V_W)[static_cast<size_t>(god_B.F(f, 1))],
                                    (*V_W)[static_cast<size_t>(god_B.F(f, 2))]};
      Eigen::Vector3d lo, hi;
      triangle_box(A[0], A[1], A[2], &lo, &hi);
      if ((lo.array() > g->hi.array()).any() || (hi.array() < g->lo.array()).any()) continue;
      for (int i = g->cell_of(lo[0], 0); i <= g->cell_of(hi[0], 0); ++i)
        for (int j = g->cell_of(lo[1], 1); j <= g->cell_of(hi[1], 1); ++j)
          for (int k = g->cell_of(lo[2], 2); k <= g->cell_of(hi[2], 2); ++k) {
            const size_t c = (static_cast<size_t>(i) * g->n[1] + j) * g->n[2] + k;
            for (int32_t s = g->start[c]; s < g->start[c + 1]; ++s) {
              const int32_t of = g->index[static_cast<size_t>(s)];
              const Eigen::Vector3d B[3] = {m.V.row(m.F(of, 0)), m.V.row(m.F(of, 1)), m.V.row(m.F(of, 2))};
              Eigen::Vector3d blo, bhi;
              triangle_box(B[0], B[1], B[2], &blo, &bhi);
              if ((lo.array() > bhi.array()).any() || (hi.array() < blo.array()).any()) continue;
              ++*num_pairs;
              if (!certainly_separated(A, B)) return false;
            }
          }
    }
  }
  return true;
}

// Per pose (rows p (3), q (4)): the number of exactly intersecting triangle
// pairs (0 when the filter proves the pose free; else the reference's count).
py::dict count_intersecting(const std::string& scene_path, const Eigen::Ref<const Eigen::MatrixXd>& poses,
                            const std::function<void(long)>& progress, bool filter) {
  if (poses.cols() != 7) throw py::value_error("poses must be N x 7 (p, q)");
  const Scene scene = load(scene_path);
  std::vector<std::unique_ptr<ObstacleGrid>> grids;
  for (const Body& b : scene.obstacles) {
    TriangleMesh m = b.mesh;
    const Mat3 R = rotation_matrix(b.pose.q);
    for (Eigen::Index v = 0; v < m.V.rows(); ++v) m.V.row(v) = (b.pose.p + R * m.V.row(v).transpose()).transpose();
    grids.push_back(make_grid(std::move(m)));
  }
  Eigen::VectorXi out = Eigen::VectorXi::Zero(poses.rows());
  long num_exact = 0, num_pairs = 0;
  std::vector<Eigen::Vector3d> V_W;
  auto last = std::chrono::steady_clock::now();
  for (Eigen::Index i = 0; i < poses.rows(); ++i) {
    Pose X;
    X.p = Vec3(poses(i, 0), poses(i, 1), poses(i, 2));
    X.q = Quat{poses(i, 3), poses(i, 4), poses(i, 5), poses(i, 6)};
    {
      py::gil_scoped_release release;
      if (!filter || !pose_certainly_free(scene.god_object.mesh, X, grids, &V_W, &num_pairs)) {
        ++num_exact;
        int64_t n = 0;
        for (auto& g : grids) {
          if (!g->exact)
            g->exact = std::make_unique<reference::ExactMeshPair>(reference::make_exact_mesh_pair(scene.god_object.mesh, g->mesh));
          n += reference::count_intersecting_pairs(*g->exact, X);
        }
        out[i] = static_cast<int>(n);
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
  d["num_exact"] = num_exact;            // poses decided by the reference's exact count
  d["num_candidate_pairs"] = num_pairs;  // pairs the filter separated (or failed on)
  return d;
}

}  // namespace

void bind_runtime(py::module_& parent) {
  py::module_ m = parent.def_submodule("runtime", "Scripted scenarios: the runtime's loops, traces, exact checks");
  m.def("run_scenario", &run, py::arg("scene"), py::arg("trace"), py::arg("threaded") = false,
        py::arg("duration") = -1.0, py::arg("lockstep_sim_period") = 1, py::arg("extra_json") = "{}",
        py::arg("progress") = nullptr,
        "Runs the scene with its hand script (lockstep by default, or threaded) and writes the trace. Returns a dict "
        "of run statistics and property checks (orthogonality, constraint energy, passivity observer). "
        "progress(run_time_s) is called about every 0.2 s of wall time.");
  m.def("scene_geometry", &geometry, py::arg("scene"),
        "Obstacles (world frame: list of (name, V, F)), god_V/god_F (body frame, origin at G), p0, q0, mass, "
        "inertia_G_B, ks, kh, delta, rate_hz, max_force.");
  m.def("count_intersecting_pairs", &count_intersecting, py::arg("scene"), py::arg("poses"),
        py::arg("progress") = nullptr, py::arg("filter") = true,
        "Exact check of god-object poses (rows p, q: N x 7) against the obstacles: dict with counts (per pose, the "
        "number of intersecting triangle pairs: 0 when a floating-point separating-axis filter with a 1e-9 m margin "
        "proves the pose free, else reference::count_intersecting_pairs in Gmpq), num_exact (poses sent to the "
        "reference) and num_candidate_pairs. filter=False sends every pose to the reference. progress(num_done) is "
        "called about every 0.2 s.");
}

}  // namespace gauss6::python
