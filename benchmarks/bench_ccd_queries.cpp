// Benchmarks of the CCD narrow phase per query (ccd.h): one vertex/face or
// edge/edge test with linear per-vertex motion, on the handcrafted queries of
// ../shared/data/ccd-sample-queries (Tight-Inclusion's sample benchmark: sliding
// and resting contacts, near-parallel edges, degenerate cases), converted to
// doubles (exact for every value of that data). Per query family and kind, the
// fixture cycles through every query at the default settings (time_tolerance
// 1e-6, min_separation 0). Counters: p50/p99/max per query (ns), boxes per query,
// hits per query, and the count of queries whose ground truth is a contact that
// the test missed (must be 0: the test is conservative).
//
// CcdQueryPass/<set>/<vf|ee>/<optimized|bisection|reference>: the worst cases
// per query set (each folder of the shared data), the optimized narrow phase at
// the default settings, the same with use_u_filter = false (the box bisection
// alone, the linear queries' only method before the u-filter), and the exact
// reference (reference/ccd.h, query_toi, on the exact rationals). One
// iteration is one pass over every query of the set, each call timed; a query's
// time is its least over the passes (so a preemption of one call does not count)
// and p50/p99/max_ns are over the queries. Counters: over_100us (queries whose
// least time exceeds 100 us), cap_hits (optimized: queries that stopped at the
// box cap or a full workspace, a conservative give-up), max_boxes.
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "bench_data.h"
#include "ccd_query_data.h"
#include "gauss6/ccd/ccd.h"
#include "gauss6/io/ccd_queries.h"
#include "gauss6/reference/ccd.h"
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

// Every query of one folder of the shared data (a "set") and kind, with the
// exact rationals kept for the reference.
struct QuerySet {
  std::vector<LinearQuery> linear;
  std::vector<CcdQuery> exact;
};
QuerySet load_set(const std::string& set, CcdQuery::Kind kind) {
  QuerySet out;
  const std::string root = shared_data_dir() + "/ccd-sample-queries";
  if (!std::filesystem::is_directory(root)) return out;
  for (const CcdQueryFile& f : list_ccd_query_files(root)) {
    if (f.kind != kind || f.path.find("/" + set + "/") == std::string::npos) continue;
    for (const CcdQuery& q : read_ccd_queries(f.path, f.kind)) {
      LinearQuery l{q.kind, {}, q.expected};
      for (int k = 0; k < 8; ++k) l.p[k] = vec(q.points[k]);
      out.linear.push_back(l);
      out.exact.push_back(q);
    }
  }
  return out;
}

enum class Impl { kOptimized, kBisection, kReference };

void BM_CcdQueryPass(benchmark::State& state, const std::string& set, CcdQuery::Kind kind, Impl impl) {
  const bool reference = impl == Impl::kReference;
  const QuerySet qs = load_set(set, kind);
  const size_t n = qs.linear.size();
  if (n == 0) return state.SkipWithError("no query files (../shared/data/ccd-sample-queries)");
  CcdSettings settings;
  settings.use_u_filter = impl != Impl::kBisection;
  CcdWorkspace ws;
  CcdResult r;
  std::vector<double> least(n, std::numeric_limits<double>::infinity());
  double cap_hits = 0, max_boxes = 0, boxes = 0, misses = 0;
  int pass = 0;
  for (auto _ : state) {
    double pass_ns = 0;
    for (size_t i = 0; i < n; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      bool hit = false;
      if (reference) {
        hit = reference::query_toi(qs.exact[i]).hit;
      } else {
        run_query(qs.linear[i], settings, &ws, &r);
        hit = r.hit;
      }
      const auto t1 = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(hit);
      const double ns = std::chrono::duration<double, std::nano>(t1 - t0).count();
      pass_ns += ns;
      least[i] = std::min(least[i], ns);
      if (pass == 0) {  // counts from the first pass (the same every pass)
        misses += qs.linear[i].expected && !hit;
        if (!reference) {
          cap_hits += r.status == CcdStatus::kMaxIterations || r.status == CcdStatus::kWorkspaceFull;
          max_boxes = std::max(max_boxes, static_cast<double>(r.iterations));
          boxes += r.iterations;
        }
      }
    }
    state.SetIterationTime(pass_ns * 1e-9);
    ++pass;
  }
  LatencyRecorder rec(n);
  double over = 0;
  for (double ns : least) {
    rec.add(ns);
    over += ns > 1e5;
  }
  rec.report(state);
  state.counters["queries"] = static_cast<double>(n);
  state.counters["over_100us"] = over;
  state.counters["missed_contacts"] = misses;
  if (!reference) {
    state.counters["cap_hits"] = cap_hits;
    state.counters["max_boxes"] = max_boxes;
    state.counters["boxes_per_query"] = boxes / static_cast<double>(n);
  }
}

void register_all() {
  for (const char* set : {"unit-tests", "erleben-cube-cliff-edges", "erleben-cube-internal-edges",
                          "erleben-sliding-spike", "erleben-spike-crack", "erleben-spike-wedge", "erleben-spikes",
                          "erleben-wedges"})
    for (auto [kind, name] : {std::pair{CcdQuery::kVertexFace, "vf"}, std::pair{CcdQuery::kEdgeEdge, "ee"}})
      for (auto [impl, impl_name] : {std::pair{Impl::kOptimized, "optimized"}, std::pair{Impl::kBisection, "bisection"},
                                     std::pair{Impl::kReference, "reference"}})
        benchmark::RegisterBenchmark(("CcdQueryPass/" + std::string(set) + "/" + name + "/" + impl_name).c_str(),
                                     BM_CcdQueryPass, std::string(set), kind, impl)
            ->UseManualTime()
            ->Iterations(3)
            ->Unit(benchmark::kMillisecond);

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
