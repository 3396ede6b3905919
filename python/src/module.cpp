// The gauss6._gauss6 extension module: one call per binding group.
#include "module.h"

PYBIND11_MODULE(_gauss6, m) {
  m.doc() = "gauss6: six-DoF god-object haptic rendering (C++ core)";
  gauss6::python::bind_core(m);
  gauss6::python::bind_device(m);
  gauss6::python::bind_quasistatics(m);
  gauss6::python::bind_reference(m);
  gauss6::python::bind_ccd(m);
  gauss6::python::bind_runtime(m);
  gauss6::python::bind_oracle(m);
}
