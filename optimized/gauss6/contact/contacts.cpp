// Contact set generation at a stop pose: BVH descent with boxes grown by the
// contact distance (axis-aligned, then oriented) or the CCD's near pairs,
// closest points of the owned vertex/face and edge/edge pairs, normals signed
// out of the obstacle, merging of duplicates, the reduction of a full set to
// its patches' supports, Jacobian rows.
#include "gauss6/contact/contacts.h"

#include <algorithm>
#include <cmath>

#include "gauss6/geometry/distance.h"
#include "gauss6/numeric/error_allowances.h"
#include "gauss6/geometry/feature_pair.h"
#include "gauss6/ccd/motion_bounds.h"

namespace gauss6 {

const char* to_string(ContactStatus s) {
  switch (s) {
    case ContactStatus::kOk: return "ok";
    case ContactStatus::kOverflow: return "overflow: more contacts than the set holds, first ones kept";
    case ContactStatus::kStackFull: return "stack_full: traversal stack too small, set incomplete";
    case ContactStatus::kInvalidInput: return "invalid_input: bad pose, distance or bodies";
  }
  return "unknown";
}

namespace {

Vec3 unit_normal(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double len = n.norm();
  return len > 0 && std::isfinite(len) ? Vec3(n / len) : Vec3::Zero();
}

// Whether a -> b -> c turns left by more than rounding: twice the signed area
// of the triangle above kCollinearSine |b - a| |c - a|. Points along a hull
// edge (the contacts of a tool's edge crossing a plate's edges) are collinear
// only to the rounding of their coordinates, which would keep them all.
constexpr double kCollinearSine = 1e-12;
bool turns_left(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d u = b - a, w = c - a;
  return u.x() * w.y() - u.y() * w.x() > kCollinearSine * u.norm() * w.norm();
}

// Marks keep[] for the vertices of the convex hull of plane[idx[0 .. n))
// (Andrew's monotone chain; points on a hull edge between two vertices, to
// kCollinearSine, and repeated points are not vertices). idx is sorted in
// place; hull: scratch of n + 1 entries.
void mark_hull(const std::vector<Eigen::Vector2d>& plane, int* idx, int n, int* hull, std::vector<unsigned char>* keep) {
  std::sort(idx, idx + n, [&](int a, int b) {
    return plane[a].x() < plane[b].x() || (plane[a].x() == plane[b].x() && plane[a].y() < plane[b].y());
  });
  int h = 0;
  for (int pass = 0; pass < 2; ++pass) {  // the lower chain, then the upper one
    const int floor = h;
    for (int i = 0; i < n; ++i) {
      const int p = idx[pass == 0 ? i : n - 1 - i];
      while (h >= floor + 2 && !turns_left(plane[hull[h - 2]], plane[hull[h - 1]], plane[p])) --h;
      hull[h++] = p;
    }
    --h;  // the chain's last point starts the other chain
  }
  for (int i = 0; i < std::max(h, 1); ++i) (*keep)[hull[i]] = 1;
}

struct Collector {
  const ContactSettings& settings;
  double merge_distance, merge_cos;
  ContactSet* set;
  bool overflow = false;

  void add(const Contact& c) {
    ++set->num_pairs_within;
    for (int i = 0; i < set->num_contacts; ++i) {
      Contact& o = set->contacts[i];
      if ((o.point - c.point).norm() <= merge_distance && o.normal.dot(c.normal) >= merge_cos) {
        if (c.separation < o.separation) o = c;
        return;
      }
    }
    if (set->num_contacts == set->capacity()) {
      ++set->num_reductions;
      if (reduce_to_patch_supports(settings.patch_angle, set) == 0) {
        overflow = true;
        return;
      }
    }
    set->contacts[set->num_contacts++] = c;
  }
};

}  // namespace

int reduce_to_patch_supports(double patch_angle, ContactSet* set) noexcept {
  const int m = set->num_contacts;
  const double patch_cos = std::cos(patch_angle);
  std::fill(set->patch.begin(), set->patch.begin() + m, -1);
  std::fill(set->keep.begin(), set->keep.begin() + m, 0);
  for (int r = 0; r < m; ++r) {
    if (set->patch[r] >= 0) continue;
    // The patch of r: the contacts not yet in a patch whose normals agree with r's.
    const Vec3& n = set->contacts[r].normal;
    int* idx = set->order.data();
    int count = 0, closest = r;
    for (int i = r; i < m; ++i) {
      if (set->patch[i] >= 0 || set->contacts[i].normal.dot(n) < patch_cos) continue;
      set->patch[i] = r;
      idx[count++] = i;
      if (set->contacts[i].separation < set->contacts[closest].separation) closest = i;
    }
    set->keep[closest] = 1;
    if (count < 3) {
      for (int k = 0; k < count; ++k) set->keep[idx[k]] = 1;
      continue;
    }
    // Coordinates in the plane normal to n (the normal's part of a point does
    // not enter its row: n x n = 0).
    const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
    for (int k = 0; k < count; ++k)
      set->plane[idx[k]] = Eigen::Vector2d(set->contacts[idx[k]].point.dot(u), set->contacts[idx[k]].point.dot(v));
    mark_hull(set->plane, idx, count, set->hull.data(), &set->keep);
  }
  int kept = 0;
  for (int i = 0; i < m; ++i)
    if (set->keep[i]) set->contacts[kept++] = set->contacts[i];
  set->num_contacts = kept;
  return m - kept;
}

ContactStatus generate_contacts(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const Pose& X_WB,
                                const ContactSettings& settings, ContactWorkspace* ws, ContactSet* set,
                                const NearPairs& near) noexcept {
  set->num_contacts = 0;
  set->num_pairs_within = 0;
  set->num_reductions = 0;
  if (!god.mesh || !god.bvh || !ws || !is_valid_pose(X_WB) || !(settings.distance > 0) ||
      !std::isfinite(settings.distance) || ws->god_world.size() != static_cast<size_t>(god.mesh->V.rows()) ||
      (num_obstacles > 0 && !obstacles) || (near.num_pairs > 0 && !near.pairs))
    return ContactStatus::kInvalidInput;
  const TriangleMesh& gm = *god.mesh;
  const Mat3 R = rotation_matrix(X_WB.q);
  const Vec3& G = X_WB.p;
  // God vertices are posed when a candidate pair first needs them: most of a
  // large mesh is never near an obstacle.
  if (++ws->stamp == 0) {  // wrapped around (every 2^32 calls)
    std::fill(ws->posed.begin(), ws->posed.end(), 0);
    ws->stamp = 1;
  }
  ws->boxes.next_interval();  // a new pose: every cached god box is stale
  const auto world = [&](int v) -> const Vec3& {
    if (ws->posed[v] != ws->stamp) {
      ws->god_world[v] = G + R * gm.V.row(v).transpose();
      ws->posed[v] = ws->stamp;
    }
    return ws->god_world[v];
  };
  // World box of a body box: centre and half extents through |R|, grown by a
  // rounding allowance (kBoxPoseRounding: the double vertices above round too).
  const Mat3 absR = R.cwiseAbs();
  const auto god_box = [&](const Aabb& b) {
    const Vec3 c = G + R * (0.5 * (b.lo + b.hi));
    const Vec3 h = absR * (0.5 * (b.hi - b.lo));
    const Vec3 slack = kBoxPoseRounding * (c.cwiseAbs() + h) + Vec3::Constant(kUnderflowFloor);
    return Aabb{c - h - slack, c + h + slack};
  };
  const double d = settings.distance;
  // Node pairs whose boxes meet are then tested as oriented boxes (bvh.h), the
  // god node's posed at X_WB and grown by d: a fixed pose, no motion.
  SweptObbFrame obb_frame;
  obb_frame.R = R;
  obb_frame.p = G;
  obb_frame.grow = d;
  Collector col{settings, settings.merge_distance > 0 ? settings.merge_distance : 1e-3 * d,
                std::cos(settings.merge_angle), set};
  const double par2 = settings.parallel_sine * settings.parallel_sine;
  ContactStatus status = ContactStatus::kOk;
  for (int o = 0; o < num_obstacles; ++o) {
    if (!obstacles[o].mesh || !obstacles[o].bvh) return ContactStatus::kInvalidInput;
    const TriangleMesh& om = *obstacles[o].mesh;
    const Bvh& ob = *obstacles[o].bvh;
    const auto ov = [&](int f, int k) -> Vec3 { return om.V.row(om.F(f, k)).transpose(); };
    const auto gv = [&](int f, int k) -> const Vec3& { return world(gm.F(f, k)); };
    const auto visit = [&](int gf, int of) {
      const uint8_t go = god.bvh->owned[gf], oo = ob.owned[of];
      const Vec3 oa = ov(of, 0), obb = ov(of, 1), oc = ov(of, 2);
      // Pairs proven farther apart than d by a separating axis have no pair within d.
      const Vec3 X[3] = {gv(gf, 0), gv(gf, 1), gv(gf, 2)}, Y[3] = {oa, obb, oc};
      if (triangle_gap_lower_bound(X, Y, d) > d) return true;
      // One pass over the table of feature-pair kinds (feature_pair.h); k: the
      // god-object's corner (vertex k, or edge k -> k + 1), j: the obstacle's.
      for_each_feature_pair(go, oo, [&](PairKind kind, int k, int j) {
        switch (kind) {
          case PairKind::kGodVertexObstacleFace: {  // the obstacle face's normal
            const Vec3& x = gv(gf, k);
            const double sep = (x - closest_point_on_triangle(x, oa, obb, oc)).norm();
            const Vec3 n = unit_normal(oa, obb, oc);
            if (sep <= d && n != Vec3::Zero()) col.add({x, n, sep, {kind, o, gf, k, of, -1}});
            break;
          }
          case PairKind::kObstacleVertexGodFace: {  // minus the god face's normal
            const Vec3 y = ov(of, j);
            const Vec3 c = closest_point_on_triangle(y, gv(gf, 0), gv(gf, 1), gv(gf, 2));
            const double sep = (y - c).norm();
            const Vec3 n = -unit_normal(gv(gf, 0), gv(gf, 1), gv(gf, 2));
            if (sep <= d && n != Vec3::Zero()) col.add({c, n, sep, {kind, o, gf, -1, of, j}});
            break;
          }
          case PairKind::kEdgeEdge: {  // closest points inside both edges, edges not parallel
            const Vec3 &g0 = gv(gf, k), &g1 = gv(gf, (k + 1) % 3);
            const Vec3 o0 = ov(of, j), o1 = ov(of, (j + 1) % 3);
            double s, t;
            closest_segment_parameters(g0, g1, o0, o1, &s, &t);
            if (!(s > 0 && s < 1 && t > 0 && t < 1)) break;
            const Vec3 pg = g0 + s * (g1 - g0), po = o0 + t * (o1 - o0);
            const double sep = (pg - po).norm();
            if (!(sep <= d)) break;
            Vec3 n = (g1 - g0).cross(o1 - o0);
            if (n.squaredNorm() <= par2 * (g1 - g0).squaredNorm() * (o1 - o0).squaredNorm()) break;
            n.normalize();
            // Sign: from the obstacle's point to the god-object's; if they coincide,
            // along the obstacle edge's outward direction (sum of its faces' normals).
            double side = n.dot(pg - po);
            if (side == 0) {
              Vec3 out = unit_normal(oa, obb, oc);
              const int nb = ob.neighbor[3 * of + j];
              if (nb >= 0) out += unit_normal(ov(nb, 0), ov(nb, 1), ov(nb, 2));
              side = n.dot(out);
            }
            if (side < 0) n = -n;
            col.add({pg, n, sep, {kind, o, gf, k, of, j}});
            break;
          }
        }
        return true;
      });
      return true;
    };
    if (near.listed()) {  // the listed pairs of this obstacle (in range: ccd_step made them)
      for (int k = 0; k < near.num_pairs; ++k) {
        const TrianglePair& p = near[k];
        if (p.obstacle == o && p.god_face < gm.F.rows() && p.obstacle_face < om.F.rows())
          visit(p.god_face, p.obstacle_face);
      }
      continue;
    }
    int node_pairs = 0;
    const auto node_box = [&](int node) {
      return ws->boxes.get(ws->boxes.nodes, node, [&] { return god_box(god.bvh->nodes[node].box); });
    };
    const auto face_box = [&](int face) {
      return ws->boxes.get(ws->boxes.faces, face, [&] { return god_box(triangle_box(gm, face)); });
    };
    const auto separated = [&](int gi, int oi) {
      return node_pair_separated(
          ws->boxes.get(ws->boxes.node_obbs, gi, [&] { return obb_frame.pose(god.bvh->nodes[gi].obb); }),
          ob.nodes[oi]);
    };
    if (for_each_candidate_pair_indexed(gm, *god.bvh, om, ob, node_box, face_box, d, &ws->stack, visit, &node_pairs,
                                        separated) ==
        TraversalStatus::kStackFull)
      status = ContactStatus::kStackFull;
  }
  // A set that was reduced while it was searched holds the contacts found
  // since its last reduction as they came: reduced once more, it is its
  // patches' supports alone (the fewer rows, the cheaper the projections).
  if (set->num_reductions > 0) reduce_to_patch_supports(settings.patch_angle, set);
  // Jacobian rows J_k = [n_k^T, ((I_k - G) x n_k)^T].
  for (int k = 0; k < set->num_contacts; ++k) {
    const Contact& c = set->contacts[k];
    set->J.row(k).head<3>() = c.normal.transpose();
    set->J.row(k).tail<3>() = (c.point - G).cross(c.normal).transpose();
  }
  if (status == ContactStatus::kOk && col.overflow) status = ContactStatus::kOverflow;
  return status;
}

}  // namespace gauss6
