// Orthogonality, constraint energy and passivity of a run, one step at a time
// (property_observers.h).
#include "gauss6/property_observers.h"

#include <algorithm>
#include <cmath>

namespace gauss6 {

void CouplingPropertyObserver::add(const CouplingStepInfo& info) noexcept {
  if (!info.has_god_object) return;
  if (info.shaded) ++num_shaded_steps;
  // Constraint stage's work on the command: au . Fc = -kh |ac - au|_M^2 (<= 0).
  const double w = info.au.dot(info.Fc);
  if (w > 0) energy_injected += w;
  else energy_removed -= w;
  // Orthogonality Fc . ac = 0, or with running offsets Fc . ac = kh lambda^T b
  // (their b != 0; README: force_orthogonal_offset).
  if (info.num_offset_rows > 0) ++num_offset_steps;
  // With ac at rounding level (pressing straight into a face: ac = 0 exactly),
  // the ratio measures rounding noise, not the solver: skip |ac| <= 1e-6 |au|.
  const double nf = info.Fc.norm(), na = info.ac.norm();
  if (nf > 0 && na > kMinRelativeAc * info.au.norm()) {
    max_rel_force_dot_ac =
        std::max(max_rel_force_dot_ac, std::abs(info.Fc.dot(info.ac) - info.offset_power) / (nf * na));
    ++num_orthogonality_checks;
  }
}

void SimPropertyObserver::add(const RuntimeModel& model, const SimStepInfo& info) noexcept {
  if (info.status == SimStepStatus::kNoHandle) return;
  ++num_constraint_checks;
  max_rel_constraint_violation = std::max(max_rel_constraint_violation, info.max_rel_constraint_violation);
  max_texture_step = std::max(max_texture_step, info.texture_step);
  if (!model.surface.active()) return;
  const Mat6 M = mass_matrix_at(model, info.x_start.q);  // the M of step 3 (at xs before the step)
  const Vec6 Fs = model.gains.kh * (M * (info.asc - info.au));
  const double w = Fs.dot(info.ac);
  if (w > 0) shading_work_injected += w;
  else shading_work_removed -= w;
}

double coupling_energy(const RuntimeModel& model, const Quat& q, const Vec6& F) {
  const double k = model.gains.kh * model.gains.ks;
  if (!(k > 0)) return 0;
  const Mat3 R = rotation_matrix(normalized(q));
  const Vec3 tau_B = R.transpose() * F.tail<3>();
  const double e = F.head<3>().squaredNorm() / model.mass + tau_B.dot(model.inertia_G_B.llt().solve(tau_B));
  return e / (2 * k);
}

void PassivityObserver::add(const RuntimeModel& model, const Pose& xh, const Vec6& F, const Quat& q) {
  // The work of the wrench held since the last tick on the handle's motion,
  // plus the energy stored in the coupling now.
  if (has_previous) work += previous_F.dot(pose_difference(xh, previous_xh));
  energy = work + coupling_energy(model, q, F);
  energy_max = std::max(energy_max, energy);
  previous_xh = xh;
  previous_F = F;
  has_previous = true;
}

}  // namespace gauss6
