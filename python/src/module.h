// Declarations of the binding groups of gauss6._gauss6, one file each.
#pragma once

#include <pybind11/pybind11.h>

namespace gauss6::python {
void bind_core(pybind11::module_& m);          // poses, meshes, mass properties, scenes
void bind_quasistatics(pybind11::module_& m);  // the projection and the coupling force
void bind_reference(pybind11::module_& m);     // the exact reference (gauss6._gauss6.reference)
void bind_device(pybind11::module_& m);        // devices and the trace writer (gauss6._gauss6.device)
}  // namespace gauss6::python
