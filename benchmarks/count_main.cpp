// gauss6_count: fixed workloads of the hot paths for load-independent counts.
//
// Each workload makes a fixed list of calls on fixed data (no timing, no
// adaptive iteration count), so that the instructions it executes do not
// depend on the machine's load. Run under callgrind,
//
//   valgrind --tool=callgrind --callgrind-out-file=OUT gauss6_count --calls CALLS.json
//
// each workload is bracketed by client requests: the statistics are zeroed
// before it and dumped after it under its name (OUT.1, OUT.2, ... with
// "desc: Trigger: Client Request: <name>"), so its instruction total excludes
// loading and set-up; CALLS.json gives each workload's number of calls, and
// instructions per call = total / calls (python/gauss6/gate.py reads both).
// Outside valgrind the requests do nothing and the program just runs.
//
//   --filter SUBSTRING    only the workloads whose name contains it
//   --plant FRACTION      a planted regression for the gate's own test: each
//                         workload repeats its first FRACTION of calls (not
//                         counted as calls), so instructions per call rise by
//                         about FRACTION
//
// Workloads:
//   CcdQuery/unit-tests, CcdQuery/erleben-sample: every unit-test query, and every
//     8th query of the erleben sets (../shared/data/ccd-sample-queries), default settings;
//   ForceCold/<family>: the cold projection of every instance of the family
//     (datasets_generated/qp/), residuals off, as bench_quasistatics.cpp;
//   CcdStep/<set>: ccd_step over every step of a datasets_generated/ccd/ set at its delta.
#include <valgrind/callgrind.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "bench_data.h"
#include "ccd_query_data.h"
#include "gauss6/io/qp_instances.h"
#include "gauss6/contact/quasistatics.h"

namespace gauss6::bench {
namespace {

struct Workload {
  std::string name;
  size_t calls;
  std::function<void(size_t)> call;  // call(i), i < calls
};

std::vector<LinearQuery> ccd_queries(const std::string& group, int every) {
  std::vector<LinearQuery> out;
  for (CcdQuery::Kind kind : {CcdQuery::kVertexFace, CcdQuery::kEdgeEdge}) {
    const std::vector<LinearQuery> all = load_queries(group, kind);
    for (size_t i = 0; i < all.size(); i += every) out.push_back(all[i]);
  }
  return out;
}

std::vector<Workload> workloads() {
  std::vector<Workload> w;
  static CcdSettings ccd_settings;
  static CcdWorkspace ccd_ws;
  static CcdResult ccd_r;
  for (auto [name, group, every] : {std::tuple{"CcdQuery/unit-tests", "unit-tests", 1},
                                    std::tuple{"CcdQuery/erleben-sample", "erleben-", 8}}) {
    auto queries = std::make_shared<std::vector<LinearQuery>>(ccd_queries(group, every));
    w.push_back({name, queries->size(), [queries](size_t i) { run_query((*queries)[i], ccd_settings, &ccd_ws, &ccd_r); }});
  }
  static ProjectionWorkspace qp_ws;
  static ProjectionResult qp_r;
  for (const char* family : {"box", "peg", "bunny", "m50"}) {
    auto inst = std::make_shared<std::vector<QpInstance>>(
        read_qp_instances(datasets_dir() + "/qp/" + family + ".json"));
    w.push_back({std::string("ForceCold/") + family, inst->size(), [inst](size_t i) {
                   const QpInstance& q = (*inst)[i];
                   ProjectionSettings s;
                   s.warm_start = false;
                   s.compute_residuals = false;
                   qp_ws.reset();
                   project(problem_of(q, q.au), s, &qp_ws, &qp_r);
                 }});
  }
  static CcdStepWorkspace step_ws;
  static CcdStepResult step_r;
  for (const char* set_name : {"peg_script", "grazing"}) {
    const CcdSet* set = &ccd_set(set_name);
    w.push_back({std::string("CcdStep/") + set_name, set->steps.size(), [set](size_t i) {
                   CcdStepSettings s;
                   s.narrow.min_separation = set->delta;
                   run_set_step(*set, set->steps[i], s, &step_ws, &step_r);
                 }});
  }
  return w;
}

int run(int argc, char** argv) {
  std::string filter, calls_path;
  double plant = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--filter" && i + 1 < argc) filter = argv[++i];
    else if (a == "--calls" && i + 1 < argc) calls_path = argv[++i];
    else if (a == "--plant" && i + 1 < argc) plant = std::atof(argv[++i]);
    else {
      std::fprintf(stderr, "usage: gauss6_count [--filter SUBSTRING] [--calls CALLS.json] [--plant FRACTION]\n");
      return 2;
    }
  }
  if (!(plant >= 0 && plant <= 1)) {
    std::fprintf(stderr, "gauss6_count: --plant must be in [0, 1]\n");
    return 2;
  }
  nlohmann::json calls = nlohmann::json::object();
  for (const Workload& w : workloads()) {
    if (!filter.empty() && w.name.find(filter) == std::string::npos) continue;
    if (w.calls == 0) {
      std::fprintf(stderr, "gauss6_count: %s: no data\n", w.name.c_str());
      return 2;
    }
    const auto extra = static_cast<size_t>(std::llround(plant * static_cast<double>(w.calls)));
    CALLGRIND_ZERO_STATS;
    for (size_t i = 0; i < w.calls; ++i) w.call(i);
    for (size_t i = 0; i < extra; ++i) w.call(i);
    CALLGRIND_DUMP_STATS_AT(w.name.c_str());
    calls[w.name] = w.calls;
  }
  if (!calls_path.empty()) {
    std::ofstream out(calls_path);
    out << calls.dump(1) << "\n";
    if (!out) {
      std::fprintf(stderr, "gauss6_count: cannot write %s\n", calls_path.c_str());
      return 2;
    }
  } else {
    std::printf("%s\n", calls.dump(1).c_str());
  }
  return 0;
}

}  // namespace
}  // namespace gauss6::bench

int main(int argc, char** argv) {
  try {
    return gauss6::bench::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gauss6_count: %s\n", e.what());
    return 2;
  }
}
