// Budgeted god-object updates (update_budget.h, docs/sim-step.md "Budgeted
// updates"): a budget that never runs out changes nothing, bit for bit; a
// budget that runs out ends the update on what is proven (the displayed motion
// free of contact, the pose out of contact, the contact set the one at that
// pose), repeats bit for bit in work units, and the next updates go on.
#include <catch2/catch.hpp>

#include <climits>
#include <cstring>

#include "gauss6/contact/contacts.h"
#include "gauss6/step/update_budget.h"
#include "runtime_fixtures.h"

namespace gauss6::test {
namespace {

// Pressing, sliding and twisting (as the bit-for-bit test of test_runtime.cpp):
// edge contacts, rotations, offsets.
Pose press_slide_twist(double t) {
  const double z = std::max(0.035, 0.2 - 0.5 * t);
  const double s = std::max(0.0, t - 0.35);
  return Pose{Vec3(0.05 * std::sin(3 * s), 0.03 * s, z), quat_exp(Vec3(0.2 * s, 0.1 * s, 0.8 * s))};
}

constexpr long kTicks = 800;

void run_with(const UpdateBudgetSettings& budget, Run* r, ScriptedDevice* device) {
  RuntimeSettings settings;
  settings.budget = budget;
  run(r, make_scene(-1e-4, 0.05), settings, device, kTicks);
}

bool same_pose(const Pose& a, const Pose& b) {
  return std::memcmp(a.p.data(), b.p.data(), sizeof(double) * 3) == 0 && a.q.w == b.q.w && a.q.x == b.q.x &&
         a.q.y == b.q.y && a.q.z == b.q.z;
}

// Every sim step of the two runs displayed the same pose and contacts.
int differing_steps(const Run& a, const Run& b) {
  REQUIRE(a.rec.sims.size() == b.rec.sims.size());
  int differing = 0;
  for (size_t k = 0; k < a.rec.sims.size(); ++k)
    differing += !same_pose(a.rec.sims[k].xs, b.rec.sims[k].xs) ||
                 a.rec.sims[k].num_contacts != b.rec.sims[k].num_contacts;
  return differing;
}

}  // namespace

TEST_CASE("budget: the settings are checked by name", "[runtime][budget]") {
  UpdateBudgetSettings s;
  CHECK(update_budget_settings_problem(s) == nullptr);
  CHECK_FALSE(s.active());
  s.cpu_seconds = -1;
  CHECK(std::string(update_budget_settings_problem(s)).find("cpu_seconds") != std::string::npos);
  s.cpu_seconds = std::nan("");
  CHECK(update_budget_settings_problem(s) != nullptr);
  s = {};
  s.work_units = -1;
  CHECK(std::string(update_budget_settings_problem(s)).find("work_units") != std::string::npos);
  s = {};
  s.check_interval = 0;
  CHECK(std::string(update_budget_settings_problem(s)).find("check_interval") != std::string::npos);
  RuntimeSettings bad;
  bad.budget.cpu_seconds = -1;
  CHECK_THROWS_WITH(RuntimeModel(make_scene(), bad), Catch::Contains("budget.cpu_seconds"));
}

TEST_CASE("budget: the count runs out at its units, the clock at its checks", "[runtime][budget]") {
  UpdateBudget b;
  const long w = kWorkWeight[static_cast<int>(Work::kNodePair)];
  b.start({0, 100 * w, 10});
  CHECK_FALSE(b.spend(Work::kNodePair, 99));
  CHECK(b.spend(Work::kNodePair, 1));  // 100 node pairs: spent
  CHECK(b.exhausted());
  CHECK(b.used() == 100 * w);
  CHECK(b.pieces(Work::kNodePair) == 100);
  b.start({0, 0, 10});  // none: never runs out
  CHECK(b.pieces(Work::kNodePair) == 0);
  CHECK_FALSE(b.spend(Work::kBox, LONG_MAX / 8));
  // A CPU budget already spent is found at the first check, check_interval units on, not before.
  b.start({1e-12, 0, 10});
  volatile double x = 0;
  for (int i = 0; i < 100000; ++i) x = x + 1;  // some CPU time
  CHECK_FALSE(b.spend(Work::kNodePair, 9));
  CHECK(b.spend(Work::kNodePair, 1));
}

TEST_CASE("budget: a budget that never runs out changes nothing, bit for bit", "[runtime][budget]") {
  ScriptedDevice d0(press_slide_twist), d1(press_slide_twist), d2(press_slide_twist);
  Run none, units, cpu;
  run_with({}, &none, &d0);
  run_with({0, LONG_MAX / 4, kDefaultBudgetCheckInterval}, &units, &d1);
  run_with({1000.0, 0, kDefaultBudgetCheckInterval}, &cpu, &d2);
  CHECK(differing_steps(none, units) == 0);
  CHECK(differing_steps(none, cpu) == 0);
  long max_units = 0;
  for (const SimStepInfo& s : units.rec.sims) {
    CHECK_FALSE(s.budget_exhausted);
    max_units = std::max(max_units, s.work_units);
  }
  CHECK(max_units > 0);  // counted: the work the budget below is cut from
  CHECK(units.data->stats.sim.budget.exhausted == 0);
  CHECK(none.rec.sims.back().work_units == 0);  // no budget: nothing counted
}

TEST_CASE("budget: an update out of budget ends on what is proven, and the next ones go on", "[runtime][budget]") {
  // The most work units an update of this run takes without a budget; three quarters of it runs
  // out on the landing and on the twisting slide, where the updates cost more than at rest.
  // (Below what an update at rest costs, no update could prove any motion: the god-object would
  // stay put, docs/sim-step.md "Limit".)
  ScriptedDevice d0(press_slide_twist);
  Run free_run;
  run_with({0, LONG_MAX / 4, kDefaultBudgetCheckInterval}, &free_run, &d0);
  long max_units = 0;
  for (const SimStepInfo& s : free_run.rec.sims) max_units = std::max(max_units, s.work_units);
  const UpdateBudgetSettings budget{0, max_units * 3 / 4, kDefaultBudgetCheckInterval};
  ScriptedDevice d1(press_slide_twist), d2(press_slide_twist);
  Run r, again;
  run_with(budget, &r, &d1);
  run_with(budget, &again, &d2);
  // Work units are deterministic: the same run, bit for bit.
  CHECK(differing_steps(r, again) == 0);
  const RuntimeModel& model = *r.model;
  CcdStepWorkspace ws;
  ContactWorkspace cws(model.god_mesh_B);
  ContactSet fresh(model.settings.max_contacts);
  int exhausted = 0, cut_short = 0, moved_out_of_budget = 0;
  for (const SimStepInfo& s : r.rec.sims) {
    // Every displayed pose out of the slab (its top at z = 0) by delta, less rounding.
    CHECK(lowest_z(model, s.xs) >= kDelta * (1 - 1e-3));
    if (!s.budget_exhausted) continue;
    ++exhausted;
    CHECK(s.ccd == CcdStatus::kOk);  // nothing given up
    CHECK(s.budget_deferred >= 0);  // (0: it ran out with the last piece of its work)
    cut_short += s.budget_deferred > 0;
    moved_out_of_budget += !same_pose(s.x_start, s.xs);
    // Property 5: the displayed motion is free of contact (a CCD without a budget, which never misses one).
    CcdStepResult check;
    CcdStepRequest request{s.x_start, s.xs};
    request.question = CcdQuestion::kFreeOfContact;
    ccd_step(model.obstacles.data(), static_cast<int>(model.obstacles.size()), model.god, request,
             model.settings.ccd, &ws, &check);
    CHECK(check.status == CcdStatus::kOk);
    CHECK_FALSE(check.hit);
    // The contact set is the one at that pose: a fresh search from the trees finds every pair within the
    // contact distance there, which the set holds (a set taken at a stop on contact reaches a little
    // farther: CCD's band, so it may hold more).
    generate_contacts(model.obstacles.data(), static_cast<int>(model.obstacles.size()), model.god, s.xs,
                      model.contact_generation, &cws, &fresh);
    CHECK(fresh.num_contacts <= s.num_contacts);
  }
  const BudgetStats& stats = r.data->stats.sim.budget;
  CHECK(exhausted > 10);
  CHECK(cut_short > 10);
  CHECK(stats.exhausted == exhausted);
  CHECK(moved_out_of_budget > 0);  // an update cut short still moved by what it proved
  CHECK(stats.longest_run >= 1);
  CHECK(r.data->stats.sim.event_counts[static_cast<int>(RuntimeEventKind::kUpdateBudgetExhausted)] >= 1);
  // The next updates went on: the god-object ends where the run without a budget ends, within a millimetre.
  CHECK((r.data->sim.xs.p - free_run.data->sim.xs.p).norm() < 1e-3);
}

}  // namespace gauss6::test
