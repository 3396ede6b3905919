// Declarations of the binding groups of gauss6._gauss6, one file each.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "gauss6/geometry/mesh.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/io/scene.h"

namespace gauss6::python {
void bind_core(pybind11::module_& m);          // poses, meshes, mass properties, scenes
void bind_quasistatics(pybind11::module_& m);  // the projection and the coupling force
void bind_reference(pybind11::module_& m);     // the exact reference (gauss6._gauss6.reference)
void bind_ccd(pybind11::module_& m);           // optimized and exact CCD side by side (gauss6._gauss6.ccd)
void bind_device(pybind11::module_& m);        // devices and the trace writer (gauss6._gauss6.device)
void bind_runtime(pybind11::module_& m);       // scripted scenarios and traces (gauss6._gauss6.runtime)
void bind_oracle(pybind11::module_& m);        // contact generation for the validation oracle (gauss6._gauss6.oracle)

// Poses cross the boundary as p (3,) and q (4,) = (w, x, y, z), the order of pose.h.
// What enters is checked: finite, q not zero, and q rescaled by a power of two when
// its size is out of range (pose.h: rescaled(); same rotation, no overflow later).
// A ValueError otherwise.
inline Quat quat_from(const Eigen::Vector4d& q_in) {
  const Quat q = rescaled(Quat{q_in[0], q_in[1], q_in[2], q_in[3]});
  if (!is_valid_pose(Pose{Vec3::Zero(), q}))
    throw pybind11::value_error("quaternion (w, x, y, z) must be finite and non-zero");
  return q;
}
inline Eigen::Vector4d quat_to(const Quat& q) { return {q.w, q.x, q.y, q.z}; }
inline Pose pose_from(const Eigen::Vector3d& p, const Eigen::Vector4d& q) {
  if (!p.allFinite()) throw pybind11::value_error("position must be finite");
  return {p, quat_from(q)};
}

// Triangle index arrays (F, #F x 3) from Python: any integer dtype, each index in
// [0, 2^31 - 1]. numpy's own cast to int32 would wrap 2^32 to 0; this refuses it
// with a ValueError naming the array.
inline MatrixX3i faces_from(const pybind11::array& F, const char* name = "F") {
  namespace py = pybind11;
  const char kind = F.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::value_error(std::string(name) + ": must be an integer array (got dtype " +
                          std::string(py::str(F.dtype())) + ")");
  if (F.ndim() != 2 || F.shape(1) != 3) throw py::value_error(std::string(name) + ": must have shape (n, 3)");
  // uint64 beyond 2^63 would wrap through int64: compare in the array's own type first.
  const py::module_ np = py::module_::import("numpy");
  if (F.size() > 0) {
    const bool below = np.attr("all")(np.attr("greater_equal")(F, 0)).cast<bool>();
    const bool above = np.attr("all")(np.attr("less_equal")(F, 2147483647)).cast<bool>();
    if (!below || !above) throw py::value_error(std::string(name) + ": every index must be in [0, 2^31 - 1]");
  }
  const auto a = py::array_t<int32_t, py::array::c_style | py::array::forcecast>::ensure(F);
  MatrixX3i out(F.shape(0), 3);
  std::copy(a.data(), a.data() + a.size(), out.data());
  return out;
}
// load_scene() with each of the scene's repair warnings (Scene::warnings) issued as
// a Python UserWarning.
Scene load_scene_warning(const std::string& path);
}  // namespace gauss6::python
