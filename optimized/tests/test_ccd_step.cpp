// Tests of ccd_step.h: no truly colliding triangle pair culled (against a
// brute-force all-pairs run of the narrow phase), hints, the proximity cache
// and its background fill, and ccd_step on steps with a known first contact.
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <random>
#include <set>
#include <tuple>

#include "gauss6/geometry/bvh.h"
#include "gauss6/ccd/ccd.h"
#include "gauss6/geometry/distance.h"
#include "gauss6/step/ccd_step.h"
#include "gauss6/step/update_budget.h"
#include "mesh_shapes.h"

using namespace gauss6;
using gauss6::test::concatenate;
using gauss6::test::make_box;
using gauss6::test::make_icosphere;

namespace {

// Brute force: every owned feature pair of every triangle pair over [0, 1]; the
// earliest hit and the set of triangle pairs with a hit.
struct BruteForce {
  bool hit = false;
  double u_hit = 1;
  std::set<std::pair<int, int>> hitting_pairs;
};
BruteForce brute_force(const TriangleMesh& god, const Bvh& gb, const TriangleMesh& obs, const Bvh& ob,
                       const CcdMotion& m, const CcdSettings& s) {
  BruteForce out;
  CcdWorkspace ws;
  CcdResult r;
  const auto V = [](const TriangleMesh& mesh, int f, int k) -> Vec3 { return mesh.V.row(mesh.F(f, k)).transpose(); };
  for (int gf = 0; gf < god.F.rows(); ++gf)
    for (int of = 0; of < obs.F.rows(); ++of) {
      const std::array<Vec3, 3> G = {V(god, gf, 0), V(god, gf, 1), V(god, gf, 2)};
      const std::array<Vec3, 3> O = {V(obs, of, 0), V(obs, of, 1), V(obs, of, 2)};
      bool any = false;
      double first = 2;
      const auto take = [&] {
        if (r.hit) { any = true; first = std::min(first, r.u_hit); }
      };
      for (int k = 0; k < 3; ++k) {
        if (gb.owned[gf] & (1u << k)) {
          ccd_rigid_vertex_face({&m, G[k], O, 0, 1}, s, &ws, &r);
          take();
        }
        if (ob.owned[of] & (1u << k)) {
          ccd_rigid_face_vertex({&m, O[k], G, 0, 1}, s, &ws, &r);
          take();
        }
        for (int j = 0; j < 3; ++j)
          if ((gb.owned[gf] & (8u << k)) && (ob.owned[of] & (8u << j))) {
            ccd_rigid_edge_edge({&m, {G[k], G[(k + 1) % 3]}, {O[j], O[(j + 1) % 3]}, 0, 1}, s, &ws, &r);
            take();
          }
      }
      if (any) {
        out.hitting_pairs.insert({gf, of});
        if (first < out.u_hit || !out.hit) out.u_hit = first;
        out.hit = true;
      }
    }
  return out;
}

}  // namespace

TEST_CASE("BVH: every truly colliding triangle pair is a candidate, ccd_step agrees with brute force", "[ccd_step]") {
  const TriangleMesh god = make_icosphere(1, 0.5);    // 80 triangles, body frame about G
  const TriangleMesh obs = make_box(2, 2, 1, Vec3(0, 0, -0.5));  // world frame, top at z = 0
  const TriangleMesh obs2 = make_icosphere(1, 0.4);
  const Bvh gb = build_bvh(god, 2), ob = build_bvh(obs, 2), ob2 = build_bvh(obs2, 2);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> U(-1, 1);
  CcdStepSettings settings;
  CcdStepWorkspace ws, ws_unordered(1 << 14, 1024, /*candidate_capacity=*/0);
  int hits = 0;
  for (int i = 0; i < 40; ++i) {
    const bool sphere = i % 2;
    const TriangleMesh& om = sphere ? obs2 : obs;
    const Bvh& obvh = sphere ? ob2 : ob;
    // Start above (or beside) the obstacle, end near or through it.
    const Vec3 start = sphere ? Vec3(1.2 * U(rng), 1.2 * U(rng), 1.2) : Vec3(U(rng), U(rng), 0.6 + 0.3 * std::abs(U(rng)));
    const Vec3 end = sphere ? Vec3(0.3 * U(rng), 0.3 * U(rng), 0.3 * U(rng)) : Vec3(U(rng), U(rng), 0.3 * U(rng));
    const Pose x0{start, normalized(Quat{1 + U(rng), U(rng), U(rng), U(rng)})};
    const Pose x1{end, normalized(quat_exp(Vec3(U(rng), U(rng), U(rng))) * x0.q)};
    CcdMotion m;
    REQUIRE(make_ccd_motion(x0, x1, &m) == MotionStatus::kOk);
    const BruteForce bf = brute_force(god, gb, om, obvh, m, settings.narrow);
    // Candidates over the whole step.
    MotionEnclosure e;
    enclose_motion(m, {0, 1}, &e);
    std::set<std::pair<int, int>> candidates;
    BvhStack stack;
    int node_pairs = 0;
    const auto ts = for_each_candidate_pair(
        god, gb, om, obvh, [&](const Aabb& b) { return swept_box(e, b); }, 0.0, &stack,
        [&](int gf, int of) {
          candidates.insert({gf, of});
          return true;
        },
        &node_pairs);
    REQUIRE(ts == TraversalStatus::kDone);
    for (const auto& p : bf.hitting_pairs) CHECK(candidates.count(p) == 1);
    // The mesh-level step finds the same first contact (both are lower bounds of
    // u*, each within its tolerance; 1e-5 bounds their difference).
    CcdBody ob_body{&om, &obvh};
    CcdStepResult r;
    ccd_step(&ob_body, 1, {&god, &gb}, {x0, x1}, settings, &ws, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    CHECK(r.hit == bf.hit);
    if (r.hit && bf.hit) {
      ++hits;
      CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
    }
    // Without a candidate buffer the pairs are tested in traversal order, not
    // earliest-first: the same first contact (same 1e-5 bound).
    CcdStepResult r_unordered;
    ccd_step(&ob_body, 1, {&god, &gb}, {x0, x1}, settings, &ws_unordered, &r_unordered);
    CHECK(r_unordered.hit == r.hit);
    if (r.hit && r_unordered.hit) CHECK(std::abs(r.u_hit - r_unordered.u_hit) <= 1e-5);
    // With hints (a hitting pair when there is one, a random pair, invalid
    // ones) and with a probe first: the same first contact (same 1e-5 bound).
    std::vector<FeaturePair> hints;
    FeaturePair h;
    h.obstacle = 0;
    h.god_face = static_cast<int>(rng() % god.F.rows());
    h.obstacle_face = static_cast<int>(rng() % om.F.rows());
    hints.push_back(h);
    if (!bf.hitting_pairs.empty() && i % 4 < 2) {
      h.god_face = bf.hitting_pairs.begin()->first;
      h.obstacle_face = bf.hitting_pairs.begin()->second;
      hints.push_back(h);
    }
    h.obstacle = 3;  // out of range: ignored
    hints.push_back(h);
    h.obstacle = 0;
    h.god_face = -1;
    hints.push_back(h);
    CcdStepSettings probing = settings;
    probing.cache.margin = i % 3 == 0 ? 0.0 : 0.01;
    CcdStepResult r_hinted;
    ccd_step(&ob_body, 1, {&god, &gb}, {x0, x1, hints.data(), static_cast<int>(hints.size())}, probing, &ws, &r_hinted);
    REQUIRE(r_hinted.status == CcdStatus::kOk);
    CHECK(r_hinted.hit == bf.hit);
    if (r_hinted.hit && bf.hit) CHECK(std::abs(r_hinted.u_hit - bf.u_hit) <= 1e-5);
    // The first sub-interval searched in lead pieces (CcdStepRequest::lead_sweep,
    // with and without a reach to scale it): other windows, the same first
    // contact (same 1e-5 bound). Every motion here sweeps far more than the
    // first piece may, so pieces are planned.
    CcdStepSettings leading = i % 3 == 0 ? settings : probing;
    leading.narrow.min_separation = i % 2 ? 0.0 : 1e-4;
    CcdStepRequest lead_request{x0, x1, i % 2 ? hints.data() : nullptr, i % 2 ? static_cast<int>(hints.size()) : 0};
    lead_request.lead_sweep = i % 3 == 0 ? 1.0 : (i % 3 == 1 ? 4.0 : 16.0);
    CcdStepResult r_lead;
    ccd_step(&ob_body, 1, {&god, &gb}, lead_request, leading, &ws, &r_lead);
    REQUIRE(r_lead.status == CcdStatus::kOk);
    CHECK(r_lead.num_sub_intervals > r.num_sub_intervals);
    if (leading.narrow.min_separation == 0) {
      CHECK(r_lead.hit == bf.hit);
      if (r_lead.hit && bf.hit) CHECK(std::abs(r_lead.u_hit - bf.u_hit) <= 1e-5);
    } else {
      // Within 1e-4 no later than the first contact; kept 1e-4 apart, no contact.
      if (r_lead.hit && bf.hit) CHECK(r_lead.u_hit <= bf.u_hit + 1e-5);
      if (!r_lead.hit) CHECK_FALSE(bf.hit);
    }
  }
  CHECK(hits >= 10);
}

TEST_CASE("ccd_step: a hint's pair is not searched twice, and a pair sharing one face with a hint is", "[ccd_step]") {
  // Hints that do not hit, each sharing one face with a pair that does (the
  // god face with another obstacle face, or the obstacle face with another
  // god face): the step searches the hints over the whole step first, then
  // skips exactly those pairs later. Skipping by one face alone would drop the
  // hitting pairs and stop late or not at all: the brute force's first contact
  // (the 1e-5 bound of the tests above) must still be found. Also on a
  // workspace whose last step was stopped by one of the hints (first, in the
  // middle, or last of them), which is then searched first
  // (CcdStepWorkspace::last_hit) and the rest in their order.
  const TriangleMesh god = make_icosphere(1, 0.5);
  const TriangleMesh obs = make_icosphere(1, 0.4);
  const Bvh gb = build_bvh(god, 2), ob = build_bvh(obs, 2);
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> U(-1, 1);
  CcdStepSettings settings;
  CcdStepWorkspace ws;
  const CcdBody ob_body{&obs, &ob};
  int checked = 0;
  for (int i = 0; i < 30; ++i) {
    const Pose x0{Vec3(1.2 * U(rng), 1.2 * U(rng), 1.2), normalized(Quat{1 + U(rng), U(rng), U(rng), U(rng)})};
    const Pose x1{Vec3(0.3 * U(rng), 0.3 * U(rng), 0.3 * U(rng)),
                  normalized(quat_exp(Vec3(U(rng), U(rng), U(rng))) * x0.q)};
    CcdMotion m;
    REQUIRE(make_ccd_motion(x0, x1, &m) == MotionStatus::kOk);
    const BruteForce bf = brute_force(god, gb, obs, ob, m, settings.narrow);
    if (!bf.hit) continue;
    std::vector<FeaturePair> hints;
    // The first pair pair_of(k), k = 1, 2, ..., that never comes within d.
    const auto add_free = [&](int n, const auto& pair_of) {
      for (int k = 1; k < n; ++k) {
        const auto [g, o] = pair_of(k);
        if (bf.hitting_pairs.count({g, o})) continue;
        hints.push_back({PairKind::kEdgeEdge, 0, g, 0, o, 0});
        return;
      }
    };
    const int num_god = static_cast<int>(god.F.rows()), num_obs = static_cast<int>(obs.F.rows());
    for (const auto& pair : bf.hitting_pairs) {
      const int gf = pair.first, of = pair.second;  // not a structured binding: clang 14 cannot capture one
      add_free(num_obs, [&](int k) { return std::pair<int, int>{gf, (of + k) % num_obs}; });  // the god face's
      add_free(num_god, [&](int k) { return std::pair<int, int>{(gf + k) % num_god, of}; });  // the obstacle face's
    }
    // Every other step, a hitting pair among them too (so the lead may hit).
    if (i % 2 == 0) {
      const auto [gf, of] = *bf.hitting_pairs.begin();
      hints.insert(hints.begin() + static_cast<long>(hints.size() / 2), FeaturePair{PairKind::kEdgeEdge, 0, gf, 0, of, 0});
    }
    CcdStepResult r;
    ws.last_hit = FeaturePair{};
    ccd_step(&ob_body, 1, {&god, &gb}, {x0, x1, hints.data(), static_cast<int>(hints.size())}, settings, &ws, &r);
    INFO("step " << i << ", " << hints.size() << " hints");
    REQUIRE(r.status == CcdStatus::kOk);
    CHECK(r.hit);
    CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
    for (const size_t lead : {size_t{0}, hints.size() / 2, hints.size() - 1}) {
      ws.last_hit = hints[lead];
      ccd_step(&ob_body, 1, {&god, &gb}, {x0, x1, hints.data(), static_cast<int>(hints.size())}, settings, &ws, &r);
      INFO("last hit: hint " << lead);
      REQUIRE(r.status == CcdStatus::kOk);
      CHECK(r.hit);
      CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
    }
    ++checked;
  }
  CHECK(checked >= 10);
}

TEST_CASE("ccd_step: steps served by the proximity cache find the first contact of a fresh search", "[ccd_step]") {
  // A ball kept near a slab with a block standing on it, by a chain of steps
  // each from the last one's stop pose, as the runtime's are: small jitters
  // (within the margin: served from the cache), presses into the slab or the
  // block (hits), and every tenth step a long move (the cache is refilled
  // where the next step starts in contact). Each step must agree with the
  // brute force (the same 1e-5 bound as above) and with a step on a workspace
  // without the cache. Run with the cache refilled at once, refilled in the
  // background a few node pairs per step (cache.fill_budget: the served steps
  // then take their pairs from a list that was completed steps after the pose
  // it holds), with margins that follow the speed (cache.margin_max), and with
  // fills a step needs cut to a few node pairs a step (cache.fill_at_once: the
  // steps descend the trees until the list is complete, then take it; the
  // first list too), and with margins capped at a fraction of the triangles'
  // size (cache.triangle_margin: each list's margin is then that cap).
  const TriangleMesh god = make_icosphere(1, 0.5);
  const TriangleMesh slab = concatenate(make_box(3, 3, 1, Vec3(0, 0, -0.5)), make_box(0.4, 0.4, 0.6, Vec3(0.6, 0, 0.3)));
  const Bvh gb = build_bvh(god, 2), sb = build_bvh(slab, 2);
  const long whole = std::numeric_limits<long>::max();  // every fill at once
  const double uncapped = ProximityCacheSettings{}.triangle_margin;
  for (const auto [budget, margin_max, at_once, triangle_margin] :
       {std::tuple{0L, 0.0, whole, uncapped}, std::tuple{12L, 0.0, whole, uncapped},
        std::tuple{12L, 0.06, whole, uncapped}, std::tuple{12L, 0.06, 5L, uncapped}, std::tuple{0L, 0.0, 5L, uncapped},
        std::tuple{12L, 0.06, whole, 0.02}}) {
  INFO("cache_fill_budget " << budget << ", cache_margin_max " << margin_max << ", cache_fill_at_once " << at_once
                            << ", cache_triangle_margin " << triangle_margin);
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> U(-1, 1);
  CcdStepSettings settings, plain;
  settings.narrow.min_separation = plain.narrow.min_separation = 1e-4;
  settings.cache.margin = 0.02;
  settings.cache.fill_budget = budget;
  settings.cache.margin_max = margin_max;
  settings.cache.fill_at_once = at_once;
  settings.cache.triangle_margin = triangle_margin;
  CcdStepWorkspace ws, ws_plain;
  const CcdBody obstacle{&slab, &sb};
  Pose x{Vec3(0.1, 0, 0.5 + 0.01), Quat{}};  // 1 cm above the slab
  std::vector<FeaturePair> hints;
  int served = 0, fills = 0, refills = 0, hits = 0, gave_up = 0;
  for (int k = 0; k < 120; ++k) {
    Vec3 dp = 0.003 * Vec3(U(rng), U(rng), U(rng));
    Vec3 turn = 0.004 * Vec3(U(rng), U(rng), U(rng));
    if (k % 3 == 2) dp += Vec3(0.01 * U(rng), 0.01 * U(rng), -0.02);  // press down
    if (k % 10 == 9) dp += Vec3(0.15 * U(rng), 0.15 * U(rng), 0.05), turn *= 20;  // a long move
    Pose target{x.p + dp, normalized(quat_exp(turn) * x.q)};
    // Keep the ball over the slab, away from its far edges.
    target.p.x() = std::clamp(target.p.x(), -0.3, 0.3);
    target.p.y() = std::clamp(target.p.y(), -1.0, 1.0);
    CcdStepResult r, r_plain;
    ccd_step(&obstacle, 1, {&god, &gb}, {x, target, hints.data(), static_cast<int>(hints.size())}, settings, &ws, &r);
    ccd_step(&obstacle, 1, {&god, &gb}, {x, target}, plain, &ws_plain, &r_plain);
    INFO("step " << k);
    CcdMotion m;
    REQUIRE(make_ccd_motion(x, target, &m) == MotionStatus::kOk);
    const BruteForce bf = brute_force(god, gb, slab, sb, m, settings.narrow);
    if (r.status == CcdStatus::kMaxIterations || r_plain.status == CcdStatus::kMaxIterations) {
      // A pair sliding at about d exhausts the bisection: a conservative hit,
      // never later than the brute force's (which then gives up too).
      ++gave_up;
      CHECK(r.hit);
      CHECK(r.u_hit <= bf.u_hit + 1e-5);
    } else {
      REQUIRE(r.status == CcdStatus::kOk);
      REQUIRE(r_plain.status == CcdStatus::kOk);
      CHECK(r.hit == bf.hit);
      CHECK(r_plain.hit == bf.hit);
      if (r.hit && bf.hit) CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
      if (r.hit && r_plain.hit) CHECK(std::abs(r.u_hit - r_plain.u_hit) <= 1e-5);
    }
    served += r.u_cached > 0;
    fills += r.cache_filled;
    refills += r.cache_refilled;
    hits += r.hit;
    // The capped lists' margin: the cap (here below the smallest margin asked).
    if (triangle_margin != uncapped && ws.cache.num_pairs >= 0) {
      REQUIRE(ws.cache.triangle_size > 0);
      REQUIRE(triangle_margin * ws.cache.triangle_size < settings.cache.margin);
      CHECK(ws.cache.margin == triangle_margin * ws.cache.triangle_size);
    }
    // The next step starts at this one's stop pose, lifted by 3 d (a motion
    // sliding at exactly d is undecidable at the default distance tolerance);
    // the pair that stopped it is its hint (the runtime passes the contacts there).
    x = make_stop_pose(r.motion, r.u_hit, gb.radius).pose;
    x.p.z() += 3e-4;
    hints.clear();
    if (r.hit) hints.push_back(r.pair);
  }
  std::printf("proximity cache (fill budget %ld, margins up to %g, %ld node pairs at once): %d of 120 steps served "
              "from it, %d fills, %d background refills, %d hits, %d give-ups\n", budget,
              std::max(margin_max, settings.cache.margin), at_once, served, fills, refills, hits, gave_up);
  CHECK(gave_up <= 6);
  CHECK(hits >= 20);
  if (triangle_margin != uncapped) {
    CHECK(served >= 10);
  } else if (at_once == whole) {
    CHECK(served >= 30);
    CHECK(fills >= 3);
    if (budget == 0) CHECK(refills == 0);
  } else if (budget > 0) {
    CHECK(refills >= 1);  // lists cut short, completed at later steps and put in use
  }
  }
}

// The settings of the background-fill tests below: the cache's margin, the
// widest a list's may grow to, and the fill's node pairs per step.
static CcdStepSettings background_fill_settings(double margin, double margin_max, long fill_budget) {
  CcdStepSettings settings;
  settings.narrow.min_separation = 1e-4;
  settings.cache.margin = margin;
  settings.cache.margin_max = margin_max;
  settings.cache.fill_budget = fill_budget;
  return settings;
}

// A hint that only tells ccd_step the step starts in contact (the cache
// serves only such steps).
static FeaturePair in_contact_hint() {
  FeaturePair hint;
  hint.obstacle = 0;
  hint.god_face = hint.obstacle_face = 0;
  return hint;
}

// The most triangles a leaf of the tree holds.
static long largest_leaf(const Bvh& bvh) {
  long most = 0;
  for (const BvhNode& n : bvh.nodes) most = std::max(most, static_cast<long>(n.count));
  return most;
}

TEST_CASE("ccd_step: the fills at once of one update share its fill_at_once work units, the first list's too",
          "[ccd_step][budget]") {
  // A ball resting 2e-4 above a slab (a hint given, as in contact), each
  // update a jitter well within the margin: the first step needs a list and
  // finds none. Each update is one call that opens it (fill_cache) and two
  // that do not, all three needing the list until it is complete: together
  // they fill at most fill_at_once work units of it, node pairs and their
  // triangle pairs' gap bounds at update_budget.h's weights (the first call
  // all of them, the others none), and at most one leaf pair's triangle pairs
  // beyond (a node pair's visit is not split), without a background fill,
  // until one puts it in use; meanwhile each step descends the trees and
  // agrees with the brute force. At 4 units the fill's first node pairs are
  // inner ones; at 40 it reaches leaf pairs, whose triangle pairs a bound of
  // node pairs would leave uncounted (40 node pairs spend more than 40 + the
  // overrun units here). Without an update budget (one call) and under one
  // that never runs out (the fill in chunks, each charged to it).
  const TriangleMesh god = make_icosphere(1, 0.5);
  double z_min = 1e300;
  for (Eigen::Index v = 0; v < god.V.rows(); ++v) z_min = std::min(z_min, god.V(v, 2));
  const TriangleMesh slab = make_box(3, 3, 1, Vec3(0, 0, -0.5));
  const Bvh gb = build_bvh(god, 2), sb = build_bvh(slab, 2);
  const long overrun = work_units(Work::kTrianglePair, largest_leaf(gb) * largest_leaf(sb));
  const CcdBody obstacle{&slab, &sb};
  const FeaturePair hint = in_contact_hint();
  const Pose x{Vec3(0, 0, 2e-4 - z_min), Quat{}};
  for (const auto [at_once, budgeted] : {std::pair{4L, false}, std::pair{40L, false}, std::pair{40L, true}}) {
    INFO("fill_at_once " << at_once << (budgeted ? ", under a budget that never runs out" : ""));
    CcdStepSettings settings = background_fill_settings(0.03, 0, 0);
    settings.cache.fill_at_once = at_once;
    CcdStepWorkspace ws;
    UpdateBudget never_out;
    if (budgeted) ws.budget = &never_out;
    long filled = 0, largest = 0;
    int updates = 0, with_triangle_pairs = 0;
    bool in_use = false;
    for (; updates < 2000 && !in_use; ++updates) {
      INFO("update " << updates);
      never_out.start({0, std::numeric_limits<long>::max() / 4, kDefaultBudgetCheckInterval});
      long node_pairs = 0, units = 0;
      for (int call = 0; call < 3 && !in_use; ++call) {
        const Pose target{x.p + Vec3(1e-4 * (call + 1), 5e-5 * (updates % 3), 0), x.q};
        CcdStepRequest request{x, target, &hint, 1};
        request.fill_cache = call == 0;
        CcdStepResult r;
        ccd_step(&obstacle, 1, {&god, &gb}, request, settings, &ws, &r);
        REQUIRE(r.status == CcdStatus::kOk);
        CcdMotion m;
        REQUIRE(make_ccd_motion(x, target, &m) == MotionStatus::kOk);
        const BruteForce bf = brute_force(god, gb, slab, sb, m, settings.narrow);
        CHECK(r.hit == bf.hit);
        CHECK_FALSE(r.cache_filled);  // never whole at once
        if (call > 0) CHECK(r.num_fill_node_pairs == 0);
        node_pairs += r.num_fill_node_pairs;
        units += work_units(Work::kNodePair, r.num_fill_node_pairs) +
                 work_units(Work::kTrianglePair, r.num_fill_triangle_pairs);
        with_triangle_pairs += r.num_fill_triangle_pairs > 0;
        in_use = r.cache_refilled;
      }
      CHECK(units <= at_once + overrun);
      largest = std::max(largest, units);
      filled += node_pairs;
    }
    CHECK(in_use);
    CHECK(updates > 1);
    CHECK(filled == ws.cache.fill_cost);
    CHECK(ws.cache.num_pairs > 0);
    CHECK(largest >= at_once);  // each update spends its allowance until the fill completes
    if (at_once > overrun) CHECK(with_triangle_pairs > 0);
  }
}

TEST_CASE("ccd_step: a ball sliding on a slab into a wall, its cache refilled in the background", "[ccd_step]") {
  // The ball slides 2e-4 above a slab (a hint given, as in contact) towards a
  // wall, 4 mm a step, with the cache refilled in the background a few node
  // pairs per step: each list is filled at a pose ahead of the ball and put
  // in use steps later. The wall comes within reach of pairs that were not in
  // the lists before; every step must still agree with the brute force, and
  // the step that meets the wall must stop where it does. (The test below,
  // with the ball wandering, also checks what each list holds.)
  // Run with every list's margin 3 cm, and with margins up to 8 cm sized to
  // the ball's speed (cache.margin_max; the ball then slides 8 mm a step).
  const TriangleMesh god = make_icosphere(1, 0.5);
  double z_min = 1e300, x_max = -1e300;
  for (Eigen::Index v = 0; v < god.V.rows(); ++v) {
    z_min = std::min(z_min, god.V(v, 2));
    x_max = std::max(x_max, god.V(v, 0));
  }
  const double wall_x = x_max + 0.25;
  const TriangleMesh scene = concatenate(make_box(3, 3, 1, Vec3(0, 0, -0.5)), make_box(0.2, 2, 1, Vec3(wall_x + 0.1, 0, 0.5)));
  const Bvh gb = build_bvh(god, 2), sb = build_bvh(scene, 2);
  for (const double margin_max : {0.0, 0.08}) {
  INFO("cache_margin_max " << margin_max);
  const CcdStepSettings settings = background_fill_settings(0.03, margin_max, 6);
  CcdStepWorkspace ws;
  const CcdBody obstacle{&scene, &sb};
  const FeaturePair hint = in_contact_hint();
  Pose x{Vec3(0, 0, 2e-4 - z_min), Quat{}};
  int served = 0, refills = 0, steps = 0;
  bool met_wall = false;
  for (; steps < 100 && !met_wall; ++steps) {
    const Pose target{x.p + Vec3(margin_max > 0 ? 0.008 : 0.004, 0, 0), x.q};
    CcdStepResult r;
    ccd_step(&obstacle, 1, {&god, &gb}, {x, target, &hint, 1}, settings, &ws, &r);
    INFO("step " << steps);
    REQUIRE(r.status == CcdStatus::kOk);
    CcdMotion m;
    REQUIRE(make_ccd_motion(x, target, &m) == MotionStatus::kOk);
    const BruteForce bf = brute_force(god, gb, scene, sb, m, settings.narrow);
    REQUIRE(r.hit == bf.hit);
    if (r.hit) CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
    served += r.u_cached > 0;
    refills += r.cache_refilled;
    met_wall = r.hit;
    x = target;
  }
  std::printf("sliding into a wall (margins up to %g): %d steps, %d served from the cache, %d background refills\n",
              std::max(margin_max, settings.cache.margin), steps, served, refills);
  CHECK(met_wall);
  CHECK(served >= steps / 2);
  CHECK(refills >= 3);
  }
}

TEST_CASE("ccd_step: a ball wandering among blocks, lists filled ahead of it in the background", "[ccd_step]") {
  // The ball wanders 2e-4 above a slab studded with blocks (a hint given, as
  // in contact), its velocity turning a little each step and its speed
  // between 1 and 12 mm a step, now and then reversing: the lists filled ahead
  // of it (cache.fill_budget) are sometimes where it goes and sometimes not,
  // and their margins follow its speed (cache.margin_max). A step that meets
  // a block stops there, and the next starts from the stop pose. Every step
  // must agree with the brute force, and every tenth step the list in use
  // must hold the pairs its margin promises.
  const TriangleMesh god = make_icosphere(1, 0.25);
  double z_min = 1e300;
  for (Eigen::Index v = 0; v < god.V.rows(); ++v) z_min = std::min(z_min, god.V(v, 2));
  TriangleMesh scene = make_box(4, 4, 1, Vec3(0, 0, -0.5));
  for (int i = -2; i <= 2; ++i)
    for (int j = -2; j <= 2; ++j)
      if (i != 0 || j != 0) scene = concatenate(scene, make_box(0.12, 0.12, 0.1, Vec3(0.55 * i, 0.55 * j, 0.05)));
  const Bvh gb = build_bvh(god, 2), sb = build_bvh(scene, 2);
  const CcdStepSettings settings = background_fill_settings(0.02, 0.06, 30);
  CcdStepWorkspace ws;
  const CcdBody obstacle{&scene, &sb};
  const FeaturePair hint = in_contact_hint();
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> U(-1, 1);
  const double z = 2e-4 - z_min;
  Pose x{Vec3(0.15, 0.1, z), Quat{}};
  double heading = 0.8;
  int served = 0, refills = 0, hits = 0;
  double widest = 0;  // the widest margin of a list checked
  for (int k = 0; k < 250; ++k) {
    heading += 0.15 * U(rng);
    if (k % 80 == 79) heading += 3.0;  // turn back
    const double speed = 0.001 + 0.011 * (0.5 + 0.5 * std::sin(k / 15.0));
    Vec3 p = x.p + speed * Vec3(std::cos(heading), std::sin(heading), 0);
    p.z() = z;
    if (std::abs(p.x()) > 1.5 || std::abs(p.y()) > 1.5) heading += 3.0, p = x.p;  // keep over the slab
    const Pose target{p, normalized(quat_exp(Vec3(0, 0, 0.02 * U(rng))) * x.q)};
    CcdStepResult r;
    ccd_step(&obstacle, 1, {&god, &gb}, {x, target, &hint, 1}, settings, &ws, &r);
    INFO("step " << k);
    CcdMotion m;
    REQUIRE(make_ccd_motion(x, target, &m) == MotionStatus::kOk);
    const BruteForce bf = brute_force(god, gb, scene, sb, m, settings.narrow);
    if (r.status == CcdStatus::kMaxIterations) {
      CHECK(r.hit);
      CHECK(r.u_hit <= bf.u_hit + 1e-5);
    } else {
      REQUIRE(r.status == CcdStatus::kOk);
      REQUIRE(r.hit == bf.hit);
      if (r.hit) CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
    }
    served += r.u_cached > 0;
    refills += r.cache_refilled;
    hits += r.hit;
    if (k % 10 == 0 && ws.cache.num_pairs >= 0) {
      // The list in use holds every pair within its reach plus its margin at
      // its pose: here, every pair with two corners that close.
      const ProximityCache& pc = ws.cache;
      std::set<std::pair<int, int>> listed;
      for (int i = 0; i < pc.num_pairs; ++i) listed.insert({pc.pairs[i].god_face, pc.pairs[i].obstacle_face});
      const double within = (pc.reach + pc.margin) * (1 - 1e-9);
      widest = std::max(widest, pc.margin);
      for (Eigen::Index gf = 0; gf < god.F.rows(); ++gf)
        for (Eigen::Index of = 0; of < scene.F.rows(); ++of) {
          double d = 1e300;
          for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
              d = std::min(d, (transform_point(pc.ref, god.V.row(god.F(gf, a)).transpose()) -
                               scene.V.row(scene.F(of, b)).transpose()).norm());
          if (d <= within) CHECK(listed.count({static_cast<int>(gf), static_cast<int>(of)}) == 1);
        }
    }
    if (r.hit) {
      x = make_stop_pose(r.motion, r.u_hit, gb.radius).pose;
      x.p.z() = z;
      heading += 3.0;  // bounce back
    } else {
      x = target;
    }
  }
  std::printf("wandering among blocks: %d of 250 steps served from the cache, %d background refills, %d hits, "
              "margins up to %g\n", served, refills, hits, widest);
  CHECK(widest > 1.5 * settings.cache.margin);
  CHECK(served >= 125);
  CHECK(refills >= 8);
  CHECK(hits >= 5);
}

TEST_CASE("ccd_step: a step served read-only from another workspace's list agrees with the brute force", "[ccd_step]") {
  // The runtime's check of a settling step's direct motion (sim_loop.cpp,
  // motion_free): min_separation 0, no cache of its own, the legs' list
  // borrowed (CcdStepWorkspace::lender). A ball kept near a slab with a
  // block on it by the legs' chain of steps (cached, as the runtime's), and
  // after each leg a check step from the leg's start to a pose nearby (in
  // the list's margin or, every fifth step, far beyond it) that must agree
  // with the brute force at min_separation 0 and with a check on a workspace
  // of its own, and must leave the borrowed list as it was. Served: when
  // the list is for the same bodies, a reach at least the check's, and a
  // margin that covers the check's motion; a list for another reach or
  // another mesh is never served. Asked as a yes/no question (kFreeOfContact), the
  // check gives the same answer with no more work.
  const TriangleMesh god = make_icosphere(1, 0.5);
  const TriangleMesh slab = concatenate(make_box(3, 3, 1, Vec3(0, 0, -0.5)), make_box(0.4, 0.4, 0.6, Vec3(0.6, 0, 0.3)));
  const TriangleMesh other = make_box(3, 3, 1, Vec3(0, 0, -0.5));
  const Bvh gb = build_bvh(god, 2), sb = build_bvh(slab, 2), ob = build_bvh(other, 2);
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> U(-1, 1);
  CcdStepSettings legs, check;
  legs.narrow.min_separation = 1e-4;
  legs.near_distance = 1.7e-4;
  legs.cache.margin = 0.02;
  legs.cache.margin_max = 0.06;
  legs.cache.fill_budget = 12;
  check.narrow.min_separation = 0;
  CcdStepWorkspace ws, ws_check, ws_alone, ws_any;
  ws_check.lender = ws_any.lender = &ws;
  const CcdBody obstacle{&slab, &sb};
  Pose x{Vec3(0.1, 0, 0.5 + 2e-4), Quat{}};
  std::vector<FeaturePair> hints = {in_contact_hint()};
  int served = 0, checks_hit = 0, shorter = 0;
  for (int k = 0; k < 150; ++k) {
    Vec3 dp = 0.003 * Vec3(U(rng), U(rng), U(rng));
    const Vec3 turn = 0.004 * Vec3(U(rng), U(rng), U(rng));
    if (k % 3 == 2) dp += Vec3(0.01 * U(rng), 0.01 * U(rng), -0.02);  // press down
    Pose target{x.p + dp, normalized(quat_exp(turn) * x.q)};
    target.p.x() = std::clamp(target.p.x(), -0.3, 0.3);
    target.p.y() = std::clamp(target.p.y(), -1.0, 1.0);
    CcdStepResult leg;
    ccd_step(&obstacle, 1, {&god, &gb}, {x, target, hints.data(), static_cast<int>(hints.size())}, legs, &ws, &leg);
    // The check: from the leg's start to its end moved a little further
    // down (into the slab on some steps), or far away on every fifth.
    const Pose end = make_stop_pose(leg.motion, leg.u_hit, gb.radius).pose;
    Pose to{end.p + Vec3(0.002 * U(rng), 0.002 * U(rng), -0.002 * (k % 2)), normalized(quat_exp(0.5 * turn) * end.q)};
    if (k % 5 == 4) to.p += Vec3(0.2, 0.1, 0.05);
    const int listed = ws.cache.num_pairs;
    const Pose list_pose = ws.cache.ref;
    const int list_uses = ws.cache.uses;
    CcdStepResult r, r_alone;
    ccd_step(&obstacle, 1, {&god, &gb}, {x, to, hints.data(), static_cast<int>(hints.size())}, check, &ws_check, &r);
    ccd_step(&obstacle, 1, {&god, &gb}, {x, to, hints.data(), static_cast<int>(hints.size())}, check, &ws_alone, &r_alone);
    INFO("step " << k);
    CHECK(ws.cache.num_pairs == listed);
    CHECK(ws.cache.uses == list_uses);
    CHECK((ws.cache.ref.p == list_pose.p));
    CcdMotion m;
    REQUIRE(make_ccd_motion(x, to, &m) == MotionStatus::kOk);
    const BruteForce bf = brute_force(god, gb, slab, sb, m, check.narrow);
    if (r.status == CcdStatus::kMaxIterations || r_alone.status == CcdStatus::kMaxIterations) {
      // A pair sliding at about 0 exhausts the bisection: a conservative hit,
      // never later than the brute force's.
      CHECK(r.hit);
      CHECK(r.u_hit <= bf.u_hit + 1e-5);
    } else {
      REQUIRE(r.status == CcdStatus::kOk);
      REQUIRE(r.hit == bf.hit);
      REQUIRE(r.hit == r_alone.hit);
      if (r.hit) CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
    }
    // The same check as a yes/no question (CcdQuestion::kFreeOfContact, as the
    // runtime asks it, with the legs' settings): the same answer, stopped at
    // the first hit it finds.
    CcdStepRequest yes_no{x, to, hints.data(), static_cast<int>(hints.size())};
    yes_no.question = CcdQuestion::kFreeOfContact;
    CcdStepResult r_any;
    ccd_step(&obstacle, 1, {&god, &gb}, yes_no, legs, &ws_any, &r_any);
    CHECK(r_any.hit == r.hit);
    CHECK((r_any.status == CcdStatus::kOk) == (r.status == CcdStatus::kOk));
    CHECK(r_any.num_node_pairs <= r.num_node_pairs);
    shorter += r_any.num_node_pairs + r_any.num_pair_tests < r.num_node_pairs + r.num_pair_tests;
    served += r.u_cached > 0;
    checks_hit += r.hit;
    if (k % 5 == 4) CHECK(r.u_cached == 0);  // beyond the list's margin: descended
    // Another reach (the legs' list holds pairs within its own reach only)
    // or another mesh behind the obstacle: not served.
    CcdStepSettings wider = check;
    wider.narrow.min_separation = 2 * legs.near_distance;
    CcdStepResult r_wide;
    ccd_step(&obstacle, 1, {&god, &gb}, {x, to}, wider, &ws_check, &r_wide);
    CHECK(r_wide.u_cached == 0);
    const CcdBody swapped{&other, &ob};
    CcdStepResult r_other;
    ccd_step(&swapped, 1, {&god, &gb}, {x, to}, check, &ws_check, &r_other);
    CHECK(r_other.u_cached == 0);
    x = make_stop_pose(leg.motion, leg.u_hit, gb.radius).pose;
    x.p.z() += 3e-4;
    hints = {in_contact_hint()};
    if (leg.hit) hints.push_back(leg.pair);
  }
  std::printf("borrowed list: %d of 150 checks served from the legs' list, %d hit, %d shorter as yes/no\n", served,
              checks_hit, shorter);
  CHECK(served >= 50);
  CHECK(checks_hit >= 20);
  CHECK(shorter >= 10);
}

TEST_CASE("ccd_step: a workspace without room to descend is never served an empty cache", "[ccd_step]") {
  // A ball pressed into a slab, in contact (a hint given), on a workspace whose
  // traversal stack holds nothing: every descent, the cache's fill included,
  // must report the workspace full and stop at the start, as a step without
  // the cache does, rather than serve the step from a list it never filled.
  const TriangleMesh god = make_icosphere(1, 0.5), slab = make_box(3, 3, 1, Vec3(0, 0, -0.5));
  const Bvh gb = build_bvh(god, 2), sb = build_bvh(slab, 2);
  double z_min = 1e300;
  for (Eigen::Index v = 0; v < god.V.rows(); ++v) z_min = std::min(z_min, god.V(v, 2));
  const Pose x0{Vec3(0, 0, 2e-4 - z_min), Quat{}}, x1{x0.p + Vec3(0, 0, -0.01), x0.q};
  const FeaturePair hint = in_contact_hint();
  const CcdBody obstacle{&slab, &sb};
  for (const double margin : {0.0, 0.02}) {
    INFO("cache_margin " << margin);
    CcdStepWorkspace ws(1 << 14, /*stack_capacity=*/0);
    CcdStepResult r;
    ccd_step(&obstacle, 1, {&god, &gb}, {x0, x1, &hint, 1}, background_fill_settings(margin, 0, 0), &ws, &r);
    CHECK(r.status == CcdStatus::kWorkspaceFull);
    CHECK(r.hit);
    CHECK(r.u_hit == 0);
    CHECK_FALSE(r.cache_filled);
  }
}

TEST_CASE("ccd_step: the proximity cache is not served for another mesh behind the same CcdBody", "[ccd_step]") {
  // A ball 2 d above a slab, in contact (a hint given): a first small step
  // fills the cache. The obstacle's CcdBody, the same variable, then points to
  // a new mesh: the slab plus a cube 5 mm beside the ball, which the next step
  // pushes the ball into (1.5 cm, within the 2 cm margin). That step must find
  // the cube, as the brute force does; on the old mesh the same step is served
  // from the cache (the control).
  const TriangleMesh god = make_icosphere(1, 0.5), slab = make_box(3, 3, 1, Vec3(0, 0, -0.5));
  const Bvh gb = build_bvh(god, 2), sb = build_bvh(slab, 2);
  CcdStepSettings settings;
  settings.narrow.min_separation = 1e-4;
  settings.cache.margin = 0.02;
  double z_min = 1e300, y_max = -1e300;
  for (Eigen::Index v = 0; v < god.V.rows(); ++v) {
    z_min = std::min(z_min, god.V(v, 2));
    y_max = std::max(y_max, god.V(v, 1));
  }
  const Pose x0{Vec3(0, 0, 2e-4 - z_min), Quat{}};
  const Pose x1{x0.p + Vec3(1e-3, 0, 0), x0.q}, x2{x1.p + Vec3(0, 0.015, 0), x1.q};
  const TriangleMesh slab_cube = concatenate(slab, make_box(0.1, 0.1, 0.1, Vec3(x1.p.x(), y_max + 0.005 + 0.05, x1.p.z())));
  const Bvh scb = build_bvh(slab_cube, 2);
  FeaturePair hint;
  hint.obstacle = 0;
  hint.god_face = hint.obstacle_face = 0;
  for (const bool swap : {false, true}) {
    CcdStepWorkspace ws;
    CcdBody obstacle{&slab, &sb};
    CcdStepResult r;
    ccd_step(&obstacle, 1, {&god, &gb}, {x0, x1, &hint, 1}, settings, &ws, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    CHECK(r.cache_filled);
    CHECK_FALSE(r.hit);
    if (swap) obstacle = {&slab_cube, &scb};
    ccd_step(&obstacle, 1, {&god, &gb}, {x1, x2, &hint, 1}, settings, &ws, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    CcdMotion m;
    REQUIRE(make_ccd_motion(x1, x2, &m) == MotionStatus::kOk);
    const BruteForce bf = brute_force(god, gb, swap ? slab_cube : slab, swap ? scb : sb, m, settings.narrow);
    CHECK(bf.hit == swap);
    CHECK(r.hit == bf.hit);
    if (r.hit && bf.hit) CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
    if (!swap) CHECK((r.u_cached == 1.0 && !r.cache_filled));  // served whole from the cache
  }
}

TEST_CASE("ccd_step: the proximity cache's keys never grow, and its settings are checked", "[ccd_step]") {
  // The cache is keyed by at most obstacle_capacity obstacles (reserved when the
  // workspace is built): a step with more obstacles is served without the cache,
  // with the same answer, and the keys' storage never grows in a step. Settings
  // the cache cannot use are refused as invalid input.
  const TriangleMesh god = make_icosphere(1, 0.5), slab = make_box(3, 3, 1, Vec3(0, 0, -0.5));
  const Bvh gb = build_bvh(god, 2), sb = build_bvh(slab, 2);
  CcdStepSettings settings;
  settings.narrow.min_separation = 1e-4;
  settings.cache.margin = 0.02;
  double z_min = 1e300;
  for (Eigen::Index v = 0; v < god.V.rows(); ++v) z_min = std::min(z_min, god.V(v, 2));
  const Pose x0{Vec3(0, 0, 2e-4 - z_min), Quat{}};
  const Pose x1{x0.p + Vec3(1e-3, 0, -1e-3), x0.q};
  const CcdBody obstacles[2] = {{&slab, &sb}, {&slab, &sb}};
  const FeaturePair hint = in_contact_hint();
  CcdStepWorkspace roomy, narrow(CcdStepWorkspace::kBoxCapacity, CcdStepWorkspace::kStackCapacity,
                                 CcdStepWorkspace::kCandidateCapacity, /*obstacle_capacity=*/1);
  const size_t capacity = narrow.cache.obstacles.capacity();
  CcdStepResult r_roomy, r_narrow;
  for (int step = 0; step < 3; ++step) {
    ccd_step(obstacles, 2, {&god, &gb}, {x0, x1, &hint, 1}, settings, &roomy, &r_roomy);
    ccd_step(obstacles, 2, {&god, &gb}, {x0, x1, &hint, 1}, settings, &narrow, &r_narrow);
    REQUIRE(r_roomy.status == CcdStatus::kOk);
    REQUIRE(r_narrow.status == CcdStatus::kOk);
    CHECK(r_roomy.hit);
    CHECK(r_narrow.hit == r_roomy.hit);
    CHECK(r_narrow.u_hit == r_roomy.u_hit);
    CHECK_FALSE(r_narrow.cache_filled);
    CHECK(r_narrow.u_cached == 0);
    CHECK(narrow.cache.obstacles.capacity() == capacity);
  }
  CHECK(roomy.cache.num_pairs >= 0);  // the control: two obstacles fit the default capacity
  CHECK(narrow.cache.num_pairs < 0);
  for (const auto& spoil : std::initializer_list<void (*)(ProximityCacheSettings*)>{
           [](ProximityCacheSettings* c) { c->margin = -1; },
           [](ProximityCacheSettings* c) { c->margin_max = std::numeric_limits<double>::infinity(); },
           [](ProximityCacheSettings* c) { c->steps_per_list = 0; },
           [](ProximityCacheSettings* c) { c->slow_fraction = 2; },
           [](ProximityCacheSettings* c) { c->fill_lead = std::numeric_limits<double>::quiet_NaN(); },
           [](ProximityCacheSettings* c) { c->min_uses = 0; },
           [](ProximityCacheSettings* c) { c->fill_budget = -1; },
           [](ProximityCacheSettings* c) { c->fill_at_once = 0; }}) {
    CcdStepSettings bad = settings;
    spoil(&bad.cache);
    CHECK_FALSE(valid_proximity_cache_settings(bad.cache));
    CcdStepResult r;
    ccd_step(obstacles, 1, {&god, &gb}, {x0, x1, &hint, 1}, bad, &roomy, &r);
    CHECK(r.status == CcdStatus::kInvalidInput);
  }
  CHECK(valid_proximity_cache_settings(ProximityCacheSettings{}));
  for (double lead : {-1.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    CcdStepRequest bad{x0, x1, &hint, 1};
    bad.lead_sweep = lead;
    CHECK(ccd_step_request_problem(bad) != nullptr);
    CcdStepResult r;
    ccd_step(obstacles, 1, {&god, &gb}, bad, settings, &roomy, &r);
    CHECK(r.status == CcdStatus::kInvalidInput);
  }
}

TEST_CASE("ccd_step: lead pieces find a first contact in whichever piece it falls", "[ccd_step]") {
  // A unit box falling flat by 3 onto a slab: its bottom face (G - 1/2) meets
  // z = 0 at u* = (z0 - 1/2) / 3, put in each of the pieces [0, 4^-6], ...,
  // [1/4, 1] (CcdStepRequest::lead_sweep; reach 0: the most pieces) and at
  // their ends. Every piece must be searched, from its start: the box is
  // through the slab by the next one.
  const TriangleMesh god = make_box(1, 1, 1);
  const TriangleMesh slab = make_box(4, 4, 1, Vec3(0, 0, -0.5));  // top face z = 0
  const Bvh gb = build_bvh(god), sb = build_bvh(slab);
  const CcdBody obstacle{&slab, &sb}, body{&god, &gb};
  CcdStepSettings plain;
  CcdStepWorkspace ws;
  for (double u_star : {1e-4, 0.000244140625, 5e-4, 2e-3, 1e-2, 0.04, 0.0625, 0.1, 0.2, 0.25, 0.3, 0.45, 0.6, 0.9}) {
    const Pose x0{Vec3(0.1, 0.2, 0.5 + 3 * u_star), Quat{}}, x1{Vec3(0.1, 0.2, 0.5 + 3 * u_star - 3), Quat{}};
    CcdStepResult r_plain, r_lead;
    ccd_step(&obstacle, 1, body, {x0, x1}, plain, &ws, &r_plain);
    CcdStepRequest leading{x0, x1};
    leading.lead_sweep = 1;
    ccd_step(&obstacle, 1, body, leading, plain, &ws, &r_lead);
    REQUIRE(r_lead.status == CcdStatus::kOk);
    CHECK(r_lead.num_sub_intervals == r_plain.num_sub_intervals + 6);
    // (z0 is rounded: u* is within 1e-15 of the value written.)
    CHECK(r_lead.hit);
    CHECK(r_lead.u_hit <= u_star + 1e-15);
    CHECK(u_star - r_lead.u_hit <= 1e-5);  // as the plain step below (time tolerance 1e-6 at speed 3)
    CHECK(u_star - r_plain.u_hit <= 1e-5);
  }
}

TEST_CASE("ccd_step: a step told its first part is free searches only the rest", "[ccd_step]") {
  // CcdStepRequest::known_free: the caller proved [0, known_free] free (the
  // runtime: a settling step's direct motion, its first part within
  // min_separation of the first leg, sim_step4.cpp proven_prefix). A unit box
  // falling flat onto a slab meets it at u*: told less than u*, the step finds
  // the same first contact as a plain one, through each way it searches (the
  // hints, a borrowed list, the descents, lead pieces). Settings outside
  // [0, 1) are refused.
  const TriangleMesh god = make_box(1, 1, 1);
  const TriangleMesh slab = make_box(4, 4, 1, Vec3(0, 0, -0.5));  // top face z = 0
  const Bvh gb = build_bvh(god), sb = build_bvh(slab);
  const CcdBody obstacle{&slab, &sb}, body{&god, &gb};
  CcdStepSettings cached;
  cached.cache.margin = 1.0;  // the list covers the whole fall
  cached.cache.margin_max = 1.0;
  cached.cache.fill_at_once = std::numeric_limits<long>::max();  // and is filled whole by the step at x0,
  cached.cache.triangle_margin = 10;                              // its margin not capped by the box's size
  for (int way = 0; way < 4; ++way) {
    for (double u_star : {0.01, 0.2, 0.45, 0.8}) {
      for (double known : {0.0, 0.5 * u_star, 0.99 * u_star}) {
        const Pose x0{Vec3(0.1, 0.2, 0.5 + 0.5 * u_star), Quat{}}, x1{Vec3(0.1, 0.2, 0.5 + 0.5 * u_star - 0.5), Quat{}};
        CcdStepSettings plain;
        CcdStepWorkspace ws, ws_told, ws_list;
        std::vector<FeaturePair> hints;
        if (way == 1) {  // the bottom face's pairs as hints: a contact searched first
          CcdStepResult full;
          ccd_step(&obstacle, 1, body, {x0, x1}, plain, &ws, &full);
          REQUIRE(full.hit);
          hints.push_back(full.pair);
        }
        if (way == 2) {  // a list filled at x0 in another workspace, borrowed
          CcdStepResult r_fill;
          ccd_step(&obstacle, 1, body, {x0, x0}, cached, &ws_list, &r_fill);
          REQUIRE(ws_list.cache.num_pairs > 0);
          ws.lender = ws_told.lender = &ws_list;
        }
        CcdStepResult r_plain, r_told;
        CcdStepRequest request{x0, x1, hints.data(), static_cast<int>(hints.size())};
        if (way == 3) request.lead_sweep = 1;
        CcdStepRequest told = request;
        told.known_free = known;
        ccd_step(&obstacle, 1, body, request, plain, &ws, &r_plain);
        ccd_step(&obstacle, 1, body, told, plain, &ws_told, &r_told);
        INFO("way " << way << " u* " << u_star << " known_free " << known);
        REQUIRE(r_plain.status == CcdStatus::kOk);
        REQUIRE(r_told.status == CcdStatus::kOk);
        REQUIRE(r_told.hit);
        if (way == 2) CHECK(r_told.u_cached > 0);
        CHECK(r_told.u_hit <= u_star + 1e-15);
        CHECK(std::abs(r_told.u_hit - r_plain.u_hit) <= 1e-5);
      }
    }
  }
  // And what it is told is not searched again: the box falls through a thin
  // plate on [0.195, 0.7] of its motion (a contact at 0.195 for a plain step)
  // and onto the slab at 0.8; told [0, 0.75] is free, the step reports the slab.
  {
    const TriangleMesh obstacles = concatenate(slab, make_box(4, 4, 0.01, Vec3(0, 0, 1.205)));
    const Bvh ob = build_bvh(obstacles);
    const CcdBody both{&obstacles, &ob};
    const Pose x0{Vec3(0.1, 0.2, 0.5 + 1.6), Quat{}}, x1{Vec3(0.1, 0.2, 0.5 + 1.6 - 2), Quat{}};
    CcdStepSettings plain;
    CcdStepRequest told{x0, x1};
    told.known_free = 0.75;
    CcdStepWorkspace ws;
    CcdStepResult r_plain, r_told;
    ccd_step(&both, 1, body, {x0, x1}, plain, &ws, &r_plain);
    ccd_step(&both, 1, body, told, plain, &ws, &r_told);
    REQUIRE(r_plain.hit);
    REQUIRE(r_told.hit);
    CHECK(std::abs(r_plain.u_hit - 0.195) <= 1e-5);
    CHECK(std::abs(r_told.u_hit - 0.8) <= 1e-5);
  }
  for (double bad : {-0.1, 1.0, 1.5, std::numeric_limits<double>::quiet_NaN()}) {
    CcdStepRequest r;
    r.known_free = bad;
    CHECK(ccd_step_request_problem(r) != nullptr);
  }
}

TEST_CASE("ccd_step: a box falling flat onto a slab, and one tipping onto it", "[ccd_step]") {
  const TriangleMesh god = make_box(1, 1, 1);
  const TriangleMesh slab = make_box(4, 4, 1, Vec3(0, 0, -0.5));  // top face z = 0
  const Bvh gb = build_bvh(god), sb = build_bvh(slab);
  const CcdBody obstacle{&slab, &sb};
  const CcdBody body{&god, &gb};
  CcdStepSettings settings;
  CcdStepWorkspace ws;
  CcdStepResult r;

  SECTION("falling: the bottom face (z = G - 1/2) reaches z = 0 at u = 1/3") {
    ccd_step(&obstacle, 1, body, {{Vec3(0.1, 0.2, 1.5), Quat{}}, {Vec3(0.1, 0.2, -1.5), Quat{}}}, settings, &ws, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    REQUIRE(r.hit);
    CHECK(mpq_class(r.u_hit) <= mpq_class(1, 3));
    CHECK(1.0 / 3 - r.u_hit <= 1e-5);  // time tolerance 1e-6, distance tolerance 1e-9 at speed 3
    // Stop pose with min separation: the exact separation stays >= d - deviation > 0.
    CcdStepSettings sep = settings;
    sep.narrow.min_separation = 1e-5;
    ccd_step(&obstacle, 1, body, {{Vec3(0.1, 0.2, 1.5), Quat{}}, {Vec3(0.1, 0.2, -1.5), Quat{}}}, sep, &ws, &r);
    REQUIRE(r.hit);
    const StopPose sp = make_stop_pose(r.motion, r.u_hit, gb.radius);
    CHECK(sp.deviation < 1e-12);
    const double bottom = sp.pose.p.z() - 0.5;
    CHECK(bottom >= 1e-5 - 1e-12);
    CHECK(bottom <= 1e-5 + 1e-4);  // no stop far from contact (3 u-tolerance + distance tolerances)
    std::printf("falling box: u_hit %.12f, gap at stop %.3e, %d triangle pairs, %d pair tests, %ld boxes\n", r.u_hit,
                bottom, r.num_triangle_pairs, r.num_pair_tests, r.num_box_iterations);
  }
  SECTION("tipping: a quarter turn about x lowers the box's edge onto the slab") {
    // G at height 0.6; turning by theta about x, the lowest edge is at
    // 0.6 - (cos theta + sin theta) / 2: zero at theta* = asin(1.2 / sqrt 2) - 45 deg.
    // With a 90 degree step, u* = tan(theta* / 2) / tan(45 deg).
    const double theta = std::asin(1.2 / std::sqrt(2.0)) - M_PI / 4;
    const double u_star = std::tan(theta / 2);
    ccd_step(&obstacle, 1, body, {{Vec3(0, 0, 0.6), Quat{}}, {Vec3(0, 0, 0.6), quat_exp(Vec3(M_PI / 2, 0, 0))}},
             settings, &ws, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    REQUIRE(r.hit);
    CHECK(r.u_hit <= u_star + 1e-12);  // 1e-12: u_star's own rounding
    CHECK(u_star - r.u_hit <= 1e-5);
    std::printf("tipping box: u_hit %.12f (u* %.12f), %d sub-intervals, %d triangle pairs, %d pair tests\n", r.u_hit,
                u_star, r.num_sub_intervals, r.num_triangle_pairs, r.num_pair_tests);
  }
  SECTION("moving away: no hit; bad poses and half turns are statuses") {
    ccd_step(&obstacle, 1, body, {{Vec3(0, 0, 0.6), Quat{}}, {Vec3(0.3, 0, 2), quat_exp(Vec3(0, 0, 1))}}, settings, &ws,
             &r);
    CHECK(r.status == CcdStatus::kOk);
    CHECK_FALSE(r.hit);
    CHECK(r.u_hit == 1.0);
    ccd_step(&obstacle, 1, body, {{Vec3(0, 0, NAN), Quat{}}, {Vec3(0, 0, 2), Quat{}}}, settings, &ws, &r);
    CHECK(r.status == CcdStatus::kInvalidInput);
    ccd_step(&obstacle, 1, body, {{Vec3(0, 0, 2), Quat{}}, {Vec3(0, 0, 2), quat_exp(Vec3(0, 0, 3.1))}}, settings, &ws,
             &r);
    CHECK(r.status == CcdStatus::kHalfTurn);
  }
}

TEST_CASE("ccd_step: a pair test that refuses its input is a conservative hit, never a miss", "[ccd_step]") {
  // A box falling onto a triangle of the plane z = 0 whose corners reach 2e30:
  // the pair tests refuse coordinates beyond 1e30 (kMaxCoordinate). The step must not
  // report a free motion through it: kInvalidInput, with a hit no later than
  // the true contact (u = 1/3).
  const TriangleMesh god = make_box(1, 1, 1);
  const TriangleMesh huge = gauss6::test::make_mesh({{-2, -2, 0}, {2e30, -2, 0}, {-2, 2e30, 0}}, {{0, 1, 2}}, "huge");
  const Bvh gb = build_bvh(god), hb = build_bvh(huge);
  const CcdBody obstacle{&huge, &hb};
  const CcdBody body{&god, &gb};
  CcdStepWorkspace ws;
  CcdStepResult r;
  for (const bool cached : {false, true}) {
    CcdStepSettings settings;
    if (!cached) settings.cache.margin = 0;
    ccd_step(&obstacle, 1, body, {{Vec3(0.1, 0.2, 1.5), Quat{}}, {Vec3(0.1, 0.2, -1.5), Quat{}}}, settings, &ws, &r);
    INFO("proximity cache " << cached);
    CHECK(r.status == CcdStatus::kInvalidInput);
    CHECK(r.hit);
    CHECK(r.u_hit <= 1.0 / 3);
  }
  // Settings that cannot serve a step are refused before any pair test, by name.
  CcdStepSettings bad;
  bad.narrow.time_tolerance = 0;
  REQUIRE(ccd_step_settings_problem(bad) != nullptr);
  CHECK(std::string(ccd_step_settings_problem(bad)).find("time_tolerance") != std::string::npos);
  ccd_step(&obstacle, 1, body, {{Vec3(0.1, 0.2, 1.5), Quat{}}, {Vec3(0.1, 0.2, -1.5), Quat{}}}, bad, &ws, &r);
  CHECK(r.status == CcdStatus::kInvalidInput);
  CHECK(r.num_pair_tests == 0);
  CHECK(ccd_step_settings_problem(CcdStepSettings{}) == nullptr);
}

TEST_CASE("ccd_step: a bar pivoting about its lowest corner over a slab agrees with the brute force", "[ccd_step]") {
  // A 10 x 2 x 2 bar tilted over a slab, its lowest corner a small gap above
  // it, turned about that corner (G moving by the turn of its offset from the
  // corner), plus a small translation that sometimes presses the corner in:
  // the motion whose translation and turn cancel near the contact, which the
  // swept oriented boxes and time bounds take as such (bvh.h: SweptObbFrame,
  // TriangleMotion::lag). Each step must agree with the brute force (the 1e-5
  // bound of the tests above), with and without hints and the cache.
  const TriangleMesh god = make_box(0.1, 0.02, 0.02);
  const TriangleMesh slab = concatenate(make_box(1, 1, 0.1, Vec3(0, 0, -0.05)), make_box(0.02, 0.4, 0.1, Vec3(0.12, 0, 0.05)));
  const Bvh gb = build_bvh(god, 2), sb = build_bvh(slab, 2);
  const CcdBody obstacle{&slab, &sb};
  std::mt19937 rng(53);
  std::uniform_real_distribution<double> U(-1, 1);
  CcdStepSettings settings, cached;
  settings.narrow.min_separation = cached.narrow.min_separation = 1e-5;
  cached.cache.margin = 1e-3;
  CcdStepWorkspace ws, ws_cached;
  int hits = 0;
  for (int i = 0; i < 40; ++i) {
    const Quat q0 = normalized(quat_exp(Vec3(0.3 * U(rng), 0.3 + 0.2 * U(rng), 0.3 * U(rng))));
    const Mat3 R0 = rotation_matrix(q0);
    Vec3 lowest(0, 0, 1e300);
    for (int k = 0; k < god.V.rows(); ++k) {
      const Vec3 x = R0 * god.V.row(k).transpose();
      if (x.z() < lowest.z()) lowest = x;
    }
    const double gap = std::pow(10.0, -2 - 2 * std::abs(U(rng)));
    const Vec3 G0 = Vec3(0.02 * U(rng), 0.02 * U(rng), gap - lowest.z());
    const Vec3 pivot = G0 + lowest;
    const Vec3 turn = (i % 4 == 0 ? 0.01 : 0.2) * Vec3(U(rng), U(rng), U(rng));
    const Mat3 Q = rotation_matrix(normalized(quat_exp(turn)));
    const Vec3 press = (i % 3 == 0 ? 2 * gap : 0.0) * Vec3(0.3 * U(rng), 0.3 * U(rng), -1);
    const Pose x0{G0, q0}, x1{pivot + Q * (G0 - pivot) + press, normalized(quat_exp(turn) * q0)};
    CcdMotion m;
    REQUIRE(make_ccd_motion(x0, x1, &m) == MotionStatus::kOk);
    const BruteForce bf = brute_force(god, gb, slab, sb, m, settings.narrow);
    INFO("step " << i << ", gap " << gap);
    CcdStepResult r;
    ccd_step(&obstacle, 1, {&god, &gb}, {x0, x1}, settings, &ws, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    CHECK(r.hit == bf.hit);
    if (r.hit && bf.hit) CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
    hits += bf.hit;
    // Hinted by a pair of faces near the pivot, through the proximity cache.
    const FeaturePair hint{PairKind::kEdgeEdge, 0, 0, 0, 2, 0};
    ccd_step(&obstacle, 1, {&god, &gb}, {x0, x1, &hint, 1}, cached, &ws_cached, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    CHECK(r.hit == bf.hit);
    if (r.hit && bf.hit) CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
  }
  CHECK(hits >= 8);
  CHECK(hits <= 32);
}

TEST_CASE("ccd_step timing on spheres", "[ccd_step][timing]") {
  // Prints per-step times for the report; fails only on a bad status.
  const TriangleMesh god = make_icosphere(3, 0.5), obs = make_icosphere(4, 1.0);
  const Bvh gb = build_bvh(god), ob = build_bvh(obs);
  CcdStepSettings settings;
  settings.narrow.min_separation = 1e-5;
  CcdStepWorkspace ws;
  CcdStepResult r;
  const CcdBody obstacle{&obs, &ob};
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-1, 1);
  double total = 0, worst = 0;
  int hits = 0;
  long pair_tests = 0, boxes = 0, triangle_pairs = 0;
  const int n = 50;
  for (int i = 0; i < n; ++i) {
    const Vec3 dir = Vec3(U(rng), U(rng), U(rng)).normalized();
    const Pose x0{1.6 * dir, Quat{}};
    const Pose x1{(1.45 + 0.1 * U(rng)) * dir + 0.02 * Vec3(U(rng), U(rng), U(rng)), quat_exp(0.05 * Vec3(U(rng), U(rng), U(rng)))};
    const auto t0 = std::chrono::steady_clock::now();
    ccd_step(&obstacle, 1, {&god, &gb}, {x0, x1}, settings, &ws, &r);
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    total += dt;
    worst = std::max(worst, dt);
    hits += r.hit;
    pair_tests += r.num_pair_tests;
    boxes += r.num_box_iterations;
    triangle_pairs += r.num_triangle_pairs;
    REQUIRE(r.status == CcdStatus::kOk);
  }
  std::printf("ccd_step, icosphere 1280 tris vs 5120 tris, approach steps: mean %.1f us, worst %.1f us, %d/%d hits; "
              "per step %ld triangle pairs, %ld pair tests, %ld boxes\n",
              1e6 * total / n, 1e6 * worst, hits, n, triangle_pairs / n, pair_tests / n, boxes / n);
}

TEST_CASE("ccd_step: a descent's cut serves only the trees it was made for", "[ccd_step]") {
  // DescentFront, carried across steps: a workspace whose last descent was of
  // other trees (another obstacle, another count of them) starts from the root
  // pairs, as a fresh workspace does: the same result, bit for bit. And one
  // whose cut is of these trees, carried over several steps without clear(),
  // finds the first contact of a fresh workspace (the 1e-5 bound of the tests
  // above: a cut may list more candidate pairs, never fewer). Not carried (the
  // default), a step's result does not depend on the steps before it.
  const TriangleMesh god = make_icosphere(2, 0.5);
  const TriangleMesh box = make_box(2, 2, 1, Vec3(0, 0, -0.5)), ball = make_icosphere(2, 0.4);
  const Bvh gb = build_bvh(god, 2), bb = build_bvh(box, 2), sb = build_bvh(ball, 2);
  const CcdBody both[2] = {{&ball, &sb}, {&box, &bb}};
  CcdStepSettings settings;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  CcdStepWorkspace carried;
  carried.front.carry = true;
  int hits = 0;
  for (int i = 0; i < 30; ++i) {
    const Pose x0{Vec3(U(rng), U(rng), 0.55 + 0.05 * std::abs(U(rng))),
                  normalized(Quat{1 + U(rng), U(rng), U(rng), U(rng)})};
    const Pose x1{Vec3(U(rng), U(rng), 0.2 * U(rng)), normalized(quat_exp(0.5 * Vec3(U(rng), U(rng), U(rng))) * x0.q)};
    const CcdBody* obstacles = i % 3 == 0 ? &both[0] : &both[1];
    const int n = i % 3 == 2 ? 1 : (i % 3 == 0 ? 2 : 1);
    CcdStepRequest request{x0, x1};
    request.lead_sweep = 4;  // pieces: several descents a step
    CcdStepWorkspace fresh;
    CcdStepResult r_fresh, r_carried;
    ccd_step(obstacles, n, {&god, &gb}, request, settings, &fresh, &r_fresh);
    const bool same_trees = carried.front.keyed({&god, &gb}, obstacles, n);
    ccd_step(obstacles, n, {&god, &gb}, request, settings, &carried, &r_carried);
    REQUIRE(r_fresh.status == CcdStatus::kOk);
    REQUIRE(r_carried.status == CcdStatus::kOk);
    CHECK(r_carried.hit == r_fresh.hit);
    if (!same_trees) {
      CHECK(r_carried.u_hit == r_fresh.u_hit);
      CHECK(r_carried.num_node_pairs == r_fresh.num_node_pairs);
    } else if (r_carried.hit && r_fresh.hit) {
      CHECK(std::abs(r_carried.u_hit - r_fresh.u_hit) <= 1e-5);
    }
    hits += r_fresh.hit;
    // Not carried: bit for bit a fresh workspace's, whatever ran before.
    CcdStepWorkspace& plain = i % 2 ? carried : fresh;
    plain.front.carry = false;
    CcdStepResult r_plain;
    ccd_step(obstacles, n, {&god, &gb}, request, settings, &plain, &r_plain);
    CHECK(r_plain.u_hit == r_fresh.u_hit);
    CHECK(r_plain.num_node_pairs == r_fresh.num_node_pairs);
    carried.front.carry = true;
  }
  CHECK(hits >= 5);
}

namespace {

// The distance between two triangles (doubles): the least of each corner's to
// the other triangle and of the nine edge pairs'.
double triangle_distance(const Vec3 A[3], const Vec3 B[3]) {
  double d = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    d = std::min(d, (A[k] - closest_point_on_triangle(A[k], B[0], B[1], B[2])).norm());
    d = std::min(d, (B[k] - closest_point_on_triangle(B[k], A[0], A[1], A[2])).norm());
    for (int j = 0; j < 3; ++j) {
      const Vec3 &a0 = A[k], &a1 = A[(k + 1) % 3], &b0 = B[j], &b1 = B[(j + 1) % 3];
      double s = 0, t = 0;
      closest_segment_parameters(a0, a1, b0, b1, &s, &t);
      d = std::min(d, ((a0 + s * (a1 - a0)) - (b0 + t * (b1 - b0))).norm());
    }
  }
  return d;
}

}  // namespace

TEST_CASE("ccd_step: a budget stop inside a later piece's descent keeps the near pairs of the pieces before",
          "[ccd_step][budget]") {
  // A ball sliding down onto a slab, its motion searched in lead pieces, under
  // work-unit budgets from a few units to more than the step takes. Where the
  // budget runs out in the descent of a piece after the first, the step stops
  // at that piece's start with the near pairs listed for the piece before
  // (they hold up to there): the contact set at the stop pose is then taken
  // from them, not from a descent of the trees. Whatever the stop, a listed
  // set holds every triangle pair within near_reach at the stop pose (the
  // pose of the nominal motion there; 1e-9 of slack for its rounding).
  const TriangleMesh god = make_icosphere(2, 0.4), slab = make_box(3, 3, 1, Vec3(0, 0, -0.5));
  const Bvh gb = build_bvh(god, 2), sb = build_bvh(slab, 2);
  const CcdBody obstacle{&slab, &sb};
  CcdStepSettings settings;
  settings.near_distance = 0.02;
  const Pose x0{Vec3(0, 0, 0.55), Quat{}}, x1{Vec3(0.3, 0.1, 0.38), normalized(quat_exp(Vec3(0.2, 0.1, 0.3)))};
  CcdStepRequest request{x0, x1};
  request.lead_sweep = 16;
  int stops = 0, kept = 0;
  for (long units = 1; units <= 3000; units = units < 40 ? units + 1 : units * 11 / 10) {
    INFO("work units " << units);
    CcdStepWorkspace ws;
    UpdateBudget budget;
    budget.start({0, units, kDefaultBudgetCheckInterval});
    ws.budget = &budget;
    CcdStepResult r;
    ccd_step(&obstacle, 1, {&god, &gb}, request, settings, &ws, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    if (!r.budget_exhausted) continue;
    ++stops;
    // Past the motion's start every stop has a list: its piece's (a stop among
    // its candidates) or the piece's before (a stop in its descent).
    if (r.u_hit > 0) {
      CHECK(r.num_near_pairs >= 0);
      kept += r.num_near_pairs >= 0;
    }
    if (r.num_near_pairs < 0) continue;
    REQUIRE(r.near_u0 <= r.u_hit);
    const Pose at = motion_pose(r.motion.nominal, r.u_hit);
    const NearPairs near = ws.near_pairs(r.num_near_pairs);
    std::set<std::pair<int, int>> listed;
    for (int k = 0; k < near.num_pairs; ++k) listed.insert({near[k].god_face, near[k].obstacle_face});
    for (Eigen::Index gf = 0; gf < god.F.rows(); ++gf) {
      Vec3 A[3];
      for (int c = 0; c < 3; ++c) A[c] = transform_point(at, god.V.row(god.F(gf, c)).transpose());
      for (Eigen::Index of = 0; of < slab.F.rows(); ++of) {
        const Vec3 B[3] = {slab.V.row(slab.F(of, 0)).transpose(), slab.V.row(slab.F(of, 1)).transpose(),
                           slab.V.row(slab.F(of, 2)).transpose()};
        if (triangle_distance(A, B) < r.near_reach - 1e-9)
          CHECK(listed.count({static_cast<int>(gf), static_cast<int>(of)}) == 1);
      }
    }
  }
  CHECK(stops > 10);
  CHECK(kept > 5);
}

