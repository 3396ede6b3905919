// What the runtime's loops send each other (runtime.h): the handle pose, the
// god-object with its contact set, and the wrench, each a plain, trivially
// copyable payload in a lock-free seqlock (shared_state.h).
//
// Frames: world frame W; poses are of G (pose.h), quaternions stored w, x, y, z.
#pragma once

#include <cstdint>
#include <vector>

#include "gauss6/geometry/feature_pair.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/contact/quasistatics.h"  // kDefaultMaxContacts
#include "gauss6/runtime/shared_state.h"

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

// Rows of 3 doubles stored contiguously (3 n doubles) seen as double[n][3].
inline double (*rows3(std::vector<double>& v))[3] { return reinterpret_cast<double (*)[3]>(v.data()); }
inline const double (*rows3(const std::vector<double>& v))[3] {
  return reinterpret_cast<const double (*)[3]>(v.data());
}

// sim -> coupling: the god-object and its contact set after a sim step. Room
// for max_contacts contacts (RuntimeSettings::max_contacts), allocated when it
// is built; the channel copies only the num_contacts rows in use.
struct GodObjectSnapshot {
  explicit GodObjectSnapshot(int max_contacts = kDefaultMaxContacts);
  int capacity() const noexcept { return static_cast<int>(separation.size()); }

  uint64_t sequence = 0;               // sim step that published it (1, 2, ...)
  double time = 0;                     // s, when it was published
  double p[3] = {0, 0, 0};             // xs
  double q[4] = {1, 0, 0, 0};
  double M[36] = {};                   // 6x6 row-major, world frame at xs's orientation
  int32_t num_contacts = 0;            // m <= capacity()
  std::vector<double> J;               // m x 6 row-major (room for capacity() rows)
  std::vector<double> point;           // m x 3: I_k, world frame (rows3() for double[m][3])
  std::vector<double> normal;          // m x 3: n_k, world frame
  std::vector<double> separation;      // m
  std::vector<FeaturePair> features;   // m: the pair each contact came from (its identity across sets)
  // Shaded surfaces (surface.h): the shading rows Js (m x 6 row-major) and
  // their unit normals (m x 3); shaded = 0 on plain surfaces (then not filled).
  int32_t shaded = 0;
  std::vector<double> Js;
  std::vector<double> shaded_normal;
  std::vector<uint64_t> wire;          // scratch of the channel's copies (capacity words of the channel)
};

// The snapshot's seqlock (SeqLockBuffer): sized for max_contacts rows when
// built; write and try_read copy the header and the rows in use, allocating
// nothing. A snapshot written or read must have at least the channel's capacity.
class GodObjectChannel {
 public:
  explicit GodObjectChannel(int max_contacts = kDefaultMaxContacts);
  int capacity() const noexcept { return capacity_; }
  // Single writer. Rows beyond the channel's capacity are not sent.
  void write(const GodObjectSnapshot& value) noexcept;
  // False (out keeps its rows, possibly partly overwritten scratch aside) when
  // nothing was written yet or every attempt raced with a write.
  bool try_read(GodObjectSnapshot* out) const noexcept;
  uint64_t num_writes() const noexcept { return lock_.num_writes(); }

 private:
  int capacity_;
  SeqLockBuffer lock_;
  std::vector<uint64_t> writer_wire_;  // the writer's scratch
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
  explicit RuntimeChannels(int max_contacts = kDefaultMaxContacts) : god_object(max_contacts) {}
  SeqLock<HandleSample> handle;
  GodObjectChannel god_object;
  SeqLock<WrenchSample> wrench;
  SeqLock<ShadedMotionSample> shaded_motion;
};


}  // namespace gauss6
