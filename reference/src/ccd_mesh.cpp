// Exact mesh-level queries of the reference: first contact of a moving mesh
// against a static one under the Cayley motion (conservative box culling, then
// the interval filter of ccd_filter.cpp, the exact primitives of ccd_exact.cpp
// for the pairs it cannot rule out), exact triangle/triangle intersection
// count and exact separation distance at a pose. The posed-mesh queries cull
// pairs on conservative boxes (groups of god-object faces, "body" here, against a walk of the
// obstacle's face tree) and decide each pair with CGAL's filtered predicates:
// interval arithmetic first, Gmpq only when the intervals cannot decide. See gauss6/reference/ccd.h.
#include "gauss6/reference/ccd.h"

#include "ccd_filter.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <stdexcept>

#include <CGAL/Bbox_3.h>
#include <CGAL/Filtered_predicate.h>
#include <CGAL/Gmpq.h>
#include <CGAL/Interval_nt.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/intersections.h>
#include <CGAL/squared_distance_3.h>

namespace gauss6::reference {
namespace {

// Exact kernel (the answers) and interval kernel (the filters' first stage;
// Interval_nt_advanced needs upward rounding: CGAL::Protect_FPU_rounding).
using ExactKernel = CGAL::Simple_cartesian<CGAL::Gmpq>;
using IntervalKernel = CGAL::Simple_cartesian<CGAL::Interval_nt_advanced>;

// Relative inflation of boxes computed in doubles from exact data. Their
// rounding errors are below 1e-14 relative to the magnitudes involved (a few
// dozen operations at 2^-53 each); 1e-9 leaves a margin of five orders.
constexpr double kBoxInflation = 1e-9;

// The empty box (lo > hi), where grow() starts: the shared Aabb's default is
// the point 0, not empty.
Aabb empty_box() { return {Vec3::Constant(1), Vec3::Constant(-1)}; }

Aabb point_box(const Vec3& p) { return {p, p}; }

void grow(Aabb* b, const Aabb& o) {
  if (o.lo.x() > o.hi.x()) return;
  if (b->lo.x() > b->hi.x()) {
    *b = o;
    return;
  }
  b->lo = b->lo.cwiseMin(o.lo);
  b->hi = b->hi.cwiseMax(o.hi);
}

// Top-down tree, median split on the longest axis of the centres.
AabbTree build_tree(const std::vector<Aabb>& boxes) {
  AabbTree t;
  t.item.resize(boxes.size());
  std::iota(t.item.begin(), t.item.end(), 0);
  if (boxes.empty()) return t;
  constexpr int kLeafSize = 4;
  struct Task {
    int node, first, count;
  };
  auto new_node = [&t] {
    t.box.push_back(empty_box());
    t.child.push_back(-1);
    t.first.push_back(0);
    t.count.push_back(0);
    return int(t.box.size()) - 1;
  };
  std::vector<Task> stack{{new_node(), 0, int(boxes.size())}};
  while (!stack.empty()) {
    const Task task = stack.back();
    stack.pop_back();
    Aabb box = empty_box(), centres = empty_box();
    for (int i = task.first; i < task.first + task.count; ++i) {
      grow(&box, boxes[t.item[i]]);
      grow(&centres, point_box(0.5 * (boxes[t.item[i]].lo + boxes[t.item[i]].hi)));
    }
    t.box[task.node] = box;
    if (task.count <= kLeafSize) {
      t.first[task.node] = task.first;
      t.count[task.node] = task.count;
      continue;
    }
    int axis = 0;
    (centres.hi - centres.lo).maxCoeff(&axis);
    const int half = task.count / 2;
    auto begin = t.item.begin() + task.first;
    std::nth_element(begin, begin + half, begin + task.count, [&](int a, int b) {
      return boxes[a].lo[axis] + boxes[a].hi[axis] < boxes[b].lo[axis] + boxes[b].hi[axis];
    });
    const int left = new_node();
    new_node();
    t.child[task.node] = left;
    stack.push_back({left, task.first, half});
    stack.push_back({left + 1, task.first + half, task.count - half});
  }
  return t;
}

// Calls visit(item) for every item whose box overlaps query.
template <class Visit>
void query_tree(const AabbTree& t, const Aabb& query, Visit&& visit) {
  if (t.box.empty()) return;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const int n = stack[--top];
    if (!overlap(t.box[n], query)) continue;
    if (t.child[n] < 0) {
      for (int i = t.first[n]; i < t.first[n] + t.count[n]; ++i) visit(t.item[i]);
    } else {
      stack[top++] = t.child[n];
      stack[top++] = t.child[n] + 1;
    }
  }
}

Vec3 vertex(const TriangleMesh& m, int v) { return m.V.row(v).transpose(); }

void check_mesh(const TriangleMesh& m, const char* name) {
  if (m.V.rows() == 0 || m.F.rows() == 0) throw std::invalid_argument(std::string(name) + " mesh is empty");
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (m.F(f, k) < 0 || m.F(f, k) >= m.V.rows())
        throw std::invalid_argument(std::string(name) + " mesh: vertex index out of range in face " +
                                    std::to_string(f));
  if (!m.V.allFinite()) throw std::invalid_argument(std::string(name) + " mesh: non-finite vertex");
}

// The body's vertices at pose X, in three forms: doubles with a proven error
// bound (for the culling boxes), interval enclosures of the exact positions
// (the filtered predicates' first stage) and the exact Gmpq positions (their
// second stage). All are p + R(q) r with R(q) the rational rotation of
// METHOD.md section 1; the exact one is transform_point_exact's value. The
// enclosures and exact values are computed on demand, for the vertices of
// candidate pairs only.
class PosedBody {
 public:
  PosedBody(const TriangleMesh& body, const Pose& X)
      : body_(body), X_(X), approx_(body.V.rows()), state_(body.V.rows(), kUnknown), exact_(body.V.rows()) {
    // The exact form throws on a zero quaternion or a non-finite coordinate:
    // check those up front so that every pose is refused the same way.
    if (X.q.w == 0 && X.q.x == 0 && X.q.y == 0 && X.q.z == 0)
      throw std::domain_error("exact pose: zero quaternion");
    if (!(std::isfinite(X.q.w) && std::isfinite(X.q.x) && std::isfinite(X.q.y) && std::isfinite(X.q.z) &&
          X.p.allFinite()))
      throw std::domain_error("non-finite coordinate in an exact query");
    // Magnitude bounds under which neither the doubles nor the intervals
    // overflow or divide by (an interval holding) zero: the largest |q_i| in
    // [2^-250, 2^250], |p_i| and |r_i| <= 2^250 (r checked per vertex).
    // Outside them (never for a metre-scale scene) vertices are handled exactly.
    const double qmax = std::max({std::abs(X.q.w), std::abs(X.q.x), std::abs(X.q.y), std::abs(X.q.z)});
    in_range_ = qmax >= kSmall && qmax <= kBig && X.p.cwiseAbs().maxCoeff() <= kBig;
    if (in_range_) {
      const double w = X.q.w, x = X.q.x, y = X.q.y, z = X.q.z, n = X.q.norm2();
      R_ << w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y), 2 * (x * y + w * z),
          w * w - x * x + y * y - z * z, 2 * (y * z - w * x), 2 * (x * z - w * y), 2 * (y * z + w * x),
          w * w - x * x - y * y + z * z;
      R_ /= n;
      CGAL::Protect_FPU_rounding<true> upward;  // Interval_nt_advanced needs it
      using I = IntervalKernel::FT;
      const I wi(w), xi(x), yi(y), zi(z);
      const I n2 = CGAL::square(wi) + CGAL::square(xi) + CGAL::square(yi) + CGAL::square(zi);
      RI_[0][0] = (wi * wi + xi * xi - yi * yi - zi * zi) / n2;
      RI_[0][1] = 2 * (xi * yi - wi * zi) / n2;
      RI_[0][2] = 2 * (xi * zi + wi * yi) / n2;
      RI_[1][0] = 2 * (xi * yi + wi * zi) / n2;
      RI_[1][1] = (wi * wi - xi * xi + yi * yi - zi * zi) / n2;
      RI_[1][2] = 2 * (yi * zi - wi * xi) / n2;
      RI_[2][0] = 2 * (xi * zi - wi * yi) / n2;
      RI_[2][1] = 2 * (yi * zi + wi * xi) / n2;
      RI_[2][2] = (wi * wi - xi * xi - yi * yi + zi * zi) / n2;
    }
  }

  // Conservative double box of vertex v: it contains the exact position. In
  // range: p + R r in doubles (R rounded from q), grown by kBoxInflation times
  // the magnitudes involved, far above the few dozen roundings of 2^-53 each
  // (and by 1e-300 against underflow). Otherwise: from the exact value
  // (mpq_get_d truncates: one step outward covers it).
  CGAL::Bbox_3 box(int v) const {
    const Vec3 r = vertex(body_, v);
    if (in_range_ && r.cwiseAbs().maxCoeff() <= kBig) {
      const Vec3 x = X_.p + R_ * r;
      const double e = kBoxInflation * (X_.p.cwiseAbs().maxCoeff() + r.cwiseAbs().sum()) + 1e-300;
      return {x.x() - e, x.y() - e, x.z() - e, x.x() + e, x.y() + e, x.z() + e};
    }
    const ExactKernel::Point_3& p = exact(v);
    double lo[3], hi[3];
    for (int c = 0; c < 3; ++c) {
      const double d = mpq_get_d(p[c].mpq());
      lo[c] = std::nextafter(d, -HUGE_VAL);
      hi[c] = std::nextafter(d, HUGE_VAL);
    }
    return {lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]};
  }

  // Conservative world box of the body-frame box b at the pose (every point
  // of b lands in it), or nullopt out of range. Centre c, half-sides h: the
  // points land within |R| h of p + R c, grown as in box(v).
  std::optional<CGAL::Bbox_3> box(const Aabb& b) const {
    if (!in_range_ || !(b.lo.cwiseAbs().maxCoeff() <= kBig && b.hi.cwiseAbs().maxCoeff() <= kBig)) return std::nullopt;
    const Vec3 c = 0.5 * (b.lo + b.hi), h = 0.5 * (b.hi - b.lo);
    const Vec3 x = X_.p + R_ * c;
    const Vec3 r = R_.cwiseAbs() * h + Vec3::Constant(kBoxInflation * (X_.p.cwiseAbs().maxCoeff() + c.cwiseAbs().sum() +
                                                                       h.cwiseAbs().sum()) + 1e-300);
    return CGAL::Bbox_3(x.x() - r.x(), x.y() - r.y(), x.z() - r.z(), x.x() + r.x(), x.y() + r.y(), x.z() + r.z());
  }

  // Interval enclosure of vertex v (interval arithmetic on the doubles of the
  // pose and of the mesh encloses the exact rational value); nullptr when the
  // magnitudes are out of range (v is then decided exactly).
  const IntervalKernel::Point_3* approx(int v) const {
    if (state_[v] == kUnknown) {
      state_[v] = kNone;
      const Vec3 r = vertex(body_, v);
      if (in_range_ && r.cwiseAbs().maxCoeff() <= kBig) {
        CGAL::Protect_FPU_rounding<true> upward;
        using I = IntervalKernel::FT;
        I c[3];
        bool finite = true;
        for (int a = 0; a < 3; ++a) {
          c[a] = I(X_.p[a]) + (RI_[a][0] * I(r[0]) + RI_[a][1] * I(r[1]) + RI_[a][2] * I(r[2]));
          finite = finite && std::isfinite(c[a].inf()) && std::isfinite(c[a].sup());
        }
        if (finite) {
          approx_[v] = IntervalKernel::Point_3(c[0], c[1], c[2]);
          state_[v] = kEnclosed;
        }
      }
    }
    return state_[v] == kEnclosed ? &approx_[v] : nullptr;
  }

  const ExactKernel::Point_3& exact(int v) const {
    if (!exact_[v]) {
      const ExactPoint x = transform_point_exact(X_, vertex(body_, v));
      exact_[v].emplace(CGAL::Gmpq(x[0].get_mpq_t()), CGAL::Gmpq(x[1].get_mpq_t()), CGAL::Gmpq(x[2].get_mpq_t()));
    }
    return *exact_[v];
  }

 private:
  static constexpr double kBig = 0x1p250, kSmall = 0x1p-250;
  enum : uint8_t { kUnknown, kEnclosed, kNone };

  const TriangleMesh& body_;
  const Pose& X_;
  bool in_range_ = false;
  Mat3 R_;                      // R(q) rounded (doubles)
  IntervalKernel::FT RI_[3][3];  // R(q) enclosed (intervals)
  mutable std::vector<IntervalKernel::Point_3> approx_;
  mutable std::vector<uint8_t> state_;
  mutable std::vector<std::optional<ExactKernel::Point_3>> exact_;
};

// A triangle of the posed body or of the obstacle, converted on demand to the
// interval kernel (first stage) or the exact kernel (second stage) by the
// converters of CGAL::Filtered_predicate.
struct BodyFace {
  const PosedBody* body;
  const TriangleMesh* mesh;
  int f;
};
struct ObstacleFace {
  const TriangleMesh* mesh;
  int f;
};

struct ToInterval {
  IntervalKernel::Triangle_3 operator()(const BodyFace& t) const {
    const IntervalKernel::Point_3* p[3];
    for (int k = 0; k < 3; ++k) {
      p[k] = t.body->approx(t.mesh->F(t.f, k));
      if (!p[k]) throw CGAL::Uncertain_conversion_exception("no interval enclosure");  // decided exactly
    }
    return {*p[0], *p[1], *p[2]};
  }
  IntervalKernel::Triangle_3 operator()(const ObstacleFace& t) const {
    auto p = [&](int k) {
      const Vec3 x = vertex(*t.mesh, t.mesh->F(t.f, k));
      return IntervalKernel::Point_3(x.x(), x.y(), x.z());  // doubles: point intervals
    };
    return {p(0), p(1), p(2)};
  }
};

struct ToExact {
  ExactKernel::Triangle_3 operator()(const BodyFace& t) const {
    return {t.body->exact(t.mesh->F(t.f, 0)), t.body->exact(t.mesh->F(t.f, 1)), t.body->exact(t.mesh->F(t.f, 2))};
  }
  ExactKernel::Triangle_3 operator()(const ObstacleFace& t) const {
    auto p = [&](int k) {
      const Vec3 x = vertex(*t.mesh, t.mesh->F(t.f, k));
      return ExactKernel::Point_3(x.x(), x.y(), x.z());  // doubles are exact in Gmpq
    };
    return {p(0), p(1), p(2)};
  }
};

// Closed triangle/triangle intersection: interval arithmetic first, exact
// Gmpq when the interval signs are uncertain (CGAL's filtered predicate).
using DoIntersect = CGAL::Filtered_predicate<ExactKernel::Do_intersect_3, IntervalKernel::Do_intersect_3, ToExact,
                                             ToInterval>;

CGAL::Bbox_3 obstacle_face_bbox(const TriangleMesh& m, int f) {
  CGAL::Bbox_3 b;
  for (int k = 0; k < 3; ++k) {
    const Vec3 x = vertex(m, m.F(f, k));
    b += CGAL::Bbox_3(x.x(), x.y(), x.z(), x.x(), x.y(), x.z());  // exact
  }
  return b;
}

CGAL::Bbox_3 to_bbox(const Aabb& b) { return {b.lo.x(), b.lo.y(), b.lo.z(), b.hi.x(), b.hi.y(), b.hi.z()}; }

// b grown by margin >= 0, rounded outward: it holds the exact grown box.
CGAL::Bbox_3 grown(const CGAL::Bbox_3& b, double margin) {
  if (margin == 0) return b;
  return {std::nextafter(b.xmin() - margin, -HUGE_VAL), std::nextafter(b.ymin() - margin, -HUGE_VAL),
          std::nextafter(b.zmin() - margin, -HUGE_VAL), std::nextafter(b.xmax() + margin, HUGE_VAL),
          std::nextafter(b.ymax() + margin, HUGE_VAL),  std::nextafter(b.zmax() + margin, HUGE_VAL)};
}

// Calls visit(body face, obstacle face) for every pair whose boxes, the body's
// grown by `margin` (>= 0), overlap (closed boxes). Every body box contains its
// posed triangle's exact position, so no pair within `margin` (in each
// coordinate) is missed. Narrowing, each step keeping every overlapping pair:
// (1) the region where the posed body's box and the obstacle's overlap;
// (2) for each body face group (ExactMeshPair::kFaceGroup nearby faces) that
// reaches the region, the obstacle faces whose boxes meet the group's box, by
// a walk of the obstacle's face tree; (3) those against each face of the group
// (its box holds the face's, so every overlapping pair is found, once).
// A walk per group, where CGAL's box_intersection_d sorted the boxes of every
// group and face in the region at each pose: the bunnies' poses, half a bunny
// in the region, spent most of their check sorting.
template <class Visit>
void candidate_pairs(const ExactMeshPair& mp, const PosedBody& posed, double margin, Visit&& visit) {
  constexpr int kGroup = ExactMeshPair::kFaceGroup;
  const TriangleMesh& body = mp.god;
  const TriangleMesh& obs = mp.obstacle;
  if (mp.obstacle_faces.box.empty() || mp.god_faces.box.empty()) return;
  auto face_bbox = [&](int f) {
    return grown(posed.box(body.F(f, 0)) + posed.box(body.F(f, 1)) + posed.box(body.F(f, 2)), margin);
  };
  // Posed group boxes (from the body-frame group boxes, or from the faces when
  // the pose is out of the doubles' range).
  const std::vector<int32_t>& body_order = mp.god_faces.item;
  std::vector<CGAL::Bbox_3> body_group_boxes(mp.god_face_groups.size());
  CGAL::Bbox_3 all;
  for (size_t g = 0; g < body_group_boxes.size(); ++g) {
    if (const auto b = posed.box(mp.god_face_groups[g])) {
      body_group_boxes[g] = grown(*b, margin);
    } else {
      for (size_t i = g * kGroup; i < std::min(body_order.size(), (g + 1) * kGroup); ++i)
        body_group_boxes[g] += face_bbox(body_order[i]);
    }
    all += body_group_boxes[g];
  }
  // (1) The region where pairs can meet: the intersection of the two boxes.
  const CGAL::Bbox_3 obstacle_all = to_bbox(mp.obstacle_faces.box[0]);
  if (!CGAL::do_overlap(all, obstacle_all)) return;
  const CGAL::Bbox_3 region(std::max(all.xmin(), obstacle_all.xmin()), std::max(all.ymin(), obstacle_all.ymin()),
                            std::max(all.zmin(), obstacle_all.zmin()), std::min(all.xmax(), obstacle_all.xmax()),
                            std::min(all.ymax(), obstacle_all.ymax()), std::min(all.zmax(), obstacle_all.zmax()));
  std::vector<std::pair<int32_t, CGAL::Bbox_3>> near;  // obstacle faces meeting a group, with their boxes
  for (size_t g = 0; g < body_group_boxes.size(); ++g) {
    const CGAL::Bbox_3& gb = body_group_boxes[g];
    if (!CGAL::do_overlap(gb, region)) continue;
    // (2) The obstacle faces whose boxes meet the group's.
    near.clear();
    const Aabb query{Vec3(gb.xmin(), gb.ymin(), gb.zmin()), Vec3(gb.xmax(), gb.ymax(), gb.zmax())};
    query_tree(mp.obstacle_faces, query, [&](int of) {
      const CGAL::Bbox_3 b = obstacle_face_bbox(obs, of);
      if (CGAL::do_overlap(b, gb)) near.emplace_back(of, b);
    });
    if (near.empty()) continue;
    // (3) Each face of the group against them.
    for (size_t i = g * kGroup; i < std::min(body_order.size(), (g + 1) * kGroup); ++i) {
      const CGAL::Bbox_3 b = face_bbox(body_order[i]);
      if (!CGAL::do_overlap(b, region)) continue;
      for (const auto& [of, ob] : near)
        if (CGAL::do_overlap(b, ob)) visit(body_order[i], of);
    }
  }
}

Aabb face_box(const std::vector<Aabb>& vertex_boxes, const TriangleMesh& m, int f) {
  Aabb b = empty_box();
  for (int k = 0; k < 3; ++k) grow(&b, vertex_boxes[m.F(f, k)]);
  return b;
}

void record(const ExactToi& toi, const FeaturePairIds& pair, MeshContact* out) {
  if (!toi.hit) return;
  const int c = compare_toi(toi, out->toi);
  if (c < 0) {
    out->toi = toi;
    out->pairs = {pair};
  } else if (c == 0) {
    out->pairs.push_back(pair);
  }
}

// The features of one type (kPairKinds' Feature) of a mesh, numbered as the
// items of the obstacle's trees: vertex v, edge edges[i], face f.
struct MeshFeatures {
  const TriangleMesh& mesh;
  const std::vector<std::array<int32_t, 2>>& edges;

  int count(Feature t) const {
    switch (t) {
      case Feature::kVertex: return int(mesh.V.rows());
      case Feature::kEdge: return int(edges.size());
      case Feature::kFace: return int(mesh.F.rows());
    }
    return 0;
  }
  FeatureId id(Feature t, int i) const {
    switch (t) {
      case Feature::kVertex: return vertex_id(i);
      case Feature::kEdge: return edge_id(edges[i][0], edges[i][1]);
      case Feature::kFace: return face_id(i);
    }
    return {};
  }
  // The vertex indices of a feature (1, 2 or 3 of them, in corner order).
  int vertices(const FeatureId& id, int32_t out[3]) const {
    switch (id.feature) {
      case Feature::kVertex: out[0] = id.a; return 1;
      case Feature::kEdge: out[0] = id.a, out[1] = id.b; return 2;
      case Feature::kFace:
        for (int k = 0; k < 3; ++k) out[k] = mesh.F(id.a, k);
        return 3;
    }
    return 0;
  }
  // Its points (vertices() of them filled).
  std::array<Vec3, 3> points(const FeatureId& id) const {
    int32_t v[3];
    std::array<Vec3, 3> p = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    for (int k = 0, n = vertices(id, v); k < n; ++k) p[k] = vertex(mesh, v[k]);
    return p;
  }
  bool valid(const FeatureId& id, Feature t) const {
    if (id.feature != t) return false;
    if (t == Feature::kFace) return id.a >= 0 && id.a < mesh.F.rows() && id.b == -1;
    const auto in = [&](int32_t v) { return v >= 0 && v < mesh.V.rows(); };
    return t == Feature::kVertex ? in(id.a) && id.b == -1 : in(id.a) && in(id.b);
  }
};

const AabbTree& obstacle_tree(const ExactMeshPair& mp, Feature t) {
  switch (t) {
    case Feature::kVertex: return mp.obstacle_vertices;
    case Feature::kEdge: return mp.obstacle_edge_tree;
    case Feature::kFace: break;
  }
  return mp.obstacle_faces;
}

// The exact solver of each kind of feature pair, indexed by PairKind (the god
// feature's points in the body frame, the obstacle's in the world frame; a
// vertex is p[0], an edge p[0], p[1]).
using PairSolver = ExactToi (*)(const ExactCayleyMotion&, const std::array<Vec3, 3>& god,
                                const std::array<Vec3, 3>& obstacle, double u_max);
ExactToi solve_vertex_face(const ExactCayleyMotion& m, const std::array<Vec3, 3>& g, const std::array<Vec3, 3>& o,
                           double u_max) {
  return ccd_rigid_vertex_face({&m, g[0], o, u_max});
}
ExactToi solve_face_vertex(const ExactCayleyMotion& m, const std::array<Vec3, 3>& g, const std::array<Vec3, 3>& o,
                           double u_max) {
  return ccd_rigid_face_vertex({&m, o[0], g, u_max});
}
ExactToi solve_edge_edge(const ExactCayleyMotion& m, const std::array<Vec3, 3>& g, const std::array<Vec3, 3>& o,
                         double u_max) {
  return ccd_rigid_edge_edge({&m, {g[0], g[1]}, {o[0], o[1]}, u_max});
}
constexpr PairSolver kPairSolvers[kNumPairKinds] = {solve_vertex_face, solve_face_vertex, solve_edge_edge};
static_assert(kPairKinds[0].kind == PairKind::kGodVertexObstacleFace &&
                  kPairKinds[1].kind == PairKind::kObstacleVertexGodFace && kPairKinds[2].kind == PairKind::kEdgeEdge,
              "kPairSolvers follows the order of kPairKinds");

}  // namespace

std::vector<std::array<int32_t, 2>> mesh_edges(const TriangleMesh& m) {
  std::vector<std::array<int32_t, 2>> e;
  e.reserve(3 * m.F.rows());
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int32_t a = m.F(f, k), b = m.F(f, (k + 1) % 3);
      if (a != b) e.push_back({std::min(a, b), std::max(a, b)});
    }
  std::sort(e.begin(), e.end());
  e.erase(std::unique(e.begin(), e.end()), e.end());
  return e;
}

ExactMeshPair make_exact_mesh_pair(const TriangleMesh& god_B, const TriangleMesh& obstacle_W) {
  check_mesh(god_B, "god-object");
  check_mesh(obstacle_W, "obstacle");
  ExactMeshPair mp;
  mp.god = god_B;
  mp.obstacle = obstacle_W;
  mp.god_edges = mesh_edges(god_B);
  mp.obstacle_edges = mesh_edges(obstacle_W);
  const TriangleMesh& o = obstacle_W;
  std::vector<Aabb> vb(o.V.rows(), empty_box()), fb(o.F.rows(), empty_box()),
      eb(mp.obstacle_edges.size(), empty_box());
  for (int v = 0; v < o.V.rows(); ++v) vb[v] = point_box(vertex(o, v));  // exact boxes
  for (int f = 0; f < o.F.rows(); ++f) fb[f] = face_box(vb, o, f);
  for (size_t e = 0; e < eb.size(); ++e) {
    grow(&eb[e], vb[mp.obstacle_edges[e][0]]);
    grow(&eb[e], vb[mp.obstacle_edges[e][1]]);
  }
  mp.obstacle_vertices = build_tree(vb);
  mp.obstacle_faces = build_tree(fb);
  mp.obstacle_edge_tree = build_tree(eb);
  std::vector<Aabb> god_vb(god_B.V.rows(), empty_box()), god_fb(god_B.F.rows(), empty_box());
  for (int v = 0; v < god_B.V.rows(); ++v) god_vb[v] = point_box(vertex(god_B, v));
  for (int f = 0; f < god_B.F.rows(); ++f) god_fb[f] = face_box(god_vb, god_B, f);
  mp.god_faces = build_tree(god_fb);
  auto groups = [](const AabbTree& t, const std::vector<Aabb>& face_boxes) {
    std::vector<Aabb> g((t.item.size() + ExactMeshPair::kFaceGroup - 1) / ExactMeshPair::kFaceGroup, empty_box());
    for (size_t i = 0; i < t.item.size(); ++i) grow(&g[i / ExactMeshPair::kFaceGroup], face_boxes[t.item[i]]);
    return g;
  };
  mp.god_face_groups = groups(mp.god_faces, god_fb);
  for (int v = 0; v < god_B.V.rows(); ++v) mp.god_radius = std::max(mp.god_radius, vertex(god_B, v).norm());
  mp.god_radius = std::nextafter(mp.god_radius, HUGE_VAL);
  return mp;
}

MeshContact mesh_first_contact(const ExactMeshPair& mp, const Pose& X0, const Pose& X1, bool filtered) {
  const ExactCayleyMotion motion = make_exact_cayley_motion(X0, X1);
  const TriangleMesh& god = mp.god;

  // Swept box of each god-object vertex r over u in [0, 1]: the point is
  // p(u) + C(u g) R0 r with p(u) on the segment [p0, p1], and C(u g) turns
  // R0 r by an angle <= theta1 = 2 atan|g| < pi about one axis, so it stays
  // within 2 |r| sin(theta1 / 2) = 2 |r| |g| / sqrt(1 + |g|^2) of R0 r.
  const double s = mpz_get_d(motion.s.get_mpz_t());
  const Vec3 g(mpz_get_d(motion.v[0].get_mpz_t()) / s, mpz_get_d(motion.v[1].get_mpz_t()) / s,
               mpz_get_d(motion.v[2].get_mpz_t()) / s);
  const double chord = 2 * g.norm() / std::sqrt(1 + g.squaredNorm());
  const Mat3 R0 = [&] {
    const Quat& q = X0.q;
    const double w = q.w, x = q.x, y = q.y, z = q.z, n = q.norm2();
    Mat3 R;
    R << w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y), 2 * (x * y + w * z),
        w * w - x * x + y * y - z * z, 2 * (y * z - w * x), 2 * (x * z - w * y), 2 * (y * z + w * x),
        w * w - x * x - y * y + z * z;
    return Mat3(R / n);
  }();
  const Vec3 pmin = X0.p.cwiseMin(X1.p), pmax = X0.p.cwiseMax(X1.p);
  const double scale = X0.p.cwiseAbs().maxCoeff() + X1.p.cwiseAbs().maxCoeff();
  std::vector<Aabb> swept(god.V.rows(), empty_box());
  for (int v = 0; v < god.V.rows(); ++v) {
    const Vec3 r = vertex(god, v);
    const Vec3 w = R0 * r;
    const double radius = chord * r.norm() + kBoxInflation * (scale + r.norm()) + 1e-300;
    swept[v] = {pmin + w - Vec3::Constant(radius), pmax + w + Vec3::Constant(radius)};
  }

  MeshContact out;
  // Pairs can only improve on the best contact so far: search [0, its upper bound].
  auto u_max = [&out] { return out.toi.hit ? std::max(out.toi.upper, std::nextafter(0.0, 1.0)) : 1.0; };
  // One loop for every kind (kPairKinds): each god-object feature's swept box
  // (the hull of its vertices' swept boxes) against the obstacle's tree of the
  // other feature. Unfiltered, every candidate is solved exactly at once;
  // filtered, the interval filter (ccd_filter.h) rules out most and bounds the
  // first contact of the rest from below, which are then solved exactly in
  // order of that bound until it passes the best contact found.
  struct Candidate {
    PairKind kind;
    FeatureId god, obstacle;
    double earliest;
  };
  std::vector<Candidate> undecided;
  const detail::IntervalMotionPtr interval_motion(motion);
  const MeshFeatures god_features{god, mp.god_edges}, obstacle_features{mp.obstacle, mp.obstacle_edges};
  for (const PairKindInfo& info : kPairKinds) {
    const PairSolver solve = kPairSolvers[int(info.kind)];
    const AabbTree& tree = obstacle_tree(mp, info.obstacle);
    for (int i = 0, n = god_features.count(info.god); i < n; ++i) {
      const FeatureId gf = god_features.id(info.god, i);
      int32_t v[3];
      const int num_vertices = god_features.vertices(gf, v);
      Aabb box = swept[v[0]];
      for (int k = 1; k < num_vertices; ++k) grow(&box, swept[v[k]]);
      const std::array<Vec3, 3> god_points = god_features.points(gf);
      query_tree(tree, box, [&](int item) {
        ++out.num_candidate_pairs;
        const FeatureId of = obstacle_features.id(info.obstacle, item);
        if (!filtered) {
          ++out.num_exact_pairs;
          record(solve(motion, god_points, obstacle_features.points(of), u_max()), {info.kind, gf, of}, &out);
          return;
        }
        const detail::FilterVerdict verdict =
            detail::filter_pair(*interval_motion.motion, info.kind, god_points, obstacle_features.points(of), 1.0);
        if (verdict.excluded)
          ++out.num_filtered_pairs;
        else
          undecided.push_back({info.kind, gf, of, verdict.earliest});
      });
    }
  }
  std::stable_sort(undecided.begin(), undecided.end(),
                   [](const Candidate& a, const Candidate& b) { return a.earliest < b.earliest; });
  for (const Candidate& c : undecided) {
    // No contact before c.earliest: beyond the best contact's upper bound, c and the rest cannot touch at u*.
    if (out.toi.hit && c.earliest > out.toi.upper) break;
    ++out.num_exact_pairs;
    record(kPairSolvers[int(c.kind)](motion, god_features.points(c.god), obstacle_features.points(c.obstacle), u_max()),
           {c.kind, c.god, c.obstacle}, &out);
  }
  return out;
}

ExactToi feature_pair_first_contact(const ExactMeshPair& mp, const ExactCayleyMotion& motion,
                                    const FeaturePairIds& pair, double u_max) {
  const int k = int(pair.kind);
  const MeshFeatures god_features{mp.god, mp.god_edges}, obstacle_features{mp.obstacle, mp.obstacle_edges};
  if (k < 0 || k >= kNumPairKinds || !god_features.valid(pair.god, kPairKinds[k].god) ||
      !obstacle_features.valid(pair.obstacle, kPairKinds[k].obstacle))
    throw std::invalid_argument("feature_pair_first_contact: the features do not match the kind or the meshes");
  return kPairSolvers[k](motion, god_features.points(pair.god), obstacle_features.points(pair.obstacle), u_max);
}

int64_t count_intersecting_pairs(const ExactMeshPair& mp, const Pose& X) {
  const PosedBody posed(mp.god, X);
  const DoIntersect do_intersect;
  int64_t count = 0;
  candidate_pairs(mp, posed, 0.0, [&](int32_t f, int32_t of) {
    if (do_intersect(BodyFace{&posed, &mp.god, f}, ObstacleFace{&mp.obstacle, of})) ++count;
  });
  return count;
}

namespace {

// An upper bound of the squared distance between two triangles given by interval enclosures
// of their vertices, for the pairs whose interval squared_distance cannot decide (near-parallel
// triangles, where CGAL's comparisons are uncertain): the squared distance between two points
// of the triangles. The points are chosen in doubles on the enclosures' midpoints (each vertex
// of one triangle against the other: its projection inside the triangle, else the nearest
// point of an edge), as barycentric weights, and evaluated in interval arithmetic from the
// enclosures: a convex combination of the true vertices lies on the true triangle whatever
// the rounding of its weights, so the bound holds. HUGE_VAL when no bound is finite.
double witness_upper_bound(const IntervalKernel::Triangle_3& A, const IntervalKernel::Triangle_3& B) {
  using I = IntervalKernel::FT;
  auto mid = [](const IntervalKernel::Point_3& p) {
    return Vec3(CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z()));
  };
  struct Witness {
    double d2 = HUGE_VAL;
    double wa[3] = {0, 0, 0}, wb[3] = {0, 0, 0};
  } best;
  // The vertex v (weights wv on its triangle) against triangle T (midpoints t[3]).
  auto against = [&](const Vec3& x, const double wv[3], const Vec3 t[3], bool v_in_a) {
    auto consider = [&](const double wt[3]) {
      const Vec3 y = wt[0] * t[0] + wt[1] * t[1] + wt[2] * t[2];
      const double d2 = (x - y).squaredNorm();
      if (d2 < best.d2) {
        best.d2 = d2;
        for (int k = 0; k < 3; ++k) {
          best.wa[k] = v_in_a ? wv[k] : wt[k];
          best.wb[k] = v_in_a ? wt[k] : wv[k];
        }
      }
    };
    const Vec3 e1 = t[1] - t[0], e2 = t[2] - t[0], n = e1.cross(e2);
    const double nn = n.squaredNorm();
    if (nn > 0) {  // the projection's barycentric coordinates
      const Vec3 r = x - t[0];
      const double v = r.cross(e2).dot(n) / nn, w = e1.cross(r).dot(n) / nn, u = 1 - v - w;
      if (u >= 0 && v >= 0 && w >= 0) {
        const double wt[3] = {u, v, w};
        consider(wt);
      }
    }
    for (int k = 0; k < 3; ++k) {  // the nearest point of each edge
      const Vec3 &p = t[k], &q = t[(k + 1) % 3];
      const double len2 = (q - p).squaredNorm();
      const double s = len2 > 0 ? std::clamp((x - p).dot(q - p) / len2, 0.0, 1.0) : 0.0;
      double wt[3] = {0, 0, 0};
      wt[k] = 1 - s;
      wt[(k + 1) % 3] = s;
      consider(wt);
    }
  };
  const Vec3 a[3] = {mid(A[0]), mid(A[1]), mid(A[2])}, b[3] = {mid(B[0]), mid(B[1]), mid(B[2])};
  for (int k = 0; k < 3; ++k) {
    double wv[3] = {0, 0, 0};
    wv[k] = 1;
    against(a[k], wv, b, true);
    against(b[k], wv, a, false);
  }
  if (!(best.d2 < HUGE_VAL)) return HUGE_VAL;
  CGAL::Protect_FPU_rounding<true> upward;
  auto point = [](const IntervalKernel::Triangle_3& T, const double w[3], int c) {
    const I sum = I(w[0]) + I(w[1]) + I(w[2]);
    return (I(w[0]) * T[0][c] + I(w[1]) * T[1][c] + I(w[2]) * T[2][c]) / sum;
  };
  I d2(0);
  for (int c = 0; c < 3; ++c) d2 += CGAL::square(point(A, best.wa, c) - point(B, best.wb, c));
  return std::isfinite(d2.sup()) ? d2.sup() : HUGE_VAL;
}

// A lower bound of the squared distance between two triangles (interval enclosures of their
// vertices), for the pairs whose interval squared_distance cannot decide: the gap between the
// triangles' projections on each one's face normal (a separating axis), squared over the
// normal's squared length, in interval arithmetic (rounding upward: the caller's mode). 0 when
// no axis separates them for sure.
double separating_axis_lower_bound(const IntervalKernel::Triangle_3& A, const IntervalKernel::Triangle_3& B) {
  using I = IntervalKernel::FT;
  double best = 0;
  for (const IntervalKernel::Triangle_3* T : {&A, &B}) {
    const IntervalKernel::Vector_3 n = CGAL::cross_product((*T)[1] - (*T)[0], (*T)[2] - (*T)[0]);
    const I nn = n.squared_length();
    if (!(nn.inf() > 0) || !std::isfinite(nn.sup())) continue;
    double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
    for (int t = 0; t < 2; ++t) {
      const IntervalKernel::Triangle_3& U = t == 0 ? A : B;
      for (int k = 0; k < 3; ++k) {
        const I d = (U[k] - CGAL::ORIGIN) * n;
        lo[t] = std::min(lo[t], d.inf());
        hi[t] = std::max(hi[t], d.sup());
      }
    }
    const double gap = std::max((I(lo[1]) - I(hi[0])).inf(), (I(lo[0]) - I(hi[1])).inf());
    if (gap > 0 && std::isfinite(gap)) {
      const I g2 = CGAL::square(I(gap)) / nn;
      if (std::isfinite(g2.inf())) best = std::max(best, g2.inf());
    }
  }
  return best;
}

// Passes 1 and 2 of separation_distance: the pairs that can still be the minimum, each with a
// lower bound of its squared distance, and an upper bound of the minimum squared distance
// (HUGE_VAL when no pair's interval enclosure was finite).
struct SeparationCandidate {
  int32_t f, of;
  double lower;  // <= the pair's exact squared distance
};

double interval_candidates(const ExactMeshPair& mp, const PosedBody& posed, double max_distance,
                           std::vector<SeparationCandidate>* close_out) {
  const TriangleMesh& body = mp.god;
  // Pass 1 (boxes): every pair whose boxes are within max_distance, with a
  // lower bound of its squared distance: the squared gap between the boxes
  // (the body's contain the exact triangle), rounded down by a relative 1e-12,
  // far above the few roundings of 2^-53 in it.
  using Candidate = SeparationCandidate;
  std::vector<Candidate> candidates;
  candidate_pairs(mp, posed, max_distance, [&](int32_t f, int32_t of) {
    const CGAL::Bbox_3 a = posed.box(body.F(f, 0)) + posed.box(body.F(f, 1)) + posed.box(body.F(f, 2));
    const CGAL::Bbox_3 b = obstacle_face_bbox(mp.obstacle, of);
    double gap2 = 0;
    for (int c = 0; c < 3; ++c) {
      const double g = std::max({0.0, a.min(c) - b.max(c), b.min(c) - a.max(c)});
      gap2 += g * g;
    }
    candidates.push_back({f, of, gap2 * (1 - 1e-12)});
  });
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.lower < b.lower; });
  // Pass 2 (intervals): by increasing box bound, while a pair can still be the
  // minimum, the enclosure [lower, upper] of its squared distance (CGAL's
  // triangle/triangle squared_distance in interval arithmetic; the box bound
  // when the interval signs are uncertain or a vertex has no enclosure).
  double best_upper = HUGE_VAL;  // >= the minimum squared distance
  std::vector<Candidate>& close = *close_out;
  const ToInterval to_interval;
  for (const Candidate& c : candidates) {
    if (c.lower > best_upper) break;
    Candidate refined = c;
    CGAL::Protect_FPU_rounding<true> upward;
    try {
      const IntervalKernel::FT d2 = CGAL::squared_distance(to_interval(BodyFace{&posed, &mp.god, c.f}),
                                                           to_interval(ObstacleFace{&mp.obstacle, c.of}));
      if (std::isfinite(d2.inf()) && std::isfinite(d2.sup())) {
        refined.lower = std::max(c.lower, d2.inf());
        best_upper = std::min(best_upper, d2.sup());
      }
    } catch (CGAL::Uncertain_conversion_exception&) {
      // No interval value: the pair's lower bound is its box's or a separating axis's, and it
      // bounds the minimum from above by two of its points (when the body's triangle has an
      // enclosure).
      try {
        const IntervalKernel::Triangle_3 A = to_interval(BodyFace{&posed, &mp.god, c.f});
        const IntervalKernel::Triangle_3 B = to_interval(ObstacleFace{&mp.obstacle, c.of});
        best_upper = std::min(best_upper, witness_upper_bound(A, B));
        refined.lower = std::max(refined.lower, separating_axis_lower_bound(A, B));
      } catch (CGAL::Uncertain_conversion_exception&) {
      }
    }
    close.push_back(refined);
  }
  return best_upper;
}

}  // namespace

SeparationBracket separation_bracket(const ExactMeshPair& mp, const Pose& X, double max_distance) {
  if (!(max_distance >= 0)) throw std::invalid_argument("separation_bracket: max_distance must be >= 0");
  const PosedBody posed(mp.god, X);
  std::vector<SeparationCandidate> close;
  const double best_upper = interval_candidates(mp, posed, max_distance, &close);
  SeparationBracket out;
  // Every pair left out is farther than max_distance (its boxes are); the candidates' lower
  // bounds hold for them; the minimum's square is at most best_upper.
  double lower2 = HUGE_VAL;
  for (const SeparationCandidate& c : close) lower2 = std::min(lower2, c.lower);
  out.lower = lower2 == HUGE_VAL ? max_distance : std::min(max_distance, std::nextafter(std::sqrt(lower2), 0.0));
  out.upper = best_upper == HUGE_VAL ? HUGE_VAL : std::nextafter(std::sqrt(best_upper), HUGE_VAL);
  out.lower = std::min(out.lower, out.upper);
  return out;
}

ExactSeparation separation_distance(const ExactMeshPair& mp, const Pose& X, double max_distance) {
  if (!(max_distance >= 0 && std::isfinite(max_distance)))
    throw std::invalid_argument("separation_distance: max_distance must be finite and >= 0");
  const PosedBody posed(mp.god, X);
  using Candidate = SeparationCandidate;
  std::vector<Candidate> close;
  const double best_upper = interval_candidates(mp, posed, max_distance, &close);
  // Pass 3 (exact): by increasing lower bound, while a pair can still win.
  std::sort(close.begin(), close.end(), [](const Candidate& a, const Candidate& b) { return a.lower < b.lower; });
  const ToExact to_exact;
  ExactSeparation out;
  CGAL::Gmpq best;
  for (const Candidate& c : close) {
    if (c.lower > best_upper || (out.within && CGAL::Gmpq(c.lower) > best)) break;
    const CGAL::Gmpq d2 =
        CGAL::squared_distance(to_exact(BodyFace{&posed, &mp.god, c.f}), to_exact(ObstacleFace{&mp.obstacle, c.of}));
    if (!out.within || d2 < best) {
      out.within = true;
      best = d2;
      out.god_face = c.f;
      out.obstacle_face = c.of;
    }
  }
  const mpq_class max2 = mpq_class(max_distance) * mpq_class(max_distance);
  if (out.within && mpq_class(best.mpq()) > max2) out = ExactSeparation{};
  if (out.within) {
    out.squared_distance = mpq_class(best.mpq());
    // Certified bracket of the distance: x_lo <= d^2 <= x_hi, then sqrt rounded outward.
    const double x = mpq_get_d(out.squared_distance.get_mpq_t());  // truncated: x <= d^2
    const double x_hi = mpq_class(x) == out.squared_distance ? x : std::nextafter(x, HUGE_VAL);
    out.lower = x == 0 ? 0.0 : std::nextafter(std::sqrt(x), 0.0);
    out.upper = x_hi == 0 ? 0.0 : std::nextafter(std::sqrt(x_hi), HUGE_VAL);
  }
  return out;
}

SeparationBound separation_within(const ExactMeshPair& mp, const Pose& X, double max_distance) {
  if (!(max_distance >= 0 && std::isfinite(max_distance)))
    throw std::invalid_argument("separation_within: max_distance must be finite and >= 0");
  const PosedBody posed(mp.god, X);
  std::vector<SeparationCandidate> close;
  const double best_upper = interval_candidates(mp, posed, max_distance, &close);  // separation_bracket's passes
  SeparationBound out;
  const CGAL::Gmpq max2 = CGAL::Gmpq(max_distance) * CGAL::Gmpq(max_distance);
  if (best_upper < HUGE_VAL && CGAL::Gmpq(best_upper) <= max2) {  // a pair's enclosure proves it
    out.within = true;
    out.upper = std::nextafter(std::sqrt(best_upper), HUGE_VAL);  // best_upper >= d^2; one more step for safety
    return out;
  }
  // The intervals proved no pair within: exactly, by increasing lower bound, the pairs they could
  // not rule out.
  std::sort(close.begin(), close.end(),
            [](const SeparationCandidate& a, const SeparationCandidate& b) { return a.lower < b.lower; });
  const ToExact to_exact;
  for (const SeparationCandidate& c : close) {
    if (CGAL::Gmpq(c.lower) > max2) break;
    out.exact = true;
    const CGAL::Gmpq d2 =
        CGAL::squared_distance(to_exact(BodyFace{&posed, &mp.god, c.f}), to_exact(ObstacleFace{&mp.obstacle, c.of}));
    if (d2 <= max2) {
      out.within = true;
      const double x = CGAL::to_interval(d2).second;  // >= d2
      out.upper = std::nextafter(std::sqrt(x), HUGE_VAL);
      return out;
    }
  }
  return out;
}

}  // namespace gauss6::reference
