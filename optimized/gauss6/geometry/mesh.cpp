// Triangle meshes: counts, edge adjacency, angle-weighted vertex normals and the
// validation report of mesh.h. Load-time code (allocates, may throw); nothing here
// runs inside a real-time loop.
#include "gauss6/geometry/mesh.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>

namespace gauss6 {
namespace {

// ---------------------------------------------------------------------------
// Exact sign of a 2-D orientation determinant, by expansion arithmetic
// (Shewchuk 1997): every product of two doubles is split exactly into a sum of
// two doubles with an FMA, and the twelve terms are summed without error. Exact
// unless a product overflows or underflows (|coordinates| within about
// 1e-150 .. 1e150), far outside any mesh this project reads.

// a + b = s + e exactly (Knuth's TwoSum).
inline void two_sum(double a, double b, double* s, double* e) {
  *s = a + b;
  const double bv = *s - a;
  const double av = *s - bv;
  *e = (a - av) + (b - bv);
}

// A non-overlapping expansion: a sum of doubles held exactly, at most 12 terms here.
struct Expansion {
  double c[12];
  int n = 0;
  // Adds b exactly (Shewchuk's Grow-Expansion with zero elimination).
  void add(double b) {
    double q = b;
    int m = 0;
    for (int i = 0; i < n; ++i) {
      double s, e;
      two_sum(q, c[i], &s, &e);
      if (e != 0.0) c[m++] = e;
      q = s;
    }
    if (q != 0.0) c[m++] = q;
    n = m;
  }
  // The largest component (the last one) carries the sign.
  int sign() const { return n == 0 ? 0 : (c[n - 1] > 0 ? 1 : -1); }
};

// Sign of (u1 - u0)(v2 - v0) - (v1 - v0)(u2 - u0), computed exactly.
int orient2d_sign(double u0, double v0, double u1, double v1, double u2, double v2) {
  // Expanded: u1 v2 - u1 v0 - u0 v2 - v1 u2 + v1 u0 + v0 u2 (u0 v0 cancels).
  const double pa[6] = {u1, -u1, -u0, -v1, v1, v0};
  const double pb[6] = {v2, v0, v2, u2, u0, u2};
  Expansion h;
  for (int i = 0; i < 6; ++i) {
    const double p = pa[i] * pb[i];
    h.add(p);
    h.add(std::fma(pa[i], pb[i], -p));  // the exact rounding error of p
  }
  return h.sign();
}

// True when the three corners are exactly collinear: the cross product
// (b - a) x (c - a) is exactly zero, i.e. all three coordinate-plane projections
// of the triangle have exactly zero signed area.
bool exactly_degenerate(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                        const Eigen::Vector3d& c) {
  return orient2d_sign(a.x(), a.y(), b.x(), b.y(), c.x(), c.y()) == 0 &&
         orient2d_sign(a.y(), a.z(), b.y(), b.z(), c.y(), c.z()) == 0 &&
         orient2d_sign(a.z(), a.x(), b.z(), b.x(), c.z(), c.x()) == 0;
}

// ---------------------------------------------------------------------------
// Half-edges sorted by undirected key: the common ground of build_adjacency()
// and validate_mesh().

struct HalfEdge {
  int32_t lo, hi;  // undirected key, lo <= hi
  int32_t face, corner;  // runs from F(face, corner) to F(face, (corner+1)%3)
};

struct EdgeTable {
  std::vector<HalfEdge> half_edges;  // sorted by (lo, hi, face, corner)
  std::vector<int32_t> edge_start;   // edge e owns half_edges[edge_start[e] .. edge_start[e+1])
  int num_edges() const { return static_cast<int>(edge_start.size()) - 1; }
};

// Builds the table over the faces f with use_face[f] (all faces when empty).
EdgeTable make_edge_table(const MatrixX3i& F, const std::vector<char>& use_face) {
  EdgeTable t;
  const int nf = static_cast<int>(F.rows());
  t.half_edges.reserve(3 * static_cast<size_t>(nf));
  for (int f = 0; f < nf; ++f) {
    if (!use_face.empty() && !use_face[f]) continue;
    for (int k = 0; k < 3; ++k) {
      const int32_t a = F(f, k), b = F(f, (k + 1) % 3);
      t.half_edges.push_back({std::min(a, b), std::max(a, b), f, k});
    }
  }
  std::sort(t.half_edges.begin(), t.half_edges.end(), [](const HalfEdge& x, const HalfEdge& y) {
    if (x.lo != y.lo) return x.lo < y.lo;
    if (x.hi != y.hi) return x.hi < y.hi;
    if (x.face != y.face) return x.face < y.face;
    return x.corner < y.corner;
  });
  for (size_t i = 0; i < t.half_edges.size(); ++i) {
    if (i == 0 || t.half_edges[i].lo != t.half_edges[i - 1].lo ||
        t.half_edges[i].hi != t.half_edges[i - 1].hi) {
      t.edge_start.push_back(static_cast<int32_t>(i));
    }
  }
  t.edge_start.push_back(static_cast<int32_t>(t.half_edges.size()));
  return t;
}

// Minimal union-find with path halving.
struct DisjointSets {
  std::vector<int32_t> parent;
  explicit DisjointSets(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int32_t find(int32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int32_t a, int32_t b) { parent[find(a)] = find(b); }
};

template <class T>
void push_capped(std::vector<int>* list, T value) {
  if (static_cast<int>(list->size()) < MeshReport::kMaxListed)
    list->push_back(static_cast<int>(value));
}

}  // namespace

int num_vertices(const TriangleMesh& m) { return static_cast<int>(m.V.rows()); }
int num_triangles(const TriangleMesh& m) { return static_cast<int>(m.F.rows()); }

void build_adjacency(TriangleMesh* m) {
  const int nv = num_vertices(*m), nf = num_triangles(*m);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      if (m->F(f, k) < 0 || m->F(f, k) >= nv)
        throw std::invalid_argument("build_adjacency: triangle " + std::to_string(f) +
                                    " has vertex index " + std::to_string(m->F(f, k)) +
                                    " outside [0, " + std::to_string(nv) + ")");

  const EdgeTable t = make_edge_table(m->F, {});
  const int ne = t.num_edges();
  MeshAdjacency& adj = m->adjacency;
  adj.E.resize(ne, 2);
  adj.EF.setConstant(ne, 2, -1);
  adj.FE.resize(nf, 3);
  adj.edge_face_count.assign(ne, 0);
  for (int e = 0; e < ne; ++e) {
    const HalfEdge& first = t.half_edges[t.edge_start[e]];
    adj.E(e, 0) = first.lo;
    adj.E(e, 1) = first.hi;
    adj.edge_face_count[e] = t.edge_start[e + 1] - t.edge_start[e];
    // EF: the first two faces in increasing face order.
    int slot = 0;
    for (int i = t.edge_start[e]; i < t.edge_start[e + 1]; ++i) {
      const HalfEdge& h = t.half_edges[i];
      adj.FE(h.face, h.corner) = e;
      if (slot < 2) adj.EF(e, slot++) = h.face;
    }
  }

  // Vertex -> faces, CSR by counting sort (faces in increasing order per vertex;
  // a face with a repeated index is listed once per distinct vertex).
  adj.VF_start.assign(nv + 1, 0);
  auto distinct_corner = [&](int f, int k) {
    for (int j = 0; j < k; ++j)
      if (m->F(f, j) == m->F(f, k)) return false;
    return true;
  };
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      if (distinct_corner(f, k)) ++adj.VF_start[m->F(f, k) + 1];
  std::partial_sum(adj.VF_start.begin(), adj.VF_start.end(), adj.VF_start.begin());
  adj.VF.assign(adj.VF_start[nv], -1);
  std::vector<int32_t> fill(adj.VF_start.begin(), adj.VF_start.end() - 1);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      if (distinct_corner(f, k)) adj.VF[fill[m->F(f, k)]++] = f;
}

Eigen::Vector3d face_normal(const TriangleMesh& m, int f) {
  const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double len = n.norm();
  if (!(len > 0.0) || !std::isfinite(len)) return Eigen::Vector3d::Zero();
  return n / len;
}

void compute_vertex_normals(TriangleMesh* m) {
  const int nv = num_vertices(*m), nf = num_triangles(*m);
  m->N.setZero(nv, 3);
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3d n = face_normal(*m, f);
    if (n.isZero()) continue;  // degenerate triangles carry no direction
    for (int k = 0; k < 3; ++k) {
      // Weight: the triangle's interior angle at this corner (Thuermer & Wuethrich 1998).
      const int i = m->F(f, k);
      const Eigen::Vector3d p = m->V.row(i);
      const Eigen::Vector3d u = Eigen::Vector3d(m->V.row(m->F(f, (k + 1) % 3))) - p;
      const Eigen::Vector3d w = Eigen::Vector3d(m->V.row(m->F(f, (k + 2) % 3))) - p;
      const double angle = std::atan2(u.cross(w).norm(), u.dot(w));
      m->N.row(i) += angle * n.transpose();
    }
  }
  for (int i = 0; i < nv; ++i) {
    const double len = m->N.row(i).norm();
    if (len > 0.0 && std::isfinite(len)) m->N.row(i) /= len;
    else m->N.row(i).setZero();
  }
}

MeshReport validate_mesh(const TriangleMesh& m) {
  MeshReport r;
  const int nv = num_vertices(m), nf = num_triangles(m);
  r.num_vertices = nv;
  r.num_triangles = nf;

  // 1. Non-finite coordinates.
  std::vector<char> finite_vertex(nv, 1);
  for (int i = 0; i < nv; ++i) {
    if (!m.V.row(i).allFinite()) {
      finite_vertex[i] = 0;
      ++r.num_nonfinite_vertices;
      push_capped(&r.nonfinite_vertices, i);
    }
  }

  // 2. Bad indices (out of range or repeated); such triangles are left out of
  //    every later check.
  std::vector<char> good_face(nf, 1);
  for (int f = 0; f < nf; ++f) {
    const int a = m.F(f, 0), b = m.F(f, 1), c = m.F(f, 2);
    const bool in_range = a >= 0 && a < nv && b >= 0 && b < nv && c >= 0 && c < nv;
    if (!in_range || a == b || b == c || c == a) {
      good_face[f] = 0;
      ++r.num_bad_indices;
      push_capped(&r.bad_triangles, f);
    }
  }

  // 3. Degenerate triangles: corners exactly collinear (exact predicate).
  for (int f = 0; f < nf; ++f) {
    if (!good_face[f]) continue;
    const int a = m.F(f, 0), b = m.F(f, 1), c = m.F(f, 2);
    if (!finite_vertex[a] || !finite_vertex[b] || !finite_vertex[c]) continue;
    if (exactly_degenerate(m.V.row(a), m.V.row(b), m.V.row(c))) {
      ++r.num_degenerate_triangles;
      push_capped(&r.degenerate_triangles, f);
    }
  }

  // 4. Edges: boundary, non-manifold, and orientation (two faces on an edge must
  //    run along it in opposite directions).
  const EdgeTable t = make_edge_table(m.F, good_face);
  r.num_edges = t.num_edges();
  for (int e = 0; e < r.num_edges; ++e) {
    const int count = t.edge_start[e + 1] - t.edge_start[e];
    if (count == 1) {
      ++r.num_boundary_edges;
      push_capped(&r.boundary_edges, e);
    } else if (count > 2) {
      ++r.num_nonmanifold_edges;
      push_capped(&r.nonmanifold_edges, e);
    } else {
      const HalfEdge& h0 = t.half_edges[t.edge_start[e]];
      const HalfEdge& h1 = t.half_edges[t.edge_start[e] + 1];
      const bool fwd0 = m.F(h0.face, h0.corner) == h0.lo;
      const bool fwd1 = m.F(h1.face, h1.corner) == h1.lo;
      if (fwd0 == fwd1) {
        ++r.num_inconsistent_edges;
        push_capped(&r.inconsistent_edges, e);
      }
    }
  }

  // 5. Non-manifold vertices: the corners around a vertex must form one fan.
  //    Corners (face, k) at the same vertex are joined when their faces share an
  //    edge through that vertex; a vertex whose corners fall into more than one
  //    group is non-manifold (e.g. two closed surfaces touching at one point).
  DisjointSets corners(3 * static_cast<size_t>(nf));
  for (int e = 0; e < r.num_edges; ++e) {
    const HalfEdge& h0 = t.half_edges[t.edge_start[e]];
    for (int i = t.edge_start[e] + 1; i < t.edge_start[e + 1]; ++i) {
      const HalfEdge& h = t.half_edges[i];
      // Each half-edge touches its start corner and its end corner; match by vertex.
      for (int end = 0; end < 2; ++end) {
        const int k = (h.corner + end) % 3;
        const int v = m.F(h.face, k);
        const int k0 = m.F(h0.face, h0.corner) == v ? h0.corner : (h0.corner + 1) % 3;
        corners.unite(3 * h.face + k, 3 * h0.face + k0);
      }
    }
  }
  std::vector<int32_t> first_root(nv, -1);
  std::vector<char> counted(nv, 0), used(nv, 0);
  for (int f = 0; f < nf; ++f) {
    if (!good_face[f]) continue;
    for (int k = 0; k < 3; ++k) {
      const int v = m.F(f, k);
      used[v] = 1;
      const int32_t root = corners.find(3 * f + k);
      if (first_root[v] < 0) {
        first_root[v] = root;
      } else if (first_root[v] != root && !counted[v]) {
        counted[v] = 1;
        ++r.num_nonmanifold_vertices;
      }
    }
  }
  for (int v = 0; v < nv; ++v)
    if (counted[v]) push_capped(&r.nonmanifold_vertices, v);

  // 6. Isolated vertices: in no (valid) triangle.
  for (int v = 0; v < nv; ++v) {
    if (!used[v]) {
      ++r.num_isolated_vertices;
      push_capped(&r.isolated_vertices, v);
    }
  }
  return r;
}

bool MeshReport::ok() const {
  return num_triangles > 0 && num_nonfinite_vertices == 0 && num_bad_indices == 0 &&
         num_degenerate_triangles == 0 && num_isolated_vertices == 0 && closed() && manifold() &&
         num_self_intersections <= 0;
}

std::string MeshReport::describe() const {
  std::ostringstream os;
  auto line = [&os](int count, const char* what, const std::vector<int>& list, const char* kind) {
    if (count <= 0) return;
    os << count << ' ' << what;
    if (!list.empty()) {
      os << " (" << kind << ' ';
      for (size_t i = 0; i < list.size(); ++i) os << (i ? ", " : "") << list[i];
      if (static_cast<int>(list.size()) < count) os << ", ...";
      os << ')';
    }
    os << '\n';
  };
  if (num_triangles == 0) os << "no triangles\n";
  line(num_nonfinite_vertices, "vertices with a non-finite coordinate", nonfinite_vertices,
       "vertices");
  line(num_bad_indices, "triangles with an out-of-range or repeated vertex index", bad_triangles,
       "triangles");
  line(num_degenerate_triangles, "degenerate (zero-area) triangles", degenerate_triangles,
       "triangles");
  line(num_boundary_edges, "boundary edges: the mesh is open", boundary_edges, "edges");
  line(num_nonmanifold_edges, "non-manifold edges (more than two triangles)", nonmanifold_edges,
       "edges");
  line(num_nonmanifold_vertices, "non-manifold vertices (triangles form several fans)",
       nonmanifold_vertices, "vertices");
  line(num_inconsistent_edges, "edges with inconsistent orientation (a flipped triangle)",
       inconsistent_edges, "edges");
  line(num_isolated_vertices, "isolated vertices (in no triangle)", isolated_vertices, "vertices");
  if (num_self_intersections > 0)
    os << num_self_intersections << " self-intersecting triangle pairs\n";
  return os.str();
}

}  // namespace gauss6
