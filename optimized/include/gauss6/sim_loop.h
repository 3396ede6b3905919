// The sim loop (METHOD.md section 2, variable rate): its state and its step.
//
//   sim_step(): xh -> au -> ac -> CCD -> xs, contacts -> publish
//
// The step reads the handle from RuntimeChannels and publishes the god-object
// and its contact set there (runtime_channels.h). Real time: sim_step and
// advance_god_object allocate nothing, lock nothing and throw nothing; every
// buffer lives in SimState, built once. Frames: world frame W; poses are of G.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "gauss6/ccd_step.h"
#include "gauss6/contacts.h"
#include "gauss6/quasistatics.h"
#include "gauss6/runtime_channels.h"
#include "gauss6/runtime_events.h"
#include "gauss6/runtime_model.h"
#include "gauss6/surface.h"

namespace gauss6 {

// Every buffer of the sim loop, allocated when built, for up to
// capacity = model.settings.max_contacts contacts.
struct SimState {
  explicit SimState(const RuntimeModel& model);
  int capacity = 0;                    // contacts the buffers below hold
  Pose xs;                             // god-object pose
  Mat6 M = Mat6::Identity();           // at xs's orientation
  ContactSet contacts;                 // the current set (capacity contacts)
  std::vector<double> gap_rhs;         // capacity: b_k = delta (1 + gap_factor) - separation_k
  ProjectionWorkspace projection_ws;
  ProjectionResult projection;
  // Shaded surfaces: the shading rows of the current set (published with J)
  // and pass 1's own projection, used when the coupling's asc is not for the last snapshot.
  std::vector<double> shaded_J;        // capacity x 6
  std::vector<double> shaded_normal;   // capacity x 3 (rows3())
  ProjectionWorkspace shading_ws;
  ProjectionResult shading;
  std::vector<double> held_J;          // capacity x 6; textures: -J_k of the contacts the command presses on
  CcdStepWorkspace ccd_ws;
  CcdStepResult ccd;
  CcdStepWorkspace check_ws;           // the settling step's check of its direct motion (advance_god_object)
  CcdStepResult check;
  std::vector<FeaturePair> ccd_hints;  // capacity: the contacts at a leg's start, tested first (ccd_step)
  double stop_deviation = 0;           // of xs from the motion's exact pose (make_stop_pose)
  // A settling step's first leg's near pairs (CcdStepResult::num_near_pairs),
  // copied before later legs reuse ccd_ws: the contact searches at the poses
  // served from that leg (a refused settle's shortened tries, keep_a_contact)
  // test them instead of descending the trees. Capacity: ccd_ws's candidates.
  std::vector<TrianglePair> proven_near;
  int num_proven_near = -1;            // -1: no list
  bool near_is_proven = false;         // ccd's near pairs index proven_near, not ccd_ws
  ContactWorkspace contact_ws;
  HandleSample handle;                 // last sample read
  GodObjectSnapshot snapshot;          // what step 5 publishes
  uint64_t step = 0;
  uint32_t step_events = 0;            // conditions found by this step (contact overflow)
  EventGate events;                    // onsets and their rate limit (runtime_events.h)
  SimStepInfo info;
};

// t is the run's clock (s): virtual in lockstep runs, steady_clock in threads.
// One sim step (METHOD.md section 2). Fills and returns s->info. Without a
// handle sample yet, the god-object stays put (and is still published).
const SimStepInfo& sim_step(const RuntimeModel& model, double t, RuntimeChannels* channels, SimState* s) noexcept;

// Step 4 of a sim step alone, from its recorded inputs (SimStepInfo::x_start,
// x_target, residual): the CCD along the Cayley motion x_start -> x_target (split
// in halves on a half turn), s->xs = its end or its stop pose (delta before the
// first contact), s->M at s->xs, and s->contacts, the contact set at s->xs. A
// first leg stopped by a graze (a contact of the last set, left inside the CCD's
// distance-tolerance band, stops it though it has not come closer) runs again
// from a waypoint that lifts the contacts to delta (1 + gap_factor), its end kept
// only when the CCD proves the direct motion x_start -> end free of contact
// (sim_loop.cpp, lift_out_of_graze). If
// that leg ends free with an empty contact set while residual != 0 (the previous
// contacts withheld part of the command, and their surface fell away under the
// linearised constraints: a convex crease or a curved surface), a settling leg
// moves on from s->xs by residual, with its own CCD and contact set, so that a
// god-object pressed against a surface follows it instead of floating off it
// for a step (which the force would show as a dropout). Each leg's motion is
// free of contact (the CCD's guarantee), and so is the motion between the two
// poses the step goes from and to: the settling leg's end is kept only when a
// CCD with min_separation 0 proves the direct Cayley motion x_start -> end free
// of contact. Otherwise the step is done again with the first leg halved
// (its own motion's pose at half the parameter, served from the first leg's
// CCD, which proved the whole motion free; split_step's when the leg was split
// at a half turn), at most kMaxSettleShortenings times; after the last,
// s->xs is the first leg's end (free, out of contact). Sets info's x_start,
// x_target, residual, settled, num_shortenings, ccd (the first status other
// than kOk over the legs of the last try), u_hit, num_halves, status and
// num_contacts. Real time: no allocation; at most 5 ccd_step calls a try (two a
// leg, one check), 20 over the 1 + kMaxSettleShortenings tries, and 3 more (a
// leg, a check) out of a graze.
constexpr int kMaxSettleShortenings = 3;
// After them, the first leg halved on (without settling) until its end keeps a contact.
constexpr int kMaxKeepHalvings = 8;
// The settling leg's first lead piece sweeps about this many times the CCD's
// reach (CcdStepSettings::lead_sweep).
constexpr double kSettleLeadSweep = 16;
void advance_god_object(const RuntimeModel& model, const Pose& x_start, const Pose& x_target, const Vec6& residual,
                        SimState* s, SimStepInfo* info) noexcept;

}  // namespace gauss6
