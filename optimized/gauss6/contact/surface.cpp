// Surface properties (surface.h): shading normals built once per obstacle,
// the texture's height fields, and the shading rows Js of a contact set.
#include "gauss6/contact/surface.h"

#include <algorithm>
#include <cmath>

namespace gauss6 {

const char* to_string(TextureKind k) {
  switch (k) {
    case TextureKind::kSine: return "sine";
    case TextureKind::kBumps: return "bumps";
    case TextureKind::kHeightMap: return "height_map";
  }
  return "unknown";
}

const char* to_string(SurfaceKind k) {
  switch (k) {
    case SurfaceKind::kNone: return "none";
    case SurfaceKind::kForceShading: return "force_shading";
    case SurfaceKind::kTexture: return "texture";
  }
  return "unknown";
}

namespace {

// Angle of triangle f at its corner k.
double corner_angle(const TriangleMesh& m, int f, int k) {
  const Vec3 a = m.V.row(m.F(f, k)).transpose();
  const Vec3 b = m.V.row(m.F(f, (k + 1) % 3)).transpose();
  const Vec3 c = m.V.row(m.F(f, (k + 2) % 3)).transpose();
  const Vec3 u = b - a, v = c - a;
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

// Row k of Js (normal n at lever r from G) and its normal.
void write_row(const Vec3& n, const Vec3& r, int k, double* Js, double (*normals)[3]) {
  const Vec3 t = r.cross(n);
  for (int i = 0; i < 3; ++i) {
    normals[k][i] = n[i];
    Js[6 * k + i] = n[i];
    Js[6 * k + 3 + i] = t[i];
  }
}

Vec3 normalized_or(const Vec3& v, const Vec3& fallback) {
  const double n = v.norm();
  return n > 0 && std::isfinite(n) ? Vec3(v / n) : fallback;
}

// The shading normal a contact's features give (surface.h's rules), before the texture.
Vec3 contact_shading_normal(const ObstacleShading& sh, const TriangleMesh& m, const Contact& c) {
  const FeaturePair& fp = c.features;
  const int f = fp.obstacle_face;
  switch (fp.kind) {
    case PairKind::kGodVertexObstacleFace: {
      // Barycentrics of the god vertex's projection on the face, clamped to it.
      const Vec3 a = m.V.row(m.F(f, 0)).transpose(), b = m.V.row(m.F(f, 1)).transpose(),
                 cc = m.V.row(m.F(f, 2)).transpose();
      const Vec3 n = (b - a).cross(cc - a);
      const double nn = n.squaredNorm();
      if (!(nn > 0)) return c.normal;
      const Vec3 p = c.point;
      double w[3] = {(cc - b).cross(p - b).dot(n) / nn, (a - cc).cross(p - cc).dot(n) / nn, 0};
      w[2] = 1 - w[0] - w[1];
      double sum = 0;
      for (double& x : w) sum += (x = std::max(x, 0.0));
      if (!(sum > 0)) return c.normal;
      Vec3 s = Vec3::Zero();
      for (int k = 0; k < 3; ++k) s += (w[k] / sum) * sh.corner_normals[3 * f + k];
      return normalized_or(s, c.normal);
    }
    case PairKind::kEdgeEdge: {
      const int k = fp.obstacle_corner;
      const int e = m.adjacency.FE.rows() > f ? m.adjacency.FE(f, k) : -1;
      if (e < 0 || !sh.smooth_edge[e]) return c.normal;  // a sharp edge stays sharp
      // The end normals: both faces' corner normals at each end, summed.
      const int va = m.F(f, k), vb = m.F(f, (k + 1) % 3);
      Vec3 na = Vec3::Zero(), nb = Vec3::Zero();
      for (int side = 0; side < 2; ++side) {
        const int g = m.adjacency.EF(e, side);
        if (g < 0) continue;
        for (int j = 0; j < 3; ++j) {
          if (m.F(g, j) == va) na += sh.corner_normals[3 * g + j];
          if (m.F(g, j) == vb) nb += sh.corner_normals[3 * g + j];
        }
      }
      const Vec3 a = m.V.row(va).transpose(), b = m.V.row(vb).transpose();
      const Vec3 ab = b - a;
      const double t = std::clamp((c.point - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
      return normalized_or((1 - t) * normalized_or(na, c.normal) + t * normalized_or(nb, c.normal), c.normal);
    }
    case PairKind::kObstacleVertexGodFace: {
      const int v = m.F(f, fp.obstacle_corner);
      return sh.smooth_vertex[v] ? sh.vertex_normals[v] : c.normal;  // a corner stays a corner
    }
  }
  return c.normal;
}

// Height-map value at pixel coordinates (x, y), tiled, bilinear; and its gradient in pixels.
double height_map_at(const TextureField& t, double x, double y, double* dx, double* dy) {
  const double fx = std::floor(x), fy = std::floor(y);
  const double ax = x - fx, ay = y - fy;
  auto wrap = [](long i, int n) { return static_cast<int>(((i % n) + n) % n); };
  const long ix = static_cast<long>(fx), iy = static_cast<long>(fy);
  const int x0 = wrap(ix, t.width), x1 = wrap(ix + 1, t.width);
  const int y0 = wrap(iy, t.height), y1 = wrap(iy + 1, t.height);
  const double h00 = t.values[y0 * t.width + x0], h10 = t.values[y0 * t.width + x1];
  const double h01 = t.values[y1 * t.width + x0], h11 = t.values[y1 * t.width + x1];
  *dx = (1 - ay) * (h10 - h00) + ay * (h11 - h01);
  *dy = (1 - ax) * (h01 - h00) + ax * (h11 - h10);
  return (1 - ay) * ((1 - ax) * h00 + ax * h10) + ay * ((1 - ax) * h01 + ax * h11);
}

// h and dh/du, dh/dv at plane coordinates (su, sv), scene units.
double field_at(const TextureField& t, double su, double sv, double* du, double* dv) {
  const double L = t.wavelength, A = t.amplitude;
  switch (t.kind) {
    case TextureKind::kSine: {
      // h = A sin(2 pi su / L): bumps and holes of height A; steepest slope 2 pi A / L.
      const double w = 2 * kPi / L;
      *du = A * w * std::cos(w * su);
      *dv = 0;
      return A * std::sin(w * su);
    }
    case TextureKind::kBumps: {
      // h = A s(su) s(sv), s(x) = (1 - cos(2 pi x / L)) / 2: a grid of round bumps of
      // period L and height A, zero on the grid lines; steepest slope pi A / L.
      const double w = 2 * kPi / L;
      const double s_u = 0.5 * (1 - std::cos(w * su)), s_v = 0.5 * (1 - std::cos(w * sv));
      const double ds_u = 0.5 * w * std::sin(w * su), ds_v = 0.5 * w * std::sin(w * sv);
      *du = A * ds_u * s_v;
      *dv = A * s_u * ds_v;
      return A * s_u * s_v;
    }
    case TextureKind::kHeightMap: {
      // The image tiles the plane, pixel pitch L / width; h = A image: a step of
      // 1 between neighbouring pixels is a slope A / pitch.
      if (t.values == nullptr || t.width < 2 || t.height < 2) return *du = *dv = 0;
      const double pitch = L / t.width;
      double dx, dy;
      const double h = height_map_at(t, su / pitch, sv / pitch, &dx, &dy);
      *du = A * dx / pitch;
      *dv = A * dy / pitch;
      return A * h;
    }
  }
  return *du = *dv = 0;
}

}  // namespace

ObstacleShading build_obstacle_shading(const TriangleMesh& m, double crease_angle, const MatrixX3d& given) {
  const int nf = num_triangles(m), nv = num_vertices(m);
  ObstacleShading sh;
  std::vector<Vec3> fn(static_cast<size_t>(nf));
  for (int f = 0; f < nf; ++f) fn[f] = face_normal(m, f);
  const double cos_crease = std::cos(std::clamp(crease_angle, 0.0, kPi));
  const bool has_given = given.rows() == nv && nv > 0;
  // Vertex -> faces (CSR): from the adjacency when built, else counted here.
  std::vector<int32_t> start(static_cast<size_t>(nv) + 1, 0), faces(static_cast<size_t>(3 * nf));
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) ++start[m.F(f, k) + 1];
  for (int v = 0; v < nv; ++v) start[v + 1] += start[v];
  {
    std::vector<int32_t> fill(start.begin(), start.end() - 1);
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) faces[fill[m.F(f, k)]++] = f;
  }
  // Per vertex: all faces' normal (angle-weighted), and whether all its faces are within the crease.
  sh.vertex_normals.assign(static_cast<size_t>(nv), Vec3::Zero());
  sh.smooth_vertex.assign(static_cast<size_t>(nv), 1);
  for (int v = 0; v < nv; ++v) {
    Vec3 s = Vec3::Zero();
    for (int i = start[v]; i < start[v + 1]; ++i) {
      const int f = faces[i];
      for (int k = 0; k < 3; ++k)
        if (m.F(f, k) == v) s += corner_angle(m, f, k) * fn[f];
      for (int j = start[v]; j < start[v + 1]; ++j)
        if (fn[f].dot(fn[faces[j]]) < cos_crease) sh.smooth_vertex[v] = 0;
    }
    sh.vertex_normals[v] = has_given ? normalized_or(given.row(v).transpose(), s) : normalized_or(s, Vec3::Zero());
    if (has_given) sh.smooth_vertex[v] = 1;
  }
  // Per corner: the faces of the vertex within the crease angle of this face.
  sh.corner_normals.assign(static_cast<size_t>(3 * nf), Vec3::Zero());
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int v = m.F(f, k);
      if (has_given) {
        sh.corner_normals[3 * f + k] = sh.vertex_normals[v];
        continue;
      }
      Vec3 s = Vec3::Zero();
      for (int i = start[v]; i < start[v + 1]; ++i) {
        const int g = faces[i];
        if (g != f && fn[f].dot(fn[g]) < cos_crease) continue;
        for (int j = 0; j < 3; ++j)
          if (m.F(g, j) == v) s += corner_angle(m, g, j) * fn[g];
      }
      sh.corner_normals[3 * f + k] = normalized_or(s, fn[f]);
    }
  }
  // Per edge: smooth when its two faces are within the crease angle.
  const int ne = static_cast<int>(m.adjacency.E.rows());
  sh.smooth_edge.assign(static_cast<size_t>(ne), 0);
  for (int e = 0; e < ne; ++e) {
    const int f = m.adjacency.EF(e, 0), g = m.adjacency.EF(e, 1);
    if (f >= 0 && g >= 0 && m.adjacency.edge_face_count[e] == 2)
      sh.smooth_edge[e] = has_given || fn[f].dot(fn[g]) >= cos_crease;
  }
  return sh;
}

double texture_height(const TextureField& t, const Vec3& x) noexcept {
  double du, dv;
  const Vec3 r = x - t.origin;
  return field_at(t, r.dot(t.u), r.dot(t.v), &du, &dv);
}

Vec3 texture_gradient(const TextureField& t, const Vec3& x) noexcept {
  double du, dv;
  const Vec3 r = x - t.origin;
  field_at(t, r.dot(t.u), r.dot(t.v), &du, &dv);
  return du * t.u + dv * t.v;
}

double texture_slope_per_amplitude(TextureKind kind, double wavelength, int width) noexcept {
  if (!(wavelength > 0)) return 0;
  switch (kind) {
    case TextureKind::kSine: return 2 * kPi / wavelength;
    case TextureKind::kBumps: return kPi / wavelength;
    case TextureKind::kHeightMap: return width > 0 ? width / wavelength : 0;
  }
  return 0;
}

double shortest_wavelength(const TextureField& t) noexcept {
  if (t.kind == TextureKind::kHeightMap && t.width > 0) return 2 * t.wavelength / t.width;
  return t.wavelength;
}

double shade_contacts(const SurfaceModel& surface, const TriangleMesh* obstacles_W, const ContactSet& set,
                      const Vec3& G, int capacity, double* Js, double (*normals)[3],
                      const TextureWeighting* weighting) noexcept {
  const int m = std::min(set.num_contacts, capacity);
  // The untextured rows: shading normals (the true normals without shading).
  for (int k = 0; k < m; ++k) {
    const Contact& c = set.contacts[k];
    Vec3 n = c.normal;
    const int o = c.features.obstacle;
    if (surface.shading && o >= 0 && o < static_cast<int>(surface.obstacles.size())) {
      const Vec3 s = contact_shading_normal(surface.obstacles[o], obstacles_W[o], c);
      if (s.allFinite() && s.dot(c.normal) >= kMinShadingCosine) n = s;
    }
    write_row(n, set.contacts[k].point - G, k, Js, normals);
  }
  if (!surface.texture || m == 0) return 0;
  // The weights: each contact's share of the force the untextured rows give the command.
  const double* lambda = nullptr;
  double total = 0;
  if (weighting != nullptr && weighting->M != nullptr && weighting->settings != nullptr &&
      weighting->workspace != nullptr && weighting->result != nullptr && weighting->result->max_rows() >= m &&
      weighting->workspace->max_rows() >= m) {
    ProjectionProblem problem;
    problem.M = weighting->M;
    problem.au = weighting->au;
    problem.J = Js;
    problem.num_rows = m;
    ProjectionSettings cold = *weighting->settings;  // the rows are new with each contact set
    cold.warm_start = false;
    if (project(problem, cold, weighting->workspace, weighting->result) == ProjectionStatus::kOptimal) {
      lambda = weighting->result->lambda.data();
      for (int k = 0; k < m; ++k) total += std::max(lambda[k], 0.0);
      if (!(total > 0 && std::isfinite(total))) lambda = nullptr;
    }
  }
  // The averaged perturbation: each contact's g_k at its obstacle point (I_k less the
  // separation along the true normal), in its tangent plane, clamped.
  Vec3 g = Vec3::Zero();
  for (int k = 0; k < m; ++k) {
    const Contact& c = set.contacts[k];
    const Vec3 n(normals[k][0], normals[k][1], normals[k][2]);
    Vec3 grad = texture_gradient(surface.field, c.point - c.separation * c.normal);
    grad -= grad.dot(n) * n;
    const double len = grad.norm();
    if (len > kMaxTextureSlope) grad *= kMaxTextureSlope / len;
    const double w = lambda != nullptr ? std::max(lambda[k], 0.0) / total : 1.0 / m;
    if (grad.allFinite()) g -= w * grad;
  }
  for (int k = 0; k < m; ++k) {
    const Vec3 n(normals[k][0], normals[k][1], normals[k][2]);
    write_row(normalized_or(n + g - g.dot(n) * n, n), set.contacts[k].point - G, k, Js, normals);
  }
  return g.norm();
}

double contact_travel(const ContactSet& set, int capacity, const Vec3& p_start, const Mat3& R_start, const Vec3& p,
                      const Mat3& R) noexcept {
  const Mat3 R01 = R_start * R.transpose();
  double travel = 0;
  for (int k = 0; k < std::min(set.num_contacts, capacity); ++k) {
    const Vec3& I = set.contacts[k].point;
    const Vec3 before = p_start + R01 * (I - p);  // the same body point at the start pose
    travel = std::max(travel, (I - before).norm());
  }
  return travel;
}

}  // namespace gauss6
