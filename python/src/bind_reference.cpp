// Bindings of the exact reference (reference/, CGAL + GMP): the exact projection
// and the exact certificate check of a floating-point answer. Exact values come
// back as decimal fraction strings ("p/q") next to their nearest doubles.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <optional>

#include "gauss6/reference/quasistatics.h"
#include "module.h"

namespace py = pybind11;

namespace gauss6::python {

namespace {
const char* to_string(reference::ProjectionStatus s) {
  switch (s) {
    case reference::ProjectionStatus::kOptimal: return "optimal";
    case reference::ProjectionStatus::kInfeasibleOffsets: return "infeasible";
    case reference::ProjectionStatus::kSolverFailure: return "solver_failure";
    case reference::ProjectionStatus::kBadInput: return "bad_input";
  }
  return "unknown";
}
const char* to_string(reference::CertificateFailure f) {
  switch (f) {
    case reference::CertificateFailure::none: return "none";
    case reference::CertificateFailure::bad_input: return "bad_input";
    case reference::CertificateFailure::negative_multiplier: return "negative_multiplier";
    case reference::CertificateFailure::violated_constraint: return "violated_constraint";
  }
  return "unknown";
}
Eigen::VectorXd rhs_or_zero(const std::optional<Eigen::VectorXd>& b, Eigen::Index m) {
  return b ? *b : Eigen::VectorXd::Zero(m);
}
}  // namespace

void bind_reference(py::module_& m) {
  py::module_ ref = m.def_submodule("reference", "The exact reference (CGAL QP solver, GMP rationals).");

  ref.def("project",
          [](const Mat6& M, const Vec6& au, const Eigen::MatrixXd& J, const std::optional<Eigen::VectorXd>& b) {
            const reference::ProjectionResult p = reference::project({M, au, J, rhs_or_zero(b, J.rows())});
            py::dict d;
            d["status"] = to_string(p.status);
            d["ac"] = p.ac_double;
            d["lam"] = Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(p.lambda_double.data(), p.lambda_double.size()));
            d["active"] = p.active_set;
            d["ac_exact"] = reference::to_strings(p.ac);
            return d;
          },
          py::arg("M"), py::arg("au"), py::arg("J"), py::arg("b") = py::none(),
          "Exact projection (CGAL QP, Gmpzf): dict with status, ac, lam (nearest doubles), active, ac_exact.");

  ref.def("check_certificate",
          [](const Mat6& M, const Vec6& au, const Eigen::MatrixXd& J, const std::optional<Eigen::VectorXd>& b,
             const std::vector<int>& active) {
            const reference::CertificateReport r =
                reference::check_certificate({M, au, J, rhs_or_zero(b, J.rows())}, active);
            py::dict d;
            d["pass"] = r.pass;
            d["failure"] = to_string(r.failure);
            d["row"] = r.row;
            d["amount"] = r.amount;
            d["rank"] = r.rank;
            d["num_dependent_rows"] = r.num_dependent_rows;
            d["ac"] = r.ac_rounded;
            d["lam"] = Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(r.lambda_rounded.data(), r.lambda_rounded.size()));
            return d;
          },
          py::arg("M"), py::arg("au"), py::arg("J"), py::arg("b"), py::arg("active"),
          "Exact KKT certificate of an active set: dict with pass, failure, row, amount, and the exact ac (rounded).");
}

}  // namespace gauss6::python
