// Bindings for the validation oracle (python/gauss6/oracle.py; gauss6._gauss6.oracle):
// gauss6's contact generation (contacts.h) at any pose of a scene's god-object, so that
// the oracle can build the cone of contact wrenches at an engine's displayed pose.
// The geometric verdicts themselves are the exact reference's (gauss6._gauss6.ccd.MeshPair).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <memory>
#include <vector>

#include "gauss6/contact/contacts.h"
#include "gauss6/io/scene.h"
#include "module.h"

namespace py = pybind11;

namespace gauss6::python {

namespace {

// A scene's obstacles (world frame, as the runtime places them) and god-object, with their trees.
class ContactGenerator {
 public:
  explicit ContactGenerator(const std::string& scene_path) : scene_(load_scene(scene_path)) {
    for (const Body& b : scene_.obstacles) {
      TriangleMesh m = b.mesh;
      const Mat3 R = rotation_matrix(b.pose.q);
      for (Eigen::Index v = 0; v < m.V.rows(); ++v) m.V.row(v) = (b.pose.p + R * m.V.row(v).transpose()).transpose();
      obstacles_.push_back(std::make_unique<TriangleMesh>(std::move(m)));
    }
    for (const auto& m : obstacles_) bvhs_.push_back(std::make_unique<Bvh>(build_bvh(*m)));
    god_bvh_ = build_bvh(scene_.god_object.mesh);
    for (size_t i = 0; i < obstacles_.size(); ++i) bodies_.push_back(CcdBody{obstacles_[i].get(), bvhs_[i].get()});
    ws_ = std::make_unique<ContactWorkspace>(scene_.god_object.mesh);
  }

  // The contact set at pose (p, q) within `distance`: points (k, 3), normals (k, 3),
  // separations (k,), J (k, 6), status, overflow count.
  py::dict contacts(const Eigen::Vector3d& p, const Eigen::Vector4d& q, double distance) {
    ContactSettings settings;
    settings.distance = distance;
    const CcdBody god{&scene_.god_object.mesh, &god_bvh_};
    const ContactStatus status = generate_contacts(bodies_.data(), static_cast<int>(bodies_.size()), god,
                                                   pose_from(p, q), settings, ws_.get(), &set_);
    const int k = set_.num_contacts;
    Eigen::MatrixXd points(k, 3), normals(k, 3), J(k, 6);
    Eigen::VectorXd separations(k);
    for (int i = 0; i < k; ++i) {
      const Contact& c = set_.contacts[static_cast<size_t>(i)];
      points.row(i) = c.point.transpose();
      normals.row(i) = c.normal.transpose();
      separations[i] = c.separation;
      J.row(i) = set_.J.row(i);
    }
    py::dict d;
    d["points"] = points;
    d["normals"] = normals;
    d["separations"] = separations;
    d["J"] = J;
    d["status"] = to_string(status);
    return d;
  }

 private:
  Scene scene_;
  std::vector<std::unique_ptr<TriangleMesh>> obstacles_;
  std::vector<std::unique_ptr<Bvh>> bvhs_;
  std::vector<CcdBody> bodies_;
  Bvh god_bvh_;
  std::unique_ptr<ContactWorkspace> ws_;
  ContactSet set_{1024};
};

}  // namespace

void bind_oracle(py::module_& parent) {
  py::module_ m = parent.def_submodule("oracle", "What the validation oracle takes from gauss6: contact generation");
  py::class_<ContactGenerator>(m, "ContactGenerator",
                               "gauss6's contact generation (contacts.h) for a scene's god-object against its obstacles.")
      .def(py::init<const std::string&>(), py::arg("scene"), "Loads the scene (LoadError on a bad one).")
      .def("contacts", &ContactGenerator::contacts, py::arg("p"), py::arg("q"), py::arg("distance"),
           "Every vertex/face and edge/edge pair within `distance` at the god-object pose (p, q), merged: dict with "
           "points (k, 3) on the god-object, normals (k, 3) out of the obstacle, separations (k,), J (k, 6) rows "
           "[n, (I - G) x n], status.");
}

}  // namespace gauss6::python
