// Channel payloads back to poses (runtime_channels.h).
#include "gauss6/runtime_channels.h"

namespace gauss6 {

Pose to_pose(const double p[3], const double q[4]) {
  Pose x;
  x.p = Vec3(p[0], p[1], p[2]);
  x.q = Quat{q[0], q[1], q[2], q[3]};
  return x;
}

}  // namespace gauss6
