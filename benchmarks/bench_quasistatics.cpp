// Benchmarks of the force computation (projection + coupling wrench) per
// instance family of datasets_generated/qp/, cold and warm-started.
//   cold: a fresh workspace per call (Cholesky of M, rows A = J L^-T, no warm start);
//   warm: the coupling loop's situation: M and J cached, au drifting slightly
//         between calls, warm start from the previous active set.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "bench_data.h"
#include "gauss6/contact/coupling.h"
#include "gauss6/io/qp_instances.h"
#include "gauss6/contact/quasistatics.h"
#include "latency.h"

namespace gauss6::bench {
namespace {

const std::vector<QpInstance>& family(const std::string& name) {
  static std::map<std::string, std::vector<QpInstance>> cache;
  auto it = cache.find(name);
  if (it == cache.end())
    it = cache.emplace(name, read_qp_instances(std::string(GAUSS6_SOURCE_DIR) + "/datasets_generated/qp/" + name +
                                               ".json")).first;
  return it->second;
}

// Keeps only the instances with at most max_rows rows (max_rows < 0: all).
std::vector<const QpInstance*> select(const std::string& name, int max_rows) {
  std::vector<const QpInstance*> out;
  for (const QpInstance& q : family(name))
    if (max_rows < 0 || q.J.rows() <= max_rows) out.push_back(&q);
  return out;
}

// Force computation from a cold workspace, cycling through the family.
void BM_ForceCold(benchmark::State& state, const std::string& name, int max_rows) {
  const auto instances = select(name, max_rows);
  if (instances.empty()) return state.SkipWithError("no instances");
  LatencyRecorder rec;
  ProjectionSettings settings;
  settings.warm_start = false;
  settings.compute_residuals = false;
  ProjectionResult result;
  size_t i = 0;
  double kh = 1.0;
  for (auto _ : state) {
    const QpInstance& q = *instances[i++ % instances.size()];
    ProjectionWorkspace ws;  // cold: nothing cached
    const ProjectionProblem p = problem_of(q, q.au);
    Vec6 F;
    rec.time(state, [&] {
      project(p, settings, &ws, &result);
      F = coupling_force(q.M, q.au, result.ac, kh);
    });
    benchmark::DoNotOptimize(F);
  }
  rec.report(state);
}

// Force computation warm: per instance, a primed workspace, then calls with au
// drifting by 1e-3 relative per call (the haptic loop between two sim steps).
void BM_ForceWarm(benchmark::State& state, const std::string& name, int max_rows) {
  const auto instances = select(name, max_rows);
  if (instances.empty()) return state.SkipWithError("no instances");
  LatencyRecorder rec;
  ProjectionSettings settings;
  settings.compute_residuals = false;
  std::vector<ProjectionWorkspace> ws(instances.size());
  ProjectionResult result;
  for (size_t k = 0; k < instances.size(); ++k) project(problem_of(*instances[k], instances[k]->au), settings, &ws[k], &result);
  size_t i = 0;
  double kh = 1.0;
  for (auto _ : state) {
    const size_t k = i % instances.size();
    const QpInstance& q = *instances[k];
    const Vec6 au = q.au * (1.0 + 1e-3 * static_cast<double>((i / instances.size()) % 8));
    ++i;
    const ProjectionProblem p = problem_of(q, au);
    Vec6 F;
    rec.time(state, [&] {
      project(p, settings, &ws[k], &result);
      F = coupling_force(q.M, au, result.ac, kh);
    });
    benchmark::DoNotOptimize(F);
  }
  rec.report(state);
}

// Warm starts along the "warm" family's trajectories (au drifting, contacts fixed).
void BM_ForceWarmSequence(benchmark::State& state) {
  const auto& all = family("warm");
  std::vector<const QpInstance*> seq;
  for (const QpInstance& q : all) seq.push_back(&q);
  std::sort(seq.begin(), seq.end(), [](auto* a, auto* b) {
    return a->sequence != b->sequence ? a->sequence < b->sequence : a->step < b->step;
  });
  LatencyRecorder rec;
  ProjectionSettings settings;
  settings.compute_residuals = false;
  ProjectionWorkspace ws;
  ProjectionResult result;
  size_t i = 0;
  for (auto _ : state) {
    const QpInstance& q = *seq[i++ % seq.size()];
    const ProjectionProblem p = problem_of(q, q.au);
    Vec6 F;
    rec.time(state, [&] {
      project(p, settings, &ws, &result);
      F = coupling_force(q.M, q.au, result.ac, 1.0);
    });
    benchmark::DoNotOptimize(F);
  }
  rec.report(state);
}

void register_all() {
  struct Fam { const char* name; int max_rows; };
  for (Fam f : {Fam{"box", 12}, Fam{"peg", 12}, Fam{"bunny", 12}, Fam{"inertia", 12}, Fam{"offsets", 12},
                Fam{"redundant", 12}, Fam{"redundant", -1}, Fam{"m50", -1}}) {
    const std::string suffix = std::string(f.name) + (f.max_rows < 0 ? "/all" : "/m<=12");
    benchmark::RegisterBenchmark(("ForceCold/" + suffix).c_str(), BM_ForceCold, std::string(f.name), f.max_rows)
        ->UseManualTime();
    benchmark::RegisterBenchmark(("ForceWarm/" + suffix).c_str(), BM_ForceWarm, std::string(f.name), f.max_rows)
        ->UseManualTime();
  }
  benchmark::RegisterBenchmark("ForceWarmSequence/warm", BM_ForceWarmSequence)->UseManualTime();
}

const int registered = (register_all(), 0);

}  // namespace
}  // namespace gauss6::bench
