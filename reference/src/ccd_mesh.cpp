// Exact mesh-level queries of the reference: first contact of a moving mesh
// against a static one under the Cayley motion (conservative box culling, then
// the exact primitives of ccd_exact.cpp), exact triangle/triangle intersection
// count and exact separation distance at a pose (CGAL, Gmpq coordinates).
// See gauss6/reference/ccd.h.
#include "gauss6/reference/ccd.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <CGAL/Gmpq.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/squared_distance_3.h>
#include <CGAL/intersections.h>

namespace gauss6::reference {
namespace {

using Kernel = CGAL::Simple_cartesian<CGAL::Gmpq>;
using Point3 = Kernel::Point_3;
using Triangle3 = Kernel::Triangle_3;

// Relative inflation of boxes computed in doubles from exact data. Their
// rounding errors are below 1e-14 relative to the magnitudes involved (a few
// dozen operations at 2^-53 each); 1e-9 leaves a margin of five orders.
constexpr double kBoxInflation = 1e-9;

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

bool overlap(const Aabb& a, const Aabb& b) {
  return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

Aabb inflated(const Aabb& b, double margin) {
  return {b.lo - Vec3::Constant(margin), b.hi + Vec3::Constant(margin)};
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
    t.box.emplace_back();
    t.child.push_back(-1);
    t.first.push_back(0);
    t.count.push_back(0);
    return int(t.box.size()) - 1;
  };
  std::vector<Task> stack{{new_node(), 0, int(boxes.size())}};
  while (!stack.empty()) {
    const Task task = stack.back();
    stack.pop_back();
    Aabb box, centres;
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

// Exact positions of the body's vertices at pose X, and conservative double
// boxes around them (mpq_get_d truncates: one step outward covers the value).
struct PosedBody {
  std::vector<Point3> exact;
  std::vector<Aabb> box;
};

PosedBody pose_body(const TriangleMesh& body, const Pose& X) {
  PosedBody posed;
  posed.exact.reserve(body.V.rows());
  posed.box.reserve(body.V.rows());
  for (int v = 0; v < body.V.rows(); ++v) {
    const ExactPoint x = transform_point_exact(X, vertex(body, v));
    Aabb b;
    for (int c = 0; c < 3; ++c) {
      const double d = mpq_get_d(x[c].get_mpq_t());
      b.lo[c] = std::nextafter(d, -HUGE_VAL);
      b.hi[c] = std::nextafter(d, HUGE_VAL);
    }
    posed.exact.emplace_back(CGAL::Gmpq(x[0].get_mpq_t()), CGAL::Gmpq(x[1].get_mpq_t()),
                             CGAL::Gmpq(x[2].get_mpq_t()));
    posed.box.push_back(b);
  }
  return posed;
}

Triangle3 obstacle_triangle(const TriangleMesh& m, int f) {
  auto p = [&](int k) {
    const Vec3 x = vertex(m, m.F(f, k));
    return Point3(x.x(), x.y(), x.z());  // doubles are exact in Gmpq
  };
  return Triangle3(p(0), p(1), p(2));
}

Aabb face_box(const std::vector<Aabb>& vertex_boxes, const TriangleMesh& m, int f) {
  Aabb b;
  for (int k = 0; k < 3; ++k) grow(&b, vertex_boxes[m.F(f, k)]);
  return b;
}

void record(const ExactToi& toi, const FeaturePair& pair, MeshContact* out) {
  if (!toi.hit) return;
  const int c = compare_toi(toi, out->toi);
  if (c < 0) {
    out->toi = toi;
    out->pairs = {pair};
  } else if (c == 0) {
    out->pairs.push_back(pair);
  }
}

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

ExactMeshPair make_exact_mesh_pair(const TriangleMesh& body_B, const TriangleMesh& obstacle_W) {
  check_mesh(body_B, "body");
  check_mesh(obstacle_W, "obstacle");
  ExactMeshPair mp;
  mp.body = body_B;
  mp.obstacle = obstacle_W;
  mp.body_edges = mesh_edges(body_B);
  mp.obstacle_edges = mesh_edges(obstacle_W);
  const TriangleMesh& o = obstacle_W;
  std::vector<Aabb> vb(o.V.rows()), fb(o.F.rows()), eb(mp.obstacle_edges.size());
  for (int v = 0; v < o.V.rows(); ++v) vb[v] = point_box(vertex(o, v));  // exact boxes
  for (int f = 0; f < o.F.rows(); ++f) fb[f] = face_box(vb, o, f);
  for (size_t e = 0; e < eb.size(); ++e) {
    grow(&eb[e], vb[mp.obstacle_edges[e][0]]);
    grow(&eb[e], vb[mp.obstacle_edges[e][1]]);
  }
  mp.obstacle_vertices = build_tree(vb);
  mp.obstacle_faces = build_tree(fb);
  mp.obstacle_edge_tree = build_tree(eb);
  for (int v = 0; v < body_B.V.rows(); ++v) mp.body_radius = std::max(mp.body_radius, vertex(body_B, v).norm());
  mp.body_radius = std::nextafter(mp.body_radius, HUGE_VAL);
  return mp;
}

MeshContact mesh_first_contact(const ExactMeshPair& mp, const Pose& X0, const Pose& X1) {
  const ExactCayleyMotion motion = make_exact_cayley_motion(X0, X1);
  const TriangleMesh& body = mp.body;
  const TriangleMesh& obs = mp.obstacle;

  // Swept box of each body vertex r over u in [0, 1]: the point is
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
  std::vector<Aabb> swept(body.V.rows());
  for (int v = 0; v < body.V.rows(); ++v) {
    const Vec3 r = vertex(body, v);
    const Vec3 w = R0 * r;
    const double radius = chord * r.norm() + kBoxInflation * (scale + r.norm()) + 1e-300;
    swept[v] = {pmin + w - Vec3::Constant(radius), pmax + w + Vec3::Constant(radius)};
  }

  MeshContact out;
  // Pairs can only improve on the best contact so far: search [0, its upper bound].
  auto u_max = [&out] { return out.toi.hit ? std::max(out.toi.upper, std::nextafter(0.0, 1.0)) : 1.0; };
  auto body_face = [&](int f) {
    return std::array<Vec3, 3>{vertex(body, body.F(f, 0)), vertex(body, body.F(f, 1)), vertex(body, body.F(f, 2))};
  };
  auto obstacle_face = [&](int f) {
    return std::array<Vec3, 3>{vertex(obs, obs.F(f, 0)), vertex(obs, obs.F(f, 1)), vertex(obs, obs.F(f, 2))};
  };
  // Body vertex / obstacle face.
  for (int v = 0; v < body.V.rows(); ++v)
    query_tree(mp.obstacle_faces, swept[v], [&](int f) {
      ++out.num_candidate_pairs;
      record(moving_vertex_face_toi(motion, vertex(body, v), obstacle_face(f), u_max()),
             {FeaturePair::kBodyVertexObstacleFace, v, f}, &out);
    });
  // Obstacle vertex / body face.
  for (int f = 0; f < body.F.rows(); ++f)
    query_tree(mp.obstacle_vertices, face_box(swept, body, f), [&](int v) {
      ++out.num_candidate_pairs;
      record(vertex_moving_face_toi(motion, vertex(obs, v), body_face(f), u_max()),
             {FeaturePair::kObstacleVertexBodyFace, f, v}, &out);
    });
  // Edge / edge.
  for (size_t e = 0; e < mp.body_edges.size(); ++e) {
    const auto& be = mp.body_edges[e];
    Aabb box = swept[be[0]];
    grow(&box, swept[be[1]]);
    query_tree(mp.obstacle_edge_tree, box, [&](int oe) {
      ++out.num_candidate_pairs;
      const auto& o = mp.obstacle_edges[oe];
      record(moving_edge_edge_toi(motion, {vertex(body, be[0]), vertex(body, be[1])},
                                  {vertex(obs, o[0]), vertex(obs, o[1])}, u_max()),
             {FeaturePair::kEdgeEdge, int32_t(e), oe}, &out);
    });
  }
  return out;
}

int64_t count_intersecting_pairs(const ExactMeshPair& mp, const Pose& X) {
  const PosedBody posed = pose_body(mp.body, X);
  int64_t count = 0;
  for (int f = 0; f < mp.body.F.rows(); ++f) {
    const Triangle3 t(posed.exact[mp.body.F(f, 0)], posed.exact[mp.body.F(f, 1)], posed.exact[mp.body.F(f, 2)]);
    query_tree(mp.obstacle_faces, face_box(posed.box, mp.body, f), [&](int of) {
      if (CGAL::do_intersect(t, obstacle_triangle(mp.obstacle, of))) ++count;
    });
  }
  return count;
}

ExactSeparation separation_distance(const ExactMeshPair& mp, const Pose& X, double max_distance) {
  if (!(max_distance >= 0)) throw std::invalid_argument("separation_distance: max_distance must be >= 0");
  const PosedBody posed = pose_body(mp.body, X);
  const TriangleMesh& body = mp.body;
  const TriangleMesh& obs = mp.obstacle;
  // Pass 1 (doubles, conservative): every pair whose boxes are within
  // max_distance, with a lower bound of its distance (box to box, rounded
  // down) and an upper bound (closest corner pair, rounded up).
  struct Candidate {
    int32_t f, of;
    double lower;
  };
  std::vector<Candidate> candidates;
  double best_upper = HUGE_VAL;
  const double margin = max_distance * (1 + 1e-12);
  for (int f = 0; f < body.F.rows(); ++f) {
    const Aabb fb = face_box(posed.box, body, f);
    query_tree(mp.obstacle_faces, inflated(fb, margin), [&](int of) {
      Aabb obox;
      for (int k = 0; k < 3; ++k) grow(&obox, point_box(vertex(obs, obs.F(of, k))));
      double gap2 = 0;
      for (int c = 0; c < 3; ++c) {
        const double g = std::max({0.0, fb.lo[c] - obox.hi[c], obox.lo[c] - fb.hi[c]});
        gap2 += g * g;
      }
      const double lower = std::sqrt(gap2) * (1 - 1e-12);
      double corner = HUGE_VAL;
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) {
          const Aabb& vb = posed.box[body.F(f, i)];
          const Vec3 x = 0.5 * (vb.lo + vb.hi);
          corner = std::min(corner, (x - vertex(obs, obs.F(of, k))).norm());
        }
      best_upper = std::min(best_upper, corner * (1 + 1e-9) + 1e-300);
      candidates.push_back({int32_t(f), int32_t(of), lower});
    });
  }
  // Pass 2 (exact): pairs by increasing lower bound, while they can still win.
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.lower < b.lower; });
  const mpq_class max2 = mpq_class(max_distance) * mpq_class(max_distance);
  ExactSeparation out;
  CGAL::Gmpq best;
  double bound = best_upper;
  for (const Candidate& c : candidates) {
    if (c.lower > bound) break;
    const Triangle3 t(posed.exact[body.F(c.f, 0)], posed.exact[body.F(c.f, 1)], posed.exact[body.F(c.f, 2)]);
    const CGAL::Gmpq d2 = CGAL::squared_distance(t, obstacle_triangle(obs, c.of));
    if (!out.within || d2 < best) {
      out.within = true;
      best = d2;
      out.body_face = c.f;
      out.obstacle_face = c.of;
      bound = std::min(bound, std::nextafter(std::sqrt(std::nextafter(CGAL::to_double(d2), HUGE_VAL)), HUGE_VAL));
    }
  }
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

}  // namespace gauss6::reference
