// The sim loop (METHOD.md section 2, variable rate): its state and its step.
//
//   sim_step(): xh -> au -> ac -> step 4 (sim_step4.h: CCD -> xs, contacts) -> publish
//
// The step reads the handle from RuntimeChannels and publishes the god-object
// and its contact set there (runtime_channels.h). Real time: sim_step and
// advance_god_object allocate nothing, lock nothing and throw nothing; every
// buffer lives in SimState, built once. Frames: world frame W; poses are of G.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "gauss6/contact/contacts.h"
#include "gauss6/contact/quasistatics.h"
#include "gauss6/runtime/runtime_channels.h"
#include "gauss6/runtime/runtime_events.h"
#include "gauss6/runtime/runtime_model.h"
#include "gauss6/runtime/sim_step4.h"
#include "gauss6/contact/surface.h"

namespace gauss6 {

// Every buffer of the sim loop, allocated when built, for up to
// capacity = model.settings.max_contacts contacts.
struct SimState {
  explicit SimState(const RuntimeModel& model);
  int capacity = 0;                    // contacts the buffers below hold
  Pose xs;                             // god-object pose
  Mat3 R = Mat3::Identity();           // xs's rotation, rotation_matrix(normalized(xs.q)), once a step
  Mat3 R_start = Mat3::Identity();     // the same at the step's x_start (textures: contact_travel)
  Mat6 M = Mat6::Identity();           // at R (mass_matrix)
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
  std::vector<double> held_J;          // capacity x 6; textures: the rows of step 3's kHold pass (sim_loop.cpp)
  std::vector<double> held_b;          // capacity: their right-hand sides
  GodObjectStep step4;                 // step 4's buffers (sim_step4.h)
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

// Step 4 alone: advance_god_object (sim_step4.h).

}  // namespace gauss6
