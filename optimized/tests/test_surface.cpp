// Tests of the surface properties (surface.h): shading normals with a crease
// angle (a faceted cylinder's sides smooth, its rims and a box's corners sharp),
// the shading rows of a contact, the textures' height fields against their
// gradients, and the texture's sampling bound.
#include <catch2/catch.hpp>

#include <cmath>

#include "gauss6/contact/surface.h"
#include "mesh_shapes.h"

using namespace gauss6;

namespace {

TriangleMesh with_adjacency(TriangleMesh m) {
  build_adjacency(&m);
  return m;
}

constexpr double kDeg = M_PI / 180;

}  // namespace

TEST_CASE("surface: shading normals keep a box's corners and round a prism's sides", "[surface]") {
  // Box: every dihedral is 90 degrees, above a 45-degree crease: every corner
  // normal is its face's normal and no vertex or edge is smooth.
  const TriangleMesh box = with_adjacency(test::make_box(1, 1, 1));
  const ObstacleShading b = build_obstacle_shading(box, 45 * kDeg);
  for (int f = 0; f < num_triangles(box); ++f)
    for (int k = 0; k < 3; ++k) CHECK((b.corner_normals[3 * f + k] - face_normal(box, f)).norm() <= 1e-15);
  for (uint8_t s : b.smooth_vertex) CHECK(s == 0);
  // Its 12 edges (90 degrees) are sharp; the 6 diagonals that split its faces are flat: smooth.
  int box_smooth = 0;
  for (int e = 0; e < static_cast<int>(b.smooth_edge.size()); ++e) {
    const int f = box.adjacency.EF(e, 0), g = box.adjacency.EF(e, 1);
    CHECK(b.smooth_edge[e] == (face_normal(box, f).dot(face_normal(box, g)) > 0.5 ? 1 : 0));
    box_smooth += b.smooth_edge[e];
  }
  CHECK(box_smooth == 6);
  // The same box with a crease of 180 degrees: every edge smooth.
  const ObstacleShading soft = build_obstacle_shading(box, 180 * kDeg);
  for (uint8_t s : soft.smooth_edge) CHECK(s == 1);

  // 12-gon prism (axis z): the sides meet at 30 degrees (smooth), the caps at 90
  // (sharp). A side face's corner normal at a ring vertex is the radial
  // direction (the two sides' normals, equal angles), within rounding.
  const int n = 12;
  const TriangleMesh prism = with_adjacency(test::make_prism(n, 0.03, 0.08));
  const ObstacleShading p = build_obstacle_shading(prism, 45 * kDeg);
  int checked = 0;
  for (int f = 0; f < num_triangles(prism); ++f) {
    if (std::abs(face_normal(prism, f).z()) > 0.5) continue;  // a cap
    for (int k = 0; k < 3; ++k) {
      const Vec3 v = prism.V.row(prism.F(f, k)).transpose();
      const Vec3 radial = Vec3(v.x(), v.y(), 0).normalized();
      CHECK((p.corner_normals[3 * f + k] - radial).norm() <= 1e-12);
      ++checked;
    }
  }
  CHECK(checked == 3 * 2 * n);
  // Edges: n vertical (30 degrees: smooth), n side diagonals and 2n cap spokes
  // (flat: smooth), 2n rims (90 degrees: sharp).
  int smooth = 0;
  for (size_t e = 0; e < p.smooth_edge.size(); ++e) smooth += p.smooth_edge[e];
  CHECK(p.smooth_edge.size() == static_cast<size_t>(6 * n));
  CHECK(smooth == 4 * n);
}

TEST_CASE("surface: a contact's shading row interpolates the face's corner normals", "[surface]") {
  const int n = 12;
  const TriangleMesh prism = with_adjacency(test::make_prism(n, 0.03, 0.08));
  SurfaceModel surface;
  surface.shading = true;
  surface.obstacles.push_back(build_obstacle_shading(prism, 45 * kDeg));
  // A side face and a god vertex 1e-6 above its centroid.
  int f = 0;
  while (std::abs(face_normal(prism, f).z()) > 0.5) ++f;
  Vec3 centroid = Vec3::Zero(), expected = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    const Vec3 v = prism.V.row(prism.F(f, k)).transpose();
    centroid += v / 3;
    expected += Vec3(v.x(), v.y(), 0).normalized();  // the corner normals are radial (above)
  }
  expected.normalize();
  ContactSet set(4);
  set.num_contacts = 1;
  Contact& c = set.contacts[0];
  c.normal = face_normal(prism, f);
  c.separation = 1e-6;
  c.point = centroid + c.separation * c.normal;
  c.features.kind = PairKind::kGodVertexObstacleFace;
  c.features.obstacle = 0;
  c.features.obstacle_face = f;
  const Vec3 G(0.05, 0.01, 0.02);
  double Js[4 * 6], normals[4][3];
  CHECK(shade_contacts(surface, &prism, set, G, 4, Js, normals) == 0);
  const Vec3 ns(normals[0][0], normals[0][1], normals[0][2]);
  CHECK((ns - expected).norm() <= 1e-12);
  CHECK(ns.dot(c.normal) < 1 - 1e-6);  // not the face's normal: the side is shaded
  const Vec3 torque = (c.point - G).cross(ns);
  for (int i = 0; i < 3; ++i) {
    CHECK(Js[i] == ns[i]);
    CHECK(std::abs(Js[3 + i] - torque[i]) <= 1e-15);
  }
  // Without shading (a texture-free, shading-free model) the true normal is kept.
  SurfaceModel plain;
  shade_contacts(plain, &prism, set, G, 4, Js, normals);
  CHECK(Vec3(normals[0][0], normals[0][1], normals[0][2]) == c.normal);
}

TEST_CASE("surface: a texture's average is weighted by the forces the contacts carry", "[surface]") {
  // Two contacts on the plane z = 0 half a sine wavelength apart (opposite
  // perturbations: their plain average is zero). The command presses on the
  // first (at G) and, turning about y, lifts the second off: only the first
  // carries force, so its perturbation alone tilts every row.
  const double A = 1e-3, L = 0.02;
  SurfaceModel surface;
  surface.texture = true;
  surface.field.kind = TextureKind::kSine;
  surface.field.amplitude = A;
  surface.field.wavelength = L;
  ContactSet set(4);
  set.num_contacts = 2;
  for (int k = 0; k < 2; ++k) {
    Contact& c = set.contacts[k];
    c.normal = Vec3::UnitZ();
    c.separation = 1e-6;
    c.point = Vec3(k * L / 2, 0, c.separation);
    c.features.kind = PairKind::kGodVertexObstacleFace;
    c.features.obstacle = 0;
  }
  const Vec3 G = set.contacts[0].point;
  const Mat6 M = Mat6::Identity();
  ProjectionSettings settings;
  ProjectionWorkspace ws(4);
  ProjectionResult result(4);
  TextureWeighting weighting{&M, Vec6::Zero(), &settings, &ws, &result};
  weighting.au << 0, 0, -1, 0, -4 / L, 0;  // the second point moves by (0, 0, -1 + 2): away
  double Js[4 * 6], normals[4][3];
  const double slope = 2 * M_PI * A / L;  // |grad h| at the first contact (x = 0), -grad h = -slope x
  CHECK(std::abs(shade_contacts(surface, nullptr, set, G, 4, Js, normals, &weighting) - slope) <= 1e-12);
  CHECK(result.lambda[0] > 0);
  CHECK(result.lambda[1] == 0);
  const Vec3 tilted = Vec3(-slope, 0, 1).normalized();
  for (int k = 0; k < 2; ++k) {
    CHECK((Vec3(normals[k][0], normals[k][1], normals[k][2]) - tilted).norm() <= 1e-12);
    CHECK(Js[6 * k + 2] == normals[k][2]);
  }
  // The plain average (no command, or one that presses on neither): zero, the true normals.
  CHECK(shade_contacts(surface, nullptr, set, G, 4, Js, normals) <= 1e-12);
  CHECK((Vec3(normals[1][0], normals[1][1], normals[1][2]) - Vec3::UnitZ()).norm() <= 1e-12);
  weighting.au << 0, 0, 1, 0, 0, 0;  // pulling away: no contact carries force
  CHECK(shade_contacts(surface, nullptr, set, G, 4, Js, normals, &weighting) <= 1e-12);
}

TEST_CASE("surface: textures' gradients match their height fields, the sampling bound", "[surface]") {
  TextureField t;
  t.amplitude = 0.0008;  // scene units: 0.8 mm bumps of 1 cm
  t.wavelength = 0.01;
  t.u = Vec3::UnitX();
  t.v = Vec3::UnitY();
  t.origin = Vec3(0.001, 0, 0);
  const float image[12] = {0.f, 0.25f, 1.f, 0.5f, 0.75f, 0.f, 0.1f, 0.9f, 0.3f, 0.6f, 0.2f, 0.4f};
  // Central differences, step 1e-7 L: truncation about (1e-7)^2 of the
  // curvature, so 1e-6 of the steepest slope holds with room.
  for (TextureKind kind : {TextureKind::kSine, TextureKind::kBumps, TextureKind::kHeightMap}) {
    t.kind = kind;
    if (kind == TextureKind::kHeightMap) t.width = 4, t.height = 3, t.values = image;
    const double h = 1e-7 * t.wavelength;
    const double slope = t.amplitude * texture_slope_per_amplitude(kind, t.wavelength, t.width);
    // Points inside pixels for the height map (its pitch is L / 4): 1/3 and 2/3 of a pixel.
    for (const Vec3 x : {Vec3(0.001 + 0.0025 / 3, 0.0025 * 2 / 3, 0.0), Vec3(0.0043, 0.0071, 0.002),
                         Vec3(-0.0121, 0.0033, -0.01)}) {
      const Vec3 g = texture_gradient(t, x);
      for (int i = 0; i < 3; ++i) {
        const Vec3 e = Vec3::Unit(i) * h;
        const double fd = (texture_height(t, x + e) - texture_height(t, x - e)) / (2 * h);
        CHECK(std::abs(fd - g[i]) <= 1e-6 * slope);
      }
      CHECK(g.norm() <= std::sqrt(2.0) * slope * (1 + 1e-12));
    }
  }
  // Sine: h = A sin(2 pi (x - x0) / L), steepest slope 2 pi A / L at the origin; height A a quarter
  // wavelength on.
  t.kind = TextureKind::kSine;
  CHECK(std::abs(texture_gradient(t, t.origin).x() - 2 * 3.14159265358979323846 * t.amplitude / t.wavelength) <= 1e-15);
  CHECK(std::abs(texture_height(t, t.origin + Vec3(t.wavelength / 4, 0, 0)) - t.amplitude) <= 1e-18);
  // Bumps: height A at a cell's centre.
  t.kind = TextureKind::kBumps;
  CHECK(std::abs(texture_height(t, t.origin + Vec3(t.wavelength / 2, t.wavelength / 2, 0)) - t.amplitude) <= 1e-18);
  CHECK(shortest_wavelength(t) == t.wavelength);
  t.kind = TextureKind::kHeightMap;
  CHECK(shortest_wavelength(t) == 2 * t.wavelength / 4);
  // Nyquist: half a wavelength per update at most.
  CHECK(max_texture_speed(0.01, 50) == 0.25);
  CHECK(shortest_felt_wavelength(0.25, 50) == 0.01);
}
