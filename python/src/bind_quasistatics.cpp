// Bindings of the quasi-static projection and the coupling force (quasistatics.h,
// coupling.h): gauss6.project(M, au, J, b=None) and gauss6.coupling_force(...).
// numpy arrays in, numpy arrays out; one workspace per call (cold start) unless
// a Projector object is used, which keeps its workspace for warm starts.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <optional>
#include <string>

#include "gauss6/contact/coupling.h"
#include "gauss6/contact/quasistatics.h"
#include "module.h"

namespace py = pybind11;

namespace gauss6::python {

namespace {

using RowsX6 = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>;

struct PyProjection {
  Vec6 ac;
  Eigen::VectorXd lam;
  std::vector<int> active;
  std::string status;
  std::string problem;  // on "bad_input", what is wrong (quasistatics.h); else empty
  int iterations;
  double stationarity, primal_infeasibility, dual_infeasibility, complementarity, kkt_relative;
};

// Checks shapes at the edge (the C++ solver takes raw row-major pointers).
// Any number of rows: the workspaces are sized for J here, at the edge.
void check_shapes(const RowsX6& J, const std::optional<Eigen::VectorXd>& b) {
  if (J.rows() > std::numeric_limits<int>::max() / 6)
    throw py::value_error("J has " + std::to_string(J.rows()) + " rows; at most " +
                          std::to_string(std::numeric_limits<int>::max() / 6));
  if (b && b->size() != J.rows())
    throw py::value_error("b has " + std::to_string(b->size()) + " entries; J has " + std::to_string(J.rows()) +
                          " rows");
}

// The solver's view of numpy data (no copy; the arrays outlive the call).
ProjectionProblem make_problem(const Mat6& M, const Vec6& au, const RowsX6& J,
                               const std::optional<Eigen::VectorXd>& b) {
  check_shapes(J, b);
  ProjectionProblem problem;
  problem.M = &M;
  problem.au = au;
  problem.J = J.rows() ? J.data() : nullptr;
  problem.b = b ? b->data() : nullptr;
  problem.num_rows = static_cast<int>(J.rows());
  return problem;
}

PyProjection run(const Mat6& M, const Vec6& au, const RowsX6& J, const std::optional<Eigen::VectorXd>& b,
                 const ProjectionSettings& settings, ProjectionWorkspace* ws) {
  const ProjectionProblem problem = make_problem(M, au, J, b);
  ProjectionResult r(std::max(problem.num_rows, 1));
  project(problem, settings, ws, &r);
  PyProjection out;
  out.ac = r.ac;
  out.lam = Eigen::Map<const Eigen::VectorXd>(r.lambda.data(), J.rows());
  out.active.assign(r.active.begin(), r.active.begin() + r.num_active);
  // Status names as Python identifiers: "optimal", "iteration_cap", "infeasible_offsets", "bad_input",
  // "uncertified".
  out.status = to_string(r.status);
  std::replace(out.status.begin(), out.status.end(), ' ', '_');
  out.problem = r.problem ? r.problem : "";
  out.iterations = r.iterations;
  out.stationarity = r.stationarity;
  out.primal_infeasibility = r.primal_infeasibility;
  out.dual_infeasibility = r.dual_infeasibility;
  out.complementarity = r.complementarity;
  out.kkt_relative = r.kkt_relative;
  return out;
}

// A projector that keeps its workspace between calls: warm starts, as in the loops.
class Projector {
 public:
  explicit Projector(const ProjectionSettings& s) : settings_(s) {}
  PyProjection project(const Mat6& M, const Vec6& au, const RowsX6& J, const std::optional<Eigen::VectorXd>& b) {
    if (J.rows() > ws_.max_rows()) ws_ = ProjectionWorkspace(static_cast<int>(J.rows()));  // grows; warm start lost
    return run(M, au, J, b, settings_, &ws_);
  }
  void reset() { ws_.reset(); }

 private:
  ProjectionSettings settings_;
  ProjectionWorkspace ws_;
};

}  // namespace

void bind_quasistatics(py::module_& m) {
  py::class_<ProjectionSettings>(m, "ProjectionSettings")
      .def(py::init<>())
      .def_readwrite("dependence_tol", &ProjectionSettings::dependence_tol)
      .def_readwrite("feasibility_tol", &ProjectionSettings::feasibility_tol)
      .def_readwrite("certificate_tol", &ProjectionSettings::certificate_tol)
      .def_readwrite("max_iterations", &ProjectionSettings::max_iterations)
      .def_readwrite("warm_start", &ProjectionSettings::warm_start)
      .def_readwrite("compute_residuals", &ProjectionSettings::compute_residuals);

  // ProjectionSettings' defaults (quasistatics.h), from a default-constructed struct.
  m.def("projection_defaults",
        [] {
          const ProjectionSettings s;
          return py::dict(py::arg("dependence_tol") = s.dependence_tol, py::arg("feasibility_tol") = s.feasibility_tol,
                          py::arg("certificate_tol") = s.certificate_tol, py::arg("max_iterations") = s.max_iterations, py::arg("warm_start") = s.warm_start,
                          py::arg("compute_residuals") = s.compute_residuals);
        },
        "Defaults of ProjectionSettings (quasistatics.h).");

  py::class_<PyProjection>(m, "Projection")
      .def_readonly("ac", &PyProjection::ac)
      .def_readonly("lam", &PyProjection::lam)
      .def_readonly("active", &PyProjection::active)
      .def_readonly("status", &PyProjection::status)
      .def_readonly("iterations", &PyProjection::iterations)
      .def_readonly("stationarity", &PyProjection::stationarity)
      .def_readonly("primal_infeasibility", &PyProjection::primal_infeasibility)
      .def_readonly("dual_infeasibility", &PyProjection::dual_infeasibility)
      .def_readonly("complementarity", &PyProjection::complementarity)
      .def_readonly("kkt_relative", &PyProjection::kkt_relative)
      .def_readonly("problem", &PyProjection::problem)
      .def("__repr__", [](const PyProjection& p) {
        return "<Projection status=" + p.status + " active=" + std::to_string(p.active.size()) +
               " iterations=" + std::to_string(p.iterations) + ">";
      });

  m.def("project",
        [](const Mat6& M, const Vec6& au, const RowsX6& J, const std::optional<Eigen::VectorXd>& b,
           std::optional<ProjectionSettings> settings) {
          ProjectionWorkspace ws(std::max(static_cast<int>(J.rows()), 1));
          ProjectionSettings s = settings.value_or(ProjectionSettings{});
          s.warm_start = false;
          return run(M, au, J, b, s, &ws);
        },
        py::arg("M"), py::arg("au"), py::arg("J"), py::arg("b") = py::none(), py::arg("settings") = py::none(),
        "ac = argmin 1/2 (a-au)^T M (a-au) s.t. J a >= b (b=None: 0). M (6,6) SPD, au (6,), J (m,6).\n"
        "Returns a Projection with .ac, .lam, .active, .status, .iterations, the KKT residuals and kkt_relative\n"
        "(their scale-free form; 'optimal' only when it is within settings.certificate_tol). Input out of the\n"
        "solver's range (non-finite, M not SPD, a length |au|_M, |J_k|_{M^-1} or |b_k|/|J_k|_{M^-1} outside\n"
        "[1e-100, 1e100], 0 allowed, once au and b are scaled up by a power of two to bring lengths under\n"
        "1e-100 into it) is refused: status 'bad_input', .problem names it.");

  py::class_<Projector>(m, "Projector", "A projection that keeps its workspace between calls (warm starts).")
      .def(py::init<const ProjectionSettings&>(), py::arg("settings") = ProjectionSettings{})
      .def("project", &Projector::project, py::arg("M"), py::arg("au"), py::arg("J"), py::arg("b") = py::none())
      .def("reset", &Projector::reset);

  m.def("time_project",
        [](const Mat6& M, const Vec6& au, const RowsX6& J, const std::optional<Eigen::VectorXd>& b, int repeats,
           bool warm) {
          // Native timing for reports (`gauss6 report qp`), not a benchmark: the
          // median of `repeats` calls timed one by one with steady_clock. Cold:
          // a fresh workspace per call; warm: the same workspace, primed once.
          const ProjectionProblem problem = make_problem(M, au, J, b);
          ProjectionSettings settings;
          settings.warm_start = warm;
          settings.compute_residuals = false;
          const int rows = std::max(problem.num_rows, 1);
          ProjectionResult r(rows);
          ProjectionWorkspace primed(rows);
          project(problem, settings, &primed, &r);
          std::vector<double> t(std::max(repeats, 1));
          for (double& ti : t) {
            ProjectionWorkspace fresh(rows);
            ProjectionWorkspace* ws = warm ? &primed : &fresh;
            const auto t0 = std::chrono::steady_clock::now();
            project(problem, settings, ws, &r);
            const auto t1 = std::chrono::steady_clock::now();
            ti = std::chrono::duration<double>(t1 - t0).count();
          }
          std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
          return t[t.size() / 2];
        },
        py::arg("M"), py::arg("au"), py::arg("J"), py::arg("b") = py::none(), py::arg("repeats") = 21,
        py::arg("warm") = false, "Median seconds of one projection, timed natively (cold or warm).");

  m.def("coupling_force",
        [](const Mat6& M, const Vec6& au, const RowsX6& J, double kh, const std::optional<Eigen::VectorXd>& b) {
          // coupling_force() makes no force for such a gain (coupling.h); here it is refused by name.
          if (!valid_coupling_gain(kh))
            throw py::value_error("kh must be finite and > 0 (the coupling stiffness; a negative one pushes into the "
                                  "obstacle), not " + py::repr(py::float_(kh)).cast<std::string>());
          ProjectionWorkspace ws(std::max(static_cast<int>(J.rows()), 1));
          ProjectionSettings s;
          s.warm_start = false;
          const PyProjection p = run(M, au, J, b, s, &ws);
          if (p.status == "bad_input") throw py::value_error("coupling_force: " + p.problem);
          return Vec6(coupling_force(M, au, p.ac, kh));
        },
        py::arg("M"), py::arg("au"), py::arg("J"), py::arg("kh"), py::arg("b") = py::none(),
        "Fc = kh M (ac - au) (force, torque), with ac the projection of au.");
}

}  // namespace gauss6::python
