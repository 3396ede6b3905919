// Bounding volume trees over triangle meshes: the surface-area build, the
// oriented-box fitting and the feature ownership (bvh.h).
#include "gauss6/geometry/bvh.h"

#include <algorithm>
#include <chrono>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include "gauss6/numeric/error_allowances.h"

namespace gauss6 {

size_t Bvh::memory_bytes() const {
  return nodes.capacity() * sizeof(BvhNode) + triangles.capacity() * sizeof(int32_t) +
         owned.capacity() * sizeof(uint8_t) + neighbor.capacity() * sizeof(int32_t) +
         sizeof(Bvh);
}

Obb fit_obb(const Vec3* points, int num_points) {
  Obb best;
  if (num_points <= 0) return best;
  Vec3 mean = Vec3::Zero();
  for (int i = 0; i < num_points; ++i) mean += points[i];
  mean /= num_points;
  Mat3 cov = Mat3::Zero();
  for (int i = 0; i < num_points; ++i) cov += (points[i] - mean) * (points[i] - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
  double best_size = std::numeric_limits<double>::infinity();
  const Mat3 frames[2] = {Mat3::Identity(), eig.eigenvectors()};
  for (const Mat3& axes : frames) {
    // A frame not orthonormal to within kObbFrameTolerance is dropped (the identity always passes).
    if (!axes.allFinite() || !near_orthonormal(axes)) continue;
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    double scale = 0;
    for (int i = 0; i < num_points; ++i) {
      const Vec3 x = axes.transpose() * points[i];
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
      scale = std::max(scale, points[i].cwiseAbs().maxCoeff());
    }
    Obb b;
    b.axes = axes;
    b.center = axes * (0.5 * (lo + hi));
    // The projections' and the centre's rounding (error_allowances.h).
    b.half = 0.5 * (hi - lo) + Vec3::Constant(kObbFitRounding * scale + kUnderflowFloor);
    const Vec3 grown = b.half + Vec3::Constant(1e-3 * b.half.norm());
    const double size = grown.prod();
    // The identity frame (the first) is kept whatever its size: where the
    // volume overflows to inf (extents beyond ~1e102) no size compares below
    // it, and the box must still hold the points.
    if (size < best_size || &axes == &frames[0]) {
      best_size = size;
      best = b;
    }
  }
  return best;
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
  std::vector<Vec3> corners;  // scratch: the vertices of a node's triangles
  Obb fit(int begin, int end) {
    corners.clear();
    for (int i = begin; i < end; ++i)
      for (int k = 0; k < 3; ++k) corners.push_back(mesh.V.row(mesh.F(bvh->triangles[i], k)).transpose());
    return fit_obb(corners.data(), static_cast<int>(corners.size()));
  }
  // Orders triangles[begin, end) and returns where to split them: the
  // surface-area heuristic (MacDonald and Booth 1990) over the triangles sorted
  // by centroid along each axis, the split that minimises area(left) n_left +
  // area(right) n_right of the two children's boxes. A median split by
  // centroid goes wrong on long triangles: the two triangles of a 6 cm strip of
  // the hole's wall have centroids 2 cm apart along it, and splitting there
  // gives two children as long as their parent, where splitting across the
  // strips halves the arcs.
  std::vector<int32_t> order[3];
  std::vector<double> right_area;
  int split(int begin, int end) {
    const int n = end - begin;
    const auto area = [](const Aabb& b) {
      const Vec3 e = b.hi - b.lo;
      return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
    };
    double best_cost = std::numeric_limits<double>::infinity();
    int best_axis = -1, best_at = n / 2;
    right_area.resize(static_cast<size_t>(n) + 1);
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<int32_t>& o = order[axis];
      o.assign(bvh->triangles.begin() + begin, bvh->triangles.begin() + end);
      std::stable_sort(o.begin(), o.end(), [&](int a, int b) { return centroid[a][axis] < centroid[b][axis]; });
      Aabb acc = tri_box[o[n - 1]];
      for (int i = n - 1; i >= 1; --i) {  // right_area[i]: triangles o[i, n)
        acc.lo = acc.lo.cwiseMin(tri_box[o[i]].lo);
        acc.hi = acc.hi.cwiseMax(tri_box[o[i]].hi);
        right_area[i] = area(acc);
      }
      acc = tri_box[o[0]];
      for (int i = 1; i < n; ++i) {  // left: o[0, i)
        const double cost = area(acc) * i + right_area[i] * (n - i);
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = axis;
          best_at = i;
        }
        acc.lo = acc.lo.cwiseMin(tri_box[o[i]].lo);
        acc.hi = acc.hi.cwiseMax(tri_box[o[i]].hi);
      }
    }
    if (best_axis < 0) {  // non-finite boxes: split in the middle as they come
      return begin + n / 2;
    }
    std::copy(order[best_axis].begin(), order[best_axis].end(), bvh->triangles.begin() + begin);
    return begin + best_at;
  }
  int build(int index, int begin, int end) {
    bvh->nodes[index].box = bounds(begin, end);
    BvhNode& node = bvh->nodes[index];
    node.obb = fit(begin, end);
    node.obb_pays = obb_volume_ratio(node.obb.half, 0.5 * (node.box.hi - node.box.lo)) < 0.5;
    node.obb_tight = near_orthonormal(node.obb.axes, kObbAxesTight);
    if (end - begin <= leaf_size) {
      bvh->nodes[index].first = begin;
      bvh->nodes[index].count = end - begin;
      return 1;
    }
    const int mid = split(begin, end);
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
    Builder b{mesh, std::max(leaf_size, 1), {}, {}, &bvh, {}, {}, {}};
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

}  // namespace gauss6
