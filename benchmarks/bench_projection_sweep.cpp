// Speed side of the projection's accuracy knobs (ProjectionSettings in
// quasistatics.h): feasibility_tol and dependence_tol, one swept at a time with
// the other at its default, cold solves cycling through every instance of the
// families that `gauss6 sweep` measures the error on (python/gauss6/sweeps.py:
// the same files, the same order). Counters: p50/p99/max per solve (ns), mean
// add/drop iterations, and the count of non-optimal statuses.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>
#include <vector>

#include "bench_data.h"
#include "gauss6/io/qp_instances.h"
#include "gauss6/contact/quasistatics.h"
#include "latency.h"

namespace gauss6::bench {
namespace {

// The families of python/gauss6/report_qp.py FAMILIES.
const std::vector<QpInstance>& sweep_instances() {
  static const std::vector<QpInstance> all = [] {
    std::vector<QpInstance> out;
    for (const char* f : {"box", "peg", "bunny", "inertia", "redundant", "m50", "offsets"})
      for (QpInstance& q : read_qp_instances(datasets_dir() + "/qp/" + f + ".json")) out.push_back(std::move(q));
    return out;
  }();
  return all;
}

void BM_ProjectionSweep(benchmark::State& state, double feasibility_tol, double dependence_tol) {
  const auto& instances = sweep_instances();
  ProjectionSettings settings;
  settings.warm_start = false;
  settings.compute_residuals = false;
  settings.feasibility_tol = feasibility_tol;
  settings.dependence_tol = dependence_tol;
  ProjectionResult result;
  LatencyRecorder rec;
  size_t i = 0;
  double iterations = 0, not_optimal = 0, calls = 0;
  for (auto _ : state) {
    const QpInstance& q = instances[i++ % instances.size()];
    const ProjectionProblem p = problem_of(q, q.au);
    ProjectionWorkspace ws;  // cold
    rec.time(state, [&] { project(p, settings, &ws, &result); });
    benchmark::DoNotOptimize(result.ac);
    iterations += result.iterations;
    not_optimal += result.status != ProjectionStatus::kOptimal;
    calls += 1;
  }
  rec.report(state);
  state.counters["iterations_per_solve"] = iterations / calls;
  state.counters["not_optimal_per_solve"] = not_optimal / calls;
}

std::string label(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0e", x);
  return buf;
}

void register_all() {
  const ProjectionSettings defaults;
  for (double f : {1e-15, 1e-14, 1e-13, 1e-12, 1e-10, 1e-8, 1e-6})
    benchmark::RegisterBenchmark(("ProjectionSweep/feasibility_tol:" + label(f)).c_str(), BM_ProjectionSweep, f,
                                 defaults.dependence_tol)
        ->UseManualTime();
  for (double d : {1e-14, 1e-12, 1e-10, 1e-8, 1e-6})
    benchmark::RegisterBenchmark(("ProjectionSweep/dependence_tol:" + label(d)).c_str(), BM_ProjectionSweep,
                                 defaults.feasibility_tol, d)
        ->UseManualTime();
}

const int registered = (register_all(), 0);

}  // namespace
}  // namespace gauss6::bench
