// Reader of the projection-instance families (datasets_generated/qp/<family>.json,
// format "gauss6-qp-instances" version 1, described in datasets_generated/qp/README.md).
//
// An instance is one quasi-static projection (METHOD.md sections 2-3):
//   ac = argmin 1/2 (a - au)^T M (a - au)   s.t.   J a >= b.
// Load-time code (library gauss6_load): it allocates and throws; never call it in a loop.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "gauss6/io/load_error.h"
#include "gauss6/geometry/pose.h"

namespace gauss6 {

struct QpInstance {
  std::string id;  // unique within its family, e.g. "box-0007"
  Mat6 M;          // generalised mass diag(m I3, I_G), world frame: kg, kg m^2; SPD
  Vec6 au;         // unconstrained step: linear (m) then angular (rad), world frame
  // Contact rows J_k = [n_k^T, (G I_k x n_k)^T], n_k unit, from the obstacle into the
  // god-object: m x 6, m >= 0 (may be empty).
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> J;
  Eigen::VectorXd b;  // m right-hand sides (m); zeros unless the family has offsets
  // "all" (every J_k au < 0), "some", or "none" (J au >= 0, so ac = au when b = 0).
  std::string push;
  int sequence = -1;  // warm-start sequence id, -1 outside a sequence
  int step = -1;      // step within the sequence, -1 outside a sequence
};

// Every instance of one family file, in file order. Numbers are read bit-exactly
// (the files hold shortest round-trip decimal forms). Throws QpInstanceError
// (load_error.h) whose message starts with the path, then the line of a JSON syntax
// error or the key ("instances[3].J[1]"), and names the problem (unreadable file, not
// JSON, wrong "format" or "version", a missing key, a wrong size, a non-number or
// non-finite value, an unknown push label).
std::vector<QpInstance> read_qp_instances(const std::string& path);

}  // namespace gauss6
