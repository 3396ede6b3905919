// Property observers of a run: the checks of METHOD.md section 5 that a trace
// cannot show exactly (it records the clamped wrench, not ac), fed one step at
// a time by the scenario's hooks (scenario.h):
//   - per coupling step: orthogonality Fc . ac = 0 (5.1) and the constraint
//     stage's energy balance au . Fc <= 0 (5.4: the constraints only remove energy);
//   - per haptic tick: a Hannaford-Ryu passivity observer on the device port.
// Each observer is written by one thread only (the loop that feeds it).
//
// Units: the scene's (metres, kilograms, seconds in the shipped scenes); wrenches
// in N and N m, world frame; energies in J.
#pragma once

#include "gauss6/runtime/runtime.h"

namespace gauss6 {

// Orthogonality is measured only where |ac| > this |au| (see CouplingPropertyObserver).
inline constexpr double kMinRelativeAc = 1e-6;

// Orthogonality and constraint energy over the coupling steps.
struct CouplingPropertyObserver {
  // Orthogonality (METHOD.md 5.1), over coupling steps with |Fc| > 0, |ac| > 1e-6 |au|
  // (below, ac is rounding noise: pressing straight into a face gives ac = 0); with
  // running offsets (b != 0) in its offset form Fc . ac = kh lambda^T b
  // (CouplingStepInfo::offset_power): max |Fc . ac - kh lambda^T b| / (|Fc| |ac|).
  double max_rel_force_dot_ac = 0;
  long num_orthogonality_checks = 0;
  long num_offset_steps = 0;           // coupling steps with a running offset (checked in the offset form)
  // The constraint stage's work on the user's command (METHOD.md 5.4 with Fu = kh M au):
  // per coupling step au . Fc = -kh |ac - au|_M^2 <= 0 (J). Sums of its positive and
  // negative parts; the positive sum must be 0 up to rounding.
  double energy_injected = 0;
  double energy_removed = 0;

  long num_shaded_steps = 0;           // coupling steps whose rows were the shading rows Js (then ac = asc
                                       // and the orthogonality above is Fc . asc = 0 under Js)

  // Adds one coupling step (steps without a god-object are skipped).
  void add(const CouplingStepInfo& info) noexcept;
};

// The god-object's own motion over the sim steps.
//   - Property 7 (METHOD.md section 5): on every step with a handle, the rows
//     of step 3 hold for ac (SimStepInfo::max_rel_constraint_violation): the
//     largest relative violation, which must stay at rounding level.
//   - Shading's energy: the shaded force Fs = kh M (asc - au) is orthogonal to
//     asc but not to the motion ac the god-object takes (the shading normal is
//     not the true one): per step Fs . ac = Fs . (ac - asc), the work the
//     shading does on the god-object's motion, 0 on plain surfaces. Sums of
//     its positive (injected) and negative parts, in J (M kh folds dt^2 in, as
//     for the coupling's energy). Bounded per step by |Fs|_M^-1 |ac - asc|_M,
//     where |ac - asc| grows with the angle between the shading and the true
//     normals (at most 60 degrees: kMinShadingCosine; at most the crease angle
//     for shading alone).
struct SimPropertyObserver {
  double max_rel_constraint_violation = 0;
  long num_constraint_checks = 0;      // steps with a handle
  double shading_work_injected = 0;
  double shading_work_removed = 0;
  double max_texture_step = 0;         // largest texture_step (scene units)

  void add(const RuntimeModel& model, const SimStepInfo& info) noexcept;
};

// V = F^T M^-1 F / (2 kh ks): the energy stored in the coupling spring
// (stiffness kh ks M) that produces F. M at the orientation q. 0 when kh ks <= 0.
double coupling_energy(const RuntimeModel& model, const Quat& q, const Vec6& F);

// Passivity observer on the device port (Hannaford and Ryu 2002): W(n) =
// sum_k F_k . (xh_{k+1} (-) xh_k), the work of the sent wrench on the handle,
// plus the energy stored in the coupling at tick n, V = F^T M^-1 F / (2 kh ks).
// A passive environment keeps W(n) + V(n) <= 0 for every n. Zero-order hold of
// a stiff coupling makes it slightly positive (about k/2 sum |dx|^2), which is
// why the constraint-stage balance (CouplingPropertyObserver) is kept apart.
struct PassivityObserver {
  double work = 0;                     // W(n), J
  double energy = 0;                   // W(n) + V(n) at the last tick, J
  double energy_max = 0;               // max(0, max_n W(n) + V(n)), J
  bool has_previous = false;
  Pose previous_xh;
  Vec6 previous_F = Vec6::Zero();

  // Adds one haptic tick: the handle pose xh, the wrench sent F, and the
  // orientation q of the god-object the force was computed at.
  void add(const RuntimeModel& model, const Pose& xh, const Vec6& F, const Quat& q);
};

}  // namespace gauss6
