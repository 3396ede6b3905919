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
#include "gauss6/step/ccd_step.h"
#include "gauss6/contact/contacts.h"
#include "gauss6/runtime/runtime.h"
#include "latency.h"

namespace gauss6::bench {
namespace {

struct StopCase {
  int pair;
  Pose pose;
};

std::vector<StopCase> stop_poses(const CcdSet& set) {
  std::vector<StopCase> out;
  for_each_set_step(set, [&](const CcdSetStep& st, const CcdStepResult& r) {
    const bool stopped = r.hit && r.status != CcdStatus::kHalfTurn && r.status != CcdStatus::kInvalidInput;
    out.push_back({st.pair, stopped ? make_stop_pose(r.motion, r.u_hit, set.pairs[st.pair]->god_bvh.radius).pose : st.x1});
  });
  return out;
}

void BM_Contacts(benchmark::State& state, const std::string& set_name) {
  const CcdSet& set = ccd_set(set_name);
  const std::vector<StopCase> cases = stop_poses(set);
  ContactSettings settings;
  settings.distance = (1 + RuntimeSettings{}.contact_factor) * set.delta;  // the runtime's band
  std::vector<ContactWorkspace> ws;
  for (const auto& p : set.pairs) ws.emplace_back(p->god);
  ContactSet contacts(64);
  PerCallCounters counters("call");
  time_each(
      state, cases, &counters,
      [&](const StopCase& c) {
        const CcdMeshPair& p = *set.pairs[c.pair];
        const CcdBody obstacle = p.obstacle_body();
        generate_contacts(&obstacle, 1, p.god_body(), c.pose, settings, &ws[c.pair], &contacts);
      },
      [&](const StopCase&) {
        benchmark::DoNotOptimize(contacts.num_contacts);
        counters.add("contacts", contacts.num_contacts);
        counters.add("pairs_within", contacts.num_pairs_within);
      });
}

void register_all() {
  for (const char* s : {"peg_script", "grazing", "bunny_script"})
    register_latency("Contacts/" + std::string(s), BM_Contacts, std::string(s));
}

const int registered = (register_all(), 0);

}  // namespace
}  // namespace gauss6::bench
