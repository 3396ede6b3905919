// The constraint-based coupling loop (METHOD.md section 3, as fast as
// possible): its state and its step.
//
//   coupling_step(): xh, (xs, M, J) -> au -> ac -> Fc -> publish
//
// No collision detection runs here. The step reads the handle and the latest
// god-object snapshot from RuntimeChannels, offsets the new rows of a new set
// (offsetting.h) and publishes Fc. Real time: coupling_step allocates nothing,
// locks nothing and throws nothing. Frames: world frame W; F = (force, torque about G).
#pragma once

#include <cstdint>

#include "gauss6/contact/offsetting.h"
#include "gauss6/contact/quasistatics.h"
#include "gauss6/runtime/runtime_channels.h"
#include "gauss6/runtime/runtime_events.h"
#include "gauss6/runtime/runtime_model.h"

namespace gauss6 {

// Every buffer of the coupling loop, for up to max_contacts rows
// (RuntimeSettings::max_contacts), allocated when built.
struct CouplingState {
  explicit CouplingState(int max_contacts = kDefaultMaxContacts)
      : god(max_contacts), offsets(max_contacts), projection_ws(max_contacts), projection(max_contacts) {}
  HandleSample handle;
  bool has_handle = false;
  Pose last_xh;                        // the handle at the last step with a god-object (offsets' release)
  bool has_last_xh = false;
  GodObjectSnapshot god;               // cached snapshot (xs, M, J)
  bool has_god = false;
  uint64_t god_writes = 0;             // channel writes seen (detects a new snapshot)
  Pose xs;
  Mat6 M = Mat6::Identity();
  OffsetState offsets;                 // offsets and identities of the cached rows (offsetting.h)
  ProjectionWorkspace projection_ws;
  ProjectionResult projection;
  EventGate events;                    // the coupling thread's onsets and their rate limit (runtime_events.h)
  CouplingStepInfo info;
};

// t is the run's clock (s): virtual in lockstep runs, steady_clock in threads.
// One coupling step (METHOD.md section 3). Fills and returns s->info.
const CouplingStepInfo& coupling_step(const RuntimeModel& model, double t, RuntimeChannels* channels,
                                      CouplingState* s) noexcept;

}  // namespace gauss6
