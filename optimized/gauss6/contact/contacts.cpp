// Contact set generation at a stop pose: BVH descent with boxes grown by the
// contact distance (axis-aligned, then oriented) or the CCD's near pairs,
// closest points of the owned vertex/face and edge/edge pairs, normals signed
// out of the obstacle, merging of duplicates, the reduction of a full set to
// its patches' supports, Jacobian rows.
#include "gauss6/contact/contacts.h"

#include <algorithm>
#include <cmath>
#include <limits>

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
  const double area = u.x() * w.y() - u.y() * w.x();
  // The bound is >= 0 (or NaN): a turn that is not left needs no norms.
  return area > 0 && area > kCollinearSine * u.norm() * w.norm();
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

// Calls on(face, corner) for each face around the vertex at corner c of face
// f (f first), walking across the edges at the vertex in one direction (mesh m,
// its faces' adjacency `neighbor`: bvh.h), until on returns false or the fan
// closes. Returns true when it closed: every face around the vertex was
// visited; false at a boundary edge, a face that lacks the vertex, more than
// kMaxFan faces (a fan that is no disc), or when on stopped it.
constexpr int kMaxFan = 64;
template <class On>
bool walk_fan(const TriangleMesh& m, const std::vector<int32_t>& neighbor, int f, int c, const On& on) {
  const int v = m.F(f, c);
  int face = f, corner = c;
  for (int step = 0; step < kMaxFan; ++step) {
    if (!on(face, corner)) return false;
    // On around v: across v's other edge in this face (from corner + 2 to
    // corner), to the face that shares it.
    const int next = neighbor[3 * static_cast<size_t>(face) + (corner + 2) % 3];
    if (next < 0) return false;
    if (next == f) return true;
    face = next;
    corner = m.F(face, 0) == v ? 0 : m.F(face, 1) == v ? 1 : m.F(face, 2) == v ? 2 : -1;
    if (corner < 0) return false;
  }
  return false;
}

// Whether the plane through the vertex at corner c of face f normal to `out`
// leaves its neighbours on or behind it (out.(w - v) <= sine |w - v| for every
// neighbour w; at(i): vertex i's position): `out` is then an outward normal of
// the vertex's body at the vertex (in its normal cone, to the angle
// asin(sine)). kUnknown when the fan around it does not close.
enum class Support { kYes, kNo, kUnknown };
template <class At>
Support vertex_support(const TriangleMesh& m, const std::vector<int32_t>& neighbor, int f, int c, const Vec3& out,
                       double sine, const At& at) {
  const Vec3 p = at(m.F(f, c));
  bool supports = true;
  const bool closed = walk_fan(m, neighbor, f, c, [&](int face, int corner) {
    for (int k = 1; k <= 2; ++k) {
      const Vec3 e = at(m.F(face, (corner + k) % 3)) - p;
      if (out.dot(e) > sine * e.norm()) supports = false;
    }
    return true;
  });
  return !closed ? Support::kUnknown : supports ? Support::kYes : Support::kNo;
}

// One side of a vertex/face pair: a mesh, its faces' adjacency, and its
// vertices' positions in the world frame.
template <class At>
struct Side {
  const TriangleMesh& mesh;
  const std::vector<int32_t>& neighbor;
  const At& at;
  Vec3 corner(int f, int k) const { return at(mesh.F(f, k)); }
};
template <class At>
Side(const TriangleMesh&, const std::vector<int32_t>&, const At&) -> Side<At>;

// The vertex/face rule (contacts.h): whether the row of the vertex at corner
// vc of face vf (p, on side V, at separation sep from the face) against face
// `face` of side W (unit outward normal nF: the row's normal is -nF seen from
// W, and the vertex's body must have -nF as an outward normal at p) is left
// out: p lies beside the face, beyond one edge or (beyond two) a corner, -nF
// does not support p's body, and another face g of W that shares a corner
// with that edge, or that corner, holds p (p's closest point on the face lies
// on that edge or corner; a vertex just beside a corner of a tool whose bottom
// is two triangles is held by the one that does not share the edge):
//  - g is as near p as the face is (to `tie`, the rounding of the two
//    separations) and within d: g's row is in the set whenever the face's is,
//    and whether the face's row is left out does not depend on d (a set at a
//    larger distance holds every row of the set at a smaller one);
//  - -n_g supports p's body, and no normal turned from it towards nF by more
//    than `turn` does (p's body leaves no room between the two: a flat plate's
//    vertex beside a tool's bottom edge). A curved body's vertex, which
//    supports normals between n_g and nF, keeps the face's row: its contact
//    with the edge pushes along a normal between the two, which n_g alone
//    does not span.
template <class AtV, class AtW>
bool held_beside(const Vec3& p, const Side<AtV>& V, int vf, int vc, const Side<AtW>& W, int face, const Vec3& nF,
                 double sep, double d, double tie, double sine, double turn) {
  const Vec3 P[3] = {W.corner(face, 0), W.corner(face, 1), W.corner(face, 2)};
  bool beyond[3];
  int count = 0;
  for (int k = 0; k < 3; ++k) {
    // nF x (P[k + 1] - P[k]) points into the face (counter-clockwise about nF).
    beyond[k] = (p - P[k]).dot(nF.cross(P[(k + 1) % 3] - P[k])) < 0;
    count += beyond[k];
  }
  if (count == 0 || count == 3) return false;  // over the face (or a degenerate one)
  if (vertex_support(V.mesh, V.neighbor, vf, vc, Vec3(-nF), sine, V.at) != Support::kNo) return false;
  const double reach = std::min(d, sep + tie);
  const double cos_turn = std::cos(turn), sin_turn = std::sin(turn);
  const auto holds = [&](int g) {
    if (g < 0 || g == face) return false;
    const Vec3 q0 = W.corner(g, 0), q1 = W.corner(g, 1), q2 = W.corner(g, 2);
    const Vec3 n2 = unit_normal(q0, q1, q2);
    if (n2 == Vec3::Zero() || !((p - closest_point_on_triangle(p, q0, q1, q2)).norm() <= reach) ||
        vertex_support(V.mesh, V.neighbor, vf, vc, Vec3(-n2), sine, V.at) != Support::kYes)
      return false;
    // n2 turned by `turn` towards nF (in their plane): it must not support p's
    // body. Normals closer than `turn` leave no such room.
    const Vec3 w = nF - nF.dot(n2) * n2;
    const double wn = w.norm();
    if (!(wn > sin_turn)) return true;
    const Vec3 turned = cos_turn * n2 + (sin_turn / wn) * w;
    return vertex_support(V.mesh, V.neighbor, vf, vc, Vec3(-turned), sine, V.at) == Support::kNo;
  };
  // The faces that share the edge's ends, or the corner: walked around each
  // (in one direction: a fan cut by a boundary is walked in part).
  const int k = count == 1 ? (beyond[0] ? 0 : beyond[1] ? 1 : 2) : (!beyond[2] ? 1 : !beyond[0] ? 2 : 0);
  bool held = false;
  for (int i = 0; i < (count == 1 ? 2 : 1) && !held; ++i)
    walk_fan(W.mesh, W.neighbor, face, (k + i) % 3, [&](int g, int) {
      held = holds(g);
      return !held;
    });
  return held;
}

// Whether the boxes [a_lo, a_hi] and [b_lo, b_hi] are more than `gap` apart
// along some axis (compared without rounding: b_lo - a_hi > gap is taken as
// b_lo > a_hi + gap rounded up).
bool boxes_apart(const Vec3& a_lo, const Vec3& a_hi, const Vec3& b_lo, const Vec3& b_hi, double gap) {
  for (int i = 0; i < 3; ++i)
    if (b_lo[i] > (Upper{a_hi[i]} + Upper{gap}).v || a_lo[i] > (Upper{b_hi[i]} + Upper{gap}).v) return true;
  return false;
}

// The contacts within d of one (god triangle, obstacle triangle) pair of
// obstacle o: one pass over the table of feature-pair kinds the two triangles
// own (feature_pair.h), each feature pair's contact added to the set (its
// normal: the face's for vertex/face, the edges' cross product for edge/edge)
// unless the vertex/face rule leaves it out (held_beside). The corners come
// from the two sides (the god-object's posed at X_WB, the obstacle's in the
// world frame).
template <class GodSide, class ObstacleSide>
struct TrianglePairContacts {
  const GodSide& god_side;
  const ObstacleSide& obstacle_side;
  const std::vector<uint8_t>& god_owned;
  const std::vector<uint8_t>& obstacle_owned;
  int o;                                   // the obstacle's index
  double d, apart, par2, support_sine;     // settings.distance; feature boxes apart; parallel_sine^2; sin(merge_angle)
  double tie, turn;                        // separations' rounding (held_beside); settings.patch_angle
  ContactCollector* col;
  ContactSet* set;
  int slab_face = -1;  // the god face of slab_n (its normal, not unit) and slab_l2 (|slab_n|^2 d^2)
  Vec3 slab_n = Vec3::Zero();
  double slab_l2 = 0;

  void test(int gf, int of) {
    const uint8_t go = god_owned[gf], oo = obstacle_owned[of];
    const Vec3 X[3] = {god_side.corner(gf, 0), god_side.corner(gf, 1), god_side.corner(gf, 2)};
    const Vec3 Y[3] = {obstacle_side.corner(of, 0), obstacle_side.corner(of, 1), obstacle_side.corner(of, 2)};
    // Two triangles whose corner boxes lie more than `apart` apart along an
    // axis have no feature pair within d: each feature's box lies inside its
    // triangle's, so each feature pair's boxes are apart too (the rounded
    // differences are monotone), and ContactApart.v's theorems hold for them.
    // The cheapest test first: most pairs of a near list that are not in
    // contact are dropped here.
    Box boxes;
    boxes.x_lo = X[0].cwiseMin(X[1]).cwiseMin(X[2]), boxes.x_hi = X[0].cwiseMax(X[1]).cwiseMax(X[2]);
    boxes.y_lo = Y[0].cwiseMin(Y[1]).cwiseMin(Y[2]), boxes.y_hi = Y[0].cwiseMax(Y[1]).cwiseMax(Y[2]);
    if (boxes_apart(boxes.x_lo, boxes.x_hi, boxes.y_lo, boxes.y_hi, apart)) return;
    // Pairs proven farther apart than d by a separating axis have no pair
    // within d. But an obstacle triangle within d of the god face's plane (a
    // flat tool on a dense flat tessellation: thousands of such pairs) is
    // within d along the face normals and along the edges' cross products,
    // all near that normal, so no axis drops it, and the axes are not tried.
    // The feature pairs of a pair the axes keep (a tool's side face over the
    // plate's triangles along its bottom edge) or do not try, most of which
    // lie far apart, are then sorted by their boxes (the bounds of their
    // corners): one is tested only when its boxes come within `apart` of each
    // other along every axis. Either way the set is the same: the axes and
    // the boxes only save work.
    if (gf != slab_face) {  // consecutive pairs often share their god face
      slab_face = gf;
      slab_n = (X[1] - X[0]).cross(X[2] - X[0]);
      slab_l2 = slab_n.squaredNorm() * (d * d);
    }
    const auto within = [&](const Vec3& y) {
      const double h = slab_n.dot(y - X[0]);
      return h * h <= slab_l2;
    };
    const bool in_slab = within(Y[0]) && within(Y[1]) && within(Y[2]);
    if (!in_slab && triangle_gap_lower_bound(X, Y, d) > d) return;
    for (int i = 0; i < 3; ++i) {
      boxes.x_reach[i] = (Upper{boxes.x_hi[i]} + Upper{apart}).v;
      boxes.y_reach[i] = (Upper{boxes.y_hi[i]} + Upper{apart}).v;
    }
    // k: the god-object's corner (vertex k, or edge k -> k + 1), j: the obstacle's.
    for_each_feature_pair(go, oo, [&](PairKind kind, int k, int j) {
      feature_pair(kind, k, j, gf, of, X, Y, boxes);
      return true;
    });
  }

  // The two triangles' corner boxes, and their upper bounds grown by `apart`
  // (rounded up, as boxes_apart rounds them: computed once for the pair's
  // feature pairs).
  struct Box {
    Vec3 x_lo, x_hi, y_lo, y_hi;
    double x_reach[3], y_reach[3];
  };
  // boxes_apart(v, v, lo, hi, apart), hi + apart given as reach.
  bool vertex_apart(const Vec3& v, const Vec3& lo, const double (&reach)[3]) const {
    for (int i = 0; i < 3; ++i)
      if (lo[i] > (Upper{v[i]} + Upper{apart}).v || v[i] > reach[i]) return true;
    return false;
  }

  void feature_pair(PairKind kind, int k, int j, int gf, int of, const Vec3 (&X)[3], const Vec3 (&Y)[3],
                    const Box& boxes) {
    switch (kind) {
      case PairKind::kGodVertexObstacleFace: {  // the obstacle face's normal
        const Vec3& x = X[k];
        if (vertex_apart(x, boxes.y_lo, boxes.y_reach)) break;
        const double sep = (x - closest_point_on_triangle(x, Y[0], Y[1], Y[2])).norm();
        const Vec3 n = unit_normal(Y[0], Y[1], Y[2]);
        if (!(sep <= d && n != Vec3::Zero())) break;
        if (held_beside(x, god_side, gf, k, obstacle_side, of, n, sep, d, tie, support_sine, turn)) {
          ++set->num_beside;
          break;
        }
        col->add({x, n, sep, {kind, o, gf, k, of, -1}});
        break;
      }
      case PairKind::kObstacleVertexGodFace: {  // minus the god face's normal
        const Vec3& y = Y[j];
        if (vertex_apart(y, boxes.x_lo, boxes.x_reach)) break;
        const Vec3 c = closest_point_on_triangle(y, X[0], X[1], X[2]);
        const double sep = (y - c).norm();
        const Vec3 n = -unit_normal(X[0], X[1], X[2]);
        if (!(sep <= d && n != Vec3::Zero())) break;
        if (held_beside(y, obstacle_side, of, j, god_side, gf, Vec3(-n), sep, d, tie, support_sine, turn)) {
          ++set->num_beside;
          break;
        }
        col->add({c, n, sep, {kind, o, gf, -1, of, j}});
        break;
      }
      case PairKind::kEdgeEdge: {  // closest points inside both edges, edges not parallel
        const Vec3 &g0 = X[k], &g1 = X[(k + 1) % 3];
        const Vec3 &o0 = Y[j], &o1 = Y[(j + 1) % 3];
        if (boxes_apart(g0.cwiseMin(g1), g0.cwiseMax(g1), o0.cwiseMin(o1), o0.cwiseMax(o1), apart)) break;
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
          Vec3 out = unit_normal(Y[0], Y[1], Y[2]);
          const int nb = obstacle_side.neighbor[3 * of + j];
          if (nb >= 0) out += unit_normal(obstacle_side.corner(nb, 0), obstacle_side.corner(nb, 1),
                                          obstacle_side.corner(nb, 2));
          side = n.dot(out);
        }
        if (side < 0) n = -n;
        col->add({pg, n, sep, {kind, o, gf, k, of, j}});
        break;
      }
    }
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

ContactCollector::ContactCollector(const ContactSettings& settings, ContactSet* set) noexcept
    : settings(settings),
      merge_distance(settings.merge_distance > 0 ? settings.merge_distance : 1e-3 * settings.distance),
      merge_cos(std::cos(settings.merge_angle)),
      set(set) {
  // A contact whose point lies farther than merge_distance along an axis is
  // not merged, whatever the rounding of the norm (which errs by under 4 u):
  // the set's contacts are mostly such, and the norm is left for the rest.
  reject = merge_distance * (1 + 8 * std::numeric_limits<double>::epsilon());
  inv_cell = 1 / (4 * reject);
  const size_t buckets = set->merge_head.size();
  indexed = inv_cell > 0 && std::isfinite(inv_cell) && buckets > 0 && (buckets & (buckets - 1)) == 0 &&
            set->merge_next.size() >= set->contacts.size();
  if (indexed) rebuild();
}

bool ContactCollector::cell_of(const Vec3& p, int64_t* ix, int64_t* iy) const {
  const double x = std::floor(p.x() * inv_cell), y = std::floor(p.y() * inv_cell);
  if (!(std::abs(x) < kMaxCell && std::abs(y) < kMaxCell)) return false;  // NaN too
  *ix = static_cast<int64_t>(x);
  *iy = static_cast<int64_t>(y);
  return true;
}

size_t ContactCollector::bucket(int64_t ix, int64_t iy) const {
  uint64_t h = static_cast<uint64_t>(ix) * 0x9E3779B97F4A7C15ull ^ static_cast<uint64_t>(iy) * 0xC2B2AE3D27D4EB4Full;
  h ^= h >> 29;
  return static_cast<size_t>(h) & (set->merge_head.size() - 1);
}

void ContactCollector::insert(int i, int64_t ix, int64_t iy) {
  const size_t b = bucket(ix, iy);
  set->merge_next[i] = set->merge_head[b];
  set->merge_head[b] = i;
}

void ContactCollector::rebuild() {
  std::fill(set->merge_head.begin(), set->merge_head.end(), -1);
  int64_t ix = 0, iy = 0;
  for (int i = 0; i < set->num_contacts; ++i) {
    if (!cell_of(set->contacts[i].point, &ix, &iy)) {
      indexed = false;
      return;
    }
    insert(i, ix, iy);
  }
}

bool ContactCollector::merges(const Contact& o, const Contact& c) const {
  if (std::abs(o.point.x() - c.point.x()) > reject || std::abs(o.point.y() - c.point.y()) > reject) return false;
  return (o.point - c.point).norm() <= merge_distance && o.normal.dot(c.normal) >= merge_cos;
}

void ContactCollector::add(const Contact& c) noexcept {
  ++set->num_pairs_within;
  int64_t ix = 0, iy = 0;
  if (indexed && !cell_of(c.point, &ix, &iy)) indexed = false;  // every contact is compared from now on
  // The first contact of the set (in its order) that c merges with.
  int first = -1;
  if (indexed) {
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int i = set->merge_head[bucket(ix + dx, iy + dy)]; i >= 0; i = set->merge_next[i])
          if ((first < 0 || i < first) && merges(set->contacts[i], c)) first = i;
  } else {
    for (int i = 0; i < set->num_contacts && first < 0; ++i)
      if (merges(set->contacts[i], c)) first = i;
  }
  if (first >= 0) {  // merged: the smaller separation stays
    Contact& o = set->contacts[first];
    if (c.separation < o.separation) {
      int64_t ox = 0, oy = 0;
      const bool moved = indexed && (!cell_of(o.point, &ox, &oy) || ox != ix || oy != iy);
      o = c;
      if (moved) rebuild();
    }
    return;
  }
  if (set->num_contacts == set->capacity()) {
    ++set->num_reductions;
    if (reduce_to_patch_supports(settings.patch_angle, set) == 0) {
      overflow = true;
      return;
    }
    if (indexed) rebuild();
  }
  if (indexed) insert(set->num_contacts, ix, iy);
  set->contacts[set->num_contacts++] = c;
}

Aabb posed_body_box(const Mat3& R, const Mat3& absR, const Vec3& G, const Aabb& box) noexcept {
  // Centre and half extents through |R|, grown by kBoxPoseRounding relative to
  // |G| + |R| |mid| + h: the magnitudes before G and R mid cancel, to which
  // the posed vertices' rounding is relative (not to |c|, which cancelling
  // makes small), and kUnderflowFloor.
  const Vec3 mid = 0.5 * (box.lo + box.hi);
  const Vec3 c = G + R * mid;
  const Vec3 h = absR * (0.5 * (box.hi - box.lo));
  const Vec3 reach = G.cwiseAbs() + absR * mid.cwiseAbs() + h;
  const Vec3 slack = kBoxPoseRounding * reach + Vec3::Constant(kUnderflowFloor);
  return Aabb{c - h - slack, c + h + slack};
}

ContactStatus generate_contacts(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const Pose& X_WB,
                                const ContactSettings& settings, ContactWorkspace* ws, ContactSet* set,
                                const NearPairs& near) noexcept {
  set->num_contacts = 0;
  set->num_pairs_within = 0;
  set->num_reductions = 0;
  set->num_beside = 0;
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
  const Mat3 absR = R.cwiseAbs();
  const auto god_box = [&](const Aabb& b) { return posed_body_box(R, absR, G, b); };
  const double d = settings.distance;
  // Node pairs whose boxes meet are then tested as oriented boxes (bvh.h), the
  // god node's posed at X_WB and grown by d: a fixed pose, no motion.
  SweptObbFrame obb_frame;
  obb_frame.set_rotation(R);
  obb_frame.p = G;
  obb_frame.grow = d;
  ContactCollector col(settings, set);
  const double par2 = settings.parallel_sine * settings.parallel_sine;
  const double support_sine = std::sin(settings.merge_angle);
  // Features whose boxes are more than `apart` apart along an axis have a
  // computed separation above d (their closest points' rounding, under 40 u
  // of the coordinates' magnitude, which `scale` bounds, is within
  // kBoxPoseRounding scale): they need no test, and the set is the same with
  // or without it. Machine-checked for d >= 2^-500 (check_delta_scale's
  // kMinDelta): proofs/ContactApart.v, apart_vertex_face, apart_edge_edge.
  double scale = std::abs(G.x()) + std::abs(G.y()) + std::abs(G.z()) + god.bvh->radius;
  for (int o = 0; o < num_obstacles; ++o)
    if (obstacles[o].bvh) scale = std::max(scale, obstacles[o].bvh->radius);
  const double apart = (Upper{2 * d} + Upper{kBoxPoseRounding} * Upper{scale}).v;
  // Two faces that share an edge compute one vertex's separations within `tie`
  // when both take that edge's branch or its ends' (each point within 200 u of
  // the coordinates' magnitude of the edge's exact closest point, the
  // separations within 460 u of it and 2^-530: proofs/ContactTie.v,
  // tie_shared_edge). The floor kNormFloor covers the squares' underflow in
  // the norms; it matters only in a scene smaller than about 2^-450.
  const double tie = std::max((Upper{kBoxPoseRounding} * Upper{scale}).v, kNormFloor);
  ContactStatus status = ContactStatus::kOk;
  for (int o = 0; o < num_obstacles; ++o) {
    if (!obstacles[o].mesh || !obstacles[o].bvh) return ContactStatus::kInvalidInput;
    const TriangleMesh& om = *obstacles[o].mesh;
    const Bvh& ob = *obstacles[o].bvh;
    const auto god_at = [&](int v) -> Vec3 { return world(v); };
    const auto obstacle_at = [&](int v) -> Vec3 { return om.V.row(v).transpose(); };
    const Side god_side{gm, god.bvh->neighbor, god_at};
    const Side obstacle_side{om, ob.neighbor, obstacle_at};
    TrianglePairContacts<decltype(god_side), decltype(obstacle_side)> pair{
        god_side, obstacle_side, god.bvh->owned, ob.owned, o, d, apart, par2, support_sine, tie, settings.patch_angle,
        &col, set};
    const auto visit = [&](int gf, int of) {
      pair.test(gf, of);
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
          ws->boxes.get(ws->boxes.node_obbs, gi, [&] { return obb_frame.pose(god.bvh->nodes[gi]); }),
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
