// Per-call latency recording for the benchmark suites: Google Benchmark reports
// statistics over repetitions, but a haptic loop cares about the distribution of
// single calls, so each fixture times every call (steady_clock, manual time) and
// reports the median and the 99th percentile as counters (in nanoseconds).
#pragma once

#include <algorithm>
#include <chrono>
#include <vector>

#include <benchmark/benchmark.h>

namespace gauss6::bench {

class LatencyRecorder {
 public:
  explicit LatencyRecorder(size_t capacity = 1 << 20) { samples_.reserve(capacity); }

  // Times f() once; feeds Google Benchmark's manual time and keeps the sample.
  template <class F>
  void time(benchmark::State& state, F&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    const auto t1 = std::chrono::steady_clock::now();
    const double ns = std::chrono::duration<double, std::nano>(t1 - t0).count();
    state.SetIterationTime(ns * 1e-9);
    if (samples_.size() < samples_.capacity()) samples_.push_back(ns);
  }

  // Writes p50_ns, p99_ns and max_ns counters (not averaged over threads or iterations).
  void report(benchmark::State& state) {
    if (samples_.empty()) return;
    std::sort(samples_.begin(), samples_.end());
    auto q = [&](double p) { return samples_[static_cast<size_t>(p * (samples_.size() - 1))]; };
    state.counters["p50_ns"] = benchmark::Counter(q(0.5));
    state.counters["p99_ns"] = benchmark::Counter(q(0.99));
    state.counters["max_ns"] = benchmark::Counter(samples_.back());
    samples_.clear();
  }

 private:
  std::vector<double> samples_;
};

}  // namespace gauss6::bench
