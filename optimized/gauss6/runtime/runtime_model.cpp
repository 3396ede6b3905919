// The runtime model: the scene's meshes, BVHs, mass properties and settings,
// checked and prepared once (runtime_model.h).
#include "gauss6/runtime/runtime_model.h"

#include <cmath>
#include <string>

#include "gauss6/numeric/error_allowances.h"

namespace gauss6 {

namespace {

// The surface model of a scene whose obstacles are meshes_W (world frame, in
// scene order, adjacency built). Copies the height map's values.
SurfaceModel build_surface_model(const Scene& scene, const std::vector<TriangleMesh>& meshes_W) {
  SurfaceModel s;
  const SurfaceSettings& ss = scene.surface;
  s.shading = ss.kind == SurfaceKind::kForceShading || (ss.kind == SurfaceKind::kTexture && ss.shading);
  s.texture = ss.kind == SurfaceKind::kTexture;
  if (s.shading) {
    for (size_t k = 0; k < meshes_W.size(); ++k) {
      // Given normals rotate with the obstacle (R(q) is a rotation: rational form over |q|^2).
      MatrixX3d given = scene.obstacles[k].given_normals;
      const Mat3 R = rotation_matrix(scene.obstacles[k].pose.q);
      for (Eigen::Index v = 0; v < given.rows(); ++v) given.row(v) = (R * given.row(v).transpose()).transpose();
      s.obstacles.push_back(build_obstacle_shading(meshes_W[k], scene.obstacles[k].crease_angle * kPi / 180, given));
    }
  }
  if (s.texture) {
    TextureField& t = s.field;
    t.kind = ss.texture;
    t.amplitude = ss.amplitude;
    t.wavelength = ss.wavelength;
    t.u = Vec3::Unit(ss.axis);
    t.v = Vec3::Unit(ss.axis_v == ss.axis ? (ss.axis + 1) % 3 : ss.axis_v);
    t.origin = ss.origin;
    if (ss.texture == TextureKind::kHeightMap) {
      t.width = ss.height_map.width;
      t.height = ss.height_map.height;
      s.height_values = ss.height_map.values;
      t.values = s.height_values.data();
    }
  }
  return s;
}

}  // namespace

EffectiveSettings resolve_runtime_settings(const Scene& scene, const RuntimeSettings& s) {
  EffectiveSettings effective{s, ContactSettings{}};
  RuntimeSettings& settings = effective.runtime;
  ContactSettings& contact_generation = effective.contact_generation;
  const ContactParameters& contact = scene.contact;
  // The CCD stops the god-object delta before contact; contacts are the pairs
  // within delta (1 + contact_factor).
  settings.ccd.narrow.min_separation = contact.delta;
  // A hit is accepted once the features are proven within 1.1 delta: the stop pose keeps
  // at least delta (the guarantee) and the search ends well before rounding-level widths
  // (the default 1e-9 is meant for unit-size queries; docs/benchmarks.md, the delta sweep).
  settings.ccd.narrow.distance_tolerance = s.ccd_distance_tolerance * contact.delta;
  // Coherence: a leg that starts in contact keeps the pairs within 64 delta
  // (cache_margin) more than the reach, and the legs after it take their
  // candidates from them while no point has moved that far from there
  // (proximity_cache.h; docs/benchmarks.md has the sweep of this margin).
  settings.ccd.cache.margin = s.cache_margin * contact.delta;
  // A list's margin grows with the god-object's speed up to 256 delta
  // (cache_margin_max; about six steps like the last one), and the next list
  // is filled 300 node pairs a step (cache_fill_budget; about 60 us on the
  // peg) while the one in use serves, at the pose the god-object is heading
  // for: a sliding god-object seldom waits for a whole fill, and a resting one
  // scans a short list.
  settings.ccd.cache.margin_max = s.cache_margin_max * contact.delta;
  settings.ccd.cache.fill_budget = s.cache_fill_budget;
  contact_generation.distance = contact.delta * (1 + settings.contact_factor);
  // The CCD lists the pairs that may come within the contact distance (and the
  // distance a hit may be accepted at, 0.1 delta more: update_contacts) of each
  // other by the stop pose, so the contact set needs no descent of its own.
  settings.ccd.near_distance = contact_generation.distance + s.near_slack * contact.delta;
  return effective;
}

RuntimeModel::RuntimeModel(const Scene& scene, const RuntimeSettings& s) : settings(s) {
  auto fail = [&](const std::string& what) {
    throw RuntimeError("scene '" + scene.path + "': " + what);
  };
  // The scene's settings meet the same rules as in a scene file (scene.h), for
  // a scene built in code too.
  for (const SettingsProblem& problem : {check_gains(scene.gains), check_contact_parameters(scene.contact),
                                         check_surface_settings(scene.surface), check_device_settings(scene.device)})
    if (problem) fail(problem.message());
  for (const Body& b : scene.obstacles)
    if (const SettingsProblem p = check_crease_angle(b.crease_angle)) fail(b.name + ": " + p.message());
  if (const SettingsProblem p = check_delta_scale(scene)) fail(p.message());
  if (num_triangles(scene.god_object.mesh) == 0) fail("the god-object's mesh is empty");
  if (!(s.contact_factor > 0) || !(s.gap_factor > 0 && s.gap_factor < s.contact_factor))
    fail("settings: need 0 < gap_factor < contact_factor");
  if (!(s.ccd_distance_tolerance > 0 && std::isfinite(s.ccd_distance_tolerance)))
    fail("settings: ccd_distance_tolerance must be > 0 (and finite)");
  if (!(s.near_slack >= 0 && std::isfinite(s.near_slack))) fail("settings: near_slack must be >= 0 (and finite)");
  if (!(s.cache_margin >= 0 && s.cache_margin_max >= 0) || !std::isfinite(s.cache_margin) ||
      !std::isfinite(s.cache_margin_max) || s.cache_fill_budget < 0)
    fail("settings: the cache's margins and fill budget must be >= 0 (and finite)");
  // Watchdogs: a timeout that is infinite, NaN or absurdly long would switch one off.
  const auto timeout_ok = [](double x) { return x > 0 && x <= kMaxTimeout; };
  if (!timeout_ok(s.device_timeout) || !timeout_ok(s.sim_timeout) || !timeout_ok(s.coupling_timeout))
    fail("settings: device_timeout, sim_timeout and coupling_timeout must be in (0, " + std::to_string(kMaxTimeout) +
         "] s (got " + std::to_string(s.device_timeout) + ", " + std::to_string(s.sim_timeout) + ", " +
         std::to_string(s.coupling_timeout) + ")");
  if (!(s.event_interval >= 0 && s.event_interval <= kMaxTimeout))
    fail("settings: event_interval must be in [0, " + std::to_string(kMaxTimeout) + "] s");
  if (s.lockstep_sim_period < 1) fail("settings: lockstep_sim_period must be >= 1");
  if (s.max_contacts < 1 || s.max_contacts > kMaxContactCapacity)
    fail("settings: max_contacts must be in [1, " + std::to_string(kMaxContactCapacity) + "]");
  if (!(s.spin_wait >= 0 && s.spin_wait <= 1)) fail("settings: spin_wait must be in [0, 1] s");
  if (const char* problem = update_budget_settings_problem(s.budget)) fail(std::string("settings: ") + problem);
  // A loop paced slower than its own watchdog would trip it on every step.
  if (!(s.sim_min_period >= 0 && s.sim_min_period < s.sim_timeout) ||
      !(s.coupling_min_period >= 0 && s.coupling_min_period < s.coupling_timeout))
    fail("settings: min periods must be >= 0 and below their loop's timeout (sim_min_period < sim_timeout, "
         "coupling_min_period < coupling_timeout)");

  // Obstacles: vertices and normals moved to the world frame once; BVHs built once.
  obstacle_meshes_W.reserve(scene.obstacles.size());
  obstacle_bvhs_W.reserve(scene.obstacles.size());
  for (const Body& b : scene.obstacles) {
    TriangleMesh m = b.mesh;
    const Mat3 R = rotation_matrix(b.pose.q);
    for (Eigen::Index v = 0; v < m.V.rows(); ++v) m.V.row(v) = (b.pose.p + R * m.V.row(v).transpose()).transpose();
    if (m.N.rows() == m.V.rows()) {
      // R(q) is a rotation times |q|^0 (rational form): normals only rotate.
      for (Eigen::Index v = 0; v < m.N.rows(); ++v) m.N.row(v) = (R * m.N.row(v).transpose()).transpose();
    }
    obstacle_meshes_W.push_back(std::move(m));
  }
  // The scene file's bound on coordinates, in the world frame and for a scene
  // built in code too: beyond it the CCD's pair tests would refuse the obstacle.
  for (size_t k = 0; k < obstacle_meshes_W.size(); ++k)
    if (!(obstacle_meshes_W[k].V.size() == 0 || obstacle_meshes_W[k].V.cwiseAbs().maxCoeff() <= kMaxSceneCoordinate))
      fail(scene.obstacles[k].name + ": a vertex coordinate (world frame) beyond " +
           std::to_string(kMaxSceneCoordinate) + " or not finite");
  if (!(scene.god_object.mesh.V.cwiseAbs().maxCoeff() <= kMaxSceneCoordinate) ||
      !(scene.god_object.pose.p.cwiseAbs().maxCoeff() <= kMaxSceneCoordinate) || !is_valid_pose(scene.god_object.pose))
    fail("the god-object's vertices or initial pose are beyond " + std::to_string(kMaxSceneCoordinate) +
         " or not valid");
  for (TriangleMesh& m : obstacle_meshes_W)
    if (m.adjacency.FE.rows() != m.F.rows()) build_adjacency(&m);
  for (const TriangleMesh& m : obstacle_meshes_W) obstacle_bvhs_W.push_back(build_bvh(m));
  // Surface properties (surface.h): shading normals and the texture, once.
  surface = build_surface_model(scene, obstacle_meshes_W);
  sim_rate_hz = scene.device.rate_hz / s.lockstep_sim_period;
  if (surface.texture) texture_max_speed = max_texture_speed(shortest_wavelength(surface.field), sim_rate_hz);
  for (size_t k = 0; k < obstacle_meshes_W.size(); ++k) obstacles.push_back({&obstacle_meshes_W[k], &obstacle_bvhs_W[k]});

  // God-object: body frame B, origin at G.
  god_mesh_B = scene.god_object.mesh;
  god_bvh_B = build_bvh(god_mesh_B);
  god = {&god_mesh_B, &god_bvh_B};
  god_radius = god_bvh_B.radius;
  if (!(god_radius >= kMinBodyRadius))
    fail("the god-object's radius about G (" + std::to_string(god_radius) +
         ") is below 2^-1000, the least the posing allowance covers (kMinBodyRadius)");

  // Inertia about G from the inertia about the centre of mass c (parallel axes).
  const MassProperties& mp = scene.god_mass.mass;
  mass = mp.mass;
  const Vec3 c = mp.center_of_mass;
  inertia_G_B = mp.inertia + mp.mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
  if (!(mass > 0) || !std::isfinite(mass) || !inertia_G_B.allFinite() || inertia_G_B.llt().info() != Eigen::Success)
    fail("the god-object's mass properties are not positive definite");

  initial_pose = scene.god_object.pose;
  gains = scene.gains;
  contact = scene.contact;
  offsets.eps = scene.contact.offset_eps;  // the rules: check_contact_parameters above
  offsets.T = scene.contact.offset_time;
  device = scene.device;

  const EffectiveSettings effective = resolve_runtime_settings(scene, s);
  if (const char* problem = ccd_step_settings_problem(effective.runtime.ccd)) fail(std::string("settings: ") + problem);
  settings = effective.runtime;
  contact_generation = effective.contact_generation;
  match_distance = settings.match_distance > 0 ? settings.match_distance : 1e-3 * god_radius;
}

Mat6 mass_matrix_at(const RuntimeModel& model, const Quat& q) { return mass_matrix(model, rotation_matrix(normalized(q))); }

Mat6 mass_matrix(const RuntimeModel& model, const Mat3& R) {
  Mat6 M = Mat6::Zero();
  M.topLeftCorner<3, 3>() = model.mass * Mat3::Identity();
  M.bottomRightCorner<3, 3>() = R * model.inertia_G_B * R.transpose();
  // Symmetric to the last bit (the projection caches M by its bytes).
  M.bottomRightCorner<3, 3>() = (0.5 * (M.bottomRightCorner<3, 3>() + M.bottomRightCorner<3, 3>().transpose())).eval();
  return M;
}

}  // namespace gauss6
