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
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "gauss6/bvh.h"
#include "gauss6/ccd_step.h"
#include "gauss6/ccd.h"
#include "gauss6/ccd_queries.h"
#include "gauss6/feature_ids.h"
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
      ccd_step(&obstacle, 1, god, X0, X1, settings, &ws_, &r);
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
                                   const Eigen::Vector4d& q1) {
    const reference::ExactMeshPair& m = exact();
    const auto t0 = Clock::now();
    ExactContact c{reference::mesh_first_contact(m, pose_from(p0, q0), pose_from(p1, q1)), 0};
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

}  // namespace

void bind_ccd(py::module_& m) {
  py::module_ ccd = m.def_submodule("ccd", "Continuous collision detection: optimized and exact, side by side.");

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
           py::arg("q1"), "Exact mesh_first_contact of the Cayley motion X0 -> X1: an ExactContact.")
      .def("pair_first_contact", &CcdMeshPair::pair_first_contact, py::arg("pair"), py::arg("p0"), py::arg("q0"),
           py::arg("p1"), py::arg("q1"),
           "Exact first contact over [0, 1] of one feature pair (kind, god feature, obstacle feature) alone under "
           "the Cayley motion X0 -> X1: an ExactContact (ValueError on ids that do not fit the kind or the meshes).")
      .def("count_intersecting_pairs", &CcdMeshPair::count_intersecting_pairs, py::arg("p"), py::arg("q"),
           "Exact number of intersecting (god, obstacle) triangle pairs at pose (p, q).")
      .def("separation", &CcdMeshPair::separation, py::arg("p"), py::arg("q"), py::arg("max_distance"),
           "Exact minimum distance at pose (p, q) over pairs within max_distance: dict with within, lower, upper.")
      .def("separation_bracket", &CcdMeshPair::separation_bracket, py::arg("p"), py::arg("q"), py::arg("max_distance"),
           "Certified bracket (lower, upper) of the minimum distance at pose (p, q), intervals only (no exact "
           "arithmetic): lower = max_distance, upper = inf when every pair is farther than max_distance.");
}

}  // namespace gauss6::python
