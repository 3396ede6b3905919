// AABB trees over triangle meshes (build, feature ownership, swept boxes) and
// the mesh-level CCD step: simultaneous descent of the god-object's and each
// obstacle's tree per sub-interval of the motion, then the narrow-phase tests of
// the owned feature pairs of each candidate triangle pair, earliest hit kept.
#include "gauss6/bvh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>

namespace gauss6 {

const char* to_string(PairKind k) {
  switch (k) {
    case PairKind::kGodVertexObstacleFace: return "god_vertex/obstacle_face";
    case PairKind::kObstacleVertexGodFace: return "obstacle_vertex/god_face";
    case PairKind::kEdgeEdge: return "edge/edge";
  }
  return "unknown";
}

size_t Bvh::memory_bytes() const {
  return nodes.capacity() * sizeof(BvhNode) + triangles.capacity() * sizeof(int32_t) +
         owned.capacity() * sizeof(uint8_t) + neighbor.capacity() * sizeof(int32_t) + sizeof(Bvh);
}

Aabb triangle_box(const TriangleMesh& m, int f) {
  Aabb b;
  const Vec3 a = m.V.row(m.F(f, 0)).transpose(), c = m.V.row(m.F(f, 1)).transpose(),
             d = m.V.row(m.F(f, 2)).transpose();
  b.lo = a.cwiseMin(c).cwiseMin(d);
  b.hi = a.cwiseMax(c).cwiseMax(d);
  return b;
}

Aabb swept_box(const MotionEnclosure& e, const Aabb& body) {
  const IVec3 r = {Interval{body.lo.x(), body.hi.x()}, Interval{body.lo.y(), body.hi.y()},
                   Interval{body.lo.z(), body.hi.z()}};
  const IVec3 w = enclose_point(e, r);
  return {Vec3(w[0].lo, w[1].lo, w[2].lo), Vec3(w[0].hi, w[1].hi, w[2].hi)};
}

Aabb inflate(const Aabb& b, double margin) {
  if (margin == 0) return b;
  Aabb out;
  for (int i = 0; i < 3; ++i) {
    out.lo[i] = next_down(b.lo[i] - margin);
    out.hi[i] = next_up(b.hi[i] + margin);
  }
  return out;
}

namespace {

struct Builder {
  const TriangleMesh& mesh;
  int leaf_size;
  std::vector<Vec3> centroid;
  std::vector<Aabb> tri_box;
  Bvh* bvh;

  Aabb bounds(int begin, int end) const {
    Aabb b = tri_box[bvh->triangles[begin]];
    for (int i = begin + 1; i < end; ++i) {
      b.lo = b.lo.cwiseMin(tri_box[bvh->triangles[i]].lo);
      b.hi = b.hi.cwiseMax(tri_box[bvh->triangles[i]].hi);
    }
    return b;
  }
  // Builds the subtree of triangles[begin, end) into node `index`; returns its depth.
  int build(int index, int begin, int end) {
    bvh->nodes[index].box = bounds(begin, end);
    if (end - begin <= leaf_size) {
      bvh->nodes[index].first = begin;
      bvh->nodes[index].count = end - begin;
      return 1;
    }
    // Split at the median centroid along the longest axis of the centroids' bounds.
    Vec3 lo = centroid[bvh->triangles[begin]], hi = lo;
    for (int i = begin + 1; i < end; ++i) {
      lo = lo.cwiseMin(centroid[bvh->triangles[i]]);
      hi = hi.cwiseMax(centroid[bvh->triangles[i]]);
    }
    int axis;
    (hi - lo).maxCoeff(&axis);
    const int mid = begin + (end - begin) / 2;
    std::nth_element(bvh->triangles.begin() + begin, bvh->triangles.begin() + mid, bvh->triangles.begin() + end,
                     [&](int a, int b) { return centroid[a][axis] < centroid[b][axis]; });
    const int left = static_cast<int>(bvh->nodes.size());
    bvh->nodes.emplace_back();
    bvh->nodes.emplace_back();
    bvh->nodes[index].first = left;
    bvh->nodes[index].count = 0;
    const int dl = build(left, begin, mid);
    const int dr = build(left + 1, mid, end);
    return 1 + std::max(dl, dr);
  }
};

}  // namespace

Bvh build_bvh(const TriangleMesh& mesh, int leaf_size) {
  const auto t0 = std::chrono::steady_clock::now();
  Bvh bvh;
  const int nf = static_cast<int>(mesh.F.rows());
  const int nv = static_cast<int>(mesh.V.rows());
  for (int v = 0; v < nv; ++v) bvh.radius = std::max(bvh.radius, mesh.V.row(v).norm());
  // Ownership: the lowest-numbered triangle of each vertex and of each edge.
  bvh.owned.assign(static_cast<size_t>(nf), 0);
  bvh.neighbor.assign(3 * static_cast<size_t>(nf), -1);
  std::vector<char> vertex_taken(static_cast<size_t>(nv), 0);
  std::map<std::pair<int, int>, std::pair<int, int>> edge_first;  // edge -> (face, slot)
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      if (!vertex_taken[a]) {
        vertex_taken[a] = 1;
        bvh.owned[f] |= static_cast<uint8_t>(1u << k);
      }
      const auto key = std::minmax(a, b);
      const auto it = edge_first.find(key);
      if (it == edge_first.end()) {
        edge_first.emplace(key, std::make_pair(f, k));
        bvh.owned[f] |= static_cast<uint8_t>(1u << (3 + k));
      } else {
        // Second face of the edge: record neighbours both ways (first pair wins
        // on a non-manifold edge).
        const auto [g, j] = it->second;
        if (bvh.neighbor[3 * f + k] < 0) bvh.neighbor[3 * f + k] = g;
        if (bvh.neighbor[3 * g + j] < 0) bvh.neighbor[3 * g + j] = f;
      }
    }
  if (nf > 0) {
    Builder b{mesh, std::max(leaf_size, 1), {}, {}, &bvh};
    b.centroid.resize(static_cast<size_t>(nf));
    b.tri_box.resize(static_cast<size_t>(nf));
    for (int f = 0; f < nf; ++f) {
      b.tri_box[f] = triangle_box(mesh, f);
      b.centroid[f] = (mesh.V.row(mesh.F(f, 0)) + mesh.V.row(mesh.F(f, 1)) + mesh.V.row(mesh.F(f, 2))).transpose() / 3;
    }
    bvh.triangles.resize(static_cast<size_t>(nf));
    std::iota(bvh.triangles.begin(), bvh.triangles.end(), 0);
    bvh.nodes.reserve(2 * static_cast<size_t>(nf / b.leaf_size + 1));
    bvh.nodes.emplace_back();
    bvh.depth = b.build(0, 0, nf);
    bvh.nodes.shrink_to_fit();
  }
  bvh.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return bvh;
}

// ---------------------------------------------------------------------------
// ccd_step
// ---------------------------------------------------------------------------

namespace {

Vec3 vertex(const TriangleMesh& m, int f, int k) { return m.V.row(m.F(f, k)).transpose(); }

// Runs the owned feature pairs of one (god triangle, obstacle triangle) pair on
// the window [u0, *u_best]; lowers *u_best and records the pair on a hit.
struct PairTester {
  const CcdMotion* motion;
  const MotionEnclosure* sub;  // the motion over the sub-interval [u0, u1]
  const CcdStepSettings* settings;
  CcdWorkspace* ws;
  CcdStepResult* result;
  double u0, u1;  // the sub-interval; tests search [u0, min(u1, best u so far)]

  double end() const { return std::min(u1, result->u_hit); }

  void consider(const CcdResult& r, const FeaturePair& p) {
    ++result->num_pair_tests;
    result->num_box_iterations += r.iterations;
    if (!r.hit || (result->hit && r.u_hit >= result->u_hit)) return;
    result->hit = true;
    result->u_hit = r.u_hit;
    result->pair = p;
    result->time_tolerance_reached = r.time_tolerance_reached;
    result->distance_reached = r.distance_reached;
    if (r.status != CcdStatus::kOk) result->status = r.status;  // conservative give-up
  }

  void test(const TriangleMesh& gm, const Bvh& gb, int gf, const TriangleMesh& om, const Bvh& ob, int of,
            int obstacle) {
    const uint8_t go = gb.owned[gf], oo = ob.owned[of];
    CcdResult r;
    const std::array<Vec3, 3> obs_face = {vertex(om, of, 0), vertex(om, of, 1), vertex(om, of, 2)};
    const std::array<Vec3, 3> god_face = {vertex(gm, gf, 0), vertex(gm, gf, 1), vertex(gm, gf, 2)};
    // Feature-level box filter over the sub-interval (conservative: swept boxes
    // enclose the motion, static boxes are grown by min_separation).
    const double margin = settings->narrow.min_separation;
    const auto box_of = [](const Vec3& a, const Vec3& b) { return Aabb{a.cwiseMin(b), a.cwiseMax(b)}; };
    const Aabb obs_face_box = inflate(triangle_box(om, of), margin);
    const Aabb god_face_swept = swept_box(*sub, triangle_box(gm, gf));
    Aabb god_swept[3], god_edge_swept[3];
    for (int k = 0; k < 3; ++k) {
      god_swept[k] = swept_box(*sub, box_of(god_face[k], god_face[k]));
      god_edge_swept[k] = swept_box(*sub, box_of(god_face[k], god_face[(k + 1) % 3]));
    }
    for (int k = 0; k < 3; ++k) {
      if (!(go & (1u << k)) || !(u0 <= end()) || !overlap(god_swept[k], obs_face_box)) continue;
      RigidVertexFaceQuery q{motion, /*vertex_on_body=*/true, god_face[k], obs_face, u0, end()};
      ccd_rigid_vertex_face(q, settings->narrow, ws, &r);
      consider(r, {PairKind::kGodVertexObstacleFace, obstacle, gf, k, of, -1});
    }
    for (int k = 0; k < 3; ++k) {
      if (!(oo & (1u << k)) || !(u0 <= end()) ||
          !overlap(god_face_swept, inflate(box_of(obs_face[k], obs_face[k]), margin)))
        continue;
      RigidVertexFaceQuery q{motion, /*vertex_on_body=*/false, obs_face[k], god_face, u0, end()};
      ccd_rigid_vertex_face(q, settings->narrow, ws, &r);
      consider(r, {PairKind::kObstacleVertexGodFace, obstacle, gf, -1, of, k});
    }
    for (int k = 0; k < 3; ++k) {
      if (!(go & (8u << k))) continue;
      for (int j = 0; j < 3; ++j) {
        if (!(oo & (8u << j)) || !(u0 <= end()) ||
            !overlap(god_edge_swept[k], inflate(box_of(obs_face[j], obs_face[(j + 1) % 3]), margin)))
          continue;
        RigidEdgeEdgeQuery q{motion, {god_face[k], god_face[(k + 1) % 3]}, {obs_face[j], obs_face[(j + 1) % 3]},
                             u0, end()};
        ccd_rigid_edge_edge(q, settings->narrow, ws, &r);
        consider(r, {PairKind::kEdgeEdge, obstacle, gf, k, of, j});
      }
    }
  }
};

}  // namespace

void ccd_step(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const Pose& X0, const Pose& X1,
              const CcdStepSettings& settings, CcdStepWorkspace* ws, CcdStepResult* result) {
  *result = CcdStepResult{};
  const bool inputs_ok = god.mesh && god.bvh && ws && (num_obstacles == 0 || obstacles) &&
                         settings.max_sub_intervals >= 1 && settings.sub_interval_angle > 0 &&
                         settings.sub_interval_travel > 0;
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
  const double margin = settings.narrow.min_separation;
  MotionEnclosure e;
  PairTester tester{&motion, &e, &settings, &ws->narrow, result, 0, 0};
  for (int i = 0; i < n; ++i) {
    const double u0 = static_cast<double>(i) / n;
    const double u1 = (i + 1 == n) ? 1.0 : static_cast<double>(i + 1) / n;
    if (result->hit && result->u_hit <= u0) break;  // earlier hit already found
    enclose_motion(motion, {u0, std::min(u1, result->u_hit)}, &e);
    tester.u0 = u0;
    tester.u1 = u1;
    const auto god_box = [&](const Aabb& body) { return swept_box(e, body); };
    for (int o = 0; o < num_obstacles; ++o) {
      const CcdBody& ob = obstacles[o];
      if (!ob.mesh || !ob.bvh) {
        result->status = CcdStatus::kInvalidInput;
        return;
      }
      const auto visit = [&](int gf, int of) {
        ++result->num_triangle_pairs;
        tester.test(*god.mesh, *god.bvh, gf, *ob.mesh, *ob.bvh, of, o);
        return true;
      };
      const TraversalStatus ts = for_each_candidate_pair(*god.mesh, *god.bvh, *ob.mesh, *ob.bvh, god_box, margin,
                                                         &ws->stack, visit, &result->num_node_pairs);
      if (ts == TraversalStatus::kStackFull) {
        // Unknown beyond here: stop conservatively at the sub-interval's start.
        result->status = CcdStatus::kWorkspaceFull;
        result->hit = true;
        result->u_hit = std::min(result->u_hit, u0);
        return;
      }
    }
  }
  if (!result->hit) result->u_hit = 1;
}

}  // namespace gauss6
