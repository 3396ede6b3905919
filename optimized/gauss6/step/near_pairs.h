// The near pairs: a read-only view of triangle pairs of the god-object and the
// obstacles that the CCD step lists (CcdStepResult::num_near_pairs) and the
// contact generation tests in place of a descent of the trees (contacts.h).
// The view points into its owner's storage (CcdStepWorkspace's candidates,
// which keep a time bound beside each pair) without copying, hence the stride.
//
// Header-only and dependency-free, below both the CCD step and the contacts.
#pragma once

#include <cstddef>
#include <cstdint>

namespace gauss6 {

// A god-object triangle and an obstacle triangle (obstacle: index into the
// obstacle list).
struct TrianglePair {
  int32_t god_face = -1, obstacle_face = -1, obstacle = -1;
};

// pairs[0 .. num_pairs), the k-th at byte offset k * stride from the first.
// num_pairs -1: no list (the consumer descends the trees instead).
struct NearPairs {
  const TrianglePair* pairs = nullptr;
  int num_pairs = -1;
  std::ptrdiff_t stride = sizeof(TrianglePair);  // bytes between consecutive pairs

  bool listed() const { return num_pairs >= 0; }
  const TrianglePair& operator[](int k) const {
    return *reinterpret_cast<const TrianglePair*>(reinterpret_cast<const char*>(pairs) + k * stride);
  }
};

}  // namespace gauss6
