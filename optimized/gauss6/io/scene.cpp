// The TOML scene loader (docs/scene-format.md, versions 1 and 2), with toml++. It applies
// the rules of the scene's settings (check_gains() and the others: scene_rules.cpp)
// at each key's line. Every error names the file, the line and column, and the key.
#include "gauss6/io/scene.h"

#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <set>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <toml++/toml.h>

#include "gauss6/geometry/mass_properties.h"
#include "gauss6/io/mesh_io.h"
#include "gauss6/io/regular_file.h"
#include "gauss6/contact/surface.h"

namespace gauss6 {

namespace {

namespace fs = std::filesystem;

// Reads typed values out of one TOML table, naming file:line:col and the dotted key in errors.
class TableReader {
 public:
  TableReader(const std::string& file, const toml::table& table, std::string prefix)
      : file_(file), table_(table), prefix_(std::move(prefix)) {}

  [[noreturn]] void fail(const toml::source_region& where, const std::string& key,
                         const std::string& message) const {
    throw SceneError(file_, static_cast<int>(where.begin.line), prefix_ + key, message,
                     static_cast<int>(where.begin.column));
  }
  [[noreturn]] void fail_missing(const std::string& key, const std::string& what) const {
    fail(table_.source(), key, "missing (" + what + ")");
  }

  // Unknown keys are errors: a misspelt key must not be silently ignored.
  void allow_only(std::initializer_list<const char*> keys) const {
    const std::set<std::string> allowed(keys.begin(), keys.end());
    for (const auto& [k, node] : table_) {
      (void)node;
      if (!allowed.count(std::string(k.str()))) {
        std::string list;
        for (const char* a : keys) list += std::string(list.empty() ? "" : ", ") + a;
        fail(k.source(), std::string(k.str()), "unknown key (allowed here: " + list + ")");
      }
    }
  }

  bool has(const char* key) const { return table_.contains(key); }
  const toml::node* node(const char* key) const { return table_.get(key); }

  std::string string(const char* key, const std::string* fallback = nullptr) const {
    const toml::node* n = table_.get(key);
    if (!n) {
      if (fallback) return *fallback;
      fail_missing(key, "a string");
    }
    if (!n->is_string()) fail(n->source(), key, "must be a string");
    return n->as_string()->get();
  }

  double number(const char* key, const double* fallback = nullptr) const {
    const toml::node* n = table_.get(key);
    if (!n) {
      if (fallback) return *fallback;
      fail_missing(key, "a number");
    }
    return as_number(*n, key);
  }

  double as_number(const toml::node& n, const std::string& key) const {
    double v;
    if (n.is_floating_point()) v = n.as_floating_point()->get();
    else if (n.is_integer()) v = static_cast<double>(n.as_integer()->get());
    else fail(n.source(), key, "must be a number");
    if (!std::isfinite(v)) fail(n.source(), key, "must be finite");
    return v;
  }

  bool boolean(const char* key, bool fallback) const {
    const toml::node* n = table_.get(key);
    if (!n) return fallback;
    if (!n->is_boolean()) fail(n->source(), key, "must be true or false");
    return n->as_boolean()->get();
  }

  int64_t integer(const char* key, const int64_t* fallback = nullptr) const {
    const toml::node* n = table_.get(key);
    if (!n) {
      if (fallback) return *fallback;
      fail_missing(key, "an integer");
    }
    if (!n->is_integer()) fail(n->source(), key, "must be an integer");
    return n->as_integer()->get();
  }

  // A fixed-length array of numbers.
  template <int N>
  Eigen::Matrix<double, N, 1> vector(const char* key, const Eigen::Matrix<double, N, 1>* fallback) const {
    const toml::node* n = table_.get(key);
    if (!n) {
      if (fallback) return *fallback;
      fail_missing(key, "an array of " + std::to_string(N) + " numbers");
    }
    const toml::array* a = n->as_array();
    if (!a || static_cast<int>(a->size()) != N)
      fail(n->source(), key, "must be an array of " + std::to_string(N) + " numbers");
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v[i] = as_number(*a->get(i), key + std::string("[") + std::to_string(i) + "]");
    return v;
  }

  Mat3 matrix3(const char* key) const {
    const toml::node* n = table_.get(key);
    if (!n) fail_missing(key, "a 3x3 array of numbers");
    const toml::array* rows = n->as_array();
    if (!rows || rows->size() != 3) fail(n->source(), key, "must be a 3x3 array of numbers");
    Mat3 m;
    for (int i = 0; i < 3; ++i) {
      const toml::array* row = rows->get(i)->as_array();
      if (!row || row->size() != 3) fail(rows->get(i)->source(), key, "must be a 3x3 array of numbers");
      for (int j = 0; j < 3; ++j) m(i, j) = as_number(*row->get(j), key);
    }
    return m;
  }

  const toml::table& table() const { return table_; }
  const std::string& file() const { return file_; }
  const std::string& prefix() const { return prefix_; }

 private:
  const std::string& file_;
  const toml::table& table_;
  std::string prefix_;
};

const toml::table& sub_table(const TableReader& parent, const char* key, bool required,
                             const toml::table& empty) {
  const toml::node* n = parent.node(key);
  if (!n) {
    if (required) parent.fail_missing(key, "a table [" + std::string(key) + "]");
    return empty;
  }
  if (!n->is_table()) parent.fail(n->source(), key, "must be a table [" + std::string(key) + "]");
  return *n->as_table();
}

void require(bool ok, const TableReader& r, const char* key, const std::string& message) {
  if (!ok) r.fail(r.node(key) ? r.node(key)->source() : r.table().source(), key, message);
}

// A broken settings rule (check_gains() and the others) as an error at its key's line.
void require(const SettingsProblem& p, const TableReader& r) {
  if (p) require(false, r, p.key.c_str(), p.problem);
}

// Pose of the mesh's own frame in the world: position and (w, x, y, z) orientation.
Pose read_pose(const TableReader& r) {
  const Vec3 zero = Vec3::Zero();
  const Eigen::Vector4d identity(1, 0, 0, 0);
  Pose x;
  x.p = r.vector<3>("position", &zero);
  const Eigen::Vector4d q = r.vector<4>("orientation", &identity);
  // stableNorm: scaled, so that (1e300, 1e300, 0, 0) neither overflows nor passes as NaN.
  require(q.stableNorm() > 1e-12, r, "orientation", "must be a non-zero quaternion (w, x, y, z)");
  x.q = normalized(Quat{q[0], q[1], q[2], q[3]});
  // Positions beyond this are far outside any scene the CCD's bounds serve.
  require(x.p.cwiseAbs().maxCoeff() <= kMaxSceneCoordinate, r, "position",
          "must be within " + std::to_string(kMaxSceneCoordinate) + " of the origin");
  return x;
}

// Reads and validates a body's mesh; the path is relative to the scene file.
void read_body_mesh(const TableReader& r, Body* body, std::vector<std::string>* warnings) {
  const std::string rel = r.string("mesh");
  const fs::path scene_dir = fs::path(r.file()).parent_path();
  body->mesh_path = (scene_dir / rel).lexically_normal().string();
  try {
    body->mesh = read_mesh(body->mesh_path);
  } catch (const MeshFileError& e) {
    r.fail(r.node("mesh")->source(), "mesh", e.what());
  }
  // Vertex normals the file gives (PLY nx, ny, nz; NOFF; OBJ vn): force shading uses them (surface.h).
  try {
    body->given_normals = read_vertex_normals(body->mesh_path);
  } catch (const MeshFileError& e) {
    r.fail(r.node("mesh")->source(), "mesh", e.what());
  }
  MatrixX3d& given = body->given_normals;
  if (given.rows() > 0 && given.rows() != body->mesh.V.rows())
    r.fail(r.node("mesh")->source(), "mesh",
           body->mesh_path + ": " + std::to_string(given.rows()) + " vertex normals for " +
               std::to_string(body->mesh.V.rows()) + " vertices");
  for (Eigen::Index v = 0; v < given.rows(); ++v) {
    const double n = given.row(v).norm();
    if (!(n > 0) || !std::isfinite(n))
      r.fail(r.node("mesh")->source(), "mesh",
             body->mesh_path + ": vertex " + std::to_string(v) + "'s normal is zero or not finite");
    given.row(v) /= n;
  }
  body->report = validate_mesh(body->mesh);
  const MeshReport& rep = body->report;
  if (rep.num_nonfinite_vertices || rep.num_bad_indices || rep.num_degenerate_triangles)
    r.fail(r.node("mesh")->source(), "mesh", body->mesh_path + ": unusable mesh:\n" + rep.describe());
  if (body->mesh.V.cwiseAbs().maxCoeff() > kMaxSceneCoordinate)
    r.fail(r.node("mesh")->source(), "mesh",
           body->mesh_path + ": a vertex coordinate beyond " + std::to_string(kMaxSceneCoordinate));
  // A closed, consistently oriented mesh whose faces are wound inward encloses a
  // negative volume: its normals point into the body and contacts with it would
  // render no force. Flip it, and say so.
  if (rep.closed()) {
    MassProperties mp;
    if (!compute_mass_properties(body->mesh, /*density=*/1.0, &mp, nullptr)) {
      TriangleMesh flipped = body->mesh;
      const Eigen::VectorXi second = flipped.F.col(1);
      flipped.F.col(1) = flipped.F.col(2);
      flipped.F.col(2) = second;
      if (compute_mass_properties(flipped, /*density=*/1.0, &mp, nullptr)) {
        body->mesh = std::move(flipped);
        given = -given;  // the file's vertex normals, if any, turn with its faces
        warnings->push_back(r.prefix() + "mesh: " + body->mesh_path +
                            ": closed but inside out (faces wound inward, enclosing a negative volume): "
                            "faces flipped" + (given.rows() > 0 ? " (and the file's vertex normals)" : ""));
      }
    }
  }
  build_adjacency(&body->mesh);
  compute_vertex_normals(&body->mesh);
}

// The god-object's mass and inertia about G must give a mass matrix the
// projection can factor in doubles: every value normal (no subnormals), within
// [1e-100, 1e100], and the inertia's condition number at most 1e12.
void check_god_mass(const TableReader& r, const char* key, const MassProperties& mp, const Mat3& I_G) {
  auto in_range = [](double v) { return std::isfinite(v) && v >= 1e-100 && v <= 1e100; };
  require(in_range(mp.mass), r, key, "the mass must be within [1e-100, 1e100] (got " + std::to_string(mp.mass) + ")");
  Eigen::SelfAdjointEigenSolver<Mat3> eig(I_G);
  const double lo = eig.eigenvalues().minCoeff(), hi = eig.eigenvalues().maxCoeff();
  require(in_range(lo) && in_range(hi) && hi <= 1e12 * lo, r, key,
          "the inertia about the reference point must have eigenvalues within [1e-100, 1e100] and a "
          "condition number of at most 1e12");
}

// A value of a table given as JSON (the [device.script] table): floats finite, no dates or times,
// each refused at its line (JSON has neither).
void check_json_representable(const TableReader& r, const toml::node& node, const std::string& key) {
  if (const toml::table* t = node.as_table()) {
    for (const auto& [k, v] : *t) check_json_representable(r, v, key + "." + std::string(k.str()));
  } else if (const toml::array* a = node.as_array()) {
    for (size_t i = 0; i < a->size(); ++i) check_json_representable(r, (*a)[i], key + "[" + std::to_string(i) + "]");
  } else if (node.is_floating_point()) {
    if (!std::isfinite(node.as_floating_point()->get())) r.fail(node.source(), key, "must be finite");
  } else if (node.is_date() || node.is_time() || node.is_date_time()) {
    r.fail(node.source(), key, "a date or time is not a hand script's value (times are seconds)");
  }
}

// The scene file parsed as TOML: a file that is not regular (a FIFO or a device
// is never read) or not TOML is an error, at its line when the parser gives one.
toml::table parse_scene_file(const std::string& path) {
  if (const std::string problem = regular_file_problem(path, uint64_t(1) << 26); !problem.empty())
    throw SceneError(path, problem);
  try {
    return toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw SceneError(path, static_cast<int>(e.source().begin.line), /*key=*/"", std::string(e.description()),
                     static_cast<int>(e.source().begin.column));
  } catch (const std::exception& e) {
    throw SceneError(path, e.what());
  }
}

// The top-level keys: the tables allowed, format, version and name.
void read_header(const TableReader& top, Scene* scene) {
  top.allow_only({"format", "version", "name", "gains", "contact", "obstacle", "god_object", "surface", "device"});
  require(top.string("format") == "gauss6-scene", top, "format", "must be \"gauss6-scene\"");
  // Compared as the file's 64-bit integer: 4294967297 is not version 1.
  const int64_t version = top.integer("version");
  require(version >= kOldestSceneFormatVersion && version <= kSceneFormatVersion, top, "version",
          "unsupported version " + std::to_string(version) + " (this build reads versions " +
              std::to_string(kOldestSceneFormatVersion) + " to " + std::to_string(kSceneFormatVersion) + ")");
  scene->version = static_cast<int>(version);
  scene->name = top.string("name");
}

// [gains]
void read_gains(const TableReader& r, Gains* gains) {
  r.allow_only({"ks", "kh"});
  gains->ks = r.number("ks");
  gains->kh = r.number("kh");
  require(check_gains(*gains), r);
}

// [contact]; contact.delta against the bodies' size is checked once they are read.
void read_contact(const TableReader& r, ContactParameters* contact) {
  r.allow_only({"delta", "offset_eps", "offset_time"});
  contact->delta = r.number("delta");
  const ContactParameters defaults;
  const double default_eps = kDefaultOffsetEpsPerDelta * contact->delta;
  contact->offset_eps = r.number("offset_eps", &default_eps);
  contact->offset_time = r.number("offset_time", &defaults.offset_time);
  require(check_contact_parameters(*contact), r);
}

// Claims a body's name: not empty and not another body's (names holds those claimed).
void claim_body_name(const TableReader& r, const std::string& name, std::set<std::string>* names) {
  require(!name.empty(), r, "name", "must not be empty");
  require(names->insert(name).second, r, "name", "\"" + name + "\" is already the name of another body");
}

// [[obstacle]], each with its name, pose, mesh and crease angle.
void read_obstacles(const TableReader& top, std::set<std::string>* names, Scene* scene) {
  const toml::node* n = top.node("obstacle");
  if (!n) return;
  const toml::array* arr = n->as_array();
  if (!arr || !arr->is_array_of_tables()) top.fail(n->source(), "obstacle", "must be an array of tables [[obstacle]]");
  for (size_t i = 0; i < arr->size(); ++i) {
    TableReader r(top.file(), *arr->get(i)->as_table(), "obstacle[" + std::to_string(i) + "].");
    r.allow_only({"name", "mesh", "position", "orientation", "crease_angle"});
    Body b;
    b.role = BodyRole::kObstacle;
    b.name = r.string("name");
    claim_body_name(r, b.name, names);
    b.pose = read_pose(r);
    read_body_mesh(r, &b, &scene->warnings);
    const double crease_default = b.crease_angle;
    b.crease_angle = r.number("crease_angle", &crease_default);
    require(check_crease_angle(b.crease_angle), r);
    scene->obstacles.push_back(std::move(b));
  }
}

// The god-object's mass properties in its mesh's frame: from a density over
// its closed mesh, or given whole (mass, center_of_mass, inertia), one or the
// other; gm records which.
MassProperties read_mass_properties(const TableReader& r, const Body& b, GodObjectMass* gm) {
  const bool has_density = r.has("density");
  const bool has_given = r.has("mass") || r.has("center_of_mass") || r.has("inertia");
  if (has_density == has_given)
    r.fail(r.table().source(), "density",
           "give either density, or all of mass, center_of_mass and inertia (not both, not neither)");
  MassProperties mp;
  if (has_density) {
    gm->from_density = true;
    gm->density = r.number("density");
    require(gm->density > 0, r, "density", "must be > 0");
    if (!b.report.closed())
      r.fail(r.node("mesh")->source(), "mesh",
             b.mesh_path + ": a mass from a density needs a closed mesh:\n" + b.report.describe());
    std::string error;
    if (!compute_mass_properties(b.mesh, gm->density, &mp, &error))
      r.fail(r.node("mesh")->source(), "mesh", b.mesh_path + ": " + error);
  } else {
    gm->from_density = false;
    mp.mass = r.number("mass");
    require(mp.mass > 0, r, "mass", "must be > 0");
    const Vec3 c = r.vector<3>("center_of_mass", nullptr);
    mp.center_of_mass = c;
    mp.inertia = r.matrix3("inertia");
    require((mp.inertia - mp.inertia.transpose()).norm() <= 1e-12 * mp.inertia.norm(), r, "inertia",
            "must be symmetric");
    Eigen::SelfAdjointEigenSolver<Mat3> eig(mp.inertia);
    require(eig.eigenvalues().minCoeff() > 0, r, "inertia", "must be positive definite");
  }
  return mp;
}

// [god_object]: its name, pose and mesh, its mass, and its body frame B (origin
// at G, the centre of mass unless reference_point is given), into which its
// mesh and mass properties are moved.
void read_god_object(const TableReader& r, std::set<std::string>* names, Scene* scene) {
  r.allow_only({"name", "mesh", "position", "orientation", "density", "mass", "center_of_mass", "inertia",
                "reference_point"});
  Body& b = scene->god_object;
  b.role = BodyRole::kGodObject;
  b.name = r.string("name");
  claim_body_name(r, b.name, names);
  const Pose X_WM = read_pose(r);  // pose of the mesh's own frame
  read_body_mesh(r, &b, &scene->warnings);
  GodObjectMass& gm = scene->god_mass;
  MassProperties mp = read_mass_properties(r, b, &gm);
  const Vec3 G = r.vector<3>("reference_point", &mp.center_of_mass);
  // G far from the mesh makes the body-frame vertices lose their digits (a vertex
  // 1 m from a G 1e17 away is rounded to 16 m): G within 100 bounding-box diagonals.
  {
    const Vec3 lo = b.mesh.V.colwise().minCoeff(), hi = b.mesh.V.colwise().maxCoeff();
    const double diagonal = (hi - lo).norm();
    require((G - 0.5 * (lo + hi)).norm() <= 100 * diagonal, r, "reference_point",
            "must lie within 100 bounding-box diagonals of the mesh (" + std::to_string(diagonal) + ")");
    const Vec3 c = mp.center_of_mass - G;
    const Mat3 I_G = mp.inertia + mp.mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
    check_god_mass(r, gm.from_density ? "density" : "mass", mp, I_G);
  }
  gm.mesh_to_body = G;
  for (int v = 0; v < b.mesh.V.rows(); ++v) b.mesh.V.row(v) -= G.transpose();
  mp.center_of_mass -= G;
  gm.mass = mp;
  b.pose = {transform_point(X_WM, G), X_WM.q};
}

// One axis key of [surface], "x", "y" or "z", as 0, 1 or 2.
int read_axis(const TableReader& r, const char* key, const std::string& fallback) {
  const std::string a = r.string(key, &fallback);
  if (a != "x" && a != "y" && a != "z") r.fail(r.node(key)->source(), key, "must be x, y or z");
  return a[0] - 'x';
}

// The keys of [surface] when kind = "texture": the texture, its size and
// axes, its image for a height map; version 1's slope converted to a height.
void read_texture(const TableReader& r, int version, SurfaceSettings* s) {
  s->shading = r.boolean("shading", false);
  const std::string sine = "sine";
  const std::string texture = r.string("texture", &sine);
  if (texture == "sine") s->texture = TextureKind::kSine;
  else if (texture == "bumps") s->texture = TextureKind::kBumps;
  else if (texture == "height_map") s->texture = TextureKind::kHeightMap;
  else r.fail(r.node("texture")->source(), "texture", "must be \"sine\", \"bumps\" or \"height_map\"");
  s->amplitude = r.number("amplitude");
  s->wavelength = r.number("wavelength");
  s->axis = read_axis(r, "axis", "x");
  const Vec3 zero = Vec3::Zero();
  s->origin = r.vector<3>("origin", &zero);
  if (s->texture != TextureKind::kSine) s->axis_v = read_axis(r, "axis_v", s->axis == 1 ? "x" : "y");
  else if (r.has("axis_v")) r.fail(r.node("axis_v")->source(), "axis_v", "only for texture = bumps or height_map");
  if (s->texture == TextureKind::kHeightMap) {
    const fs::path image = fs::path(r.file()).parent_path() / r.string("image");
    s->height_map.path = image.lexically_normal().string();
    std::string error;
    if (!read_height_map(s->height_map.path, &s->height_map, &error))
      r.fail(r.node("image")->source(), "image", error);
  } else if (r.has("image")) {
    r.fail(r.node("image")->source(), "image", "only for texture = \"height_map\"");
  }
  if (version == 1) {
    // Version 1's amplitude was the height field's steepest slope, in (0, 1]: the
    // same field in scene units (surface.h) is A = slope L / (2 pi) for the sine,
    // slope L / pi for the bumps, slope L / width (a pixel's pitch) for a height map.
    if (!(s->amplitude > 0 && s->amplitude <= 1))
      r.fail(r.node("amplitude")->source(), "amplitude", "must be in (0, 1] (version 1: a slope)");
    const double per = texture_slope_per_amplitude(s->texture, s->wavelength, s->height_map.width);
    if (per > 0) s->amplitude /= per;  // else the wavelength's rule below names the problem
  }
  require(check_surface_settings(*s), r);
}

// [surface] (optional): its kind, and a texture's keys only for a texture.
void read_surface(const TableReader& r, int version, SurfaceSettings* s) {
  r.allow_only({"kind", "shading", "texture", "amplitude", "wavelength", "axis", "axis_v", "origin", "image"});
  const std::string none = "none";
  const std::string kind = r.string("kind", &none);
  if (kind == "none") s->kind = SurfaceKind::kNone;
  else if (kind == "force_shading") s->kind = SurfaceKind::kForceShading;
  else if (kind == "texture") s->kind = SurfaceKind::kTexture;
  else r.fail(r.node("kind")->source(), "kind", "must be \"none\", \"force_shading\" or \"texture\"");
  if (s->kind == SurfaceKind::kTexture) {
    read_texture(r, version, s);
  } else {
    for (const char* k : {"shading", "texture", "amplitude", "wavelength", "axis", "axis_v", "origin", "image"})
      if (r.has(k)) r.fail(r.node(k)->source(), k, "only for kind = \"texture\"");
  }
}

// A simulated device's hand script: a script's name, a .json file, or a
// [device.script] table kept as JSON.
void read_device_script(const TableReader& r, DeviceSettings* d) {
  const toml::node* script = r.node("script");
  if (script && script->is_table()) {
    // The hand script in the scene: checked here for what JSON cannot hold (its key names, types
    // and times are the device's hand_script_from_json's to check, at run time, naming the key).
    check_json_representable(r, *script, "script");
    std::ostringstream json;
    json << toml::json_formatter{*script->as_table()};
    d->script_json = json.str();
  } else if (script && !script->is_string()) {
    r.fail(script->source(), "script", "must be a script's name, a .json file or a table (the script itself)");
  } else if (!script) {
    r.fail_missing("script", "a script's name, a .json file or a [device.script] table: docs/scene-format.md");
  } else {
    d->script = r.string("script");
  }
}

// A HID device's USB ids (16-bit; -1 means any), serial and path.
void read_hid_keys(const TableReader& r, DeviceSettings* d) {
  const int64_t any = -1;
  for (const char* k : {"vendor_id", "product_id"})
    if (const int64_t id = r.integer(k, &any); id < -1 || id > 0xFFFF)
      require(false, r, k, "must be a 16-bit USB id in [0, 65535] (or -1 for any)");
  d->vendor_id = static_cast<int>(r.integer("vendor_id", &any));
  d->product_id = static_cast<int>(r.integer("product_id", &any));
  const std::string blank;
  d->serial = r.string("serial", &blank);
  d->path = r.string("path", &blank);
}

// [device]: its kind and that kind's keys (another kind's keys are errors),
// its rate and force limits.
void read_device(const TableReader& r, DeviceSettings* d) {
  r.allow_only({"kind", "rate_hz", "max_force", "max_torque", "script", "trace", "vendor_id", "product_id",
                "serial", "path"});
  const std::string kind = r.string("kind");
  std::vector<std::string> own;
  if (kind == "simulated") {
    d->kind = DeviceKind::kSimulated;
    read_device_script(r, d);
    own = {"script"};
  } else if (kind == "replay") {
    d->kind = DeviceKind::kReplay;
    d->trace = (fs::path(r.file()).parent_path() / r.string("trace")).lexically_normal().string();
    own = {"trace"};
  } else if (kind == "hid") {
    d->kind = DeviceKind::kHid;
    read_hid_keys(r, d);
    own = {"vendor_id", "product_id", "serial", "path"};
  } else {
    r.fail(r.node("kind")->source(), "kind", "must be \"simulated\", \"replay\" or \"hid\"");
  }
  // Keys of another device kind are errors, not silently ignored.
  for (const char* k : {"script", "trace", "vendor_id", "product_id", "serial", "path"}) {
    bool mine = false;
    for (const std::string& o : own) mine |= o == k;
    if (!mine && r.has(k)) r.fail(r.node(k)->source(), k, "not a key of a \"" + kind + "\" device");
  }
  const DeviceSettings defaults;
  d->rate_hz = r.number("rate_hz", &defaults.rate_hz);
  d->max_force = r.number("max_force", &defaults.max_force);
  d->max_torque = r.number("max_torque", &defaults.max_torque);
  require(check_device_settings(*d), r);
}

}  // namespace

// A reader per table of the scene format (docs/scene-format.md), called in this
// order: the error reported is the first one met in it.
Scene load_scene(const std::string& path) {
  Scene scene;
  scene.path = path;
  const toml::table root = parse_scene_file(path);
  const toml::table empty;  // an optional table left out
  const TableReader top(path, root, "");
  read_header(top, &scene);
  read_gains(TableReader(path, sub_table(top, "gains", true, empty), "gains."), &scene.gains);
  const TableReader contact(path, sub_table(top, "contact", true, empty), "contact.");
  read_contact(contact, &scene.contact);
  std::set<std::string> names;  // the bodies' names, each once
  read_obstacles(top, &names, &scene);
  read_god_object(TableReader(path, sub_table(top, "god_object", true, empty), "god_object."), &names, &scene);
  require(check_delta_scale(scene), contact);  // delta against the bodies' coordinates
  read_surface(TableReader(path, sub_table(top, "surface", false, empty), "surface."), scene.version,
               &scene.surface);
  read_device(TableReader(path, sub_table(top, "device", true, empty), "device."), &scene.device);
  return scene;
}

std::vector<BodySummary> summarize_scene(const Scene& scene, bool check_self_intersections) {
  std::vector<BodySummary> out;
  std::vector<const Body*> bodies;
  for (const Body& b : scene.obstacles) bodies.push_back(&b);
  bodies.push_back(&scene.god_object);
  for (const Body* b : bodies) {
    BodySummary s;
    s.name = b->name;
    s.role = b->role;
    s.num_triangles = num_triangles(b->mesh);
    s.num_vertices = num_vertices(b->mesh);
    s.closed = b->report.closed();
    s.manifold = b->report.manifold();
    if (check_self_intersections) s.num_self_intersections = count_self_intersections(b->mesh);
    const Mat3 R = rotation_matrix(b->pose.q);
    MassProperties mp;
    if (b->role == BodyRole::kGodObject) {
      mp = scene.god_mass.mass;
    } else {
      std::string error;
      if (!s.closed || !compute_mass_properties(b->mesh, /*density=*/1.0, &mp, &error)) {
        mp.mass = std::nan("");
        mp.center_of_mass.setConstant(std::nan(""));
        mp.inertia.setConstant(std::nan(""));
      }
    }
    s.mass = mp.mass;
    s.center_of_mass_W = transform_point(b->pose, mp.center_of_mass);
    s.inertia_W = R * mp.inertia * R.transpose();
    s.bbox_min_W.setConstant(INFINITY);
    s.bbox_max_W.setConstant(-INFINITY);
    for (int v = 0; v < b->mesh.V.rows(); ++v) {
      const Vec3 p = transform_point(b->pose, b->mesh.V.row(v).transpose());
      s.bbox_min_W = s.bbox_min_W.cwiseMin(p);
      s.bbox_max_W = s.bbox_max_W.cwiseMax(p);
    }
    out.push_back(std::move(s));
  }
  return out;
}

Mat6 god_object_mass_matrix(const Scene& scene, const Quat& q) {
  // Inertia about G by the parallel-axis theorem (G is the centre of mass unless the scene says otherwise).
  const MassProperties& mp = scene.god_mass.mass;
  const Vec3 c = mp.center_of_mass;
  const Mat3 I_G = mp.inertia + mp.mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
  MassProperties about_G = mp;
  about_G.inertia = I_G;
  return mass_matrix(about_G, rotation_matrix(q));
}

}  // namespace gauss6
