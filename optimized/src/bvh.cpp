// Bounding volume trees over triangle meshes (surface-area build, oriented-box
// fitting, feature ownership, swept boxes) and the mesh-level CCD step: the
// hinted pairs first, then the candidates of the proximity cache (coherence
// between steps) where it covers the step, else per sub-interval of the
// motion a simultaneous descent of the god-object's and each obstacle's tree;
// a time bound for each candidate triangle pair and then for each of its owned
// feature pairs, and the narrow-phase tests of the rest, earliest first,
// earliest hit kept.
#include "gauss6/bvh.h"

#include <algorithm>
#include <chrono>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

namespace gauss6 {

size_t Bvh::memory_bytes() const {
  return nodes.capacity() * sizeof(BvhNode) + triangles.capacity() * sizeof(int32_t) +
         owned.capacity() * sizeof(uint8_t) + neighbor.capacity() * sizeof(int32_t) +
         sizeof(Bvh);
}

Aabb swept_box(const MotionEnclosure& e, const Aabb& body) {
  const IVec3 r = {Interval{body.lo.x(), body.hi.x()}, Interval{body.lo.y(), body.hi.y()},
                   Interval{body.lo.z(), body.hi.z()}};
  const IVec3 w = enclose_point(e, r);
  return {Vec3(w[0].lo, w[1].lo, w[2].lo), Vec3(w[0].hi, w[1].hi, w[2].hi)};
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
    if (!axes.allFinite()) continue;
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
    // Each projection is within 1e-15 |x|_inf of the exact one on the rounded
    // axes; the centre's own rounding likewise: 1e-13 scale covers both.
    b.half = 0.5 * (hi - lo) + Vec3::Constant(1e-13 * scale + 1e-300);
    const Vec3 grown = b.half + Vec3::Constant(1e-3 * b.half.norm());
    const double size = grown.prod();
    if (size < best_size) {
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

// ---------------------------------------------------------------------------
// ccd_step
// ---------------------------------------------------------------------------

namespace {

Vec3 vertex(const TriangleMesh& m, int f, int k) { return m.V.row(m.F(f, k)).transpose(); }

// The god-object at a sub-interval's start u0 in doubles (X = p + R r_B), and
// bounds on how far the exactly moving point p(u) + R(u) r_B, for u in [u0, u1]
// and |r_B| <= the god radius rho, can lie from the double X:
//   - static_error: the stop pose's deviation (make_stop_pose: double pose vs
//     exact motion) plus the double evaluation of R(q) r_B + p and of one
//     projection n.X (|n| = 1 up to rounding): a few roundings of terms bounded
//     by |p|_inf + rho, well within 1e-13 (|p|_inf + rho);
//   - the motion: p(u) - p(u0) = (u - u0) dp, with dp within drift of its
//     midpoint dp_mid, and R(u) R(u0)^T is the turn about g by 2 (atan(u |g|) -
//     atan(u0 |g|)) <= 2 (u - u0) |g| (atan is 1-Lipschitz), so a body point r_B
//     moves by at most (u - u0)(|dp_mid| + drift + turn_rate |r_B|), turn_rate
//     = 2 |g| (speed: that for |r_B| = rho), and along a direction n by at most
//     (u - u0)(|n.dp_mid| + drift + turn_rate |r_B|).
struct StartFrame {
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero(), dp_mid = Vec3::Zero();
  double u0 = 0, static_error = 0, speed = 0, drift = 0, turn_rate = 0, rho = 0;
  double dp_max = 0;  // |dp| for every dp in the motion's enclosure (rounded up)
  // The turn: R(u) R(u0)^T turns about the exact g by at most 2 (u - u0) |g|;
  // omega = 2 g_mid (g's midpoint), within omega_error of 2 g for every g in
  // its enclosure, and omega2 >= |2 g|^2.
  Vec3 omega = Vec3::Zero();
  double omega_error = 0, omega2 = 0;
  double omega_norm = 0;  // >= |omega|
  double g2 = 0;          // >= |g|^2
  void set(const CcdMotion& m, double u, double rho_in) {
    const StopPose sp = make_stop_pose(m, u, rho_in);
    u0 = u;
    rho = rho_in;
    R = rotation_matrix(sp.pose.q);
    p = sp.pose.p;
    double dp2 = 0, drift2 = 0;
    for (int i = 0; i < 3; ++i) {
      const Interval& c = m.dp[i];
      const double a = std::max(std::abs(c.lo), std::abs(c.hi));
      dp2 = next_up(dp2 + next_up(a * a));
      dp_mid[i] = 0.5 * c.lo + 0.5 * c.hi;
      const double r = std::max(next_up(c.hi - dp_mid[i]), next_up(dp_mid[i] - c.lo));
      drift2 = next_up(drift2 + next_up(r * r));
    }
    drift = next_up(std::sqrt(drift2));
    turn_rate = next_up(2 * next_up(std::sqrt(m.g2.hi)));
    double g_err2 = 0;
    for (int i = 0; i < 3; ++i) {
      const Interval& c = m.g[i];
      omega[i] = c.lo + c.hi;  // 2 g_mid (exact: doubling)
      const double r = std::max(next_up(c.hi - 0.5 * (c.lo + c.hi)), next_up(0.5 * (c.lo + c.hi) - c.lo));
      g_err2 = next_up(g_err2 + next_up(r * r));
    }
    omega_error = next_up(2 * next_up(std::sqrt(g_err2)));
    omega2 = next_up(4 * m.g2.hi);
    g2 = m.g2.hi;
    omega_norm = next_up(omega.norm() * (1 + 1e-15));
    dp_max = next_up(std::sqrt(dp2));
    speed = next_up(dp_max + next_up(turn_rate * rho));
    static_error = next_up(sp.deviation + next_up(1e-13 * next_up(p.cwiseAbs().maxCoeff() + rho)));
    if (!std::isfinite(static_error) || !std::isfinite(speed) || !std::isfinite(drift) || !dp_mid.allFinite() ||
        !omega.allFinite() || !std::isfinite(omega_error) || !std::isfinite(omega2)) {
      static_error = speed = drift = turn_rate = dp_max = std::numeric_limits<double>::infinity();
      omega.setZero();
      omega_norm = 0;
    }
  }

  // How far the turn by phi over [u0, u0 + tau], tau <= tau_max, may fall
  // behind tau omega (TriangleMotion::lag): phi = 2 (atan(u |g|) - atan(u0 |g|))
  // lies between 2 tau |g| / (1 + u1^2 |g|^2) and 2 tau |g| (u1 = u0 + tau_max),
  // and sin(phi) >= phi (1 - phi^2 / 6); so sin(phi) / (2 tau |g|) >= 1 - u1^2
  // |g|^2 - (2 tau |g|)^2 / 6. At most 1.
  double lag(double tau_max) const {
    const double u1 = std::min(1.0, next_up(u0 + tau_max));
    const double a = next_up(tau_max * turn_rate);
    const double l = next_up(next_up(next_up(u1 * u1) * g2) + next_up(next_up(a * a) / 6));
    return l < 1 ? l : 1.0;  // also NaN
  }

  // The oriented-box frame of the sub-interval [u0, u1] (bvh.h, PosedObb,
  // SweptObbFrame: directional), grown by the distance sought d. A point at
  // offset r (exact, at u0) from G moves by tau dp + (lambda tau 2 g) x r +
  // (1 - cos(phi)) e x (e x r), tau = u - u0 <= span, lambda in [1 - lag, 1]:
  // that is tau (dp_mid + omega x r) plus at most span (drift + (omega_error +
  // lag |omega| + span omega2 / 2) |r|) (the lag, 2 g's distance from omega,
  // 1 - cos(phi) <= phi^2 / 2); with r taken from the double pose, within 2
  // static_error of the exact one, plus span (turn_rate + |omega|) 2
  // static_error.
  SweptObbFrame obb_frame(double u1, double d) const {
    SweptObbFrame f;
    f.R = R;
    f.p = p;
    const double span = next_up(u1 - u0);
    f.step = (u1 - u0) * dp_mid;
    f.spin = (u1 - u0) * omega;
    f.spread = next_up(span * omega_norm);
    // The step's own rounding (relative 2^-53 per coordinate) joins the drift.
    const double step_error = next_up(1e-15 * f.step.cwiseAbs().maxCoeff() * 2);
    const double offsets = next_up(next_up(span * next_up(turn_rate + omega_norm)) * next_up(2 * static_error));
    f.grow = next_up(next_up(next_up(static_error + d) + next_up(next_up(span * drift) + step_error)) + offsets);
    const double rest = next_up(next_up(omega_error + next_up(lag(span) * omega_norm)) + next_up(0.5 * next_up(span * omega2)));
    f.turn = next_up(span * rest);
    if (!std::isfinite(f.grow) || !std::isfinite(f.turn) || !std::isfinite(f.spread) || !f.step.allFinite() ||
        !f.spin.allFinite()) {
      f.grow = std::numeric_limits<double>::infinity();
      f.step.setZero();
      f.spin.setZero();
      f.spread = 0;
    }
    return f;
  }

  // A lower bound of the first u >= u0 at which the god triangle gf can come
  // within min_separation d of the obstacle triangle `of` (u0 when unknown). At
  // u the god-object's points are within static_error of their double positions
  // X = p + R r_B at u0 moved as above; so a separating axis of the double
  // triangles (triangle_time_lower_bound: face normals, and edge cross products,
  // which separate a long side strip of the peg from the wide fan triangles
  // around the hole's rim where no face normal does) with gap g, along which the
  // triangle approaches at most at |n.dp_mid| + drift plus its turn about G
  // (TriangleMotion: the directional part from omega, the rest in w), keeps
  // every feature pair farther than d until (g - static_error - d) / that. The
  // search stops once the bound passes u_limit, and the bound is used for
  // u <= u_limit only: the turn's second-order term is taken for tau_max =
  // u_limit - u0. w, for r the largest |r_B| of the triangle's corners (>= that
  // of any of its points): drift; (omega_error + tau_max omega2 / 2) r (the
  // exact turn rate's distance from omega, and the second-order term);
  // turn_rate (static_error + 1e-12 r) (the double corners' offsets from G are
  // within static_error of the exact ones).
  double earliest(const TriangleMesh& gm, int gf, const TriangleMesh& om, int of, double d, double u_limit) const {
    Vec3 X[3], Y[3];
    const double r2 = place(gm, gf, om, of, X, Y);
    // |r_B| of any point of the triangle <= that of its farthest corner.
    return earliest(X, Y, radius(r2), d, u_limit);
  }
  // The same for a god triangle X (its corners at u0, doubles; r >= the
  // largest |r_B| of them) and an obstacle triangle Y, either possibly
  // degenerate (a feature: see for_each_separating_axis), `extra` an axis to
  // try first.
  double earliest(const Vec3 X[3], const Vec3 Y[3], double r, double d, double u_limit,
                  const Vec3* extra = nullptr) const {
    const double tau_max = next_up(u_limit - u0);
    TriangleMotion m;
    m.v = dp_mid;
    m.omega = omega;
    m.centre = p;
    m.lag = lag(tau_max);
    const double second = next_up(0.5 * next_up(tau_max * omega2));
    const double offsets = next_up(turn_rate * next_up(static_error + 1e-12 * r));
    m.w = next_up(next_up(drift + next_up(next_up(omega_error + second) * r)) + offsets);
    if (!(m.w < std::numeric_limits<double>::infinity())) return u0;
    const double reach = next_up(static_error + d);
    const double tau = triangle_time_lower_bound(X, Y, m, reach, tau_max, extra);
    if (!(tau > 0)) return u0;
    return next_down(u0 + tau);
  }

  // A lower bound of the distance of the god triangle gf at u0 (exact) from
  // the obstacle triangle `of`: the separating-axis bound of the double
  // triangles less static_error (0 when none proves more), computed until it
  // exceeds `enough`; *radius: the largest |r_B| of gf's corners.
  double gap(const TriangleMesh& gm, int gf, const TriangleMesh& om, int of, double enough, double* r) const {
    Vec3 X[3], Y[3];
    *r = radius(place(gm, gf, om, of, X, Y));
    const double g = triangle_gap_lower_bound(X, Y, next_up(static_error + enough));
    return std::max(0.0, next_down(g - static_error));
  }

  // A body point's double position at u0.
  Vec3 pose(const Vec3& r_B) const { return R * r_B + p; }
  // A bound >= sqrt(r2) and <= rho (every body point's |r_B| is).
  double radius(double r2) const { return std::min(rho, next_up(std::sqrt(r2) * (1 + 1e-15))); }

 private:
  // The god triangle's corners at u0 (doubles) and the obstacle triangle's;
  // returns the largest |r_B|^2 of the god corners.
  double place(const TriangleMesh& gm, int gf, const TriangleMesh& om, int of, Vec3 X[3], Vec3 Y[3]) const {
    double r2 = 0;
    for (int k = 0; k < 3; ++k) {
      const Vec3 r_B = gm.V.row(gm.F(gf, k)).transpose();
      r2 = std::max(r2, r_B.squaredNorm());
      X[k] = R * r_B + p;
      Y[k] = om.V.row(om.F(of, k)).transpose();
    }
    return r2;
  }
};

// How far any point r_B of a body lies at pose b from where it lies at pose
// a, both exact (p + R(q) r_B, R(q) the rotation of the unit quaternion
// q / |q|): at most shift + turn |r_B|, with shift >= |p_b - p_a| and turn >=
// |R(q_b) - R(q_a)|: for unit quaternions R(a)^T R(b) = R(conj(a) b) turns by
// theta with |vec(conj(a) b)| = sin(theta / 2), and a turn by theta moves a
// point by at most 2 sin(theta / 2) |r_B|. In doubles the two normalisations
// and the product's components are within a few units of 2^-53 (every term is
// at most 1 in magnitude): 1e-14 covers them, and 1e-15 the rounding of
// |p_b - p_a|. Infinite on non-finite input.
struct Displacement {
  double shift = 0, turn = 0;
  Displacement(const Pose& a, const Pose& b) {
    const Quat qa = normalized(a.q), qb = normalized(b.q);
    const Vec3 v = qa.w * qb.vec() - qb.w * qa.vec() - qa.vec().cross(qb.vec());  // vec(conj(qa) qb)
    turn = next_up(next_up(2 * v.norm()) + 1e-14);
    shift = next_up((b.p - a.p).norm() * (1 + 1e-15));
    if (!(turn < std::numeric_limits<double>::infinity() && shift < std::numeric_limits<double>::infinity()))
      turn = shift = std::numeric_limits<double>::infinity();
  }
  // Grown by a motion from b over [0, u] (StartFrame at 0: |dp| <= dp_max, and
  // R(u) R(0)^T turns by at most u turn_rate).
  void add(const StartFrame& f, double u) {
    shift = next_up(shift + next_up(u * f.dp_max));
    turn = next_up(turn + next_up(u * f.turn_rate));
  }
  double bound(double radius) const { return next_up(shift + next_up(turn * radius)); }
};

// Runs the owned feature pairs of one (god triangle, obstacle triangle) pair on
// the window [u0, *u_best]; lowers *u_best and records the pair on a hit.
struct PairTester {
  const CcdMotion* motion;
  const MotionEnclosure* sub;  // the motion over the sub-interval [u0, u1]
  const CcdStepSettings* settings;
  CcdWorkspace* ws;
  CcdStepResult* result;
  double u0, u1;  // the sub-interval; tests search [u0, min(u1, best u so far)]
  SweptBoxCache* swept = nullptr;  // god vertex boxes over *sub, shared by the pairs of the sub-interval
  const StartFrame* start = nullptr;  // the god-object at u0 and its motion bounds
  double reach = 0;                   // the narrow phase's min_separation

  // Once a pair hit at u_b, later pairs search only up to u_b - time_tolerance:
  // a contact in (u_b - tol, u_b] cannot lower the step's answer by more than
  // the tolerance, and the step reports u_b - tol (see ccd_step), which is then
  // <= u* for those pairs too.
  double end() const { return result->hit ? std::min(u1, result->u_hit - settings->narrow.time_tolerance) : u1; }
  bool done() const { return result->hit && end() <= u0; }

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
    // Vertex boxes over the sub-interval (cached per mesh vertex). At each u the
    // motion maps body points affinely, so an edge or the face lies in the hull
    // of its vertices' world points, hence in the hull of their swept boxes.
    Aabb god_swept[3], god_edge_swept[3];
    for (int k = 0; k < 3; ++k)
      god_swept[k] = swept->get(swept->vertices, gm.F(gf, k),
                                [&] { return swept_box(*sub, box_of(god_face[k], god_face[k])); });
    const auto hull_of = [](const Aabb& a, const Aabb& b) { return Aabb{a.lo.cwiseMin(b.lo), a.hi.cwiseMax(b.hi)}; };
    for (int k = 0; k < 3; ++k) god_edge_swept[k] = hull_of(god_swept[k], god_swept[(k + 1) % 3]);
    const Aabb god_face_swept = hull_of(god_edge_swept[0], god_swept[2]);
    // Each feature pair's own time bound (StartFrame::earliest on the features
    // as degenerate triangles, the axis between their closest points at u0
    // tried first): a pair sliding along at its gap, or turning across it,
    // needs no test.
    Vec3 X[3];
    double rad[3];
    bool posed = false;
    const auto pose_god_face = [&] {  // once, for the first feature past the box filter
      if (posed) return;
      posed = true;
      for (int k = 0; k < 3; ++k) {
        X[k] = start->pose(god_face[k]);
        rad[k] = start->radius(god_face[k].squaredNorm());
      }
    };
    const Vec3* Y = obs_face.data();
    // The bound also starts the feature pair's search: nothing comes within
    // reach before it, so the narrow phase searches [from, end()] only (a
    // contact sliding along at its gap is then searched from where the
    // motion can first close it, not across the whole step).
    double from = u0;
    const auto apart = [&](const Vec3 A[3], const Vec3 B[3], double radius, const Vec3& axis) {
      from = std::max(u0, start->earliest(A, B, radius, reach, end(), &axis));
      if (from <= end()) return false;
      ++result->num_feature_culls;
      return true;
    };
    for (int k = 0; k < 3; ++k) {
      if (!(go & (1u << k)) || !(u0 <= end()) || !overlap(god_swept[k], obs_face_box)) continue;
      pose_god_face();
      const Vec3 A[3] = {X[k], X[k], X[k]};
      if (apart(A, Y, rad[k], X[k] - closest_point_on_triangle(X[k], Y[0], Y[1], Y[2]))) continue;
      RigidVertexFaceQuery q{motion, /*vertex_on_body=*/true, god_face[k], obs_face, from, end()};
      ccd_rigid_vertex_face(q, settings->narrow, ws, &r);
      consider(r, {PairKind::kGodVertexObstacleFace, obstacle, gf, k, of, -1});
    }
    for (int k = 0; k < 3; ++k) {
      if (!(oo & (1u << k)) || !(u0 <= end()) ||
          !overlap(god_face_swept, inflate(box_of(obs_face[k], obs_face[k]), margin)))
        continue;
      pose_god_face();
      const Vec3 B[3] = {Y[k], Y[k], Y[k]};
      if (apart(X, B, std::max({rad[0], rad[1], rad[2]}), closest_point_on_triangle(Y[k], X[0], X[1], X[2]) - Y[k]))
        continue;
      RigidVertexFaceQuery q{motion, /*vertex_on_body=*/false, obs_face[k], god_face, from, end()};
      ccd_rigid_vertex_face(q, settings->narrow, ws, &r);
      consider(r, {PairKind::kObstacleVertexGodFace, obstacle, gf, -1, of, k});
    }
    for (int k = 0; k < 3; ++k) {
      if (!(go & (8u << k))) continue;
      for (int j = 0; j < 3; ++j) {
        if (!(oo & (8u << j)) || !(u0 <= end()) ||
            !overlap(god_edge_swept[k], inflate(box_of(obs_face[j], obs_face[(j + 1) % 3]), margin)))
          continue;
        pose_god_face();
        const int k1 = (k + 1) % 3, j1 = (j + 1) % 3;
        const Vec3 A[3] = {X[k], X[k1], X[k1]}, B[3] = {Y[j], Y[j1], Y[j1]};
        double s = 0, t = 0;
        closest_segment_parameters(X[k], X[k1], Y[j], Y[j1], &s, &t);
        if (apart(A, B, std::max(rad[k], rad[k1]), (X[k] + s * (X[k1] - X[k])) - (Y[j] + t * (Y[j1] - Y[j])))) continue;
        RigidEdgeEdgeQuery q{motion, {god_face[k], god_face[(k + 1) % 3]}, {obs_face[j], obs_face[(j + 1) % 3]},
                             from, end()};
        ccd_rigid_edge_edge(q, settings->narrow, ws, &r);
        consider(r, {PairKind::kEdgeEdge, obstacle, gf, k, of, j});
      }
    }
  }
};

}  // namespace

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
      if (searched(cand[c].god_face, cand[c].obstacle_face, cand[c].obstacle)) continue;
      const CcdBody& ob = obstacles[cand[c].obstacle];
      tester.test(*god.mesh, *god.bvh, cand[c].god_face, *ob.mesh, *ob.bvh, cand[c].obstacle_face,
                  cand[c].obstacle);
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
        cand[num_cand++] = {t, c.god_face, c.obstacle_face, c.obstacle};  // fits: the cache has cand's capacity
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
        cand[num_cand++] = {t, gf, of, o};
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
