// Generalised mass matrices shared by the coupling and offsetting tests.
#pragma once

#include "gauss6/geometry/pose.h"

namespace gauss6::test {

// M = diag(m I3, I_G) of a 2 kg box with a slightly non-diagonal inertia (one
// off-diagonal term couples the first two angular axes): symmetric positive
// definite, and unlike a multiple of the identity, so the M-metric matters.
inline Mat6 box_mass_matrix() {
  Mat6 M = Mat6::Zero();
  M.diagonal() << 2.0, 2.0, 2.0, 0.01, 0.02, 0.03;
  M(3, 4) = M(4, 3) = 0.001;
  return M;
}

}  // namespace gauss6::test
