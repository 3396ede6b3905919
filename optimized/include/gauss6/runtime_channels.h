// What the runtime's loops send each other (runtime.h): the handle pose, the
// god-object with its contact set, and the wrench, each a plain, trivially
// copyable payload in a lock-free seqlock (shared_state.h).
//
// Frames: world frame W; poses are of G (pose.h), quaternions stored w, x, y, z.
#pragma once

#include <cstdint>

#include "gauss6/pose.h"
#include "gauss6/quasistatics.h"  // kMaxContacts
#include "gauss6/shared_state.h"

namespace gauss6 {

// ---------------------------------------------------------------------------
// Channel payloads (plain arrays: trivially copyable).
// ---------------------------------------------------------------------------

// haptic -> sim, coupling: the handle pose xh.
struct HandleSample {
  double time = 0;                     // s
  double p[3] = {0, 0, 0};
  double q[4] = {1, 0, 0, 0};          // w, x, y, z
  uint64_t tick = 0;                   // haptic tick that read it
};

// sim -> coupling: the god-object and its contact set after a sim step.
struct GodObjectSnapshot {
  uint64_t sequence = 0;               // sim step that published it (1, 2, ...)
  double time = 0;                     // s, when it was published
  double p[3] = {0, 0, 0};             // xs
  double q[4] = {1, 0, 0, 0};
  double M[36] = {};                   // 6x6 row-major, world frame at xs's orientation
  int32_t num_contacts = 0;            // m <= kMaxContacts
  double J[kMaxContacts * 6] = {};     // m x 6 row-major
  double point[kMaxContacts][3] = {};  // I_k, world frame
  double normal[kMaxContacts][3] = {}; // n_k, world frame
  double separation[kMaxContacts] = {};
  // Shaded surfaces (surface.h): the shading rows Js (m x 6 row-major) and
  // their unit normals; shaded = 0 on plain surfaces (then not filled).
  int32_t shaded = 0;
  double Js[kMaxContacts * 6] = {};
  double shaded_normal[kMaxContacts][3] = {};
};

// coupling -> sim (shaded surfaces): asc, the projection of au under Js (pass 1).
struct ShadedMotionSample {
  uint64_t god_sequence = 0;           // the snapshot (sim step) whose xs and Js it used
  double time = 0;                     // s, when it was computed
  double asc[6] = {0, 0, 0, 0, 0, 0};  // world frame, a = (aG, alpha)
};

// coupling -> haptic: the wrench Fc.
struct WrenchSample {
  double time = 0;                     // s, when it was computed
  double F[6] = {0, 0, 0, 0, 0, 0};    // force, torque about G; world frame
  double god_time = 0;                 // time of the snapshot it used (-1: none yet)
};

struct RuntimeChannels {
  SeqLock<HandleSample> handle;
  SeqLock<GodObjectSnapshot> god_object;
  SeqLock<WrenchSample> wrench;
  SeqLock<ShadedMotionSample> shaded_motion;
};

Pose to_pose(const double p[3], const double q[4]);

}  // namespace gauss6
