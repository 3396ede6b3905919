// Tests of bvh.h: tree structure and feature ownership, conservative swept boxes,
// no truly colliding triangle pair culled (against a brute-force all-pairs run of
// the narrow phase), and ccd_step on steps with a known first contact.
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "gauss6/bvh.h"
#include "gauss6/ccd_step.h"
#include "gauss6/distance.h"
#include "gauss6/motion_bounds.h"
#include "mesh_shapes.h"

using namespace gauss6;
using gauss6::test::concatenate;
using gauss6::test::make_box;
using gauss6::test::make_icosphere;

namespace {

bool contains(const Aabb& outer, const Aabb& inner) {
  return (outer.lo.array() <= inner.lo.array()).all() && (inner.hi.array() <= outer.hi.array()).all();
}

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
          ccd_rigid_vertex_face({&m, true, G[k], O, 0, 1}, s, &ws, &r);
          take();
        }
        if (ob.owned[of] & (1u << k)) {
          ccd_rigid_vertex_face({&m, false, O[k], G, 0, 1}, s, &ws, &r);
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

TEST_CASE("BVH: structure, boxes and feature ownership", "[bvh]") {
  const TriangleMesh mesh = make_icosphere(3, 1.0);  // 1280 triangles
  const Bvh bvh = build_bvh(mesh, 4);
  std::printf("BVH of %d triangles: %zu nodes, depth %d, %.1f KiB, built in %.3f ms\n", static_cast<int>(mesh.F.rows()),
              bvh.nodes.size(), bvh.depth, bvh.memory_bytes() / 1024.0, 1e3 * bvh.build_seconds);
  // Every triangle in exactly one leaf, inside its leaf's box; children inside parents.
  std::vector<int> seen(mesh.F.rows(), 0);
  for (const BvhNode& n : bvh.nodes) {
    if (n.count > 0) {
      CHECK(n.count <= 4);
      for (int i = 0; i < n.count; ++i) {
        const int f = bvh.triangles[n.first + i];
        ++seen[f];
        CHECK(contains(n.box, triangle_box(mesh, f)));
      }
    } else {
      CHECK(contains(n.box, bvh.nodes[n.first].box));
      CHECK(contains(n.box, bvh.nodes[n.first + 1].box));
    }
  }
  for (int c : seen) REQUIRE(c == 1);
  CHECK(bvh.depth <= 12);  // balanced: ceil(log2(1280 / 4)) + 1 = 10
  // Each vertex owned once; each undirected edge owned once.
  std::vector<int> vown(mesh.V.rows(), 0);
  std::map<std::pair<int, int>, int> eown;
  for (int f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      if (bvh.owned[f] & (1u << k)) ++vown[mesh.F(f, k)];
      const auto e = std::minmax(mesh.F(f, k), mesh.F(f, (k + 1) % 3));
      eown[e] += (bvh.owned[f] & (8u << k)) ? 1 : 0;
      CHECK(bvh.neighbor[3 * f + k] >= 0);  // closed mesh: every edge has a neighbour
    }
  for (int c : vown) CHECK(c == 1);
  for (const auto& [e, c] : eown) CHECK(c == 1);
}

TEST_CASE("BVH: swept boxes contain the moving box over the u-range", "[bvh]") {
  std::mt19937 rng(2);
  std::normal_distribution<double> n(0, 1);
  for (int i = 0; i < 200; ++i) {
    const Pose x0{{n(rng), n(rng), n(rng)}, normalized(Quat{n(rng), n(rng), n(rng), n(rng)})};
    const Pose x1{x0.p + Vec3(n(rng), n(rng), n(rng)),
                  normalized(quat_exp(0.012 * i * Vec3(n(rng), n(rng), n(rng)).normalized()) * x0.q)};
    CcdMotion m;
    REQUIRE(make_ccd_motion(x0, x1, &m) == MotionStatus::kOk);
    const double u0 = 0.5 * std::abs(std::tanh(n(rng))), u1 = std::min(1.0, u0 + 0.3 * std::abs(n(rng)));
    MotionEnclosure e;
    enclose_motion(m, {u0, u1}, &e);
    const Vec3 c(n(rng), n(rng), n(rng)), h = Vec3(n(rng), n(rng), n(rng)).cwiseAbs() * 0.3;
    const Aabb body{c - h, c + h};
    const Aabb w = swept_box(e, body);
    for (int k = 0; k <= 10; ++k)
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3 r(corner & 1 ? body.hi.x() : body.lo.x(), corner & 2 ? body.hi.y() : body.lo.y(),
                     corner & 4 ? body.hi.z() : body.lo.z());
        // 1e-12: motion_point's own rounding.
        const Vec3 p = motion_point(m.nominal, u0 + (u1 - u0) * k / 10, r);
        REQUIRE((p.array() >= w.lo.array() - 1e-12).all());
        REQUIRE((p.array() <= w.hi.array() + 1e-12).all());
      }
  }
}

TEST_CASE("BVH: every truly colliding triangle pair is a candidate; ccd_step agrees with brute force", "[bvh]") {
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
    ccd_step(&ob_body, 1, {&god, &gb}, x0, x1, settings, &ws, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    CHECK(r.hit == bf.hit);
    if (r.hit && bf.hit) {
      ++hits;
      CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
    }
    // Without a candidate buffer the pairs are tested in traversal order, not
    // earliest-first: the same first contact (same 1e-5 bound).
    CcdStepResult r_unordered;
    ccd_step(&ob_body, 1, {&god, &gb}, x0, x1, settings, &ws_unordered, &r_unordered);
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
    probing.cache_margin = i % 3 == 0 ? 0.0 : 0.01;
    CcdStepResult r_hinted;
    ccd_step(&ob_body, 1, {&god, &gb}, x0, x1, probing, &ws, &r_hinted, hints.data(), static_cast<int>(hints.size()));
    REQUIRE(r_hinted.status == CcdStatus::kOk);
    CHECK(r_hinted.hit == bf.hit);
    if (r_hinted.hit && bf.hit) CHECK(std::abs(r_hinted.u_hit - bf.u_hit) <= 1e-5);
  }
  CHECK(hits >= 10);
}

TEST_CASE("ccd_step: a hint's pair is not searched twice, and a pair sharing one face with a hint is", "[bvh]") {
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
    for (const auto& [gf, of] : bf.hitting_pairs) {
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
    ccd_step(&ob_body, 1, {&god, &gb}, x0, x1, settings, &ws, &r, hints.data(), static_cast<int>(hints.size()));
    INFO("step " << i << ", " << hints.size() << " hints");
    REQUIRE(r.status == CcdStatus::kOk);
    CHECK(r.hit);
    CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
    for (const size_t lead : {size_t{0}, hints.size() / 2, hints.size() - 1}) {
      ws.last_hit = hints[lead];
      ccd_step(&ob_body, 1, {&god, &gb}, x0, x1, settings, &ws, &r, hints.data(), static_cast<int>(hints.size()));
      INFO("last hit: hint " << lead);
      REQUIRE(r.status == CcdStatus::kOk);
      CHECK(r.hit);
      CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
    }
    ++checked;
  }
  CHECK(checked >= 10);
}

TEST_CASE("ccd_step: steps served by the proximity cache find the first contact of a fresh search", "[bvh]") {
  // A ball kept near a slab with a block standing on it, by a chain of steps
  // each from the last one's stop pose, as the runtime's are: small jitters
  // (within the margin: served from the cache), presses into the slab or the
  // block (hits), and every tenth step a long move (the cache is refilled
  // where the next step starts in contact). Each step must agree with the
  // brute force (the same 1e-5 bound as above) and with a step on a workspace
  // without the cache. Run with the cache refilled at once, refilled in the
  // background a few node pairs per step (cache_fill_budget: the served steps
  // then take their pairs from a list that was completed steps after the pose
  // it holds), and with margins that follow the speed (cache_margin_max).
  const TriangleMesh god = make_icosphere(1, 0.5);
  const TriangleMesh slab = concatenate(make_box(3, 3, 1, Vec3(0, 0, -0.5)), make_box(0.4, 0.4, 0.6, Vec3(0.6, 0, 0.3)));
  const Bvh gb = build_bvh(god, 2), sb = build_bvh(slab, 2);
  for (const auto [budget, margin_max] : {std::pair{0L, 0.0}, std::pair{12L, 0.0}, std::pair{12L, 0.06}}) {
  INFO("cache_fill_budget " << budget << ", cache_margin_max " << margin_max);
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> U(-1, 1);
  CcdStepSettings settings, plain;
  settings.narrow.min_separation = plain.narrow.min_separation = 1e-4;
  settings.cache_margin = 0.02;
  settings.cache_fill_budget = budget;
  settings.cache_margin_max = margin_max;
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
    ccd_step(&obstacle, 1, {&god, &gb}, x, target, settings, &ws, &r, hints.data(), static_cast<int>(hints.size()));
    ccd_step(&obstacle, 1, {&god, &gb}, x, target, plain, &ws_plain, &r_plain);
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
    // The next step starts at this one's stop pose, lifted by 3 d (a motion
    // sliding at exactly d is undecidable at the default distance tolerance);
    // the pair that stopped it is its hint (the runtime passes the contacts there).
    x = make_stop_pose(r.motion, r.u_hit, gb.radius).pose;
    x.p.z() += 3e-4;
    hints.clear();
    if (r.hit) hints.push_back(r.pair);
  }
  std::printf("proximity cache (fill budget %ld, margins up to %g): %d of 120 steps served from it, %d fills, %d "
              "background refills, %d hits, %d give-ups\n", budget, std::max(margin_max, settings.cache_margin), served,
              fills, refills, hits, gave_up);
  CHECK(gave_up <= 6);
  CHECK(served >= 30);
  CHECK(fills >= 3);
  CHECK(hits >= 20);
  if (budget == 0) CHECK(refills == 0);
  }
}

// The settings of the background-fill tests below: the cache's margin, the
// widest a list's may grow to, and the fill's node pairs per step.
static CcdStepSettings background_fill_settings(double margin, double margin_max, long fill_budget) {
  CcdStepSettings settings;
  settings.narrow.min_separation = 1e-4;
  settings.cache_margin = margin;
  settings.cache_margin_max = margin_max;
  settings.cache_fill_budget = fill_budget;
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

TEST_CASE("ccd_step: a ball sliding on a slab into a wall, its cache refilled in the background", "[bvh]") {
  // The ball slides 2e-4 above a slab (a hint given, as in contact) towards a
  // wall, 4 mm a step, with the cache refilled in the background a few node
  // pairs per step: each list is filled at a pose ahead of the ball and put
  // in use steps later. The wall comes within reach of pairs that were not in
  // the lists before; every step must still agree with the brute force, and
  // the step that meets the wall must stop where it does. (The test below,
  // with the ball wandering, also checks what each list holds.)
  // Run with every list's margin 3 cm, and with margins up to 8 cm sized to
  // the ball's speed (cache_margin_max; the ball then slides 8 mm a step).
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
    ccd_step(&obstacle, 1, {&god, &gb}, x, target, settings, &ws, &r, &hint, 1);
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
              std::max(margin_max, settings.cache_margin), steps, served, refills);
  CHECK(met_wall);
  CHECK(served >= steps / 2);
  CHECK(refills >= 3);
  }
}

TEST_CASE("ccd_step: a ball wandering among blocks, lists filled ahead of it in the background", "[bvh]") {
  // The ball wanders 2e-4 above a slab studded with blocks (a hint given, as
  // in contact), its velocity turning a little each step and its speed
  // between 1 and 12 mm a step, now and then reversing: the lists filled ahead
  // of it (cache_fill_budget) are sometimes where it goes and sometimes not,
  // and their margins follow its speed (cache_margin_max). A step that meets
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
    ccd_step(&obstacle, 1, {&god, &gb}, x, target, settings, &ws, &r, &hint, 1);
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
      const CcdStepWorkspace::ProximityCache& pc = ws.cache;
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
  CHECK(widest > 1.5 * settings.cache_margin);
  CHECK(served >= 125);
  CHECK(refills >= 8);
  CHECK(hits >= 5);
}

TEST_CASE("ccd_step: a workspace without room to descend is never served an empty cache", "[bvh]") {
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
    ccd_step(&obstacle, 1, {&god, &gb}, x0, x1, background_fill_settings(margin, 0, 0), &ws, &r, &hint, 1);
    CHECK(r.status == CcdStatus::kWorkspaceFull);
    CHECK(r.hit);
    CHECK(r.u_hit == 0);
    CHECK_FALSE(r.cache_filled);
  }
}

TEST_CASE("ccd_step: the proximity cache is not served for another mesh behind the same CcdBody", "[bvh]") {
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
  settings.cache_margin = 0.02;
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
    ccd_step(&obstacle, 1, {&god, &gb}, x0, x1, settings, &ws, &r, &hint, 1);
    REQUIRE(r.status == CcdStatus::kOk);
    CHECK(r.cache_filled);
    CHECK_FALSE(r.hit);
    if (swap) obstacle = {&slab_cube, &scb};
    ccd_step(&obstacle, 1, {&god, &gb}, x1, x2, settings, &ws, &r, &hint, 1);
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

TEST_CASE("ccd_step: a box falling flat onto a slab, and one tipping onto it", "[bvh]") {
  const TriangleMesh god = make_box(1, 1, 1);
  const TriangleMesh slab = make_box(4, 4, 1, Vec3(0, 0, -0.5));  // top face z = 0
  const Bvh gb = build_bvh(god), sb = build_bvh(slab);
  const CcdBody obstacle{&slab, &sb};
  const CcdBody body{&god, &gb};
  CcdStepSettings settings;
  CcdStepWorkspace ws;
  CcdStepResult r;

  SECTION("falling: the bottom face (z = G - 1/2) reaches z = 0 at u = 1/3") {
    ccd_step(&obstacle, 1, body, {Vec3(0.1, 0.2, 1.5), Quat{}}, {Vec3(0.1, 0.2, -1.5), Quat{}}, settings, &ws, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    REQUIRE(r.hit);
    CHECK(mpq_class(r.u_hit) <= mpq_class(1, 3));
    CHECK(1.0 / 3 - r.u_hit <= 1e-5);  // time tolerance 1e-6, distance tolerance 1e-9 at speed 3
    // Stop pose with min separation: the exact separation stays >= d - deviation > 0.
    CcdStepSettings sep = settings;
    sep.narrow.min_separation = 1e-5;
    ccd_step(&obstacle, 1, body, {Vec3(0.1, 0.2, 1.5), Quat{}}, {Vec3(0.1, 0.2, -1.5), Quat{}}, sep, &ws, &r);
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
    ccd_step(&obstacle, 1, body, {Vec3(0, 0, 0.6), Quat{}}, {Vec3(0, 0, 0.6), quat_exp(Vec3(M_PI / 2, 0, 0))},
             settings, &ws, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    REQUIRE(r.hit);
    CHECK(r.u_hit <= u_star + 1e-12);  // 1e-12: u_star's own rounding
    CHECK(u_star - r.u_hit <= 1e-5);
    std::printf("tipping box: u_hit %.12f (u* %.12f), %d sub-intervals, %d triangle pairs, %d pair tests\n", r.u_hit,
                u_star, r.num_sub_intervals, r.num_triangle_pairs, r.num_pair_tests);
  }
  SECTION("moving away: no hit; bad poses and half turns are statuses") {
    ccd_step(&obstacle, 1, body, {Vec3(0, 0, 0.6), Quat{}}, {Vec3(0.3, 0, 2), quat_exp(Vec3(0, 0, 1))}, settings, &ws,
             &r);
    CHECK(r.status == CcdStatus::kOk);
    CHECK_FALSE(r.hit);
    CHECK(r.u_hit == 1.0);
    ccd_step(&obstacle, 1, body, {Vec3(0, 0, NAN), Quat{}}, {Vec3(0, 0, 2), Quat{}}, settings, &ws, &r);
    CHECK(r.status == CcdStatus::kInvalidInput);
    ccd_step(&obstacle, 1, body, {Vec3(0, 0, 2), Quat{}}, {Vec3(0, 0, 2), quat_exp(Vec3(0, 0, 3.1))}, settings, &ws,
             &r);
    CHECK(r.status == CcdStatus::kHalfTurn);
  }
}

TEST_CASE("ccd_step: a bar pivoting about its lowest corner over a slab agrees with the brute force", "[bvh]") {
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
  cached.cache_margin = 1e-3;
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
    ccd_step(&obstacle, 1, {&god, &gb}, x0, x1, settings, &ws, &r);
    REQUIRE(r.status == CcdStatus::kOk);
    CHECK(r.hit == bf.hit);
    if (r.hit && bf.hit) CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
    hits += bf.hit;
    // Hinted by a pair of faces near the pivot, through the proximity cache.
    const FeaturePair hint{PairKind::kEdgeEdge, 0, 0, 0, 2, 0};
    ccd_step(&obstacle, 1, {&god, &gb}, x0, x1, cached, &ws_cached, &r, &hint, 1);
    REQUIRE(r.status == CcdStatus::kOk);
    CHECK(r.hit == bf.hit);
    if (r.hit && bf.hit) CHECK(std::abs(r.u_hit - bf.u_hit) <= 1e-5);
  }
  CHECK(hits >= 8);
  CHECK(hits <= 32);
}

TEST_CASE("ccd_step timing on spheres", "[bvh][timing]") {
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
    ccd_step(&obstacle, 1, {&god, &gb}, x0, x1, settings, &ws, &r);
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

TEST_CASE("swept box cache: returns the box of the asked index in the current sub-interval", "[bvh]") {
  // A 2-entry cache (indices 0 and 2 share a slot): every get() must return the
  // box that make() gives for that index and stamp, recomputing on a slot
  // collision and after next_interval(), and reusing a valid entry.
  SweptBoxCache cache(1);
  int calls = 0, interval = 0;
  const auto box_of = [&](int index) {
    ++calls;
    Aabb b;
    b.lo = Vec3::Constant(index + 100.0 * interval);
    b.hi = b.lo + Vec3::Ones();
    return b;
  };
  const auto check = [&](int index) {
    const Aabb& b = cache.get(cache.nodes, index, [&] { return box_of(index); });
    return b.lo.x() == index + 100.0 * interval;
  };
  cache.next_interval();
  CHECK(check(0));
  CHECK(check(0));
  CHECK(calls == 1);  // reused
  CHECK(check(2));    // same slot as 0: recomputed
  CHECK(check(0));
  CHECK(calls == 3);
  CHECK(check(1));
  CHECK(calls == 4);
  ++interval;
  cache.next_interval();  // every entry stale
  CHECK(check(1));
  CHECK(check(0));
  CHECK(calls == 6);
}

namespace {

// Reference distance of two triangles in long double: the minimum over the six
// vertex/triangle and nine edge/edge distances (enough for disjoint triangles;
// intersecting pairs are not generated below). Independent of contacts.h.
using Vec3L = Eigen::Matrix<long double, 3, 1>;
long double point_segment(const Vec3L& x, const Vec3L& a, const Vec3L& b) {
  const Vec3L ab = b - a;
  const long double t = std::clamp((x - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300L), 0.0L, 1.0L);
  return (a + t * ab - x).norm();
}
long double point_triangle(const Vec3L& x, const Vec3L T[3]) {
  const Vec3L n = (T[1] - T[0]).cross(T[2] - T[0]);
  const Vec3L y = x - n * ((x - T[0]).dot(n) / n.squaredNorm());  // projection on the plane
  bool inside = true;
  for (int k = 0; k < 3; ++k) inside &= (T[(k + 1) % 3] - T[k]).cross(y - T[k]).dot(n) >= 0;
  if (inside) return (x - y).norm();
  long double best = point_segment(x, T[0], T[1]);
  for (int k = 1; k < 3; ++k) best = std::min(best, point_segment(x, T[k], T[(k + 1) % 3]));
  return best;
}
long double segment_segment(const Vec3L& p0, const Vec3L& p1, const Vec3L& q0, const Vec3L& q1) {
  // Minimum over a fine parameter grid refined around its best cell, plus the end cases.
  long double best = std::min({point_segment(p0, q0, q1), point_segment(p1, q0, q1), point_segment(q0, p0, p1),
                               point_segment(q1, p0, p1)});
  const Vec3L d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const long double a = d1.dot(d1), e = d2.dot(d2), b = d1.dot(d2), c = d1.dot(r), f = d2.dot(r);
  const long double den = a * e - b * b;
  if (den > 1e-24L * a * e) {
    const long double s = (b * f - c * e) / den, t = (a * f - b * c) / den;
    if (s >= 0 && s <= 1 && t >= 0 && t <= 1) best = std::min(best, (p0 + s * d1 - q0 - t * d2).norm());
  }
  return best;
}
long double triangle_distance(const Vec3 A[3], const Vec3 B[3]) {
  Vec3L a[3], b[3];
  for (int k = 0; k < 3; ++k) {
    a[k] = A[k].cast<long double>();
    b[k] = B[k].cast<long double>();
  }
  long double best = std::numeric_limits<long double>::infinity();
  for (int k = 0; k < 3; ++k) best = std::min({best, point_triangle(a[k], b), point_triangle(b[k], a)});
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      best = std::min(best, segment_segment(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]));
  return best;
}

// Two disjoint triangles at `scale`: A about a random centre c (every fourth
// long and thin, a peg's side strip), B placed gap = scale 10^(-gap_decades U)
// beyond a random plane (normal m) through A's extreme point, two thirds of
// them farther still; with nearly_parallel, B lies almost in that plane.
struct DisjointPair {
  Vec3 A[3], B[3], c, m;
  double gap = 0;
};
// n and U are the caller's (a normal distribution keeps a spare draw).
DisjointPair disjoint_pair(std::mt19937& rng, std::normal_distribution<double>& n,
                           std::uniform_real_distribution<double>& U, int i, double scale, double gap_decades,
                           bool nearly_parallel) {
  DisjointPair out;
  out.c = scale * 10 * Vec3(n(rng), n(rng), n(rng));
  for (int k = 0; k < 3; ++k) out.A[k] = out.c + scale * Vec3(n(rng), n(rng), n(rng));
  if (i % 4 == 0) out.A[2] = out.A[0] + 1e-2 * (out.A[2] - out.A[0]) + 30 * (out.A[1] - out.A[0]);
  out.m = Vec3(n(rng), n(rng), n(rng)).normalized();
  const Vec3& m = out.m;
  double top = -1e300;
  for (const Vec3& a : out.A) top = std::max(top, m.dot(a));
  out.gap = scale * std::pow(10.0, -gap_decades * U(rng));
  for (int k = 0; k < 3; ++k) {
    Vec3 v = out.c + scale * Vec3(n(rng), n(rng), n(rng));
    if (nearly_parallel) v -= m * m.dot(v - out.c) * 0.999;
    out.B[k] = v + m * (top + out.gap - m.dot(v) + scale * std::abs(n(rng)) * (i % 3 == 0 ? 0 : 1));
  }
  return out;
}

}  // namespace

TEST_CASE("triangle_gap_lower_bound: never above the distance, and useful", "[bvh]") {
  std::mt19937 rng(31);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> U(0, 1);
  int checked = 0, useful = 0, separated_by_plane = 0;
  for (int i = 0; i < 20000; ++i) {
    // Triangle A about a random centre; B placed a random gap beyond a random
    // plane through A's extreme point (so they are disjoint), at scales from
    // 1e-3 to 1e3, some long and thin (a peg's side strip), some coplanar-ish.
    const double scale = std::pow(10.0, 6 * U(rng) - 3);
    const DisjointPair pair = disjoint_pair(rng, n, U, i, scale, 9, /*nearly_parallel=*/i % 7 == 0);
    const Vec3 *A = pair.A, *B = pair.B, &c = pair.c;
    const double gap = pair.gap;
    const long double exact = triangle_distance(A, B);
    if (!(exact > 0)) continue;
    const double bound = triangle_gap_lower_bound(A, B, std::numeric_limits<double>::infinity());
    ++checked;
    // The reference's own rounding: long double, relative 1e-17 of the coordinates.
    REQUIRE(static_cast<long double>(bound) <= exact + 1e-16L * (c.norm() + 30 * scale));
    useful += bound >= 0.5 * static_cast<double>(exact);
    // The early exit returns more than `enough` or the full bound.
    const double enough = 0.25 * static_cast<double>(exact);
    const double early = triangle_gap_lower_bound(A, B, enough);
    CHECK((early > enough || early == bound));
    separated_by_plane += gap > 1e-6 * scale;
  }
  std::printf("triangle_gap_lower_bound: %d pairs, bound >= half the distance on %d\n", checked, useful);
  CHECK(checked > 19000);
  CHECK(useful > checked / 4);  // many pairs' closest features are not along the 11 axes
  CHECK(separated_by_plane > 1000);
  // Touching and intersecting triangles: no gap.
  const Vec3 T[3] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const Vec3 S[3] = {Vec3(0.2, 0.2, 0), Vec3(0.2, 0.2, 1), Vec3(1, 1, 1)};  // touches T at a point
  CHECK(triangle_gap_lower_bound(T, S, 0) == 0);
  const Vec3 P[3] = {Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(1, 1, 1)};  // pierces T
  CHECK(triangle_gap_lower_bound(T, P, 0) == 0);
  const Vec3 N[3] = {Vec3(0, 0, std::nan("")), Vec3(1, 0, 2), Vec3(0, 1, 2)};
  CHECK(triangle_gap_lower_bound(T, N, 0) == 0);
}

TEST_CASE("triangle_time_lower_bound: no motion within its bounds comes within reach before it", "[bvh]") {
  // A moves by tau v plus a turn about a random centre c at rate omega. Given
  // either way: as a turn (TriangleMotion::omega, centre, and w = the
  // second-order term omega^2 / 2 max |x - c| for tau <= 1), or as any motion
  // of speed w >= |omega| max |x - c| (omega = 0). At sampled tau below the
  // bound (and below 1 for the former), A must stay farther than reach from B
  // (the reference distance of the test above, in long double).
  std::mt19937 rng(43);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> U(0, 1);
  int bounded = 0, infinite = 0, receding = 0, tighter = 0, turning = 0, pivots = 0, pivots_tighter = 0;
  for (int i = 0; i < 4000; ++i) {
    const double scale = std::pow(10.0, 4 * U(rng) - 2);
    const DisjointPair pair = disjoint_pair(rng, n, U, i, scale, 3, /*nearly_parallel=*/false);
    const Vec3 *A = pair.A, *B = pair.B, &c0 = pair.c, &m = pair.m;
    const double gap = pair.gap;
    const double reach = i % 5 == 0 ? 0.0 : gap * U(rng);
    // The motion: towards B, across, or away (v), and a turn.
    Vec3 v = scale * Vec3(n(rng), n(rng), n(rng));
    if (i % 3 == 1) v = scale * (m + 0.1 * Vec3(n(rng), n(rng), n(rng)));
    if (i % 3 == 2) v = -scale * m;
    Vec3 centre = c0 + scale * Vec3(n(rng), n(rng), n(rng));
    Vec3 omega = (i % 2 ? 0.0 : 0.3) * Vec3(n(rng), n(rng), n(rng));
    double lever = 0;
    for (int k = 0; k < 3; ++k) lever = std::max(lever, (A[k] - centre).norm());
    const bool directional = i % 4 == 0 || i % 4 == 2;
    // Given as a turn, one fast enough to close the gap within tau = 1.
    if (directional) omega = 2 * gap / lever * Vec3(n(rng), n(rng), n(rng)).normalized();
    // A pivot (i % 4 == 2), as a peg's tip pressed on a wall while G moves
    // towards it: the turn swings A's centroid away from B about A's corner
    // nearest B (omega along m x (centroid - corner)), and the centre sits
    // beside that corner so that G's translation v = -omega x (corner -
    // centre), which keeps the corner in place to first order, points at B.
    const bool pivot = i % 4 == 2;
    if (pivot) {
      int p = 0;
      for (int k = 1; k < 3; ++k)
        if (m.dot(A[k]) > m.dot(A[p])) p = k;
      const Vec3 axis = m.cross((A[0] + A[1] + A[2]) / 3 - A[p]);
      if (axis.norm() > 0) omega = omega.norm() * axis.normalized();
      if (omega.norm() > 0) centre = A[p] + scale * m.cross(omega.normalized());
      lever = 0;
      for (int k = 0; k < 3; ++k) lever = std::max(lever, (A[k] - centre).norm());
      v = -omega.cross(A[p] - centre);
    }
    TriangleMotion isotropic, turn;
    isotropic.v = turn.v = v;
    isotropic.w = omega.norm() * lever * (1 + 1e-9);
    turn.omega = omega;
    turn.centre = centre;
    turn.w = 0.5 * omega.squaredNorm() * lever * (1 + 1e-9);
    // The turn by t |omega| (quat_exp below) moves x - c by sin(t |omega|) e x
    // (x - c) + ...: lambda = sin(t |omega|) / (t |omega|) >= 1 - (t |omega|)^2 / 6
    // for t <= 1.
    if (directional) turn.lag = std::min(1.0, omega.squaredNorm() / 6 * (1 + 1e-9));
    const double tau = triangle_time_lower_bound(A, B, directional ? turn : isotropic, reach,
                                                 std::numeric_limits<double>::infinity());
    REQUIRE(tau >= 0);
    if (directional && omega != Vec3::Zero()) {
      ++turning;
      const double tau_iso = triangle_time_lower_bound(A, B, isotropic, reach, std::numeric_limits<double>::infinity());
      tighter += std::min(tau, 1.0) > std::min(tau_iso, 1.0);
      if (pivot) {
        // Without the lag bound (lag 1: the turn may fall behind entirely, and
        // the translation alone moves the pivot corner) the bound is never later.
        TriangleMotion lagging = turn;
        lagging.lag = 1;
        const double tau_lagging =
            triangle_time_lower_bound(A, B, lagging, reach, std::numeric_limits<double>::infinity());
        ++pivots;
        REQUIRE(tau >= tau_lagging);
        pivots_tighter += tau > 1.01 * tau_lagging;

      }
    }
    if (std::isinf(tau)) {
      ++infinite;
      REQUIRE(omega == Vec3::Zero());  // only a pure translation can never close the gap
    }
    if (!(tau > 0)) continue;
    ++bounded;
    receding += i % 3 == 2 && omega == Vec3::Zero() && tau > 1e6;  // moving away: only the rounding slack bounds it
    const double t_end = directional ? std::min(tau, 1.0) : (std::isinf(tau) ? 10.0 : tau);
    for (int s = 0; s <= 16; ++s) {
      const double t = t_end * s / 16 * (s == 16 ? 0.999999 : 1.0);
      Vec3 At[3];
      const Mat3 Rt = rotation_matrix(normalized(quat_exp(t * omega)));
      for (int k = 0; k < 3; ++k) At[k] = centre + Rt * (A[k] - centre) + t * v;
      const long double dist = triangle_distance(At, B);
      // Rounding of the posed corners and the reference: 1e-14 of the coordinates.
      REQUIRE(dist >= static_cast<long double>(reach) - 1e-14L * (c0.norm() + 40 * scale));
    }
  }
  std::printf("triangle_time_lower_bound: %d pairs with a positive bound, %d receding ones above 1e6, %d infinite; "
              "the turn's direction gives a later bound (up to 1) on %d of %d turning pairs, the lag bound a later "
              "one on %d of %d pivots\n",
              bounded, receding, infinite, tighter, turning, pivots_tighter, pivots);
  CHECK(bounded > 2000);
  CHECK(receding > 100);
  CHECK(tighter > turning / 10);
  CHECK(pivots_tighter > pivots / 2);
  // Touching triangles: no time at all.
  const Vec3 T[3] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const Vec3 S[3] = {Vec3(0.2, 0.2, 0), Vec3(0.2, 0.2, 1), Vec3(1, 1, 1)};
  TriangleMotion up;
  up.v = Vec3(0, 0, 1);
  up.w = 1;
  CHECK(triangle_time_lower_bound(T, S, up, 0, 1) == 0);
  const Vec3 N[3] = {Vec3(0, 0, std::nan("")), Vec3(1, 0, 2), Vec3(0, 1, 2)};
  CHECK(triangle_time_lower_bound(T, N, up, 0, 1) == 0);
}

TEST_CASE("obb_separated: never separates a swept box from a box it reaches, separates far ones", "[bvh]") {
  // The god box (body frame) posed by (R, p), swept along `step` and grown by
  // grow + turn |r_B| (SweptObbFrame::pose); a world point of that swept set is
  // put on the boundary or inside a random oriented world box, which must then
  // not be separated. A world box beyond the swept set's bounding sphere must be.
  std::mt19937 rng(37);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> U(0, 1);
  const auto random_axes = [&](int i) {
    if (i % 5 == 0) return Mat3(Mat3::Identity());
    return rotation_matrix(normalized(Quat{n(rng), n(rng), n(rng), n(rng)}));
  };
  int separated_far = 0, far = 0;
  for (int i = 0; i < 20000; ++i) {
    const double scale = std::pow(10.0, 4 * U(rng) - 2);
    SweptObbFrame f;
    f.R = rotation_matrix(normalized(Quat{n(rng), n(rng), n(rng), n(rng)}));
    if (i % 7 == 0) f.R = rotation_matrix(normalized(quat_exp(1e-3 * Vec3(n(rng), n(rng), n(rng)))));
    f.p = scale * 10 * Vec3(n(rng), n(rng), n(rng));
    f.step = i % 3 == 0 ? Vec3::Zero() : Vec3(scale * std::pow(10.0, -4 * U(rng)) * Vec3(n(rng), n(rng), n(rng)));
    f.grow = i % 4 == 0 ? 0.0 : scale * std::pow(10.0, -8 * U(rng));
    f.turn = i % 2 == 0 ? 0.0 : 1e-3 * U(rng);
    // Directional (every third): the turn's first order swept with the box.
    if (i % 3 == 2) {
      f.spin = 1e-2 * U(rng) * Vec3(n(rng), n(rng), n(rng)).normalized();
      f.spread = f.spin.norm() * (1 + 1e-15);
    }
    Obb body;
    body.axes = random_axes(i);
    body.half = scale * Vec3(n(rng), n(rng), n(rng)).cwiseAbs();
    if (i % 4 == 1) body.half[i % 3] *= 100;  // long and thin
    if (i % 6 == 2) body.half[(i + 1) % 3] = 0;  // flat
    body.center = scale * Vec3(n(rng), n(rng), n(rng));
    const PosedObb a = f.pose(body);
    // A point of the body box (a corner or inside), posed, moved along the
    // step (and its turn's first order spin x (R x_B)), and pushed out by up to
    // its grow (turn included).
    Vec3 x_local;
    for (int k = 0; k < 3; ++k) x_local[k] = (i % 2 ? 2 * U(rng) - 1 : (U(rng) < 0.5 ? -1 : 1)) * body.half[k];
    const Vec3 x_B = body.center + body.axes * x_local;
    const double reach = f.grow + f.turn * x_B.norm();
    const Vec3 y = f.R * x_B + f.p + U(rng) * (f.step + f.spin.cross(f.R * x_B)) +
                   0.999 * reach * Vec3(n(rng), n(rng), n(rng)).normalized();
    REQUIRE(reach <= a.grow);
    // A world box with y inside or on its boundary.
    Obb world;
    world.axes = random_axes(i + 1);
    world.half = scale * Vec3(U(rng), U(rng), U(rng));
    if (i % 3 == 1) world.half[i % 3] = 0;
    Vec3 offset;
    for (int k = 0; k < 3; ++k) offset[k] = (i % 5 == 3 ? (U(rng) < 0.5 ? -1 : 1) : 2 * U(rng) - 1) * world.half[k];
    world.center = y - world.axes * offset;
    REQUIRE_FALSE(obb_separated(a, world));
    // A world box beyond the swept set's bounding sphere: separated.
    const double radius = body.half.norm() + a.half_step.norm() + a.grow;
    const Vec3 dir = Vec3(n(rng), n(rng), n(rng)).normalized();
    Obb away;
    away.axes = random_axes(i + 2);
    away.half = Vec3::Constant(scale);
    away.center = a.center + a.half_step + dir * (radius * 1.01 + 2 * std::sqrt(3.0) * scale);
    ++far;
    separated_far += obb_separated(a, away);
  }
  CHECK(separated_far == far);
  // NaN: never separated.
  PosedObb bad;
  bad.center = Vec3(std::nan(""), 0, 0);
  CHECK_FALSE(obb_separated(bad, Obb{}));
}

TEST_CASE("fit_obb: holds every point, and is thin for points on a thin arc", "[bvh]") {
  std::mt19937 rng(41);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> U(0, 1);
  for (int i = 0; i < 2000; ++i) {
    const double scale = std::pow(10.0, 6 * U(rng) - 3);
    const Vec3 c = 10 * scale * Vec3(n(rng), n(rng), n(rng));
    std::vector<Vec3> pts(3 + i % 20);
    const Vec3 dir = Vec3(n(rng), n(rng), n(rng)).normalized();
    for (Vec3& x : pts) {
      x = c + scale * Vec3(n(rng), n(rng), n(rng));
      if (i % 3 == 0) x = c + scale * n(rng) * dir;                     // collinear
      if (i % 3 == 1) x -= dir * dir.dot(x - c);                        // coplanar
    }
    const Obb b = fit_obb(pts.data(), static_cast<int>(pts.size()));
    REQUIRE((b.axes.transpose() * b.axes - Mat3::Identity()).cwiseAbs().maxCoeff() < 1e-14);
    for (const Vec3& x : pts) {
      const Vec3 local = b.axes.transpose() * (x - b.center);
      // The test's own rounding: the subtraction and product, 1e-15 of the coordinates.
      REQUIRE((local.cwiseAbs() - b.half).maxCoeff() <= 1e-15 * (c.norm() + 10 * scale));
    }
  }
  // Two 10 cm strips of a 1 cm cylinder, 5 degrees each (a peg's leaf): its
  // thickness is the arc's sagitta, where its axis-aligned box at 45 degrees
  // is half a millimetre thick.
  std::vector<Vec3> strip;
  for (int k = 0; k < 3; ++k)
    for (double y : {-0.05, 0.05}) {
      const double a = M_PI / 4 + (k - 1) * 5 * M_PI / 180;
      strip.push_back(Vec3(0.01 * std::cos(a), y, 0.01 * std::sin(a)));
    }
  const Obb s = fit_obb(strip.data(), static_cast<int>(strip.size()));
  CHECK(s.half.minCoeff() < 0.01 * (1 - std::cos(5 * M_PI / 180)));
  CHECK(obb_volume_ratio(s.half, Vec3(0.0006, 0.05, 0.0006)) < 0.5);
}
