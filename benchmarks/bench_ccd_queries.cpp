// Benchmarks of the CCD narrow phase per query (ccd.h): one vertex/face or
// edge/edge test with linear per-vertex motion, on the handcrafted queries of
// ../shared/data/ccd-sample-queries (Tight-Inclusion's sample benchmark: sliding
// and resting contacts, near-parallel edges, degenerate cases), converted to
// doubles (exact for every value of that data). Per query family and kind, the
// fixture cycles through every query at the default settings (time_tolerance
// 1e-6, min_separation 0). Counters: p50/p99/max per query (ns), boxes per query,
// hits per query, and the count of queries whose ground truth is a contact that
// the test missed (must be 0: the test is conservative).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>
#include <vector>

#include "bench_data.h"
#include "ccd_query_data.h"
#include "gauss6/ccd.h"
#include "gauss6/ccd_queries.h"
#include "latency.h"

namespace gauss6::bench {
namespace {

void BM_CcdQuery(benchmark::State& state, const std::string& group, CcdQuery::Kind kind) {
  const std::vector<LinearQuery> queries = load_queries(group, kind);
  if (queries.empty()) return state.SkipWithError("no query files (../shared/data/ccd-sample-queries)");
  CcdSettings settings;
  CcdWorkspace ws;
  CcdResult r;
  // Misses of true contacts, over one pass, before timing.
  double misses = 0;
  for (const LinearQuery& q : queries) {
    run_query(q, settings, &ws, &r);
    misses += q.expected && !r.hit;
  }
  LatencyRecorder rec;
  size_t i = 0;
  double boxes = 0, hits = 0, calls = 0;
  for (auto _ : state) {
    const LinearQuery& q = queries[i++ % queries.size()];
    rec.time(state, [&] { run_query(q, settings, &ws, &r); });
    benchmark::DoNotOptimize(r.u_hit);
    boxes += r.iterations;
    hits += r.hit;
    calls += 1;
  }
  rec.report(state);
  state.counters["queries"] = static_cast<double>(queries.size());
  state.counters["boxes_per_query"] = boxes / calls;
  state.counters["hits_per_query"] = hits / calls;
  state.counters["missed_contacts"] = misses;
}

void register_all() {
  for (const char* group : {"unit-tests", "erleben-"})
    for (auto [kind, name] : {std::pair{CcdQuery::kVertexFace, "vf"}, std::pair{CcdQuery::kEdgeEdge, "ee"}})
      benchmark::RegisterBenchmark(("CcdQuery/" + std::string(group == std::string("erleben-") ? "erleben" : group) +
                                    "/" + name).c_str(),
                                   BM_CcdQuery, std::string(group), kind)
          ->UseManualTime();
}

const int registered = (register_all(), 0);

}  // namespace
}  // namespace gauss6::bench
