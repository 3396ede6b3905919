// Declarations of the binding groups of gauss6._gauss6, one file each.
#pragma once

#include <pybind11/pybind11.h>

#include <Eigen/Core>

#include "gauss6/pose.h"

namespace gauss6::python {
void bind_core(pybind11::module_& m);          // poses, meshes, mass properties, scenes
void bind_quasistatics(pybind11::module_& m);  // the projection and the coupling force
void bind_reference(pybind11::module_& m);     // the exact reference (gauss6._gauss6.reference)
void bind_ccd(pybind11::module_& m);           // optimized and exact CCD side by side (gauss6._gauss6.ccd)
void bind_device(pybind11::module_& m);        // devices and the trace writer (gauss6._gauss6.device)
void bind_runtime(pybind11::module_& m);       // scripted scenarios and traces (gauss6._gauss6.runtime)
void bind_oracle(pybind11::module_& m);        // contact generation for the validation oracle (gauss6._gauss6.oracle)

// Poses cross the boundary as p (3,) and q (4,) = (w, x, y, z), the order of pose.h.
inline Quat quat_from(const Eigen::Vector4d& q) { return {q[0], q[1], q[2], q[3]}; }
inline Eigen::Vector4d quat_to(const Quat& q) { return {q.w, q.x, q.y, q.z}; }
inline Pose pose_from(const Eigen::Vector3d& p, const Eigen::Vector4d& q) { return {p, quat_from(q)}; }
}  // namespace gauss6::python
