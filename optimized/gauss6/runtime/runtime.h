// The god-object runtime: the three loops of METHOD.md sections 2-3 over an
// immutable RuntimeModel and per-loop states (MuJoCo's mjModel / mjData).
//
//   sim loop      (variable rate)  sim_step():      xh -> au -> ac -> CCD -> xs, contacts
//   coupling loop (fast)           coupling_step(): xh, (xs, M, J) -> au -> ac -> Fc
//   haptic loop   (fixed rate)     haptic_tick():   device read -> Fc -> safety -> device write
//
// The loops talk only through RuntimeChannels (lock-free seqlocks, shared_state.h).
// Two ways to run them:
//   run_lockstep(): one thread, a virtual clock and a fixed schedule; a run is
//     repeatable bit for bit (tests, replays, batch reproduction of figures);
//   run_threaded(): one std::thread per loop, the haptic loop paced by
//     sleep_until at the device's rate (real use).
//
// Units and frames: world frame W, scene units (metres in the shipped scenes),
// seconds. Poses are of G (pose.h). Accelerations a are the quasi-static per-step
// displacements (coupling.h); wrenches F = (force, torque about G), world frame.
//
// Choices the method leaves open (see sim_loop.cpp, and offsetting.cpp for the offsets, for the reasons):
//   - the sim loop regenerates the contact set at every new xs (hit or not), so
//     a god-object sliding off an edge drops that edge's rows; when the step's
//     motion (projected on the previous contacts' tangent cone) ends free and
//     out of contact while those contacts withheld part of the command, the step
//     settles: it moves on by the withheld part au - ac (CCD again), so that a
//     god-object pressed on a convex crease or a curved surface stays on it
//     (advance_god_object);
//   - the CCD stops delta before contact, and the sim loop's projection keeps
//     each contact's gap near delta (1 + gap_factor) (J_k a >= gap_target -
//     separation_k), so that sliding is never taken for a new contact; the
//     coupling loop, hence the force, uses exactly J a >= 0 (or the offsets);
//   - a row of a new set is "the same constraint" as a cached one when it
//     comes from the same feature pair (plain surfaces) (an edge/edge row whose normal turns
//     with the god-object stays the same), or its body-frame point and its
//     normal match: its offset runs on; a new row's
//     d_k is J_k ac_old, ac_old the projection on the previous set's rows (what
//     the user felt: J_k au without), so that a contact sliding across
//     triangles, whose rows change identity, is not offset again; after a set
//     with no rows, the last non-empty set stands in for it for offset_time
//     (a contact lost for a step, e.g. sliding over a crease, is not ramped again);
//   - on plain surfaces, offsets are passive: the energy an offset puts in while it relaxes under
//     a pushing row is lent, and given back when the hand backs off (its
//     right-hand side goes down, and comes up again only where its row does
//     not push), so that a release returns no more than the user put in
//     (offsetting.h; f_k rises from d_k to 0 in T while the user does not
//     back off with energy lent). Not on shaded surfaces, where the coupling's
//     projection is also the god-object's motion (coupling_loop.cpp); there,
//     too, rows are matched by point and normal only.
//   - force shading and textures are refused (RuntimeError) when the model is built.
//
// Real-time rules: sim_step, coupling_step and haptic_tick allocate nothing, lock
// nothing and throw nothing; every buffer lives in the states, built once.
// Exceptions (RuntimeError) only come from building the model.
//
// One concept a header, all included here:
//   runtime_model.h     RuntimeError, RuntimeSettings, RuntimeModel, mass_matrix_at
//   runtime_channels.h  the channel payloads and RuntimeChannels
//   runtime_events.h    event kinds, per-step records, RuntimeObserver
//   runtime_stats.h     DurationStats, LoopStats, RuntimeStats
//   sim_loop.h          SimState, sim_step, advance_god_object
//   coupling_loop.h     CouplingState, coupling_step
//   haptic_loop.h       HapticState, haptic_tick, make_safe_wrench
//   runtime.h           RuntimeData, run_lockstep, run_threaded
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <vector>

#include "gauss6/runtime/coupling_loop.h"
#include "gauss6/runtime/device_port.h"
#include "gauss6/runtime/haptic_loop.h"
#include "gauss6/runtime/runtime_channels.h"
#include "gauss6/runtime/runtime_events.h"
#include "gauss6/runtime/runtime_model.h"
#include "gauss6/runtime/runtime_stats.h"
#include "gauss6/runtime/sim_loop.h"

namespace gauss6 {

// Everything a run mutates: channels, the three states, statistics.
struct RuntimeData {
  explicit RuntimeData(const RuntimeModel& model);
  RuntimeChannels channels;
  SimState sim;
  CouplingState coupling;
  HapticState haptic;
  RuntimeStats stats;
};

// ---------------------------------------------------------------------------
// Runs.
// ---------------------------------------------------------------------------

// Deterministic lockstep run of num_ticks haptic ticks on a virtual clock
// t_k = k / rate_hz: at tick k, first a sim step when k % lockstep_sim_period
// == 0, then the haptic tick (device read, coupling step, device write). Stops
// early when the device ends. The coupling always runs in the tick.
void run_lockstep(const RuntimeModel& model, Device* device, long num_ticks, const RuntimeObserver& observer,
                  RuntimeData* data);

// Threaded run: haptic thread (sleep_until at rate_hz), sim thread, and with
// kCouplingLoop a coupling thread, for `seconds` of wall time or until *stop
// becomes true (stop may be null) or the device ends. Blocks until all joined.
// A watchdog thread guards the haptic thread: no tick ended for device_timeout
// (read() or write() blocked) -> Device::halt_force() and kHapticStalled (the
// haptic thread watches the sim and coupling threads: kSimStalled, kCouplingStalled).
// Both runs report their pending coalesced events (EventGate) when they end.
void run_threaded(const RuntimeModel& model, Device* device, double seconds, const std::atomic<bool>* stop,
                  const RuntimeObserver& observer, RuntimeData* data);

}  // namespace gauss6
