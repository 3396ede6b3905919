// Lock-free channels between the three loops (METHOD.md sections 2-3): a
// single-writer sequence lock (seqlock) over a trivially copyable payload.
//
//   sim -> coupling   : the god-object snapshot (xs, M, J, contacts, sequence)
//   coupling -> haptic: the wrench Fc
//   haptic -> others  : the handle pose xh
//
// Protocol and memory ordering (H.-J. Boehm, "Can seqlocks get along with
// programming language memory models?", MSPC 2012). The payload is stored as
// an array of std::atomic<uint64_t> words accessed with relaxed operations, so
// that a reader racing with the writer reads stale or mixed words (never
// undefined behaviour) and the sequence number tells it to retry.
//
//   writer (one thread only):            reader (any number of threads):
//     s = seq (relaxed)                     s0 = seq (acquire); odd: retry
//     seq = s + 1 (relaxed)                 words (relaxed)
//     fence(release)                        fence(acquire)
//     words (relaxed)                       s1 = seq (relaxed)
//     seq = s + 2 (release)                 s0 != s1: retry (torn)
//
// The release fence orders the odd sequence store before the payload stores;
// the final release store publishes the payload; the reader's acquire fence
// orders its payload loads before the second sequence load. A reader that sees
// s0 == s1 (even) therefore copied exactly the payload of write number s0 / 2:
// torn reads are impossible. The writer never waits (wait-free); a reader
// retries at most max_attempts times and reports failure instead of spinning
// for ever, so a real-time reader keeps its previous copy and goes on.
//
// SeqLock<T> holds a fixed-size payload; SeqLockBuffer is the same protocol
// over a run of words whose capacity is fixed when it is built (a payload sized
// by a runtime capacity, e.g. the contact set's): the words are allocated once,
// in the constructor, and each write publishes its length with them.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <memory>
#include <type_traits>

namespace gauss6 {

template <class T>
class SeqLock {
  static_assert(std::is_trivially_copyable_v<T>, "SeqLock payloads must be trivially copyable");

 public:
  static constexpr size_t kNumWords = (sizeof(T) + sizeof(uint64_t) - 1) / sizeof(uint64_t);

  SeqLock() {
    for (auto& w : words_) w.store(0, std::memory_order_relaxed);
  }
  SeqLock(const SeqLock&) = delete;
  SeqLock& operator=(const SeqLock&) = delete;

  // Publishes value. Single writer only. Wait-free, no allocation.
  void write(const T& value) noexcept {
    std::array<uint64_t, kNumWords> buf{};
    std::memcpy(buf.data(), &value, sizeof(T));
    const uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    for (size_t i = 0; i < kNumWords; ++i) words_[i].store(buf[i], std::memory_order_relaxed);
    seq_.store(s + 2, std::memory_order_release);
  }

  // Copies the latest complete value into *out and returns true; returns false
  // (leaving *out untouched) when nothing was written yet or when every one of
  // max_attempts attempts raced with a write.
  bool try_read(T* out, int max_attempts = 64) const noexcept {
    std::array<uint64_t, kNumWords> buf;
    for (int attempt = 0; attempt < max_attempts; ++attempt) {
      const uint64_t s0 = seq_.load(std::memory_order_acquire);
      if (s0 == 0) return false;   // never written
      if (s0 & 1) continue;        // write in progress
      for (size_t i = 0; i < kNumWords; ++i) buf[i] = words_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) != s0) continue;  // torn: retry
      std::memcpy(static_cast<void*>(out), buf.data(), sizeof(T));
      return true;
    }
    return false;
  }

  // Number of completed writes (cheap: one acquire load); lets a reader skip
  // the copy when nothing new was published.
  uint64_t num_writes() const noexcept { return seq_.load(std::memory_order_acquire) / 2; }

 private:
  alignas(64) std::atomic<uint64_t> seq_{0};
  alignas(64) std::array<std::atomic<uint64_t>, kNumWords> words_;
};

// The seqlock over up to capacity words (allocated here, once). write() and
// try_read() copy only the words written (their count travels with them), and
// allocate nothing.
class SeqLockBuffer {
 public:
  explicit SeqLockBuffer(size_t capacity_words)
      : capacity_(capacity_words), words_(new std::atomic<uint64_t>[capacity_words > 0 ? capacity_words : 1]) {
    for (size_t i = 0; i < capacity_; ++i) words_[i].store(0, std::memory_order_relaxed);
  }
  SeqLockBuffer(const SeqLockBuffer&) = delete;
  SeqLockBuffer& operator=(const SeqLockBuffer&) = delete;

  size_t capacity() const noexcept { return capacity_; }

  // Publishes words[0, n), n <= capacity (more are not written). Single writer only.
  void write(const uint64_t* words, size_t n) noexcept {
    n = n < capacity_ ? n : capacity_;
    const uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    length_.store(n, std::memory_order_relaxed);
    for (size_t i = 0; i < n; ++i) words_[i].store(words[i], std::memory_order_relaxed);
    seq_.store(s + 2, std::memory_order_release);
  }

  // Copies the latest complete payload into out (room for capacity() words) and
  // returns its length; returns 0 (out may hold a torn copy) when nothing was
  // written yet or when every one of max_attempts attempts raced with a write.
  size_t try_read(uint64_t* out, int max_attempts = 64) const noexcept {
    for (int attempt = 0; attempt < max_attempts; ++attempt) {
      const uint64_t s0 = seq_.load(std::memory_order_acquire);
      if (s0 == 0) return 0;       // never written
      if (s0 & 1) continue;        // write in progress
      size_t n = length_.load(std::memory_order_relaxed);
      n = n < capacity_ ? n : capacity_;  // a torn length is caught below; never read past the buffer
      for (size_t i = 0; i < n; ++i) out[i] = words_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) != s0) continue;  // torn: retry
      return n;
    }
    return 0;
  }

  uint64_t num_writes() const noexcept { return seq_.load(std::memory_order_acquire) / 2; }

 private:
  alignas(64) std::atomic<uint64_t> seq_{0};
  std::atomic<uint64_t> length_{0};
  size_t capacity_;
  std::unique_ptr<std::atomic<uint64_t>[]> words_;
};

}  // namespace gauss6
