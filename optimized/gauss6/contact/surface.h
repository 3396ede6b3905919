// Surface properties (METHOD.md section 6): force shading and textures. The
// model (shading normals per obstacle face corner, the texture's height field)
// is built once from a Scene; shade_contacts() turns a contact set into the
// shading constraint space Js, the rows the coupling loop projects on (pass 1:
// asc = projection of au under Js, Fc = kh M (asc - au)) while the sim loop
// still moves the god-object under the true rows J (pass 2: ac = projection of
// asc under J), so that the god-object never penetrates (property 7).
//
// Shading normals (per obstacle, world frame): for face f and its corner k, the
// normal of vertex F(f, k) as seen from f: the angle-weighted sum of the face
// normals of the vertex's faces whose normal is within the obstacle's crease
// angle of f's, normalised. An edge whose dihedral angle is above the crease
// angle stays sharp, so a faceted cylinder feels round while the corners of a
// box stay corners. The rule per contact kind (contacts.h's conventions):
//   - god vertex / obstacle face: the barycentric interpolation of the face's
//     corner normals at the god vertex's projection on the face (clamped to it);
//   - edge / edge: on a smooth obstacle edge (dihedral within the crease angle)
//     the interpolation along the edge of its end normals (each the normalised
//     sum of the two faces' corner normals there); on a sharp edge the true
//     normal: a crease stays a crease;
//   - obstacle vertex / god face: the vertex's own normal when the vertex is
//     smooth (all its faces within the crease angle of one another), else the
//     true normal (the god face's): a corner stays a corner.
// A shading normal that leans more than 60 degrees from the true normal
// (cosine < kMinShadingCosine) is replaced by the true normal.
//
// Textures (bump mapping of the force direction): a height field h over the
// world (the paper's sine along an axis, a grid of bumps, or a height-map image
// tiled over the plane of two axes, the point projected along the third), of
// amplitude A and wavelength L in scene units: h = A sin(2 pi u / L) (bumps and
// holes, steepest slope 2 pi A / L); h = A s(u) s(v), s(x) = (1 - cos(2 pi x /
// L)) / 2 (round bumps of height A, steepest slope pi A / L); h = A times the
// image (in [0, 1]) tiled with pitch L / width (a step of 1 between neighbouring
// pixels is a slope A width / L). At each contact, the
// perturbation g_k = -(grad h)_t, the gradient's part in the contact's tangent
// plane, with |g_k| clamped to kMaxTextureSlope; g = the average of the g_k
// over the contacts (several contacts: the perturbations are averaged, section
// 6.2), and every row's normal becomes normalize(n_k + g - (g . n_k) n_k).
// Shading and texture combine: the texture perturbs the shading normals.
//
// The average is weighted by the force each contact carries: w_k = lambda_k /
// sum lambda, the multipliers of the command au projected under the untextured
// rows (the shading rows, or the true ones), at the pose the rows are built
// for (TextureWeighting). A plain average let contacts that carry no force
// tilt it: on the textured Figure 8 cylinder the probe lies on a facet with its
// tip and a second vertex half a wavelength apart (opposite perturbations,
// average 0); when it rolls off the second vertex, that contact (no force: the
// probe moves away from it) left the set and the average jumped to the tip's
// own perturbation, turning the force by 25 degrees in one tick. A contact
// leaves the set or joins it with a multiplier near zero (it carries no force
// when the god-object moves away from it, and little when the command has
// only just reached it), so the weighted average moves as continuously as the
// force does; with equal forces it is the plain average. Without a command
// (weighting null), or when no contact carries force, the plain average.
//
// Real time: shade_contacts() and the texture functions allocate nothing, lock
// nothing and throw nothing.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gauss6/contact/contacts.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/contact/quasistatics.h"

namespace gauss6 {

// The surface settings a scene gives (docs/scene-format.md, [surface]).
enum class SurfaceKind { kNone, kForceShading, kTexture };
enum class TextureKind { kSine, kBumps, kHeightMap };
const char* to_string(SurfaceKind k);
const char* to_string(TextureKind k);

// A grey height-map image (texture = height_map), values in [0, 1], row 0 at v = 0.
struct HeightMapImage {
  std::string path;        // as resolved
  int width = 0, height = 0;
  std::vector<float> values;  // width * height, row-major
};

struct SurfaceSettings {
  SurfaceKind kind = SurfaceKind::kNone;
  bool shading = false;    // texture: on force-shaded normals too (kind = force_shading: always)
  TextureKind texture = TextureKind::kSine;  // texture: sine along axis, a grid of bumps, a height map
  double amplitude = 0;    // texture: the height field's amplitude, scene units (surface.h: sine A sin, bumps of
                           // height A, height map A times the image); version 1 files' slope is converted at load
  double wavelength = 0;   // texture: period along the axes (scene units; height map: the image's width)
  int axis = 0;            // texture: the u axis, 0 = x, 1 = y, 2 = z
  int axis_v = 1;          // texture bumps / height map: the v axis (not axis)
  Vec3 origin = Vec3::Zero();  // texture: the point of phase 0 (scene units, world frame)
  HeightMapImage height_map;   // texture = height_map: the image
};

inline constexpr double kMinShadingCosine = 0.5;  // shading normal within 60 degrees of the true one
inline constexpr double kMaxTextureSlope = 1.0;   // |grad h| clamp: the force tilts by at most 45 degrees

// Shading normals of one obstacle, world frame.
struct ObstacleShading {
  std::vector<Vec3> corner_normals;     // 3 #F: corner k of face f at 3 f + k
  std::vector<Vec3> vertex_normals;     // #V: angle-weighted over all faces
  std::vector<uint8_t> smooth_vertex;   // #V: 1 when all the vertex's faces are within the crease angle
  std::vector<uint8_t> smooth_edge;     // #E (adjacency numbering): 1 when the dihedral is within it
};

// The texture's height field, world frame (scene.h's TextureSettings resolved).
struct TextureField {
  TextureKind kind = TextureKind::kSine;
  double amplitude = 0;                 // A, scene units
  double wavelength = 0;                // L, scene units (height map: the image's width)
  Vec3 u = Vec3::UnitX(), v = Vec3::UnitY();  // the axes (unit); sine uses u only
  Vec3 origin = Vec3::Zero();
  int width = 0, height = 0;            // height map: pixels
  const float* values = nullptr;        // height map: row-major, in [0, 1] (the Scene's image)
};

// The surface model, built once (RuntimeModel::surface). Movable, not
// copyable: field.values points into height_values (a move keeps the buffer).
struct SurfaceModel {
  SurfaceModel() = default;
  SurfaceModel(SurfaceModel&&) = default;
  SurfaceModel& operator=(SurfaceModel&&) = default;
  SurfaceModel(const SurfaceModel&) = delete;
  SurfaceModel& operator=(const SurfaceModel&) = delete;
  bool shading = false;
  bool texture = false;
  std::vector<ObstacleShading> obstacles;  // filled when shading
  TextureField field;
  std::vector<float> height_values;        // the height map's values (field.values)
  bool active() const { return shading || texture; }
};

// Builds the shading normals of a world-frame mesh (adjacency built) with a
// crease angle in radians; `given` (#V by 3, unit) replaces the computed
// vertex normals when it has a row per vertex (normals from the mesh file: then
// every corner takes its vertex's given normal and every vertex and edge is smooth).
ObstacleShading build_obstacle_shading(const TriangleMesh& mesh_W, double crease_angle, const MatrixX3d& given = {});


// h(x) and grad h(x) (world frame) of the texture at a world point.
double texture_height(const TextureField& t, const Vec3& x) noexcept;
Vec3 texture_gradient(const TextureField& t, const Vec3& x) noexcept;
// The texture's steepest slope per unit of amplitude (1 / scene units): 2 pi / L
// for the sine, pi / L for the bumps, width / L for a height map (0 when L or
// the width is not positive). A texture's steepest slope is A times it.
double texture_slope_per_amplitude(TextureKind kind, double wavelength, int width) noexcept;
// The texture's shortest wavelength (scene units): L for the sine and the
// bumps, two pixels for a height map.
double shortest_wavelength(const TextureField& t) noexcept;
// The largest distance a contact point of `set` (at the pose (p, R), its first
// `capacity` contacts) moved from the pose (p_start, R_start), the rotations
// rotation_matrix of the poses' q: how far a textured contact slid in one sim
// step (beyond half the shortest wavelength the texture is undersampled at
// this speed, max_texture_speed).
double contact_travel(const ContactSet& set, int capacity, const Vec3& p_start, const Mat3& R_start, const Vec3& p,
                      const Mat3& R) noexcept;
// The sampling bound of the method (METHOD.md 6.2): a texture is felt only if
// the contact point moves less than half its shortest wavelength per constraint
// update (Nyquist). Fastest exploration speed v = L_min f / 2 at update rate f
// (Hz); shortest wavelength felt at speed v: 2 v / f.
inline double max_texture_speed(double shortest_wavelength, double update_hz) {
  return 0.5 * shortest_wavelength * update_hz;
}
inline double shortest_felt_wavelength(double speed, double update_hz) { return 2 * speed / update_hz; }

// What weights a texture's average (the top of this file): the command au at
// the pose the rows are built for, the mass matrix there, and the projection's
// settings and buffers (at least the set's rows; a cold start: the rows are new
// with each contact set).
struct TextureWeighting {
  const Mat6* M = nullptr;
  Vec6 au = Vec6::Zero();
  const ProjectionSettings* settings = nullptr;
  ProjectionWorkspace* workspace = nullptr;
  ProjectionResult* result = nullptr;
};

// The shading rows of a contact set at the god-object's reference point G:
// Js (m x 6 row-major, m = set.num_contacts <= capacity) and the shaded unit
// normals (m). obstacles_W: the world-frame meshes the set's features index.
// Without shading the normals are the true ones; with a texture they are
// perturbed by the average of the contacts' perturbations, weighted as
// `weighting` says (null: the plain average). Returns the averaged texture
// perturbation's norm (0 without one).
double shade_contacts(const SurfaceModel& surface, const TriangleMesh* obstacles_W, const ContactSet& set,
                      const Vec3& G, int capacity, double* Js, double (*normals)[3],
                      const TextureWeighting* weighting = nullptr) noexcept;

}  // namespace gauss6
