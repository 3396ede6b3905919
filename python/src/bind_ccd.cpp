// Bindings of continuous collision detection (gauss6._gauss6.ccd): the optimized
// CCD (ccd.h, bvh.h) and the exact reference (reference/ccd.h) side by side, for
// the `gauss6 ccd` and `gauss6 crosscheck ccd` commands. Both sides are timed in
// C++ (std::chrono::steady_clock) around the calls alone, so the timings exclude
// Python and file parsing.
//
// Poses: p (3,) in scene units (metres), q (4,) as (w, x, y, z), not necessarily
// unit (METHOD.md section 1: R(q) is the rational rotation over |q|^2). The
// god-object mesh is given in its body frame B (origin at G), the obstacle in the
// world frame W.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "gauss6/geometry/bvh.h"
#include "gauss6/step/ccd_step.h"
#include "gauss6/ccd/ccd.h"
#include "gauss6/io/ccd_queries.h"
#include "gauss6/geometry/feature_ids.h"
#include "gauss6/reference/ccd.h"
#include "module.h"

namespace py = pybind11;

namespace gauss6::python {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

CcdQuery::Kind kind_from(const std::string& kind) {
  if (kind == "vf") return CcdQuery::kVertexFace;
  if (kind == "ee") return CcdQuery::kEdgeEdge;
  throw py::value_error("kind must be 'vf' or 'ee', not '" + kind + "'");
}

// Runs every query of one file through one implementation's linear-motion
// primitive. Returns per-query arrays (hit, expected, line) and the seconds spent
// in the primitive calls only. The optimized CCD takes doubles: `inexact` counts
// the queries whose rationals are not all doubles (none in the shared data).
py::dict run_query_file(const std::string& path, const std::string& kind, const std::string& impl,
                        double time_tolerance) {
  // The optimized CCD refuses a query under a tolerance that is not > 0 (an
  // invalid-input status, no hit): refused here first, by name, so that no
  // refusal is counted as a miss.
  if (!(std::isfinite(time_tolerance) && time_tolerance > 0))
    throw py::value_error("time_tolerance must be finite and > 0 (the u-width of an accepted interval), not " +
                          py::repr(py::float_(time_tolerance)).cast<std::string>());
  const std::vector<CcdQuery> queries = read_ccd_queries(path, kind_from(kind));
  const size_t n = queries.size();
  std::vector<bool> hit(n), expected(n);
  std::vector<int> line(n);
  for (size_t i = 0; i < n; ++i) {
    expected[i] = queries[i].expected;
    line[i] = queries[i].line;
  }
  double seconds = 0;
  int inexact = 0;
  if (impl == "reference") {
    const auto t0 = Clock::now();
    for (size_t i = 0; i < n; ++i) hit[i] = reference::query_toi(queries[i]).hit;
    seconds = seconds_since(t0);
  } else if (impl == "optimized") {
    // Convert first (outside the timing), then run.
    std::vector<std::array<Vec3, 8>> pts(n);
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < 8; ++k) {
        bool exact = true;
        const auto x = to_double(queries[i].points[k], &exact);
        if (!exact) ++inexact;
        pts[i][k] = Vec3(x[0], x[1], x[2]);
      }
    CcdSettings settings;
    settings.time_tolerance = time_tolerance;
    CcdWorkspace ws;
    CcdResult r;
    const auto t0 = Clock::now();
    for (size_t i = 0; i < n; ++i) {
      const auto& x = pts[i];
      if (queries[i].kind == CcdQuery::kVertexFace) {
        LinearVertexFaceQuery q;
        q.vertex = {x[0], x[4]};
        q.face = {{{x[1], x[2], x[3]}, {x[5], x[6], x[7]}}};
        ccd_linear_vertex_face(q, settings, &ws, &r);
      } else {
        LinearEdgeEdgeQuery q;
        q.edge_a = {{{x[0], x[1]}, {x[4], x[5]}}};
        q.edge_b = {{{x[2], x[3]}, {x[6], x[7]}}};
        ccd_linear_edge_edge(q, settings, &ws, &r);
      }
      if (r.status == CcdStatus::kInvalidInput)
        throw py::value_error(path + ":" + std::to_string(line[i]) + ": the optimized CCD refused the query (" +
                              to_string(r.status) + ")");
      hit[i] = r.hit;
    }
    seconds = seconds_since(t0);
  } else {
    throw py::value_error("impl must be 'optimized' or 'reference', not '" + impl + "'");
  }
  py::dict d;
  d["hit"] = hit;
  d["expected"] = expected;
  d["line"] = line;
  d["inexact"] = inexact;
  d["seconds"] = seconds;
  return d;
}

// ---------------------------------------------------------------------------
// Per-query CCD for users (gauss6.ccd.vertex_face and the others): one query per
// call, the optimized narrow phase (ccd.h) and its exact twin (reference/ccd.h).

// CcdResult with its status as a Python identifier ("ok", "max_iterations",
// "workspace_full", "invalid_input", "half_turn").
struct QueryResult {
  CcdResult r;
  std::string status;
};
std::string status_name(CcdStatus s) {
  const std::string full = to_string(s);
  return full.substr(0, full.find(':'));
}
QueryResult make_result(const CcdResult& r) { return {r, status_name(r.status)}; }

// The settings of one call: CcdSettings' defaults unless given (keyword arguments).
CcdSettings query_settings(double min_separation, std::optional<double> time_tolerance,
                           std::optional<double> distance_tolerance, std::optional<int> max_iterations,
                           std::optional<bool> use_u_filter, std::optional<bool> early_hit) {
  CcdSettings s;
  s.min_separation = min_separation;
  if (time_tolerance) s.time_tolerance = *time_tolerance;
  if (distance_tolerance) s.distance_tolerance = *distance_tolerance;
  if (max_iterations) s.max_iterations = *max_iterations;
  if (use_u_filter) s.use_u_filter = *use_u_filter;
  if (early_hit) s.early_hit = *early_hit;
  return s;
}

// One workspace per Python thread, sized once (the queries never allocate; a
// workspace per call would cost more than most queries).
CcdWorkspace& query_workspace() {
  thread_local CcdWorkspace ws;
  return ws;
}

using Face = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;  // one vertex a row
using Edge = Eigen::Matrix<double, 2, 3, Eigen::RowMajor>;  // one endpoint a row
std::array<Vec3, 3> rows3(const Face& f) { return {Vec3(f.row(0)), Vec3(f.row(1)), Vec3(f.row(2))}; }
std::array<Vec3, 2> rows2(const Edge& e) { return {Vec3(e.row(0)), Vec3(e.row(1))}; }

QueryResult linear_vertex_face(const Eigen::Vector3d& v0, const Face& f0, const Eigen::Vector3d& v1, const Face& f1,
                               double u_end, const CcdSettings& s) {
  LinearVertexFaceQuery q;
  q.vertex = {v0, v1};
  q.face = {rows3(f0), rows3(f1)};
  q.u_end = u_end;
  CcdResult r;
  ccd_linear_vertex_face(q, s, &query_workspace(), &r);
  return make_result(r);
}
QueryResult linear_edge_edge(const Edge& a0, const Edge& b0, const Edge& a1, const Edge& b1, double u_end,
                             const CcdSettings& s) {
  LinearEdgeEdgeQuery q;
  q.edge_a = {rows2(a0), rows2(a1)};
  q.edge_b = {rows2(b0), rows2(b1)};
  q.u_end = u_end;
  CcdResult r;
  ccd_linear_edge_edge(q, s, &query_workspace(), &r);
  return make_result(r);
}

// Rigid queries: the Cayley motion of the two poses; a pose the motion refuses
// (zero or non-finite quaternion, a half turn) is a status, as in the runtime.
template <class Query, class Fn>
QueryResult rigid(const Eigen::Vector3d& p0, const Eigen::Vector4d& q0, const Eigen::Vector3d& p1,
                  const Eigen::Vector4d& q1, Query q, double u_end, const CcdSettings& s, Fn fn) {
  CcdMotion motion;
  CcdResult r;
  const MotionStatus ms = make_ccd_motion(pose_from(p0, q0), pose_from(p1, q1), &motion);
  if (ms != MotionStatus::kOk) {
    r.status = ms == MotionStatus::kHalfTurn ? CcdStatus::kHalfTurn : CcdStatus::kInvalidInput;
    r.hit = true;  // conservative, as ccd_step
    r.u_hit = 0;
    return make_result(r);
  }
  q.motion = &motion;
  q.u_end = u_end;
  fn(q, s, &query_workspace(), &r);
  return make_result(r);
}

// The exact answer (reference/ccd.h) of the same queries, inputs taken as the
// rationals their doubles denote.
reference::ExactPoint exact_point(const Vec3& v) { return {mpq_class(v.x()), mpq_class(v.y()), mpq_class(v.z())}; }
template <size_t N>
std::array<reference::ExactPoint, N> exact_points(const std::array<Vec3, N>& v) {
  std::array<reference::ExactPoint, N> out;
  for (size_t i = 0; i < N; ++i) out[i] = exact_point(v[i]);
  return out;
}
void check_finite(const Eigen::Ref<const Eigen::MatrixXd>& x, const char* name) {
  if (!x.allFinite()) throw py::value_error(std::string(name) + ": coordinates must be finite");
}
reference::ExactCayleyMotion exact_motion(const Eigen::Vector3d& p0, const Eigen::Vector4d& q0,
                                          const Eigen::Vector3d& p1, const Eigen::Vector4d& q1) {
  try {
    return reference::make_exact_cayley_motion(pose_from(p0, q0), pose_from(p1, q1));
  } catch (const std::domain_error& e) {
    throw py::value_error(e.what());
  }
}
template <class Fn>
reference::ExactToi exact_call(Fn fn) {
  try {
    return fn();
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

// A query file (ccd_queries.h) as arrays: points (n, 8, 3) as doubles in file
// order (rows 0-3 at t = 0, 4-7 at t = 1), expected, line, and exact (every
// coordinate of the query is the double given).
py::dict read_query_arrays(const std::string& path, const std::string& kind_name) {
  const std::vector<CcdQuery> queries = read_ccd_queries(path, kind_from(kind_name));
  const auto n = static_cast<py::ssize_t>(queries.size());
  py::array_t<double> points({n, py::ssize_t(8), py::ssize_t(3)});
  py::array_t<bool> expected(n), exact(n);
  py::array_t<int> line(n);
  auto P = points.mutable_unchecked<3>();
  auto E = expected.mutable_unchecked<1>(), X = exact.mutable_unchecked<1>();
  auto L = line.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    bool all_exact = true;
    for (int k = 0; k < 8; ++k) {
      bool ok = true;
      const auto x = to_double(queries[i].points[k], &ok);
      all_exact = all_exact && ok;
      for (int j = 0; j < 3; ++j) P(i, k, j) = x[j];
    }
    E(i) = queries[i].expected;
    X(i) = all_exact;
    L(i) = queries[i].line;
  }
  py::dict d;
  d["points"] = points;
  d["expected"] = expected;
  d["line"] = line;
  d["exact"] = exact;
  return d;
}

// Canonical feature ids (feature_ids.h) to and from Python: a pair is the tuple
// (kind, (feature, a, b) of the god-object, (feature, a, b) of the obstacle), kind
// as to_string(PairKind), feature "vertex", "edge" or "face"; the same tuple for
// the optimized step's pair and the reference's, so Python compares them with ==.
const char* to_string(Feature f) {
  switch (f) {
    case Feature::kVertex: return "vertex";
    case Feature::kEdge: return "edge";
    case Feature::kFace: return "face";
  }
  return "unknown";
}
py::tuple to_python(const FeaturePairIds& p) {
  auto id = [](const FeatureId& f) { return py::make_tuple(to_string(f.feature), f.a, f.b); };
  return py::make_tuple(to_string(p.kind), id(p.god), id(p.obstacle));
}
FeaturePairIds from_python(const py::tuple& t) {
  auto kind = [](const std::string& s) {
    for (const PairKindInfo& k : kPairKinds)
      if (s == to_string(k.kind)) return k.kind;
    throw py::value_error("unknown pair kind '" + s + "'");
  };
  auto id = [](const py::tuple& f) {
    const std::string name = f[0].cast<std::string>();
    for (const Feature x : {Feature::kVertex, Feature::kEdge, Feature::kFace})
      if (name == to_string(x)) return FeatureId{x, f[1].cast<int32_t>(), f[2].cast<int32_t>()};
    throw py::value_error("unknown feature '" + name + "'");
  };
  if (t.size() != 3) throw py::value_error("a feature pair is (kind, god feature, obstacle feature)");
  return {kind(t[0].cast<std::string>()), id(t[1].cast<py::tuple>()), id(t[2].cast<py::tuple>())};
}

// The exact first contact of a mesh step, kept whole so that the optimized u_hit
// can be compared with u* exactly (compare_toi), never through a rounded double.
struct ExactContact {
  reference::MeshContact contact;
  double seconds = 0;
};

// One obstacle (world frame) and one god-object (body frame): the optimized
// structures (BVHs, workspace) and, built on first use, the exact ones.
class CcdMeshPair {
 public:
  CcdMeshPair(const MatrixX3d& obstacle_V, const py::array& obstacle_F_in, const MatrixX3d& god_V,
              const py::array& god_F_in) {
    const MatrixX3i obstacle_F = faces_from(obstacle_F_in, "obstacle_F"), god_F = faces_from(god_F_in, "god_F");
    obstacle_.V = obstacle_V;
    obstacle_.F = obstacle_F;
    god_.V = god_V;
    god_.F = god_F;
    const MeshReport ro = validate_mesh(obstacle_), rg = validate_mesh(god_);
    if (ro.num_bad_indices || ro.num_nonfinite_vertices || rg.num_bad_indices || rg.num_nonfinite_vertices)
      throw py::value_error("mesh with a bad index or a non-finite vertex");
    obstacle_bvh_ = build_bvh(obstacle_);
    god_bvh_ = build_bvh(god_);
  }

  double god_radius() const { return god_bvh_.radius; }

  // Optimized ccd_step from X0 to X1 with min_separation (scene units). The stop
  // pose is make_stop_pose(motion, u_hit, radius) on a hit, X1 otherwise.
  // `repeats` runs of the same step; seconds is the fastest (least disturbed).
  py::dict step(const Eigen::Vector3d& p0, const Eigen::Vector4d& q0, const Eigen::Vector3d& p1,
                const Eigen::Vector4d& q1, double min_separation, double time_tolerance, int repeats) {
    const Pose X0 = pose_from(p0, q0), X1 = pose_from(p1, q1);
    CcdStepSettings settings;
    settings.narrow.min_separation = min_separation;
    settings.narrow.time_tolerance = time_tolerance;
    const CcdBody obstacle{&obstacle_, &obstacle_bvh_}, god{&god_, &god_bvh_};
    CcdStepResult r;
    double best = 0;
    for (int i = 0; i < std::max(repeats, 1); ++i) {
      const auto t0 = Clock::now();
      ccd_step(&obstacle, 1, god, {X0, X1}, settings, &ws_, &r);
      const double s = seconds_since(t0);
      if (i == 0 || s < best) best = s;
    }
    Pose stop = X1;
    double deviation = 0;
    if (r.hit && r.status != CcdStatus::kHalfTurn && r.status != CcdStatus::kInvalidInput) {
      const StopPose sp = make_stop_pose(r.motion, r.u_hit, god_bvh_.radius);
      stop = sp.pose;
      deviation = sp.deviation;
    }
    py::dict d;
    d["status"] = to_string(r.status);
    d["hit"] = r.hit;
    d["u_hit"] = r.u_hit;
    d["pair"] = to_string(r.pair.kind);
    // The pair that stopped the step, in canonical ids (None without a hit on a pair).
    const bool on_pair = r.hit && r.pair.god_face >= 0 && r.pair.obstacle_face >= 0;
    d["pair_ids"] = on_pair ? py::object(to_python(feature_ids(r.pair, god_.F, obstacle_.F))) : py::none();
    d["stop_p"] = Eigen::Vector3d(stop.p);
    d["stop_q"] = quat_to(stop.q);
    d["deviation"] = deviation;
    d["time_tolerance_reached"] = r.time_tolerance_reached;
    d["num_pair_tests"] = r.num_pair_tests;
    d["seconds"] = best;
    return d;
  }

  // Exact first contact u* of the Cayley motion X0 -> X1 (mesh_first_contact).
  ExactContact exact_first_contact(const Eigen::Vector3d& p0, const Eigen::Vector4d& q0, const Eigen::Vector3d& p1,
                                   const Eigen::Vector4d& q1, bool filtered) {
    const reference::ExactMeshPair& m = exact();
    const auto t0 = Clock::now();
    ExactContact c{reference::mesh_first_contact(m, pose_from(p0, q0), pose_from(p1, q1), filtered), 0};
    c.seconds = seconds_since(t0);
    return c;
  }

  // Exact first contact over [0, 1] of one feature pair (canonical ids) alone.
  ExactContact pair_first_contact(const py::tuple& pair, const Eigen::Vector3d& p0, const Eigen::Vector4d& q0,
                                  const Eigen::Vector3d& p1, const Eigen::Vector4d& q1) {
    const FeaturePairIds ids = from_python(pair);
    const reference::ExactMeshPair& m = exact();
    const auto t0 = Clock::now();
    ExactContact c;
    try {
      c.contact.toi = reference::feature_pair_first_contact(
          m, reference::make_exact_cayley_motion(pose_from(p0, q0), pose_from(p1, q1)), ids);
    } catch (const std::invalid_argument& e) {
      throw py::value_error(e.what());
    }
    if (c.contact.toi.hit) c.contact.pairs = {ids};
    c.seconds = seconds_since(t0);
    return c;
  }

  int64_t count_intersecting_pairs(const Eigen::Vector3d& p, const Eigen::Vector4d& q) {
    return reference::count_intersecting_pairs(exact(), pose_from(p, q));
  }

  py::dict separation(const Eigen::Vector3d& p, const Eigen::Vector4d& q, double max_distance) {
    const reference::ExactSeparation s = reference::separation_distance(exact(), pose_from(p, q), max_distance);
    py::dict d;
    d["within"] = s.within;
    d["lower"] = s.lower;
    d["upper"] = s.upper;
    d["squared_distance"] = s.within ? s.squared_distance.get_str() : std::string();
    return d;
  }

  py::dict separation_within(const Eigen::Vector3d& p, const Eigen::Vector4d& q, double max_distance) {
    reference::SeparationBound s;
    try {
      s = reference::separation_within(exact(), pose_from(p, q), max_distance);
    } catch (const std::invalid_argument& e) {
      throw py::value_error(e.what());
    }
    py::dict d;
    d["within"] = s.within;
    d["upper"] = s.upper;
    d["exact"] = s.exact;
    return d;
  }

  std::pair<double, double> separation_bracket(const Eigen::Vector3d& p, const Eigen::Vector4d& q,
                                               double max_distance) {
    const reference::SeparationBracket b = reference::separation_bracket(exact(), pose_from(p, q), max_distance);
    return {b.lower, b.upper};
  }

 private:
  const reference::ExactMeshPair& exact() {
    if (!exact_) exact_ = std::make_unique<reference::ExactMeshPair>(reference::make_exact_mesh_pair(god_, obstacle_));
    return *exact_;
  }

  TriangleMesh obstacle_, god_;
  Bvh obstacle_bvh_, god_bvh_;
  CcdStepWorkspace ws_;
  std::unique_ptr<reference::ExactMeshPair> exact_;
};


// The CCD query files (ccd_queries.h format): listed, read as arrays, run through one implementation.
void bind_query_files(py::module_& ccd) {
  ccd.def("list_query_files",
          [](const std::string& root) {
            py::list out;
            for (const CcdQueryFile& f : list_ccd_query_files(root))
              out.append(py::make_tuple(f.path, f.kind == CcdQuery::kVertexFace ? "vf" : "ee"));
            return out;
          },
          py::arg("root"),
          "Every *.csv under root in a folder named vertex-face or edge-edge: list of (path, 'vf'|'ee'), sorted.");
  ccd.def("run_query_file", &run_query_file, py::arg("path"), py::arg("kind"), py::arg("impl"),
          py::arg("time_tolerance") = 1e-6,
          "Runs every query of a CCD query file (ccd_queries.h format) through impl ('optimized' or 'reference'): "
          "dict with hit, expected, line (per query), inexact, seconds (primitive calls only).");
  ccd.def("read_query_file", &read_query_arrays, py::arg("path"), py::arg("kind"),
          "A CCD query file (ccd_queries.h format) as arrays: dict with points (n, 8, 3) as doubles in file order "
          "(rows 0-3 at u = 0, 4-7 at u = 1), expected, line, exact (each coordinate is the double given).");
}

// Per-query CCD of the optimized narrow phase, linear and rigid (documented for users in
// python/gauss6/ccd.py).
void bind_queries(py::module_& ccd) {
  py::class_<QueryResult>(ccd, "QueryResult",
                          "One CCD query's answer: hit, u_hit (<= the exact first contact u*), status, "
                          "time_tolerance_reached, distance_reached, iterations, filter_intervals.")
      .def_property_readonly("hit", [](const QueryResult& q) { return q.r.hit; },
                             "a contact (or, with min_separation > 0, a distance <= min_separation) may occur in "
                             "[u_begin, u_end]; true on a give-up (conservative)")
      .def_property_readonly("u_hit", [](const QueryResult& q) { return q.r.u_hit; },
                             "time of impact: u_hit <= u*; u_end when there is no hit")
      .def_property_readonly("status", [](const QueryResult& q) { return q.status; },
                             "'ok', 'max_iterations', 'workspace_full' (gave up: hit reported), 'invalid_input', "
                             "'half_turn' (rigid: split the step)")
      .def_property_readonly("time_tolerance_reached", [](const QueryResult& q) { return q.r.time_tolerance_reached; },
                             "u-width of the accepted box")
      .def_property_readonly("distance_reached", [](const QueryResult& q) { return q.r.distance_reached; },
                             "on a hit, the features are within this distance at u_hit (inf on a give-up)")
      .def_property_readonly("iterations", [](const QueryResult& q) { return q.r.iterations; }, "boxes examined")
      .def_property_readonly("filter_intervals", [](const QueryResult& q) { return q.r.filter_intervals; },
                             "u-intervals the u-filter examined (filtered queries; at most 256)")
      .def("__repr__", [](const QueryResult& q) {
        return "<QueryResult status=" + q.status + " hit=" + (q.r.hit ? "True" : "False") +
               " u_hit=" + py::repr(py::float_(q.r.u_hit)).cast<std::string>() + ">";
      });

  ccd.def("vertex_face",
          [](const Eigen::Vector3d& v0, const Face& f0, const Eigen::Vector3d& v1, const Face& f1, double u_end,
             double min_separation, std::optional<double> tt, std::optional<double> dt, std::optional<int> mi) {
            return linear_vertex_face(v0, f0, v1, f1, u_end, query_settings(min_separation, tt, dt, mi, {}, {}));
          },
          py::arg("vertex_start"), py::arg("face_start"), py::arg("vertex_end"), py::arg("face_end"), py::kw_only(),
          py::arg("u_end") = 1.0, py::arg("min_separation") = 0.0, py::arg("time_tolerance") = py::none(),
          py::arg("distance_tolerance") = py::none(), py::arg("max_iterations") = py::none(),
          "Linear vertex/face CCD: vertex (3,) and face (3, 3) (a vertex a row) at u = 0 and u = 1.");
  ccd.def("edge_edge",
          [](const Edge& a0, const Edge& b0, const Edge& a1, const Edge& b1, double u_end, double min_separation,
             std::optional<double> tt, std::optional<double> dt, std::optional<int> mi) {
            return linear_edge_edge(a0, b0, a1, b1, u_end, query_settings(min_separation, tt, dt, mi, {}, {}));
          },
          py::arg("edge_a_start"), py::arg("edge_b_start"), py::arg("edge_a_end"), py::arg("edge_b_end"),
          py::kw_only(), py::arg("u_end") = 1.0, py::arg("min_separation") = 0.0,
          py::arg("time_tolerance") = py::none(), py::arg("distance_tolerance") = py::none(),
          py::arg("max_iterations") = py::none(),
          "Linear edge/edge CCD: edges (2, 3) (an endpoint a row) at u = 0 and u = 1.");
  ccd.def("rigid_vertex_face",
          [](const Eigen::Vector3d& p0, const Eigen::Vector4d& q0, const Eigen::Vector3d& p1,
             const Eigen::Vector4d& q1, const Eigen::Vector3d& vertex_B, const Face& face_W, double u_end,
             double min_separation, std::optional<double> tt, std::optional<double> dt, std::optional<int> mi,
             std::optional<bool> uf, std::optional<bool> eh) {
            RigidVertexFaceQuery q;
            q.vertex_B = vertex_B;
            q.face_W = rows3(face_W);
            return rigid(p0, q0, p1, q1, q, u_end, query_settings(min_separation, tt, dt, mi, uf, eh),
                         ccd_rigid_vertex_face);
          },
          py::arg("p0"), py::arg("q0"), py::arg("p1"), py::arg("q1"), py::arg("vertex_B"), py::arg("face_W"),
          py::kw_only(), py::arg("u_end") = 1.0, py::arg("min_separation") = 0.0,
          py::arg("time_tolerance") = py::none(), py::arg("distance_tolerance") = py::none(),
          py::arg("max_iterations") = py::none(), py::arg("use_u_filter") = py::none(),
          py::arg("early_hit") = py::none(),
          "Rigid vertex/face CCD: the body's vertex (body frame) under the Cayley motion (p0, q0) -> (p1, q1), "
          "the face static (world frame).");
  ccd.def("rigid_face_vertex",
          [](const Eigen::Vector3d& p0, const Eigen::Vector4d& q0, const Eigen::Vector3d& p1,
             const Eigen::Vector4d& q1, const Face& face_B, const Eigen::Vector3d& vertex_W, double u_end,
             double min_separation, std::optional<double> tt, std::optional<double> dt, std::optional<int> mi,
             std::optional<bool> uf, std::optional<bool> eh) {
            RigidFaceVertexQuery q;
            q.face_B = rows3(face_B);
            q.vertex_W = vertex_W;
            return rigid(p0, q0, p1, q1, q, u_end, query_settings(min_separation, tt, dt, mi, uf, eh),
                         ccd_rigid_face_vertex);
          },
          py::arg("p0"), py::arg("q0"), py::arg("p1"), py::arg("q1"), py::arg("face_B"), py::arg("vertex_W"),
          py::kw_only(), py::arg("u_end") = 1.0, py::arg("min_separation") = 0.0,
          py::arg("time_tolerance") = py::none(), py::arg("distance_tolerance") = py::none(),
          py::arg("max_iterations") = py::none(), py::arg("use_u_filter") = py::none(),
          py::arg("early_hit") = py::none(),
          "Rigid face/vertex CCD: the body's face (body frame) moving, the vertex static (world frame).");
  ccd.def("rigid_edge_edge",
          [](const Eigen::Vector3d& p0, const Eigen::Vector4d& q0, const Eigen::Vector3d& p1,
             const Eigen::Vector4d& q1, const Edge& edge_B, const Edge& edge_W, double u_end,
             double min_separation, std::optional<double> tt, std::optional<double> dt, std::optional<int> mi,
             std::optional<bool> uf, std::optional<bool> eh) {
            RigidEdgeEdgeQuery q;
            q.edge_B = rows2(edge_B);
            q.edge_W = rows2(edge_W);
            return rigid(p0, q0, p1, q1, q, u_end, query_settings(min_separation, tt, dt, mi, uf, eh),
                         ccd_rigid_edge_edge);
          },
          py::arg("p0"), py::arg("q0"), py::arg("p1"), py::arg("q1"), py::arg("edge_B"), py::arg("edge_W"),
          py::kw_only(), py::arg("u_end") = 1.0, py::arg("min_separation") = 0.0,
          py::arg("time_tolerance") = py::none(), py::arg("distance_tolerance") = py::none(),
          py::arg("max_iterations") = py::none(), py::arg("use_u_filter") = py::none(),
          py::arg("early_hit") = py::none(),
          "Rigid edge/edge CCD: the body's edge (body frame) moving, the other edge static (world frame).");
}

// The exact first contact of the same queries (reference).
void bind_exact_queries(py::module_& ccd) {
  py::class_<reference::ExactToi>(ccd, "ExactToi", "Exact first contact u* of one query (reference).")
      .def_readonly("hit", &reference::ExactToi::hit)
      .def_readonly("lower", &reference::ExactToi::lower, "double bracket lower <= u* <= upper")
      .def_readonly("upper", &reference::ExactToi::upper)
      .def("compare", [](const reference::ExactToi& t, double u) { return reference::compare_toi(t, u); },
           py::arg("u"), "Exact sign of u - u* (-1, 0, +1); a miss counts as u* = +infinity.")
      .def("__repr__", [](const reference::ExactToi& t) {
        return std::string("<ExactToi hit=") + (t.hit ? "True" : "False") +
               " lower=" + py::repr(py::float_(t.lower)).cast<std::string>() + ">";
      });
  ccd.def("exact_vertex_face",
          [](const Eigen::Vector3d& v0, const Face& f0, const Eigen::Vector3d& v1, const Face& f1) {
            check_finite(v0, "vertex_start"), check_finite(f0, "face_start");
            check_finite(v1, "vertex_end"), check_finite(f1, "face_end");
            reference::LinearVertexFaceQuery q;
            q.vertex = {exact_point(v0), exact_point(v1)};
            q.face = {exact_points(rows3(f0)), exact_points(rows3(f1))};
            return reference::ccd_linear_vertex_face(q);
          },
          py::arg("vertex_start"), py::arg("face_start"), py::arg("vertex_end"), py::arg("face_end"),
          "Exact first contact over u in [0, 1] of vertex_face's query (no separation): an ExactToi.");
  ccd.def("exact_edge_edge",
          [](const Edge& a0, const Edge& b0, const Edge& a1, const Edge& b1) {
            check_finite(a0, "edge_a_start"), check_finite(b0, "edge_b_start");
            check_finite(a1, "edge_a_end"), check_finite(b1, "edge_b_end");
            reference::LinearEdgeEdgeQuery q;
            q.edge_a = {exact_points(rows2(a0)), exact_points(rows2(a1))};
            q.edge_b = {exact_points(rows2(b0)), exact_points(rows2(b1))};
            return reference::ccd_linear_edge_edge(q);
          },
          py::arg("edge_a_start"), py::arg("edge_b_start"), py::arg("edge_a_end"), py::arg("edge_b_end"),
          "Exact first contact over u in [0, 1] of edge_edge's query (no separation): an ExactToi.");
  ccd.def("exact_rigid_vertex_face",
          [](const Eigen::Vector3d& p0, const Eigen::Vector4d& q0, const Eigen::Vector3d& p1,
             const Eigen::Vector4d& q1, const Eigen::Vector3d& vertex_B, const Face& face_W, double u_end) {
            check_finite(vertex_B, "vertex_B"), check_finite(face_W, "face_W");
            const reference::ExactCayleyMotion m = exact_motion(p0, q0, p1, q1);
            return exact_call([&] { return reference::ccd_rigid_vertex_face({&m, vertex_B, rows3(face_W), u_end}); });
          },
          py::arg("p0"), py::arg("q0"), py::arg("p1"), py::arg("q1"), py::arg("vertex_B"), py::arg("face_W"),
          py::kw_only(), py::arg("u_end") = 1.0, "Exact first contact over [0, u_end] of rigid_vertex_face's query.");
  ccd.def("exact_rigid_face_vertex",
          [](const Eigen::Vector3d& p0, const Eigen::Vector4d& q0, const Eigen::Vector3d& p1,
             const Eigen::Vector4d& q1, const Face& face_B, const Eigen::Vector3d& vertex_W, double u_end) {
            check_finite(face_B, "face_B"), check_finite(vertex_W, "vertex_W");
            const reference::ExactCayleyMotion m = exact_motion(p0, q0, p1, q1);
            return exact_call([&] { return reference::ccd_rigid_face_vertex({&m, vertex_W, rows3(face_B), u_end}); });
          },
          py::arg("p0"), py::arg("q0"), py::arg("p1"), py::arg("q1"), py::arg("face_B"), py::arg("vertex_W"),
          py::kw_only(), py::arg("u_end") = 1.0, "Exact first contact over [0, u_end] of rigid_face_vertex's query.");
  ccd.def("exact_rigid_edge_edge",
          [](const Eigen::Vector3d& p0, const Eigen::Vector4d& q0, const Eigen::Vector3d& p1,
             const Eigen::Vector4d& q1, const Edge& edge_B, const Edge& edge_W, double u_end) {
            check_finite(edge_B, "edge_B"), check_finite(edge_W, "edge_W");
            const reference::ExactCayleyMotion m = exact_motion(p0, q0, p1, q1);
            return exact_call([&] { return reference::ccd_rigid_edge_edge({&m, rows2(edge_B), rows2(edge_W), u_end}); });
          },
          py::arg("p0"), py::arg("q0"), py::arg("p1"), py::arg("q1"), py::arg("edge_B"), py::arg("edge_W"),
          py::kw_only(), py::arg("u_end") = 1.0, "Exact first contact over [0, u_end] of rigid_edge_edge's query.");
}

// A mesh pair for mesh-level CCD: the optimized step, the exact first contact and separations.
void bind_mesh_pair(py::module_& ccd) {
  py::class_<ExactContact>(ccd, "ExactContact", "Exact first contact u* of a mesh step (reference).")
      .def_property_readonly("hit", [](const ExactContact& c) { return c.contact.toi.hit; })
      .def_property_readonly("lower", [](const ExactContact& c) { return c.contact.toi.lower; },
                             "double bracket lower <= u* <= upper (adjacent doubles or equal)")
      .def_property_readonly("upper", [](const ExactContact& c) { return c.contact.toi.upper; })
      .def_property_readonly("num_pairs", [](const ExactContact& c) { return c.contact.pairs.size(); })
      .def_property_readonly("pairs",
                             [](const ExactContact& c) {
                               py::list out;
                               for (const FeaturePairIds& p : c.contact.pairs) out.append(to_python(p));
                               return out;
                             },
                             "every feature pair touching exactly at u*, as (kind, god feature, obstacle feature)")
      .def_property_readonly("num_candidate_pairs", [](const ExactContact& c) { return c.contact.num_candidate_pairs; })
      .def_property_readonly("num_filtered_pairs", [](const ExactContact& c) { return c.contact.num_filtered_pairs; },
                             "candidate pairs ruled out by the interval filter")
      .def_property_readonly("num_exact_pairs", [](const ExactContact& c) { return c.contact.num_exact_pairs; },
                             "candidate pairs solved exactly (root isolation)")
      .def_readonly("seconds", &ExactContact::seconds)
      .def("compare", [](const ExactContact& c, double u) { return reference::compare_toi(c.contact.toi, u); },
           py::arg("u"), "Exact sign of u - u* (-1, 0, +1); a miss counts as u* = +infinity.");

  py::class_<CcdMeshPair>(ccd, "MeshPair",
                          "An obstacle (world frame) and a god-object (body frame, origin at G) for mesh-level CCD.")
      .def(py::init<const MatrixX3d&, const py::array&, const MatrixX3d&, const py::array&>(), py::arg("obstacle_V"),
           py::arg("obstacle_F"), py::arg("god_V"), py::arg("god_F"))
      .def_property_readonly("god_radius", &CcdMeshPair::god_radius, "max |r_B| over the god-object's vertices")
      .def("step", &CcdMeshPair::step, py::arg("p0"), py::arg("q0"), py::arg("p1"), py::arg("q1"),
           py::arg("min_separation"), py::arg("time_tolerance") = 1e-6, py::arg("repeats") = 1,
           "Optimized ccd_step: dict with status, hit, u_hit, pair (its kind), pair_ids (the pair in canonical ids, "
           "as ExactContact.pairs), stop_p, stop_q, deviation, seconds (fastest run).")
      .def("exact_first_contact", &CcdMeshPair::exact_first_contact, py::arg("p0"), py::arg("q0"), py::arg("p1"),
           py::arg("q1"), py::arg("filtered") = true,
           "Exact mesh_first_contact of the Cayley motion X0 -> X1: an ExactContact (filtered=False: every "
           "candidate pair solved exactly, the same answer; for comparisons).")
      .def("pair_first_contact", &CcdMeshPair::pair_first_contact, py::arg("pair"), py::arg("p0"), py::arg("q0"),
           py::arg("p1"), py::arg("q1"),
           "Exact first contact over [0, 1] of one feature pair (kind, god feature, obstacle feature) alone under "
           "the Cayley motion X0 -> X1: an ExactContact (ValueError on ids that do not fit the kind or the meshes).")
      .def("count_intersecting_pairs", &CcdMeshPair::count_intersecting_pairs, py::arg("p"), py::arg("q"),
           "Exact number of intersecting (god, obstacle) triangle pairs at pose (p, q).")
      .def("separation_within", &CcdMeshPair::separation_within, py::arg("p"), py::arg("q"), py::arg("max_distance"),
           "Whether the exact minimum distance at pose (p, q) is <= max_distance (reference separation_within): "
           "dict with within, upper (a certified upper bound of it when within) and exact (Gmpq was needed).")
      .def("separation", &CcdMeshPair::separation, py::arg("p"), py::arg("q"), py::arg("max_distance"),
           "Exact minimum distance at pose (p, q) over pairs within max_distance: dict with within, lower, upper.")
      .def("separation_bracket", &CcdMeshPair::separation_bracket, py::arg("p"), py::arg("q"), py::arg("max_distance"),
           "Certified bracket (lower, upper) of the minimum distance at pose (p, q), intervals only (no exact "
           "arithmetic): lower = max_distance, upper = inf when every pair is farther than max_distance.");
}

}  // namespace

void bind_ccd(py::module_& m) {
  py::module_ ccd = m.def_submodule("ccd", "Continuous collision detection: optimized and exact, side by side.");
  bind_query_files(ccd);
  bind_queries(ccd);
  bind_exact_queries(ccd);
  bind_mesh_pair(ccd);
}

}  // namespace gauss6::python
