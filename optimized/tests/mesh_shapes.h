// Small closed triangle meshes built in code for the tests: box, tetrahedron,
// regular n-gon prism and icosphere. All are counter-clockwise seen from outside
// (outward normals), without duplicate vertices.
#pragma once

#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "gauss6/geometry/mesh.h"

namespace gauss6::test {

// Appends the triangles of a quad (p, q, r, s), counter-clockwise.
inline void add_quad(std::vector<std::array<int, 3>>* tris, int p, int q, int r, int s) {
  tris->push_back({p, q, r});
  tris->push_back({p, r, s});
}

inline TriangleMesh make_mesh(const std::vector<Eigen::Vector3d>& V,
                              const std::vector<std::array<int, 3>>& F, const char* name) {
  TriangleMesh m;
  m.V.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (size_t i = 0; i < V.size(); ++i) m.V.row(static_cast<Eigen::Index>(i)) = V[i].transpose();
  m.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (size_t f = 0; f < F.size(); ++f)
    for (int k = 0; k < 3; ++k) m.F(static_cast<Eigen::Index>(f), k) = F[f][k];
  m.source = name;
  return m;
}

// Axis-aligned box of sides a x b x c centred at `center`: 8 vertices, 12 triangles.
// Vertex i has corner (x, y, z) = bits (i & 1, i & 2, i & 4): low or high side.
inline TriangleMesh make_box(double a, double b, double c,
                             const Eigen::Vector3d& center = Eigen::Vector3d::Zero()) {
  std::vector<Eigen::Vector3d> V;
  for (int i = 0; i < 8; ++i)
    V.push_back(center + Eigen::Vector3d((i & 1) ? a / 2 : -a / 2, (i & 2) ? b / 2 : -b / 2,
                                         (i & 4) ? c / 2 : -c / 2));
  std::vector<std::array<int, 3>> F;
  add_quad(&F, 0, 2, 3, 1);  // z low  (-z)
  add_quad(&F, 4, 5, 7, 6);  // z high (+z)
  add_quad(&F, 0, 1, 5, 4);  // y low  (-y)
  add_quad(&F, 2, 6, 7, 3);  // y high (+y)
  add_quad(&F, 0, 4, 6, 2);  // x low  (-x)
  add_quad(&F, 1, 3, 7, 5);  // x high (+x)
  return make_mesh(V, F, "box");
}

// The tetrahedron with corners 0, e1, e2, e3.
inline TriangleMesh make_unit_tetrahedron() {
  const std::vector<Eigen::Vector3d> V = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  return make_mesh(V, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}, "tetrahedron");
}

// Prism over the regular n-gon of circumradius r (a vertex on +x), height h along
// z, centred at the origin. Caps are fans around a centre vertex.
inline TriangleMesh make_prism(int n, double r, double h) {
  std::vector<Eigen::Vector3d> V;
  for (int ring = 0; ring < 2; ++ring)
    for (int i = 0; i < n; ++i) {
      const double t = 2.0 * M_PI * i / n;
      V.emplace_back(r * std::cos(t), r * std::sin(t), ring ? h / 2 : -h / 2);
    }
  V.emplace_back(0, 0, -h / 2);  // 2n: bottom centre
  V.emplace_back(0, 0, h / 2);   // 2n + 1: top centre
  std::vector<std::array<int, 3>> F;
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    F.push_back({2 * n, j, i});                  // bottom cap, -z
    F.push_back({2 * n + 1, n + i, n + j});      // top cap, +z
    add_quad(&F, i, j, n + j, n + i);            // side, outward
  }
  return make_mesh(V, F, "prism");
}

// Icosahedron subdivided `levels` times (each triangle into four), vertices on the
// sphere of radius r centred at the origin. 10 * 4^levels + 2 vertices.
inline TriangleMesh make_icosphere(int levels, double r) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> V = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& v : V) v = r * v.normalized();
  std::vector<std::array<int, 3>> F = {
      {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      V.push_back(r * (V[a] + V[b]).normalized());
      const int idx = static_cast<int>(V.size()) - 1;
      midpoint.emplace(key, idx);
      return idx;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& f : F) {
      const int ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
      next.push_back({f[0], ab, ca});
      next.push_back({f[1], bc, ab});
      next.push_back({f[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    F.swap(next);
  }
  return make_mesh(V, F, "icosphere");
}

// Both meshes in one (the second's indices shifted), as two bodies in one file.
inline TriangleMesh concatenate(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh m;
  m.V.resize(a.V.rows() + b.V.rows(), 3);
  m.V << a.V, b.V;
  m.F.resize(a.F.rows() + b.F.rows(), 3);
  m.F << a.F, (b.F.array() + static_cast<int32_t>(a.V.rows())).matrix();
  m.source = a.source + "+" + b.source;
  return m;
}

// The same surface with every triangle reversed (inward normals).
inline TriangleMesh flipped(TriangleMesh m) {
  m.F.col(1).swap(m.F.col(2));
  return m;
}

}  // namespace gauss6::test
