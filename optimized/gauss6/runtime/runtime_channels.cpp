// Channel payloads back to poses, and the god-object snapshot's channel: its
// layout in words (runtime_channels.h).
#include "gauss6/runtime/runtime_channels.h"

#include <algorithm>
#include <cstring>
#include <type_traits>

namespace gauss6 {

namespace {

// The snapshot in words: a header (sequence, time, p, q, M, num_contacts,
// shaded), then the m rows of J, point, normal, separation, features and,
// when shaded, of Js and shaded_normal, each array in turn.
constexpr size_t kHeaderWords = 1 + 1 + 3 + 4 + 36 + 1 + 1;
constexpr size_t kFeatureWords = sizeof(FeaturePair) / sizeof(uint64_t);
constexpr size_t kWordsPerRow = 6 + 3 + 3 + 1 + kFeatureWords;
constexpr size_t kShadedWordsPerRow = 6 + 3;

size_t max_words(int capacity) {
  return kHeaderWords + static_cast<size_t>(std::max(capacity, 0)) * (kWordsPerRow + kShadedWordsPerRow);
}

static_assert(sizeof(double) == sizeof(uint64_t));
static_assert(sizeof(FeaturePair) % sizeof(uint64_t) == 0 && std::is_trivially_copyable_v<FeaturePair>);

void put(uint64_t*& w, const FeaturePair* x, size_t n) {
  std::memcpy(w, x, n * sizeof(FeaturePair));
  w += n * kFeatureWords;
}
void get(const uint64_t*& w, FeaturePair* x, size_t n) {
  std::memcpy(x, w, n * sizeof(FeaturePair));
  w += n * kFeatureWords;
}

void put(uint64_t*& w, const double* x, size_t n) {
  std::memcpy(w, x, n * sizeof(double));
  w += n;
}
void get(const uint64_t*& w, double* x, size_t n) {
  std::memcpy(x, w, n * sizeof(double));
  w += n;
}

}  // namespace

GodObjectSnapshot::GodObjectSnapshot(int max_contacts) {
  const size_t n = static_cast<size_t>(std::max(max_contacts, 0));
  J.assign(6 * n, 0.0);
  point.assign(3 * n, 0.0);
  normal.assign(3 * n, 0.0);
  separation.assign(n, 0.0);
  features.assign(n, FeaturePair{});
  Js.assign(6 * n, 0.0);
  shaded_normal.assign(3 * n, 0.0);
  wire.assign(max_words(max_contacts), 0);
}

GodObjectChannel::GodObjectChannel(int max_contacts)
    : capacity_(std::max(max_contacts, 0)), lock_(max_words(capacity_)), writer_wire_(max_words(capacity_), 0) {}

void GodObjectChannel::write(const GodObjectSnapshot& g) noexcept {
  const size_t m = static_cast<size_t>(std::clamp(g.num_contacts, 0, std::min(capacity_, g.capacity())));
  uint64_t* w = writer_wire_.data();
  *w++ = g.sequence;
  put(w, &g.time, 1);
  put(w, g.p, 3);
  put(w, g.q, 4);
  put(w, g.M, 36);
  *w++ = m;
  *w++ = g.shaded ? 1 : 0;
  put(w, g.J.data(), 6 * m);
  put(w, g.point.data(), 3 * m);
  put(w, g.normal.data(), 3 * m);
  put(w, g.separation.data(), m);
  put(w, g.features.data(), m);
  if (g.shaded) {
    put(w, g.Js.data(), 6 * m);
    put(w, g.shaded_normal.data(), 3 * m);
  }
  lock_.write(writer_wire_.data(), static_cast<size_t>(w - writer_wire_.data()));
}

bool GodObjectChannel::try_read(GodObjectSnapshot* out) const noexcept {
  if (out->capacity() < capacity_ || out->wire.size() < lock_.capacity()) return false;
  const size_t n = lock_.try_read(out->wire.data());
  if (n < kHeaderWords) return false;
  // The row count and the shading flag close the header: the payload must be
  // exactly as long as they say (it always is: the seqlock returns whole copies).
  const uint64_t* w = out->wire.data();
  const size_t m = static_cast<size_t>(w[kHeaderWords - 2]);
  const bool shaded = w[kHeaderWords - 1] != 0;
  if (m > static_cast<size_t>(capacity_) ||
      n != kHeaderWords + m * (kWordsPerRow + (shaded ? kShadedWordsPerRow : 0)))
    return false;
  GodObjectSnapshot& g = *out;
  g.sequence = *w++;
  get(w, &g.time, 1);
  get(w, g.p, 3);
  get(w, g.q, 4);
  get(w, g.M, 36);
  w += 2;
  g.num_contacts = static_cast<int32_t>(m);
  g.shaded = shaded ? 1 : 0;
  get(w, g.J.data(), 6 * m);
  get(w, g.point.data(), 3 * m);
  get(w, g.normal.data(), 3 * m);
  get(w, g.separation.data(), m);
  get(w, g.features.data(), m);
  if (shaded) {
    get(w, g.Js.data(), 6 * m);
    get(w, g.shaded_normal.data(), 3 * m);
  }
  return true;
}

}  // namespace gauss6
