// Benchmarks of contact generation (generate_contacts, contacts.h): the sim loop's
// work after the CCD, at the poses where the god-object stops. The poses are the
// stop poses of the steps of datasets_generated/ccd/ sets (ccd_step at the set's
// delta, then make_stop_pose; X1 where no hit), so they lie within a few delta of
// the obstacle, as in use. Contact distance: delta (1 + 0.5), the runtime's
// default contact_factor (runtime.h). Counters: p50/p99/max per call (ns), mean
// contacts and pairs within distance per call.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "bench_data.h"
#include "gauss6/contacts.h"
#include "latency.h"

namespace gauss6::bench {
namespace {

struct StopCase {
  int pair;
  Pose pose;
};

std::vector<StopCase> stop_poses(const CcdSet& set) {
  CcdStepSettings settings;
  settings.narrow.min_separation = set.delta;
  CcdStepWorkspace ws;
  CcdStepResult r;
  std::vector<StopCase> out;
  for (const CcdSetStep& st : set.steps) {
    const CcdMeshPair& p = *set.pairs[st.pair];
    const CcdBody obstacle = p.obstacle_body();
    ccd_step(&obstacle, 1, p.god_body(), st.x0, st.x1, settings, &ws, &r);
    const bool stopped = r.hit && r.status != CcdStatus::kHalfTurn && r.status != CcdStatus::kInvalidInput;
    out.push_back({st.pair, stopped ? make_stop_pose(r.motion, r.u_hit, p.god_bvh.radius).pose : st.x1});
  }
  return out;
}

void BM_Contacts(benchmark::State& state, const std::string& set_name) {
  const CcdSet& set = ccd_set(set_name);
  const std::vector<StopCase> cases = stop_poses(set);
  ContactSettings settings;
  settings.distance = 1.5 * set.delta;
  std::vector<ContactWorkspace> ws;
  for (const auto& p : set.pairs) ws.emplace_back(p->god);
  ContactSet contacts(64);
  LatencyRecorder rec;
  size_t i = 0;
  double num_contacts = 0, num_within = 0, calls = 0;
  for (auto _ : state) {
    const StopCase& c = cases[i++ % cases.size()];
    const CcdMeshPair& p = *set.pairs[c.pair];
    const CcdBody obstacle = p.obstacle_body();
    rec.time(state, [&] { generate_contacts(&obstacle, 1, p.god_body(), c.pose, settings, &ws[c.pair], &contacts); });
    benchmark::DoNotOptimize(contacts.num_contacts);
    num_contacts += contacts.num_contacts;
    num_within += contacts.num_pairs_within;
    calls += 1;
  }
  rec.report(state);
  state.counters["contacts_per_call"] = num_contacts / calls;
  state.counters["pairs_within_per_call"] = num_within / calls;
}

void register_all() {
  for (const char* s : {"peg_script", "grazing", "bunny_script"})
    benchmark::RegisterBenchmark(("Contacts/" + std::string(s)).c_str(), BM_Contacts, std::string(s))
        ->UseManualTime()
        ->Unit(benchmark::kMicrosecond);
}

const int registered = (register_all(), 0);

}  // namespace
}  // namespace gauss6::bench
