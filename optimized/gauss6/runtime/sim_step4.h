// Step 4 of the sim step (METHOD.md section 2): the god-object's move along
// the constrained command, x_start -> x_target = x_start (+) ac, stopped delta
// before the first contact, and the contact set at the pose it ends at. Its
// contract, and how often each of its paths runs, is docs/sim-step.md. One
// mechanism carries it:
//   - a proven leg: a motion the CCD proved free (LegEnd), from which poses,
//     near pairs and a prefix proof of nearby motions are served;
//   - one detour rule: a detour (a graze's lift, a settling leg) is explored as
//     a leg of its own and its end kept only when the direct motion x_start ->
//     end is proven free;
//   - one halving schedule: a refused settle halves the first leg, first with a
//     settle each (kMaxSettleShortenings), then without (kMaxKeepHalvings) until
//     its end keeps a contact, then stays at x_start.
// Real time: no allocation, no locks, no exceptions; every buffer lives in
// GodObjectStep, built once with the sim loop's state (sim_loop.h, which holds
// one and calls advance_god_object; this module knows nothing of that state).
#pragma once

#include <vector>

#include "gauss6/contact/contacts.h"
#include "gauss6/contact/quasistatics.h"
#include "gauss6/step/ccd_step.h"
#include "gauss6/step/near_pairs.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/runtime/runtime_events.h"
#include "gauss6/runtime/runtime_model.h"
#include "gauss6/step/update_budget.h"

namespace gauss6 {

// The halving schedule (docs/sim-step.md): the first leg's end is tried at u =
// 1, 1/2, ..., 2^-kMaxSettleShortenings of its motion with a settling leg each,
// then halved on without settling, at most kMaxKeepHalvings more times, until
// its end keeps a contact.
constexpr int kMaxSettleShortenings = 3;
constexpr int kMaxKeepHalvings = 8;
// The settling leg's first lead piece sweeps about this many times the CCD's
// reach (CcdStepSettings::lead_sweep): a settling leg starts just off the
// surface it lifted from and stops again soon after its start.
constexpr double kSettleLeadSweep = 16;

// Where a leg left the god-object: a motion the CCD proved free up to u (of
// the Cayley motion from `from`), the pose there and the near pairs that hold
// at it. A leg run in halves (a half turn) is not one motion: one_piece false.
struct LegEnd {
  Pose from;                    // the motion's start
  CcdStepResult ccd;            // the CCD of the motion (of its last half when split)
  double u = 1;                 // the end's parameter on that motion
  bool one_piece = true;        // the motion from `from` is ccd.motion (no split)
  Pose xs;                      // the pose at u (make_stop_pose)
  double posing_error = 0;      // a vertex posed at xs from the exact motion's at u (inf: none served)
  NearPairs near;               // every pair within ccd.near_reach at xs (num_pairs -1: none)
};

// The paths the last step took (docs/sim-step.md, whose table counts them).
struct StepPaths {
  bool grazed = false;          // the first leg was stopped by a graze (a contact left in the CCD's band)
  bool lifted = false;          // ... and the lift out of it was kept
  int settles = 0;              // settling legs run
  int refused = 0;              // settled ends refused (the direct motion not proven free)
  int keep_halvings = 0;        // halvings after the last settle, to keep a contact
  bool stayed = false;          // the step ended at x_start (no halving kept a contact)
  // Where an update's work units went (under a budget, RuntimeSettings::budget;
  // 0 without one): the first legs' CCDs (the proximity list's fills of the
  // update included), the checks of detours' direct motions (motion_free), and
  // the detours' own legs (settling legs, a graze's lift leg).
  long first_leg_units = 0;
  long check_units = 0;
  long detour_units = 0;
};

// Step 4's buffers, built once.
struct GodObjectStep {
  explicit GodObjectStep(const RuntimeModel& model);
  GodObjectStep(const GodObjectStep&) = delete;  // check_ws lends from legs_ws: never moved
  GodObjectStep& operator=(const GodObjectStep&) = delete;
  CcdStepWorkspace legs_ws;           // every leg's (with the proximity cache)
  CcdStepWorkspace check_ws;          // the checks' (borrowing the legs' list and cut)
  CcdStepResult check;
  std::vector<FeaturePair> hints;     // the contacts at x_start, tested first by every CCD of the step
  int num_hints = 0;
  LegEnd leg;                         // where the god-object stands now
  LegEnd proven;                      // the first leg from x_start, whole and free, served by halvings
  std::vector<TrianglePair> proven_near;  // its near pairs, copied before later legs reuse legs_ws
  ContactWorkspace contact_ws;        // the contact search at a leg's end
  std::vector<double> lift_b;         // a graze's lift: the gap rows' right-hand sides (max_contacts)
  ProjectionWorkspace lift_ws;
  ProjectionResult lift;
  StepPaths paths;
  uint32_t events = 0;                // this step's events (event_bit: kContactOverflow, kUpdateBudgetExhausted)
  UpdateBudget budget;                // the update's (RuntimeSettings::budget; docs/sim-step.md, "Budgeted updates")
  bool budget_ran_out = false;        // the last update's did: this one's first leg searches in lead pieces
};

// The midpoint of the step x0 -> x1 (position halfway, rotation half the
// relative angle, shortest way): where a leg that turns by half a turn or more
// is cut (each half then turns by at most 90 degrees), and where the halving
// schedule halves a target it cannot serve from a proven leg.
Pose split_step(const Pose& x0, const Pose& x1);

// Step 4 of a sim step, from its inputs (SimStepInfo::x_start, x_target,
// residual; M the mass matrix at x_start, *contacts the set there): info->xs
// and *contacts after the step, by the rules of docs/sim-step.md. Between
// x_start and the pose it ends at, the Cayley motion is free of contact
// (property 5) and keeps the CCD's separation at its end (property 6); the
// contact set is the one at that pose. When the first leg ends free and out of
// contact while residual != 0 (the previous contacts withheld part of the
// command and their surface fell away), a settling leg moves on by residual;
// its end is kept only when the direct motion is proven free, the first leg
// halved otherwise. Sets info's x_start, x_target, residual, settled,
// num_shortenings, ccd (the first status other than kOk over the legs of the
// last try), u_hit, num_halves, status, xs and num_contacts, and g->paths and
// g->events. Real time: no allocation; at most 5 CCDs a try (two a leg, split
// at a half turn, and one check) over 1 + kMaxSettleShortenings tries, and 3
// more out of a graze. Under a budget (RuntimeSettings::budget) the update
// ends when it runs out, at the end of what its CCDs proved free, with the
// contact set there (info's budget_exhausted and work_units; the sim loop
// measures budget_deferred).
void advance_god_object(const RuntimeModel& model, const Pose& x_start, const Pose& x_target, const Vec6& residual,
                        const Mat6& M, ContactSet* contacts, GodObjectStep* g, SimStepInfo* info) noexcept;

}  // namespace gauss6
