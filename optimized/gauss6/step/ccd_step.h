// The mesh-level CCD step ccd_step() (METHOD.md section 4): the first contact
// between the moving god-object and the static obstacles along the in-between
// motion, over all their feature pairs, with its settings (CcdStepSettings),
// its result (CcdStepResult, the near pairs for the contact generation
// included) and its workspace (CcdStepWorkspace: the narrow phase's boxes,
// the descent's stack and its last cut (DescentFront), the candidate list,
// the god-object's swept boxes and the proximity cache), each allocated once.
//
// Frames: obstacles in the world frame W, the god-object in its body frame B
// (origin at G); swept boxes of god nodes come from the interval enclosure of
// the motion (ccd.h, motion_bounds.h): for every u in the range and every body
// point in the node's box, the world point lies in the swept box, rounding
// included.
//
// Real time: no allocation, no locks, no exceptions; fixed-capacity stacks and
// lists in the workspace, a full one reported as a status.
#pragma once

#include "gauss6/step/ccd_step_types.h"

namespace gauss6 {

// Why the settings cannot serve a step (nullptr when they can): every
// tolerance positive and finite (time_tolerance below 1, the whole window),
// min_separation and near_distance finite and >= 0, max_iterations and
// max_sub_intervals >= 1, the sub-interval bounds positive and finite, the
// proximity cache's settings valid. ccd_step refuses such a step (kInvalidInput)
// before any pair test; RuntimeModel refuses them when it is built.
const char* ccd_step_settings_problem(const CcdStepSettings& settings);

// Why the request cannot be served (nullptr when it can): known_free in [0, 1)
// and lead_sweep finite and >= 0 (hints out of range are ignored). ccd_step
// refuses such a step (kInvalidInput) before any pair test.
const char* ccd_step_request_problem(const CcdStepRequest& request);

// The first contact of the god-object moving from X0 to X1 (the Cayley motion)
// with any obstacle: u_hit <= u* over all feature pairs. Per sub-interval, the
// candidate triangle pairs get a rigorous lower bound of their first contact
// from a separating-axis bound of their distance at the sub-interval's start
// (triangle_gap_lower_bound) and a bound on the god-object's speed; pairs
// that cannot touch in time are dropped, the rest are tested earliest-first,
// each only up to (best u so far) - time_tolerance, and the step reports the
// best u less time_tolerance (so u* - u_hit grows by at most that tolerance).
// Inputs: obstacles[0 .. num_obstacles) (world frame), god (body frame; its
// radius about G, god.bvh->radius, at most kMaxCoordinate, else kInvalidInput),
// the request (the motion X0 -> X1, poses of G). Stop pose:
// make_stop_pose(result.motion, result.u_hit, god.bvh->radius) when hit (u = 1 otherwise); with narrow.min_separation = d
// its exact separation is >= d - deviation (proofs/StopPose.v, stop_pose_separation).
//
// request.hints[0 .. num_hints): feature pairs likely to touch first (the runtime
// passes the contacts at X0); their triangle pairs are tested over the whole
// step before the descent (and not again after it). A pair pressed against an
// obstacle then gives a hit near u = 0 at once, and the descent searches only
// up to it, with boxes swept over that short range: the peg pressed into the
// hole's rim, commanded a millimetre into it, no longer sweeps that millimetre
// through the hole. Any hint is a real pair, so the answer's guarantee is the
// same with or without them; out-of-range hints are ignored.
//
// With settings.cache.margin > 0, ws->cache carries candidates from one step
// to the next (proximity_cache.h): the same answer as a fresh descent, for a
// fraction of its cost while the god-object stays near a pose.
// With settings.cache.fill_budget > 0 as well, the next list is filled that
// many node pairs per step, at the pose the god-object is heading for, while
// the list in use serves.
// With settings.cache.margin = 0 and ws->lender set, the lender's list serves the
// step read-only under the same rule (the whole rest of the step or nothing).
// Asked CcdQuestion::kFreeOfContact, the step answers only whether the motion
// is free: it stops at the first hit it finds (the hints first), whose u_hit is
// not the first contact's; hit and status are the same as a first contact's at
// min_separation 0 (a hit is never taken back by a later search), so it is for
// checks, never for a stop pose.
void ccd_step(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const CcdStepRequest& request,
              const CcdStepSettings& settings, CcdStepWorkspace* ws, CcdStepResult* result) noexcept;

}  // namespace gauss6
