// The mesh-level CCD step (ccd_step.h): the hinted pairs first, then the
// candidates of the proximity cache (coherence between steps) where it covers
// the step, else per sub-interval of the motion a simultaneous descent of the
// god-object's and each obstacle's tree; a time bound for each candidate
// triangle pair and then for each of its owned feature pairs, and the
// narrow-phase tests of the rest, earliest first, earliest hit kept.
#include "gauss6/ccd_step.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "gauss6/distance.h"
#include "pair_tester.h"

namespace gauss6 {

using detail::Displacement;
using detail::PairTester;
using detail::StartFrame;

void ccd_step(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const Pose& X0, const Pose& X1,
              const CcdStepSettings& settings, CcdStepWorkspace* ws, CcdStepResult* result, const FeaturePair* hints,
              int num_hints) {
  *result = CcdStepResult{};
  bool inputs_ok = god.mesh && god.bvh && ws && (num_obstacles == 0 || obstacles) &&
                   settings.max_sub_intervals >= 1 && settings.sub_interval_angle > 0 &&
                   settings.sub_interval_travel > 0;
  for (int o = 0; inputs_ok && o < num_obstacles; ++o) inputs_ok = obstacles[o].mesh && obstacles[o].bvh;
  if (!inputs_ok) {
    result->status = CcdStatus::kInvalidInput;
    return;
  }
  const MotionStatus ms = make_ccd_motion(X0, X1, &result->motion);
  if (ms != MotionStatus::kOk) {
    result->status = ms == MotionStatus::kHalfTurn ? CcdStatus::kHalfTurn : CcdStatus::kInvalidInput;
    return;
  }
  const CcdMotion& motion = result->motion;
  // Sub-intervals: enough that each turns by at most sub_interval_angle and moves
  // G by at most sub_interval_travel radii, so the swept boxes stay tight.
  const double angle = motion_angle(motion.nominal, 1.0);
  const double travel = motion.nominal.dp.norm() / std::max(god.bvh->radius, 1e-300);
  const double want = std::max(angle / settings.sub_interval_angle, travel / settings.sub_interval_travel);
  const int n = static_cast<int>(std::clamp(std::ceil(want), 1.0, static_cast<double>(settings.max_sub_intervals)));
  result->num_sub_intervals = n;
  MotionEnclosure e;
  StartFrame start;
  PairTester tester{&motion, &e, &settings, &ws->narrow, result, 0, 0, &ws->swept, &start,
                    settings.narrow.min_separation};
  CcdStepWorkspace::Candidate* const cand = ws->candidates.data();
  const int cand_capacity = static_cast<int>(ws->candidates.size());
  const double d = settings.narrow.min_separation;
  // The boxes and the pairs' time bounds take the larger of d and the near
  // distance: the candidates are then the near pairs too (a pair that cannot
  // come within the near distance cannot come within d).
  const double reach = std::max(d, settings.near_distance);
  // The hints' triangle pairs first, over the whole step (each distinct pair once).
  // A pair searched here over [0, e] needs no second search: every later
  // window [u0, end()] ends at or before e (end() only shrinks), and the
  // search returned the pair's first contact in [0, e], if any. The sliding
  // contacts are the dearest pairs to search (their gap stays near delta).
  // among(count, ...): the triangle pair is one of hints[0 .. count).
  const auto among = [&](int count, int gf, int of, int o) {
    for (int h = 0; h < count; ++h)
      if (hints[h].god_face == gf && hints[h].obstacle_face == of && hints[h].obstacle == o) return true;
    return false;
  };
  int num_searched = 0;  // hints[0 .. num_searched) were searched (valid or not)
  const auto searched = [&](int gf, int of, int o) { return among(num_searched, gf, of, o); };
  // The hints and the proximity cache both start from the god-object at u = 0.
  if ((hints && num_hints > 0) || settings.cache_margin > 0) start.set(motion, 0.0, god.bvh->radius);
  if (hints && num_hints > 0) {
    enclose_motion(motion, {0, 1}, &e);
    ws->swept.next_interval();
    tester.u0 = 0;
    tester.u1 = 1;
    // The hint on the triangle pair that stopped the workspace's last step, if
    // any, goes first (CcdStepWorkspace::last_hit); the others keep their
    // order: lead, 0, 1, .., lead - 1, lead + 1, ... Either way, once hints[h]
    // is done, so are all of hints[0 .. h].
    const FeaturePair& last = ws->last_hit;
    int lead = 0;
    for (int h = 0; h < num_hints; ++h)
      if (hints[h].god_face == last.god_face && hints[h].obstacle_face == last.obstacle_face &&
          hints[h].obstacle == last.obstacle) {
        lead = h;
        break;
      }
    for (int k = 0; k < num_hints && !tester.done(); ++k) {
      const int h = k == 0 ? lead : (k <= lead ? k - 1 : k);
      const FeaturePair& f = hints[h];
      // (Every obstacle's mesh and tree were checked with the inputs.)
      const bool valid = f.obstacle >= 0 && f.obstacle < num_obstacles && f.god_face >= 0 &&
                         f.god_face < god.mesh->F.rows() && f.obstacle_face >= 0 &&
                         f.obstacle_face < obstacles[f.obstacle].mesh->F.rows();
      if (!valid || among(h, f.god_face, f.obstacle_face, f.obstacle)) continue;  // each distinct pair once
      const CcdBody& ob = obstacles[f.obstacle];
      tester.test(*god.mesh, *god.bvh, f.god_face, *ob.mesh, *ob.bvh, f.obstacle_face, f.obstacle);
      if (k > 0 || lead == 0) num_searched = h + 1;  // (the lead alone is not hints[0 .. lead])
    }
  }
  // Lists the candidate triangle pairs of every obstacle over the motion
  // enclosed in e (start: its frame at u0), the god boxes grown by `dist`:
  // node pairs whose world boxes meet are then tested as oriented boxes (bvh.h:
  // the god node's posed at u0, swept along the translation up to u_end, grown
  // by what else its points may move, plus dist), and visit(gf, of, o) gets the
  // rest (false: stop). Call ws->swept.next_interval() first whenever e changed.
  // traverse(): the same for the motion enclosed in `enc` from `frame`, one
  // obstacle o, from the node pairs pending on `stack` (resume_candidate_pairs)
  // for at most `budget` node pairs, counted in *num_node_pairs.
  const auto traverse = [&](const StartFrame& frame, const MotionEnclosure& enc, double u_end, double dist, int o,
                            BvhStack* stack, int* pending, long budget, int* num_node_pairs, const auto& visit) {
    const SweptObbFrame obb_frame = frame.obb_frame(u_end, dist);
    const auto god_node_obb = [&](int node) -> const PosedObb& {
      return ws->swept.get(ws->swept.node_obbs, node, [&] { return obb_frame.pose(god.bvh->nodes[node].obb); });
    };
    // God boxes grown by dist once here (outward rounded), so the traversal
    // compares them with the obstacles' exact boxes as they are (margin 0
    // below): the same test as growing each obstacle box, without its roundings
    // per node pair.
    const auto box_over = [&](const Aabb& body) { return inflate(swept_box(enc, body), dist); };
    const auto god_node_box = [&](int node) {
      return ws->swept.get(ws->swept.nodes, node, [&] { return box_over(god.bvh->nodes[node].box); });
    };
    const auto god_face_box = [&](int face) {
      return ws->swept.get(ws->swept.faces, face, [&] { return box_over(triangle_box(*god.mesh, face)); });
    };
    const CcdBody& ob = obstacles[o];
    const auto separated = [&](int gi, int oi) { return node_pair_separated(god_node_obb(gi), ob.bvh->nodes[oi]); };
    return resume_candidate_pairs(*god.mesh, *god.bvh, *ob.mesh, *ob.bvh, god_node_box, god_face_box, /*margin=*/0,
                                  stack, pending, budget, [&](int gf, int of) { return visit(gf, of, o); },
                                  num_node_pairs, separated);
  };
  const auto descend = [&](double u_end, double dist, const auto& visit) {
    for (int o = 0; o < num_obstacles; ++o) {
      int pending = 0;
      if (!start_candidate_pairs(*god.bvh, *obstacles[o].bvh, &ws->stack, &pending)) return TraversalStatus::kStackFull;
      const TraversalStatus ts = traverse(start, e, u_end, dist, o, &ws->stack, &pending,
                                          std::numeric_limits<long>::max(), &result->num_node_pairs, visit);
      if (ts != TraversalStatus::kDone) return ts;
    }
    return TraversalStatus::kDone;
  };
  // Earliest-first: each hit shortens the windows of the pairs after it, and
  // once a pair's bound passes the best u so far, so do all the rest.
  const auto test_candidates = [&](int num_cand) {
    std::sort(cand, cand + num_cand, [](const auto& a, const auto& b) { return a.earliest < b.earliest; });
    for (int c = 0; c < num_cand; ++c) {
      if (cand[c].earliest > tester.end() || tester.done()) break;
      const TrianglePair& p = cand[c].pair;
      if (searched(p.god_face, p.obstacle_face, p.obstacle)) continue;
      const CcdBody& ob = obstacles[p.obstacle];
      tester.test(*god.mesh, *god.bvh, p.god_face, *ob.mesh, *ob.bvh, p.obstacle_face, p.obstacle);
    }
  };
  // Whatever the testing finds, u_hit stays <= the end of the window the near
  // pairs were listed for.
  const auto set_near_pairs = [&](int num_cand, double u0) {
    if (settings.near_distance <= 0) return;
    result->num_near_pairs = num_cand;
    result->near_u0 = u0;
    result->near_reach = reach;
  };

  // Coherence (CcdStepWorkspace::ProximityCache): [0, u_cached] is the range
  // over which no point moves farther than the margin from the cache's pose;
  // there the cached pairs are the candidates, with no descent. The range is
  // used when it covers the rest of the step (up to a hint's hit), or, when
  // the god-object starts in contact and no hint hit, as a short first search
  // (under half a sub-interval: a contact likely to be met soon, as a bunny's
  // ear turned back onto the back it rests on, ends the step there without
  // sweeping the boxes over the whole step). A range covering only part of a
  // step would search the pairs near X0 twice: not used. The cache is refilled
  // at X0 when its own range cannot be used for this step and a fresh one's
  // would (a step that moves less than the margin, or a short first search).
  double u_cached = 0;
  CcdStepWorkspace::ProximityCache& pc = ws->cache;
  CcdStepWorkspace::ProximityCache::Fill& pf = pc.fill;
  const double margin = settings.cache_margin, rho = god.bvh->radius;  // start: at u = 0 (above)
  const double margin_max = std::max(settings.cache_margin_max, margin);
  // The margin of a list filled now: about six steps like the last one (v),
  // within [margin, margin_max]: a wide one while the god-object slides
  // steadily (fewer fills), the narrow one at rest (a shorter list to scan).
  const auto list_margin = [&](double v) { return std::clamp(6 * v, margin, margin_max); };
  const auto same = [](const CcdBody& a, const CcdBody& b) { return a.mesh == b.mesh && a.bvh == b.bvh; };
  const auto is_keyed = [&] {
    bool k = pc.num_pairs >= 0 && same(pc.god, god) && pc.reach == reach && pc.margin_min == margin &&
             pc.margin_max == margin_max && static_cast<int>(pc.obstacles.size()) == num_obstacles;
    for (int o = 0; k && o < num_obstacles; ++o) k = same(pc.obstacles[static_cast<size_t>(o)], obstacles[o]);
    return k;
  };
  // Fills: every pair not proven apart by reach + pf.margin with the god-object
  // at pf.ref (X0, or the pose a background fill is started at: see the end of
  // this function), descended into pf.pairs obstacle by obstacle, a budget of
  // node pairs at a time (run_fill: true once complete; a fill that does not
  // fit, in pf.pairs or on pf.stack, is dropped), then swapped in (put_fill).
  const auto start_obstacle = [&] {
    if (pf.obstacle < num_obstacles &&
        !start_candidate_pairs(*god.bvh, *obstacles[pf.obstacle].bvh, &pf.stack, &pf.pending))
      pf.active = false;
  };
  const auto start_fill = [&](const Pose& at, double m) {
    pf.margin = m;
    pf.ref = X0;
    pf.motion = motion;
    if (&at != &X0) {
      CcdMotion still;
      if (make_ccd_motion(at, at, &still) == MotionStatus::kOk) {
        pf.ref = at;
        pf.motion = still;
      }
    }
    pf.cost = 0;
    pf.num_pairs = 0;
    pf.obstacle = 0;
    pf.active = true;
    pf.complete = false;
    start_obstacle();
  };
  const auto fill_some = [&](long budget) {
    if (!pf.active) return false;
    StartFrame frame;
    frame.set(pf.motion, 0.0, rho);
    MotionEnclosure enc;
    enclose_motion(pf.motion, {0, 0}, &enc);
    ws->swept.next_interval();
    const int capacity = static_cast<int>(pf.pairs.size());
    const double fill_dist = next_up(reach + pf.margin);
    while (pf.obstacle < num_obstacles) {
      int used = 0;
      const TraversalStatus ts = traverse(frame, enc, 0.0, fill_dist, pf.obstacle, &pf.stack, &pf.pending, budget,
                                          &used, [&](int gf, int of, int o) {
        double radius = 0;
        const double gap = frame.gap(*god.mesh, gf, *obstacles[o].mesh, of, fill_dist, &radius);
        if (gap > fill_dist) return true;
        if (pf.num_pairs == capacity) return false;  // does not fit: no cache
        pf.pairs[static_cast<size_t>(pf.num_pairs++)] = {gap, radius, gf, of, o};
        return true;
      });
      result->num_fill_node_pairs += used;
      pf.cost += used;
      budget -= used;
      if (ts == TraversalStatus::kPaused) return false;
      if (ts != TraversalStatus::kDone) {
        pf.active = false;
        return false;
      }
      ++pf.obstacle;
      start_obstacle();
      if (!pf.active) return false;
    }
    pf.complete = true;
    pc.fill_cost = pf.cost;
    return true;
  };
  const auto run_fill = [&](long budget) {
    const bool complete = fill_some(budget);
    ws->swept.next_interval();  // the boxes cached were the fill's, not e's
    return complete;
  };
  const auto put_fill = [&] {
    std::swap(pc.pairs, pf.pairs);
    pc.num_pairs = pf.num_pairs;
    pc.ref = pf.ref;
    pc.reach = reach;
    pc.margin = pf.margin;
    pc.margin_min = margin;
    pc.margin_max = margin_max;
    pc.god = god;
    pc.obstacles.assign(obstacles, obstacles + num_obstacles);
    pc.uses = 0;
    pf.active = false;
  };
  bool keyed = margin > 0 && is_keyed();
  if (margin > 0 && !keyed) pf.active = false;  // a fill for other meshes or settings
  double moved = std::numeric_limits<double>::infinity();  // from the cache's pose to X0
  if (margin > 0 && !tester.done()) {
    const double u_rest = result->hit ? result->u_hit : 1.0;
    const bool probing = hints && num_hints > 0 && !result->hit;
    const auto range = [&](double moved, double m) {  // [0, u] keeps every point within m of ref (0: none)
      const double u = start.speed > 0 ? next_down(next_down(m - moved) / start.speed) : 1.0;
      return u > 0 ? std::min(u, 1.0) : 0.0;  // also NaN
    };
    // The part of a cache range [0, u] to search from the cache (0: none): all
    // of it when it covers the rest of the step; as a first search, at most
    // the range over which no point moves a quarter of the margin, and only
    // when that is under half a sub-interval (a longer one saves no descent).
    const double u_probe = start.speed > 0 ? next_down(0.25 * margin / start.speed) : 1.0;
    const auto window = [&](double u) {
      if (!(u > 0)) return 0.0;  // also NaN
      if (u >= u_rest) return u;
      const double w = std::min(u, u_probe);
      return probing && w > 0 && w < 0.5 / n ? w : 0.0;
    };
    const auto usable = [&](double u) { return window(u) > 0; };
    Displacement since(keyed ? pc.ref : X0, X0);
    moved = keyed ? since.bound(rho) : std::numeric_limits<double>::infinity();
    u_cached = keyed ? range(moved, pc.margin) : 0.0;
    if (keyed && pf.active) {
      // The fill's pose is ahead of the god-object's path (see below): put it
      // in use once it leaves more of its margin than the list in use does, or
      // (finished now if need be) when that list cannot serve this step.
      const Displacement ahead(pf.ref, X0);
      const double moved_ahead = ahead.bound(rho);
      const bool better = pf.margin - moved_ahead > pc.margin - moved;
      const bool needed = !usable(u_cached) && usable(range(moved_ahead, pf.margin));
      if (!usable(u_cached) && !needed) {
        pf.active = false;  // the god-object went elsewhere
      } else if ((better && pf.complete) || (needed && run_fill(std::numeric_limits<long>::max()))) {
        put_fill();
        result->cache_refilled = true;
        since = ahead;
        moved = moved_ahead;
        u_cached = range(moved, pc.margin);
      }
    }
    const bool fresh = usable(u_cached);
    if (fresh) ++pc.uses;
    // A fill costs more than a descent over the step (its boxes are grown by
    // the margin) and pays only when later steps use it: after a fill that
    // served fewer than two later steps (a peg sliding half the margin a step,
    // steps that each start far from the last), the next 8 chances to fill
    // are passed over (plain descents), and the one after that fills.
    // A step that moves at most a quarter of the margin fills regardless (the
    // list then serves the next steps unless the god-object speeds up).
    const double fresh_margin = list_margin(pc.has_last ? Displacement(pc.last_x0, X0).bound(rho) : 0.0);
    bool fill = !fresh && usable(range(Displacement(X0, X0).bound(rho), fresh_margin));
    if (fill && 4 * start.speed <= margin) {
      pc.rest = 0;
    } else if (fill && pc.rest > 0) {
      fill = --pc.rest == 0;
    } else if (fill && pc.num_pairs >= 0 && pc.uses < 2) {
      pc.rest = 8;
      fill = false;
    }
    if (fill) {
      // At once, at X0 (u = 0).
      start_fill(X0, fresh_margin);
      const bool filled = run_fill(std::numeric_limits<long>::max());
      pc.clear();
      u_cached = 0;
      keyed = false;
      if (filled) {
        put_fill();
        keyed = true;
        result->cache_filled = true;
        since = Displacement(X0, X0);
        moved = since.bound(rho);
        u_cached = range(moved, pc.margin);
      }
    }
    u_cached = window(u_cached);
    result->u_cached = u_cached;
    if (u_cached > 0) {
      enclose_motion(motion, {0, std::min(u_cached, result->u_hit)}, &e);
      ws->swept.next_interval();
      tester.u0 = 0;
      tester.u1 = u_cached;
      // Each pair's own certificate first: its gap at the cache's pose less how
      // far its points can move from there by u_cached (a few flops); the
      // time bound only for the pairs it does not keep beyond the reach.
      Displacement moving = since;
      moving.add(start, u_cached);
      int num_cand = 0;
      for (int k = 0; k < pc.num_pairs; ++k) {
        const CcdStepWorkspace::ProximityCache::Pair& c = pc.pairs[static_cast<size_t>(k)];
        ++result->num_triangle_pairs;
        if (next_down(c.gap - moving.bound(c.radius)) > reach) {
          ++result->num_axis_culls;
          continue;
        }
        const double t = start.earliest(*god.mesh, c.god_face, *obstacles[c.obstacle].mesh, c.obstacle_face,
                                        reach, tester.end());
        if (t > tester.end()) {
          ++result->num_axis_culls;
          continue;
        }
        cand[num_cand++] = {{c.god_face, c.obstacle_face, c.obstacle}, t};  // fits: the cache has cand's capacity
      }
      set_near_pairs(num_cand, 0.0);
      test_candidates(num_cand);
    }
  }

  for (int i = 0; i < n; ++i) {
    const double u0 = std::max(static_cast<double>(i) / n, u_cached);
    const double u1 = (i + 1 == n) ? 1.0 : static_cast<double>(i + 1) / n;
    if (!(u0 < u1)) continue;  // inside the cached range
    if (result->hit && result->u_hit - settings.narrow.time_tolerance <= u0) break;  // nothing left to search
    enclose_motion(motion, {u0, std::min(u1, result->u_hit)}, &e);
    start.set(motion, u0, god.bvh->radius);
    tester.u0 = u0;
    tester.u1 = u1;
    // Candidate triangle pairs, each with a lower bound of its first contact
    // (StartFrame::earliest); those that cannot touch before the
    // sub-interval's end are dropped here. When the buffer is full the rest are
    // tested at once, in traversal order (same result, less pruning).
    int num_cand = 0;
    bool listed = true;  // every candidate of this sub-interval is in cand (no overflow, no early stop)
    ws->swept.next_interval();  // e changed: every cached god box is stale
    const TraversalStatus ts = descend(std::min(u1, result->u_hit), reach, [&](int gf, int of, int o) {
      const CcdBody& ob = obstacles[o];
      ++result->num_triangle_pairs;
      const double t = start.earliest(*god.mesh, gf, *ob.mesh, of, reach, tester.end());
      if (t > tester.end()) {
        ++result->num_axis_culls;
        return true;
      }
      if (num_cand < cand_capacity) {
        cand[num_cand++] = {{gf, of, o}, t};
        return true;
      }
      listed = false;
      if (!searched(gf, of, o)) tester.test(*god.mesh, *god.bvh, gf, *ob.mesh, *ob.bvh, of, o);
      // A hit at the sub-interval's start cannot be bettered: stop.
      return !tester.done();
    });
    if (ts == TraversalStatus::kStackFull) {
      // Unknown beyond here: stop conservatively at the sub-interval's start.
      result->status = CcdStatus::kWorkspaceFull;
      result->hit = true;
      result->u_hit = std::min(result->u_hit, u0);
      return;
    }
    if (ts == TraversalStatus::kStopped) listed = false;
    set_near_pairs(listed ? num_cand : -1, u0);
    test_candidates(num_cand);
  }
  // The background fill (CcdStepSettings::cache_fill_budget node pairs per
  // step, while the list in use serves). Each step is taken to move the
  // god-object as much as the last one did (v), and a fill to take as many
  // steps as the last one did (j). A fill is started when the list in use has
  // about j steps left, at the pose the god-object will reach if it goes on
  // so for j steps and 3/4 of the margin further: put in use about j steps
  // from now, that list then serves from 3/4 of the margin behind its pose to
  // the margin ahead. Any pose is sound (the list is for the pose it was
  // filled at); a good guess only makes the list serve longer.
  if (margin > 0 && settings.cache_fill_budget > 0 && keyed) {
    if (!pf.active && result->u_cached > 0 && pc.has_last) {
      const double v = Displacement(pc.last_x0, X0).bound(rho);
      const double j = std::ceil(static_cast<double>(std::max(pc.fill_cost, 1L)) /
                                 static_cast<double>(settings.cache_fill_budget));
      const double m = list_margin(v);
      if (v > 0 && v < m && pc.margin - moved <= (j + 1) * v) {
        const double k = j + std::max(0.0, 0.75 * m / v - 1);
        const Quat dq = normalized(X0.q * conjugate(pc.last_x0.q));
        const Pose ahead{X0.p + k * (X0.p - pc.last_x0.p), normalized(quat_exp(k * quat_log(dq)) * X0.q)};
        start_fill(ahead, m);
      }
    }
    if (pf.active && !pf.complete) run_fill(settings.cache_fill_budget);
  }
  if (margin > 0) {
    pc.last_x0 = X0;
    pc.has_last = true;
  }
  if (!result->hit) {
    result->u_hit = 1;
  } else {
    // Pairs searched only up to u_b - tol (PairTester::end): stop there.
    result->u_hit = std::max(0.0, result->u_hit - settings.narrow.time_tolerance);
    ws->last_hit = result->pair;
    result->time_tolerance_reached += settings.narrow.time_tolerance;
  }
}

}  // namespace gauss6
