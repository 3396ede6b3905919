// Per-call latency recording for the benchmark suites: Google Benchmark reports
// statistics over repetitions, but a haptic loop cares about the distribution of
// single calls, so each fixture times every call (steady_clock, manual time) and
// reports the median and the 99th percentile as counters (in nanoseconds); and
// the functions the fixtures share (per-call counters, the timing loop, registration).
#pragma once

#include <algorithm>
#include <chrono>
#include <ctime>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>

namespace gauss6::bench {

class LatencyRecorder {
 public:
  explicit LatencyRecorder(size_t capacity = 1 << 20) { samples_.reserve(capacity); }

  // Times f() once; feeds Google Benchmark's manual time and keeps the sample.
  template <class F>
  void time(benchmark::State& state, F&& f) {
    state.SetIterationTime(sample(f) * 1e-9);
  }

  // Times f() once and keeps the sample; returns it (ns). For fixtures whose one
  // iteration is many calls (they set the iteration's time themselves).
  template <class F>
  double sample(F&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    const auto t1 = std::chrono::steady_clock::now();
    const double ns = std::chrono::duration<double, std::nano>(t1 - t0).count();
    if (samples_.size() < samples_.capacity()) samples_.push_back(ns);
    return ns;
  }

  // Keeps a sample measured elsewhere (ns).
  void add(double ns) {
    if (samples_.size() < samples_.capacity()) samples_.push_back(ns);
  }

  // Writes <prefix>p50_ns, p99_ns and max_ns counters (not averaged over threads or iterations).
  void report(benchmark::State& state, const std::string& prefix = "") {
    if (samples_.empty()) return;
    std::sort(samples_.begin(), samples_.end());
    auto q = [&](double p) { return samples_[static_cast<size_t>(p * (samples_.size() - 1))]; };
    state.counters[prefix + "p50_ns"] = benchmark::Counter(q(0.5));
    state.counters[prefix + "p99_ns"] = benchmark::Counter(q(0.99));
    state.counters[prefix + "max_ns"] = benchmark::Counter(samples_.back());
    samples_.clear();
  }

 private:
  std::vector<double> samples_;
};

// CPU time of the calling thread (ns): unlike wall time, it does not count the
// time the thread was preempted, which on a loaded machine (2 cores shared with
// builds) is what a wall-clock p99 mostly measures (a scheduler slice, ~4 ms).
inline double thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e9 * static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec);
}

// Per-call means of a fixture's counts (hits, pair tests, contacts, ...):
// add(name, value) once per call and name, report() writes name_per_<unit>.
class PerCallCounters {
 public:
  explicit PerCallCounters(std::string unit = "step") : unit_(std::move(unit)) {}
  void add(const char* name, double value) { sums_[name] += value; }
  void next_call() { ++calls_; }
  void report(benchmark::State& state) const {
    if (calls_ == 0) return;
    for (const auto& [name, sum] : sums_) state.counters[name + "_per_" + unit_] = sum / calls_;
  }

 private:
  std::string unit_;
  std::map<std::string, double> sums_;
  double calls_ = 0;
};

// The fixtures' loop: each iteration times call(item) on the next of `items`
// (round-robin), then count(item) adds that call's counts to *counters (and
// keeps its result alive); at the end, the latencies and per-call means.
template <class Item, class Call, class Count>
void time_each(benchmark::State& state, const std::vector<Item>& items, PerCallCounters* counters, Call&& call,
               Count&& count) {
  if (items.empty()) return state.SkipWithError("no items");
  LatencyRecorder rec;
  size_t i = 0;
  for (auto _ : state) {
    const Item& item = items[i++ % items.size()];
    rec.time(state, [&] { call(item); });
    count(item);
    counters->next_call();
  }
  rec.report(state);
  counters->report(state);
}

// Registers a per-call latency benchmark (manual time, shown in microseconds).
template <class... Args>
benchmark::internal::Benchmark* register_latency(const std::string& name, Args&&... args) {
  return benchmark::RegisterBenchmark(name.c_str(), std::forward<Args>(args)...)
      ->UseManualTime()
      ->Unit(benchmark::kMicrosecond);
}

}  // namespace gauss6::bench
