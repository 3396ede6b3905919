// Benchmarks of the bounding volume hierarchy: its build (load time) per mesh,
// and the leaf-size knob of build_bvh() as it acts on the sim loop's CCD step
// (ccd_step over every step of a datasets_generated/ccd/ set). Leaf size changes
// the traversal, not the answer's guarantee: the counter u_hit_max_diff reports
// max |u_hit(leaf) - u_hit(leaf 4)| over the set's steps, so that the sweep
// (python/gauss6/sweeps.py) can tell when a leaf size changes the error too.
// Counters: p50/p99/max per call (ns); per step: node pairs, pair tests.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "bench_data.h"
#include "gauss6/geometry/bvh.h"
#include "gauss6/step/ccd_step.h"
#include "gauss6/io/mesh_io.h"
#include "latency.h"

namespace gauss6::bench {
namespace {

const TriangleMesh& mesh(const std::string& relpath) {
  static std::map<std::string, TriangleMesh> cache;
  auto it = cache.find(relpath);
  if (it == cache.end()) it = cache.emplace(relpath, read_mesh(datasets_dir() + "/" + relpath)).first;
  return it->second;
}

// build_bvh on one mesh (the scene loader's cost per body).
void BM_BvhBuild(benchmark::State& state, const std::string& relpath, int leaf_size) {
  const TriangleMesh& m = mesh(relpath);
  LatencyRecorder rec(1 << 12);
  size_t nodes = 0;
  for (auto _ : state) {
    Bvh bvh;
    rec.time(state, [&] { bvh = build_bvh(m, leaf_size); });
    nodes = bvh.nodes.size();
    benchmark::DoNotOptimize(bvh.nodes.data());
  }
  rec.report(state);
  state.counters["triangles"] = static_cast<double>(m.F.rows());
  state.counters["nodes"] = static_cast<double>(nodes);
}

// u_hit of every step of a set at its delta (1 where no hit).
std::vector<double> step_answers(const CcdSet& set) {
  std::vector<double> u;
  for_each_set_step(set, [&](const CcdSetStep&, const CcdStepResult& r) { u.push_back(r.hit ? r.u_hit : 1.0); });
  return u;
}

// ccd_step over the set's steps in turn, BVHs built with leaf_size.
void BM_CcdStepLeafSize(benchmark::State& state, const std::string& set_name, int leaf_size) {
  const CcdSet& set = ccd_set(set_name, leaf_size);
  // Agreement with the default leaf size, checked before timing.
  const std::vector<double> u = step_answers(set), u_default = step_answers(ccd_set(set_name, 4));
  double max_diff = 0;
  for (size_t i = 0; i < u.size(); ++i) max_diff = std::max(max_diff, std::abs(u[i] - u_default[i]));
  CcdStepSettings settings;
  settings.narrow.min_separation = set.delta;
  CcdStepWorkspace ws;
  CcdStepResult r;
  PerCallCounters counters;
  time_each(
      state, set.steps, &counters, [&](const CcdSetStep& st) { run_set_step(set, st, settings, &ws, &r); },
      [&](const CcdSetStep&) {
        benchmark::DoNotOptimize(r.u_hit);
        counters.add("node_pairs", r.num_node_pairs);
        counters.add("pair_tests", r.num_pair_tests);
      });
  state.counters["u_hit_max_diff"] = max_diff;
}

void register_all() {
  for (const char* m : {"peg_in_hole/peg.off", "peg_in_hole/box_with_hole.off", "bunny/bunny.off"})
    for (int leaf : {1, 2, 4, 8, 16})
      register_latency("BvhBuild/" + std::string(m) + "/leaf:" + std::to_string(leaf), BM_BvhBuild, std::string(m),
                       leaf);
  // Sets with contacts on both meshes; iterations: a few passes over each set.
  struct Case { const char* set; int iterations; };
  for (Case c : {Case{"peg_script", 190}, Case{"random", 180}, Case{"bunny_script", 60}})
    for (int leaf : {1, 2, 4, 8, 16})
      register_latency("CcdStepLeafSize/" + std::string(c.set) + "/leaf:" + std::to_string(leaf), BM_CcdStepLeafSize,
                       std::string(c.set), leaf)
          ->Iterations(c.iterations);
}

const int registered = (register_all(), 0);

}  // namespace
}  // namespace gauss6::bench
