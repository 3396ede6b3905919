// The scene: an immutable model built once from a TOML file (docs/scene-format.md)
// and shared read-only by every loop (MuJoCo's mjModel). Loading validates every
// key and value, reads and validates the meshes, and computes the god-object's
// mass properties once. Errors are SceneError exceptions (load_error.h; load time
// only) whose message names the file, line, column and key.
#pragma once

#include <string>
#include <vector>

#include "gauss6/io/load_error.h"
#include "gauss6/geometry/mass_properties.h"
#include "gauss6/geometry/mesh.h"
#include "gauss6/contact/surface.h"
#include "gauss6/geometry/pose.h"

namespace gauss6 {

inline constexpr int kSceneFormatVersion = 2;        // what this build writes and documents
inline constexpr int kOldestSceneFormatVersion = 1;  // the oldest it reads (docs/scene-format.md, Versions)

enum class BodyRole { kObstacle, kGodObject };
enum class DeviceKind { kSimulated, kReplay, kHid };
const char* to_string(BodyRole r);
const char* to_string(DeviceKind k);

struct Body {
  std::string name;
  BodyRole role = BodyRole::kObstacle;
  std::string mesh_path;   // as resolved (absolute or relative to the working directory)
  TriangleMesh mesh;       // body frame B: origin at the reference point G (god-object),
                           // or the mesh's own frame (obstacles)
  Pose pose;               // X_WB: obstacles' fixed pose; the god-object's initial pose of G
  MeshReport report;       // validation at load (self-intersections not checked: -1)
  double crease_angle = 45;  // obstacles, degrees in [0, 180]: force shading keeps an edge whose
                             // dihedral angle is above this sharp (0: flat; 180: every edge smooth)
  MatrixX3d given_normals; // obstacles: unit vertex normals from the mesh file (empty: none given)
};

struct GodObjectMass {
  bool from_density = true;
  double density = 0;      // when from_density
  MassProperties mass;     // body frame B (centre of mass relative to G; inertia about the COM)
  Vec3 mesh_to_body = Vec3::Zero();  // r_B = r_mesh - mesh_to_body (G in the mesh's frame)
};

struct Gains {
  double ks = 0.5;   // au = ks (xh (-) xs)
  double kh = 0;     // Fc = kh M (ac - au)
};

// The defaults of the scene file's optional keys are stated once, here: as the
// default values of the settings structs below (a default-constructed struct holds
// them), and for offset_eps, which is relative to delta, as a factor. The loader
// takes them from here and so do the Python bindings (gauss6.defaults()).
inline constexpr double kDefaultOffsetEpsPerDelta = -10;  // contact.offset_eps = -10 delta

struct ContactParameters {
  double delta = 0;           // separation kept before contact (scene units); required
  double offset_eps = 0;      // new rows with J_k au < offset_eps are offset (< 0);
                              // the loader's default is kDefaultOffsetEpsPerDelta * delta
  double offset_time = 0.05;  // time T of an offset's return to 0 (s)
};

struct DeviceSettings {
  DeviceKind kind = DeviceKind::kSimulated;  // required in a scene file
  double rate_hz = 1000;   // Hz
  double max_force = 20;   // N: force clamp
  double max_torque = 1;   // N m: torque clamp
  std::string script;      // simulated: scripted hand trajectory's name or .json file (empty: script_json)
  std::string script_json; // simulated: the hand script given in the scene ([device.script] table), as JSON
  std::string trace;       // replay: trace file (resolved)
  int vendor_id = -1, product_id = -1;  // hid: -1 = any
  std::string serial, path;             // hid: empty = any
};

struct Scene {
  std::string path;        // the scene file
  std::string name;
  int version = kSceneFormatVersion;
  std::vector<Body> obstacles;
  Body god_object;
  GodObjectMass god_mass;
  Gains gains;
  ContactParameters contact;
  SurfaceSettings surface;
  DeviceSettings device;
  // What the loader repaired, one line each ("obstacle[0].mesh: box.off: closed but
  // inside out (signed volume -0.001): faces flipped"). Empty for a clean scene.
  std::vector<std::string> warnings;
};

// The rules a scene's settings must meet (docs/scene-format.md, "Rules"), stated
// once (gauss6/io/scene_rules.cpp, in the core): the loader applies them and names the
// file, line and key; the runtime model (runtime_model.h) applies them to any
// Scene, one built in code included. Each check returns the first broken rule, or an
// empty problem when every rule holds. NaN and infinities break every rule.
struct SettingsProblem {
  std::string table;    // the scene file's table ("gains"); empty when the rules hold
  std::string key;      // the key in that table ("kh")
  std::string problem;  // "must be > 0"
  explicit operator bool() const { return !key.empty(); }
  std::string message() const { return table + "." + key + ": " + problem; }  // "gains.kh: must be > 0"
};
// Coordinates (positions, mesh vertices, in the world frame too) beyond this are
// refused: the CCD's pair tests refuse coordinates beyond 1e30 (kMaxCoordinate, gauss6/ccd/motion.h);
// 1e12 leaves room for poses and motions.
inline constexpr double kMaxSceneCoordinate = 1e12;
SettingsProblem check_gains(const Gains& gains);                         // 0 < ks <= 1, kh > 0
SettingsProblem check_contact_parameters(const ContactParameters& contact);  // delta > 0, offset_eps < 0,
                                                                         // offset_time > 0
SettingsProblem check_surface_settings(const SurfaceSettings& surface);  // texture: amplitude > 0,
                                                                         // wavelength > 0, axis 0, 1 or 2,
                                                                         // bumps/height map: axis_v another
                                                                         // axis; height map: an image of
                                                                         // >= 2 x 2 values in [0, 1]
SettingsProblem check_crease_angle(double degrees);                      // [[obstacle]]: 0 <= crease_angle <= 180
// delta against the scene's size: delta at least kMinDelta and within
// [kMinDeltaPerExtent, kMaxDeltaPerExtent] of scene_extent(scene), the largest
// distance from the origin any vertex reaches (obstacles where they stand, the
// god-object at its initial pose).
// The floor: the distance and CCD tests square coordinate differences, whose
// rounding (eps extent^2) reaches delta^2 at delta = sqrt(eps) extent = 1.5e-8
// extent; the god-object then no longer slides along a surface (it stays put with
// no sideways force: the faceted cylinder, extent 0.05, from delta = 5e-9, 1e-7
// of its extent, while it slides at 7e-9). 1e-6 keeps eps extent^2 below 2.2e-4
// delta^2, a factor 7 above that edge.
inline constexpr double kMinDeltaPerExtent = 1e-6;
// The ceiling: delta is the unfelt separation kept before contact (the paper's
// scenes use 1e-5 of their size). A band of 1e-2 of the scene's extent is already
// coarse; beyond it the band swallows the scene (the proximity cache's margins of
// 64..256 delta span it many times over, the god-object stops far off the
// surfaces, and delta = 0.5 in a 5 cm scene ran 27 times slower than real time
// with the god-object stuck).
inline constexpr double kMaxDeltaPerExtent = 1e-2;
// And delta at least kMinDelta, whatever the scene's size: the CCD's rounded
// bounds widen values near zero by up to 2^-599 (4.8e-181) absolute
// (rounding.h); 1e-150 keeps that 30 orders of magnitude below delta.
inline constexpr double kMinDelta = 1e-150;
double scene_extent(const Scene& scene);
SettingsProblem check_delta_scale(const Scene& scene);
SettingsProblem check_device_settings(const DeviceSettings& device);     // 100 <= rate_hz <= 10000,
                                                                         // max_force > 0, max_torque > 0

// Reads a PNG image (any bit depth and colour type; converted to grey by
// libpng) into *out with values in [0, 1]; false with a message on failure.
// Writes one (8-bit grey, values rounded) for tests and generators. Load time only.
bool read_height_map(const std::string& path, HeightMapImage* out, std::string* error);
bool write_height_map(const std::string& path, const HeightMapImage& image, std::string* error);

// Loads and validates a scene file. Throws SceneError.
Scene load_scene(const std::string& path);

// What `gauss6 scene info` prints for one body, world frame.
struct BodySummary {
  std::string name;
  BodyRole role = BodyRole::kObstacle;
  int num_triangles = 0, num_vertices = 0;
  bool closed = false, manifold = false;
  int num_self_intersections = -1;  // -1: not checked
  // God-object: its mass properties. Obstacles have no density: their mass is
  // reported at density 1 (that is, their volume); NaN when the mesh is open.
  double mass = 0;
  Vec3 center_of_mass_W = Vec3::Zero();
  Mat3 inertia_W = Mat3::Zero();    // about the centre of mass, world axes
  Vec3 bbox_min_W = Vec3::Zero(), bbox_max_W = Vec3::Zero();
};

// Summaries of every body (obstacles first, then the god-object) at their scene
// poses. The exact self-intersection test runs only when asked (it is slow on
// large meshes).
std::vector<BodySummary> summarize_scene(const Scene& scene, bool count_self_intersections);

// The god-object's 6x6 mass matrix M at orientation q (world frame, about G).
Mat6 god_object_mass_matrix(const Scene& scene, const Quat& q);

}  // namespace gauss6
