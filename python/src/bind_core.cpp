// Bindings of the core vocabulary: poses, the Cayley motion, meshes, mass
// properties and scenes. numpy arrays in and out (Eigen types by value).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "gauss6/ccd/ccd.h"
#include "gauss6/io/load_error.h"
#include "gauss6/geometry/mass_properties.h"
#include "gauss6/geometry/mesh.h"
#include "gauss6/io/mesh_io.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/io/qp_instances.h"
#include "gauss6/io/scene.h"
#include "module.h"

namespace py = pybind11;

namespace gauss6::python {

namespace {

py::dict summary_dict(const BodySummary& s) {
  py::dict d;
  d["name"] = s.name;
  d["role"] = to_string(s.role);
  d["triangles"] = s.num_triangles;
  d["vertices"] = s.num_vertices;
  d["closed"] = s.closed;
  d["manifold"] = s.manifold;
  d["self_intersections"] = s.num_self_intersections;
  d["mass"] = s.mass;
  d["center_of_mass"] = s.center_of_mass_W;
  d["inertia"] = s.inertia_W;
  d["bbox_min"] = s.bbox_min_W;
  d["bbox_max"] = s.bbox_max_W;
  return d;
}
}  // namespace

Scene load_scene_warning(const std::string& path) {
  Scene scene = load_scene(path);
  for (const std::string& w : scene.warnings)
    if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw py::error_already_set();
  return scene;
}

namespace {

// The defaults of the scene file's optional keys and of the CCD settings, read
// from default-constructed C++ structs: the one place they are stated.
void bind_defaults(py::module_& m) {
  m.def("defaults",
        [] {
          const ContactParameters contact;
          const SurfaceSettings surface;
          const DeviceSettings device;
          const CcdSettings ccd;
          py::dict d;
          d["contact"] = py::dict(py::arg("offset_eps_per_delta") = kDefaultOffsetEpsPerDelta,
                                  py::arg("offset_time") = contact.offset_time,
                                  // delta's range (check_delta_scale): these times the scene's extent, and kMinDelta
                                  py::arg("min_delta_per_extent") = kMinDeltaPerExtent,
                                  py::arg("max_delta_per_extent") = kMaxDeltaPerExtent,
                                  py::arg("min_delta") = kMinDelta);
          d["surface"] = py::dict(py::arg("kind") = to_string(surface.kind));
          d["device"] = py::dict(py::arg("rate_hz") = device.rate_hz, py::arg("max_force") = device.max_force,
                                 py::arg("max_torque") = device.max_torque);
          d["ccd"] = py::dict(py::arg("time_tolerance") = ccd.time_tolerance,
                              py::arg("distance_tolerance") = ccd.distance_tolerance,
                              py::arg("max_iterations") = ccd.max_iterations);
          return d;
        },
        "Defaults of the scene file's optional keys (contact: offset_eps as a multiple of delta) and of "
        "CcdSettings, from the C++ structs.");
}

// Poses: p (3,), q (4,) as (w, x, y, z).
void bind_poses(py::module_& m) {
  m.def("rotation_matrix", [](const Eigen::Vector4d& q) { return rotation_matrix(quat_from(q)); }, py::arg("q"),
        "Rational rotation matrix R(q) = (...)/|q|^2 of METHOD.md section 1.");
  m.def("pose_difference",
        [](const Eigen::Vector3d& ph, const Eigen::Vector4d& qh, const Eigen::Vector3d& ps, const Eigen::Vector4d& qs) {
          return pose_difference(pose_from(ph, qh), pose_from(ps, qs));
        },
        py::arg("ph"), py::arg("qh"), py::arg("ps"), py::arg("qs"), "xh (-) xs as a 6-vector (linear, angular).");
  m.def("pose_update",
        [](const Eigen::Vector3d& p, const Eigen::Vector4d& q, const Vec6& a) {
          const Pose x = pose_update(pose_from(p, q), a);
          return py::make_tuple(Eigen::Vector3d(x.p), quat_to(x.q));
        },
        py::arg("p"), py::arg("q"), py::arg("a"), "xs (+) a: returns (p, q).");
}

// Meshes: read, validated, their mass properties.
void bind_meshes(py::module_& m) {
  py::class_<MeshReport>(m, "MeshReport")
      .def_readonly("num_vertices", &MeshReport::num_vertices)
      .def_readonly("num_triangles", &MeshReport::num_triangles)
      .def_readonly("num_edges", &MeshReport::num_edges)
      .def_readonly("num_nonfinite_vertices", &MeshReport::num_nonfinite_vertices)
      .def_readonly("num_bad_indices", &MeshReport::num_bad_indices)
      .def_readonly("num_degenerate_triangles", &MeshReport::num_degenerate_triangles)
      .def_readonly("num_boundary_edges", &MeshReport::num_boundary_edges)
      .def_readonly("num_nonmanifold_edges", &MeshReport::num_nonmanifold_edges)
      .def_readonly("num_nonmanifold_vertices", &MeshReport::num_nonmanifold_vertices)
      .def_readonly("num_self_intersections", &MeshReport::num_self_intersections)
      .def_property_readonly("closed", &MeshReport::closed)
      .def_property_readonly("manifold", &MeshReport::manifold)
      .def("ok", &MeshReport::ok)
      .def("describe", &MeshReport::describe);
  m.def("read_mesh",
        [](const std::string& path) {
          const TriangleMesh mesh = read_mesh(path);
          return py::make_tuple(mesh.V, mesh.F);
        },
        py::arg("path"), "Reads an OBJ/OFF/PLY/STL triangle mesh: returns (V #Vx3 float64, F #Fx3 int32).");
  m.def("validate_mesh",
        [](const MatrixX3d& V, const py::array& F, bool self_intersections) {
          TriangleMesh mesh;
          mesh.V = V;
          mesh.F = faces_from(F);
          MeshReport r = validate_mesh(mesh);
          if (self_intersections && r.num_bad_indices == 0) r.num_self_intersections = count_self_intersections(mesh);
          return r;
        },
        py::arg("V"), py::arg("F"), py::arg("self_intersections") = false);
  m.def("mass_properties",
        [](const MatrixX3d& V, const py::array& F, double density) {
          TriangleMesh mesh;
          mesh.V = V;
          mesh.F = faces_from(F);
          MassProperties mp;
          std::string error;
          if (!compute_mass_properties(mesh, density, &mp, &error)) throw py::value_error(error);
          py::dict d;
          d["volume"] = mp.volume;
          d["mass"] = mp.mass;
          d["center_of_mass"] = mp.center_of_mass;
          d["inertia"] = mp.inertia;
          return d;
        },
        py::arg("V"), py::arg("F"), py::arg("density"),
        "Volume, mass, centre of mass and inertia about it (mesh frame) of a closed mesh.");
}

// Projection instances (datasets_generated/qp/), read by the C++ reader.
void bind_qp_instances(py::module_& m) {
  py::class_<QpInstance>(m, "QpInstance")
      .def_readonly("id", &QpInstance::id)
      .def_readonly("M", &QpInstance::M)
      .def_readonly("au", &QpInstance::au)
      .def_readonly("J", &QpInstance::J)
      .def_readonly("b", &QpInstance::b)
      .def_readonly("push", &QpInstance::push)
      .def_readonly("sequence", &QpInstance::sequence)
      .def_readonly("step", &QpInstance::step);
  m.def("read_qp_instances", &read_qp_instances, py::arg("path"),
        "Reads a projection-instance family file (datasets_generated/qp/README.md).");
}

// Scenes: loaded once (load_scene), then summarised here and resolved into
// the effective settings by runtime.effective_settings, without reading the
// files again.
void bind_scenes(py::module_& m) {
  py::class_<Scene>(m, "Scene", "A loaded and validated scene (opaque; gauss6.load_scene).")
      .def_readonly("path", &Scene::path)
      .def_readonly("name", &Scene::name);
  m.def("load_scene", &load_scene_warning, py::arg("path"),
        "Loads and validates a scene file and its meshes (raises LoadError naming file, line and key; "
        "what the loader repaired, e.g. an inside-out mesh flipped, is a UserWarning).");
  m.def("scene_summary",
        [](const Scene& scene, bool self_intersections) {
          py::list bodies;
          for (const BodySummary& s : summarize_scene(scene, self_intersections)) bodies.append(summary_dict(s));
          py::dict d;
          d["name"] = scene.name;
          d["bodies"] = bodies;
          d["gains"] = py::dict(py::arg("ks") = scene.gains.ks, py::arg("kh") = scene.gains.kh);
          d["contact"] = py::dict(py::arg("delta") = scene.contact.delta,
                                  py::arg("offset_eps") = scene.contact.offset_eps,
                                  py::arg("offset_time") = scene.contact.offset_time);
          d["extent"] = scene_extent(scene);  // the length delta's range is stated in (scene.h)
          d["surface"] = to_string(scene.surface.kind);
          d["device"] = to_string(scene.device.kind);
          return d;
        },
        py::arg("scene"), py::arg("self_intersections") = true, "Summarises a loaded scene's bodies.");
}

}  // namespace

void bind_core(py::module_& m) {
  // Every load-time error (load_error.h: scenes, meshes, CCD query and projection-
  // instance files) becomes gauss6.LoadError, a ValueError with the same message
  // ("FILE:LINE: KEY: problem"). SceneError and MeshFileError are its old names.
  const auto& load_error = py::register_exception<LoadError>(m, "LoadError", PyExc_ValueError);
  m.attr("SceneError") = load_error;
  m.attr("MeshFileError") = load_error;

  bind_defaults(m);
  bind_poses(m);
  bind_meshes(m);
  bind_qp_instances(m);
  bind_scenes(m);
}

}  // namespace gauss6::python
