// Tests of the TOML scene loader (scene.h, docs/scene-format.md): a valid scene
// loads with its mass properties, and every kind of bad input is an error that
// names the file, the line and the key.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

#include <unistd.h>

#include "gauss6/geometry/mass_properties.h"
#include "gauss6/runtime/runtime_model.h"
#include "gauss6/io/scene.h"

using namespace gauss6;
namespace fs = std::filesystem;

namespace {

// A 2 x 1 x 0.5 box centred at (1, 0.5, 0.25) (its corner at the origin), outward triangles.
const char* kBoxObj =
    "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nv 0 0 0.5\nv 2 0 0.5\nv 2 1 0.5\nv 0 1 0.5\n"
    "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\n"
    "f 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";

const char* kScene = R"(format = "gauss6-scene"
version = 1
name = "test"

[gains]
ks = 0.5
kh = 100.0

[contact]
delta = 1e-5

[[obstacle]]
name = "floor"
mesh = "box.obj"
position = [0.0, 0.0, -1.0]

[god_object]
name = "brick"
mesh = "box.obj"
position = [0.0, 0.0, 1.0]
orientation = [1.0, 0.0, 0.0, 1.0]
density = 2.0

[device]
kind = "simulated"
script = "none"
)";

struct TempScene {
  fs::path dir;
  // A directory of its own (process id and a counter): tests run in parallel processes.
  explicit TempScene(const std::string& scene_text) {
    static int counter = 0;
    dir = fs::temp_directory_path() /
          ("gauss6_scene_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(dir);
    std::ofstream(dir / "box.obj") << kBoxObj;
    std::ofstream(dir / "scene.toml") << scene_text;
  }
  ~TempScene() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
  std::string path() const { return (dir / "scene.toml").string(); }
};

// Replaces the first occurrence of `from` in the valid scene.
std::string edited(const std::string& from, const std::string& to) {
  std::string s = kScene;
  const size_t at = s.find(from);
  REQUIRE(at != std::string::npos);
  return s.replace(at, from.size(), to);
}

// The loader's error message for a scene already written (fails the test when it loads).
std::string load_error_at(const TempScene& t) {
  try {
    load_scene(t.path());
  } catch (const SceneError& e) {
    return e.what();
  }
  FAIL("the scene loaded but should not have");
  return "";
}

// The loader's error message for a scene text (fails the test when it loads).
std::string load_error(const std::string& text) { return load_error_at(TempScene(text)); }

}  // namespace

TEST_CASE("a valid scene loads with its mass properties computed once", "[scene]") {
  TempScene t(kScene);
  const Scene s = load_scene(t.path());
  CHECK(s.name == "test");
  REQUIRE(s.obstacles.size() == 1);
  CHECK(s.obstacles[0].name == "floor");
  CHECK(s.gains.kh == 100.0);
  CHECK(s.contact.offset_eps == Approx(-1e-4));  // default -10 delta
  CHECK(s.contact.offset_time == 0.05);
  CHECK(s.device.rate_hz == 1000.0);
  CHECK(s.surface.kind == SurfaceKind::kNone);
  // Box 2 x 1 x 0.5 at density 2: mass 2, inertia m/12 (b^2 + c^2) etc. (rounding only).
  const MassProperties& mp = s.god_mass.mass;
  CHECK(mp.mass == Approx(2.0).epsilon(1e-14));
  CHECK(mp.inertia(0, 0) == Approx(2.0 / 12 * (1 + 0.25)).epsilon(1e-12));
  CHECK(mp.inertia(1, 1) == Approx(2.0 / 12 * (4 + 0.25)).epsilon(1e-12));
  CHECK(mp.inertia(2, 2) == Approx(2.0 / 12 * (4 + 1)).epsilon(1e-12));
  // The body frame's origin is the centre of mass; the pose is the pose of G:
  // the mesh frame sits at (0, 0, 1) rotated 90 degrees about z, so G = (0, 0, 1) + Rz (1, 0.5, 0.25).
  CHECK(mp.center_of_mass.norm() < 1e-14);
  CHECK((s.god_object.pose.p - Vec3(-0.5, 1.0, 1.25)).norm() < 1e-14);
  // M = diag(m I, R I R^T): the 90-degree turn swaps the x and y inertias.
  const Mat6 M = god_object_mass_matrix(s, s.god_object.pose.q);
  CHECK(M(0, 0) == Approx(2.0));
  CHECK(M(3, 3) == Approx(mp.inertia(1, 1)).epsilon(1e-12));
  CHECK(M(4, 4) == Approx(mp.inertia(0, 0)).epsilon(1e-12));
}

TEST_CASE("scene summaries report world-frame bounding boxes and mass properties", "[scene]") {
  TempScene t(kScene);
  const Scene s = load_scene(t.path());
  const auto sum = summarize_scene(s, /*count_self_intersections=*/true);
  REQUIRE(sum.size() == 2);
  CHECK(sum[0].role == BodyRole::kObstacle);
  CHECK(sum[0].mass == Approx(1.0));  // volume, at density 1
  CHECK((sum[0].bbox_min_W - Vec3(0, 0, -1)).norm() < 1e-15);
  CHECK((sum[0].bbox_max_W - Vec3(2, 1, -0.5)).norm() < 1e-15);
  CHECK(sum[1].num_triangles == 12);
  CHECK(sum[1].closed);
  CHECK(sum[1].manifold);
  CHECK(sum[1].num_self_intersections == 0);
  CHECK((sum[1].bbox_min_W - Vec3(-1, 0, 1)).norm() < 1e-14);
  CHECK((sum[1].bbox_max_W - Vec3(0, 2, 1.5)).norm() < 1e-14);
}

TEST_CASE("bad scenes are errors that name the file, line and key", "[scene]") {
  using Catch::Matchers::Contains;
  // Unknown key, with its line.
  CHECK_THAT(load_error(edited("ks = 0.5", "ks = 0.5\nkd = 3.0")), Contains("scene.toml:7:1: gains.kd: unknown key"));
  // Missing key.
  CHECK_THAT(load_error(edited("kh = 100.0\n", "")), Contains("gains.kh: missing"));
  // Bad values.
  CHECK_THAT(load_error(edited("delta = 1e-5", "delta = -1.0")), Contains("contact.delta: must be > 0"));
  CHECK_THAT(load_error(edited("density = 2.0", "density = \"heavy\"")), Contains("god_object.density: must be a number"));
  CHECK_THAT(load_error(edited("position = [0.0, 0.0, 1.0]", "position = [0.0, 1.0]")),
             Contains("god_object.position: must be an array of 3 numbers"));
  CHECK_THAT(load_error(edited("version = 1", "version = 3")), Contains("version: unsupported version 3"));
  CHECK_THAT(load_error(edited("kind = \"simulated\"", "kind = \"telepathic\"")), Contains("device.kind: must be"));
  CHECK_THAT(load_error(edited("script = \"none\"", "script = \"none\"\ntrace = \"x.g6t\"")),
             Contains("device.trace: not a key of a \"simulated\" device"));
  CHECK_THAT(load_error(edited("density = 2.0", "density = 2.0\nmass = 1.0")), Contains("give either density"));
  CHECK_THAT(load_error(edited("name = \"brick\"", "name = \"floor\"")), Contains("already the name of another body"));
  CHECK_THAT(load_error(edited("orientation = [1.0, 0.0, 0.0, 1.0]", "orientation = [0.0, 0.0, 0.0, 0.0]")),
             Contains("god_object.orientation: must be a non-zero quaternion"));
  // A missing mesh file names the mesh key and the file.
  CHECK_THAT(load_error(edited("mesh = \"box.obj\"", "mesh = \"nowhere.obj\"")),
             Contains("obstacle[0].mesh") && Contains("nowhere.obj"));
  // TOML syntax errors carry the parser's line.
  CHECK_THAT(load_error(edited("ks = 0.5", "ks = = 0.5")), Contains("scene.toml:6:"));
}

// Version 2 states a texture's amplitude in scene units; version 1 stated the
// height field's steepest slope, converted at load into the same field.
TEST_CASE("texture amplitudes are in scene units, version 1's slopes are converted", "[scene]") {
  using Catch::Matchers::Contains;
  const auto text = [](int version, const char* texture, const char* amplitude) {
    const std::string s = edited("version = 1", "version = " + std::to_string(version));
    const size_t device = s.find("[device]");
    return s.substr(0, device) + "[surface]\nkind = \"texture\"\ntexture = \"" + texture + "\"\namplitude = " +
           amplitude + "\nwavelength = 0.01\n\n" + s.substr(device);
  };
  const auto amplitude = [&](int version, const char* texture, const char* a) {
    TempScene t(text(version, texture, a));
    return load_scene(t.path()).surface.amplitude;
  };
  const double pi = 3.14159265358979323846;
  CHECK(amplitude(2, "sine", "0.0008") == 0.0008);
  CHECK(std::abs(amplitude(1, "sine", "0.5") - 0.5 * 0.01 / (2 * pi)) <= 1e-18);
  CHECK(std::abs(amplitude(1, "bumps", "0.5") - 0.5 * 0.01 / pi) <= 1e-18);
  // Scene units have no upper bound; a version 1 slope still must be in (0, 1].
  CHECK(amplitude(2, "sine", "2.0") == 2.0);
  CHECK_THAT(load_error(text(1, "sine", "2.0")), Contains("surface.amplitude: must be in (0, 1] (version 1: a slope)"));
  CHECK_THAT(load_error(text(2, "sine", "0.0")), Contains("surface.amplitude: must be > 0"));
}

// Vertex normals from a PLY file (nx, ny, nz) reach the scene, normalised, for
// force shading; a count that does not match the vertices is refused by name.
TEST_CASE("vertex normals given in a PLY mesh are loaded for force shading", "[scene]") {
  using Catch::Matchers::Contains;
  // The box of kBoxObj, each vertex's normal along its outward diagonal (length sqrt(3), not unit).
  const double c[8][3] = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}, {0, 0, 0.5}, {2, 0, 0.5}, {2, 1, 0.5}, {0, 1, 0.5}};
  const int f[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                        {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  auto ply = [&](int num_normals_rows) {
    std::ostringstream o;
    o << "ply\nformat ascii 1.0\nelement vertex 8\nproperty double x\nproperty double y\nproperty double z\n"
      << (num_normals_rows ? "property double nx\nproperty double ny\nproperty double nz\n" : "")
      << "element face 12\nproperty list uchar int vertex_indices\nend_header\n";
    for (const auto& v : c) {
      o << v[0] << " " << v[1] << " " << v[2];
      if (num_normals_rows) o << " " << (v[0] > 0 ? 1 : -1) << " " << (v[1] > 0 ? 1 : -1) << " " << (v[2] > 0 ? 1 : -1);
      o << "\n";
    }
    for (const auto& t : f) o << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
    return o.str();
  };
  TempScene t(edited("mesh = \"box.obj\"", "mesh = \"box.ply\""));
  std::ofstream(t.dir / "box.ply") << ply(1);
  const Scene s = load_scene(t.path());
  const MatrixX3d& N = s.obstacles[0].given_normals;
  REQUIRE(N.rows() == 8);
  for (int v = 0; v < 8; ++v) {
    CHECK(std::abs(N.row(v).norm() - 1) <= 1e-15);
    CHECK(N(v, 0) * (c[v][0] > 0 ? 1 : -1) > 0.57);  // along the outward diagonal: 1 / sqrt(3) each
  }
  // Force shading takes them as they are: every corner of a vertex gets its given normal.
  {
    std::string shaded = edited("mesh = \"box.obj\"", "mesh = \"box.ply\"");
    shaded.insert(shaded.find("[device]"), "[surface]\nkind = \"force_shading\"\n\n");
    std::ofstream(t.dir / "scene.toml") << shaded;
    const Scene sc = load_scene(t.path());
    const RuntimeModel model(sc, RuntimeSettings{});  // the floor: identity orientation, normals as given
    const SurfaceModel& surface = model.surface;
    REQUIRE(surface.obstacles.size() == 1);
    const TriangleMesh& m = sc.obstacles[0].mesh;
    for (int f = 0; f < num_triangles(m); ++f)
      for (int k = 0; k < 3; ++k)
        CHECK((surface.obstacles[0].corner_normals[3 * f + k] - N.row(m.F(f, k)).transpose()).norm() <= 1e-15);
    std::ofstream(t.dir / "scene.toml") << edited("mesh = \"box.obj\"", "mesh = \"box.ply\"");
  }
  // Without normals in the file: none given (the shading computes them); the god-object's OBJ neither.
  std::ofstream(t.dir / "box.ply") << ply(0);
  CHECK(load_scene(t.path()).obstacles[0].given_normals.rows() == 0);
  CHECK(load_scene(t.path()).god_object.given_normals.rows() == 0);
  // A zero normal is refused, naming the vertex.
  std::string zero = ply(1);
  zero.replace(zero.find("0 0 0 -1 -1 -1"), 14, "0 0 0 0 0 0");
  std::ofstream(t.dir / "box.ply") << zero;
  CHECK_THAT(load_error_at(t), Contains("vertex 0's normal is zero or not finite"));
}

// OBJ vn normals (through the face corners) and NOFF normals reach the scene the
// same way, normalised; a zero one is refused, naming the vertex.
TEST_CASE("vertex normals given in an OBJ or NOFF mesh are loaded for force shading", "[scene]") {
  using Catch::Matchers::Contains;
  // kBoxObj with vertex i's normal in vn record i (along its outward diagonal), every corner naming it.
  std::string obj = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nv 0 0 0.5\nv 2 0 0.5\nv 2 1 0.5\nv 0 1 0.5\n"
                    "vn -1 -1 -1\nvn 1 -1 -1\nvn 1 1 -1\nvn -1 1 -1\nvn -1 -1 1\nvn 1 -1 1\nvn 1 1 1\nvn -1 1 1\n";
  std::string noff = "NOFF\n8 12 0\n0 0 0 -1 -1 -1\n2 0 0 1 -1 -1\n2 1 0 1 1 -1\n0 1 0 -1 1 -1\n"
                     "0 0 0.5 -1 -1 1\n2 0 0.5 1 -1 1\n2 1 0.5 1 1 1\n0 1 0.5 -1 1 1\n";
  {
    std::istringstream faces(std::string(kBoxObj).substr(std::string(kBoxObj).find('f')));
    for (std::string f; faces >> f;) {
      int a, b, c;
      faces >> a >> b >> c;
      obj += "f " + std::to_string(a) + "//" + std::to_string(a) + " " + std::to_string(b) + "//" + std::to_string(b) +
             " " + std::to_string(c) + "//" + std::to_string(c) + "\n";
      noff += "3 " + std::to_string(a - 1) + " " + std::to_string(b - 1) + " " + std::to_string(c - 1) + "\n";
    }
  }
  for (const std::string& name : {"box.obj", "box.off"}) {
    INFO(name);
    const std::string& text = name == std::string("box.obj") ? obj : noff;
    TempScene t(edited("mesh = \"box.obj\"", "mesh = \"" + std::string(name) + "\""));
    std::ofstream(t.dir / name) << text;
    const Scene s = load_scene(t.path());
    const MatrixX3d& N = s.obstacles[0].given_normals;
    REQUIRE(N.rows() == 8);
    for (int v = 0; v < 8; ++v) {
      CHECK(std::abs(N.row(v).norm() - 1) <= 1e-15);
      CHECK(std::abs(std::abs(N(v, 2)) - 1 / std::sqrt(3.0)) <= 1e-15);  // the diagonal, normalised
    }
    std::string zero = text;
    const std::string first = name == std::string("box.obj") ? "vn -1 -1 -1" : "0 0 0 -1 -1 -1";
    zero.replace(zero.find(first), first.size(), name == std::string("box.obj") ? "vn 0 0 0" : "0 0 0 0 0 0");
    std::ofstream(t.dir / name) << zero;
    CHECK_THAT(load_error_at(t), Contains("vertex 0's normal is zero or not finite"));
  }
}

TEST_CASE("given mass properties are validated", "[scene]") {
  using Catch::Matchers::Contains;
  const std::string given = "mass = 1.0\ncenter_of_mass = [1.0, 0.5, 0.25]\n";
  CHECK_THAT(load_error(edited("density = 2.0", given + "inertia = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]")),
             Contains("god_object.inertia: must be positive definite"));
  CHECK_THAT(load_error(edited("density = 2.0", given + "inertia = [[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]")),
             Contains("god_object.inertia: must be symmetric"));
  TempScene t(edited("density = 2.0", given + "inertia = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]]"));
  const Scene s = load_scene(t.path());
  CHECK_FALSE(s.god_mass.from_density);
  CHECK(s.god_mass.mass.mass == 1.0);
  CHECK(s.god_mass.mass.inertia(2, 2) == 3.0);
}

TEST_CASE("the settings rules are one function per table and the loader uses them", "[scene]") {
  using Catch::Matchers::Contains;
  CHECK_FALSE(check_gains(Gains{0.5, 100.0}));
  CHECK(check_gains(Gains{0.5, 0.0}).message() == "gains.kh: must be > 0");
  CHECK(check_gains(Gains{1.5, 100.0}).message() == "gains.ks: must be in (0, 1]");
  CHECK(check_gains(Gains{0.5, std::nan("")}).key == "kh");
  ContactParameters c;
  c.delta = 1e-5;
  c.offset_eps = -1e-4;
  CHECK_FALSE(check_contact_parameters(c));
  c.offset_eps = 0;
  CHECK(check_contact_parameters(c).message() == "contact.offset_eps: must be < 0");
  CHECK_FALSE(check_device_settings(DeviceSettings{}));  // the defaults meet the rules
  DeviceSettings d;
  d.rate_hz = 50;
  CHECK(check_device_settings(d).message() == "device.rate_hz: must be in [100, 10000]");
  SurfaceSettings s;
  s.kind = SurfaceKind::kTexture;
  s.amplitude = 0.2;
  s.wavelength = 0;
  CHECK(check_surface_settings(s).message() == "surface.wavelength: must be > 0");
  // The loader reports a broken rule at its key's line.
  CHECK_THAT(load_error(edited("kh = 100.0", "kh = 0.0")), Contains("scene.toml:7:6: gains.kh: must be > 0"));
  CHECK_THAT(load_error(edited("script = \"none\"", "script = \"none\"\nrate_hz = 50.0")),
             Contains("device.rate_hz: must be in [100, 10000]"));
}

TEST_CASE("contact.delta is refused outside its range of the scene's extent", "[scene][delta]") {
  using Catch::Matchers::Contains;
  // The test scene's extent: the god-object's far corner, rotated about x at (0, 0, 1).
  const double extent = scene_extent(load_scene(TempScene(kScene).path()));
  REQUIRE(extent > 1);
  // Below kMinDeltaPerExtent of it the god-object stopped sliding (scene.h), and the
  // delta of 1e-9..1e-14 that did so were accepted; above kMaxDeltaPerExtent the band
  // swallows the scene (0.5 and 1e300 were accepted).
  for (const char* bad : {"1e-9", "1e-12", "1e-14", "2e-6"})
    CHECK_THAT(load_error(edited("delta = 1e-5", std::string("delta = ") + bad)),
               Contains("contact.delta: must be at least 1e-6 of the scene's extent"));
  for (const char* bad : {"0.5", "1e300", "0.1"})
    CHECK_THAT(load_error(edited("delta = 1e-5", std::string("delta = ") + bad)),
               Contains("contact.delta: must be at most 1e-2 of the scene's extent"));
  // The bounds themselves are accepted (the rule and the loader are one function).
  for (const double ok : {kMinDeltaPerExtent * extent * (1 + 1e-15), kMaxDeltaPerExtent * extent * (1 - 1e-15)}) {
    Scene s = load_scene(TempScene(kScene).path());
    s.contact.delta = ok;
    CHECK_FALSE(check_delta_scale(s));
  }
}

TEST_CASE("the loader refuses what the runtime cannot represent, and names it", "[scene]") {
  // A 64-bit integer is not narrowed: 2^32 + 1 is not version 1.
  CHECK_THAT(load_error(edited("version = 1", "version = 4294967297")), Catch::Contains("unsupported version 4294967297"));
  // A mass in the subnormal range, and a reference point 1e17 away from the mesh.
  const std::string given = "mass = 1e-320\ncenter_of_mass = [0.0, 0.0, 0.0]\n"
                            "inertia = [[1e-320, 0.0, 0.0], [0.0, 1e-320, 0.0], [0.0, 0.0, 1e-320]]";
  CHECK_THAT(load_error(edited("density = 2.0", given)), Catch::Contains("god_object.mass: the mass must be within"));
  CHECK_THAT(load_error(edited("density = 2.0", "density = 2.0\nreference_point = [1e17, 0.0, 0.0]")),
             Catch::Contains("god_object.reference_point: must lie within 100 bounding-box diagonals"));
  CHECK_THAT(load_error(edited("position = [0.0, 0.0, -1.0]", "position = [1e300, 0.0, -1.0]")),
             Catch::Contains("obstacle[0].position: must be within"));
  CHECK_THAT(load_error(edited("kind = \"simulated\"\nscript = \"none\"", "kind = \"hid\"\nvendor_id = 4294967297")),
             Catch::Contains("device.vendor_id: must be a 16-bit USB id"));
}

TEST_CASE("a quaternion of huge components is normalised, not turned into NaN", "[scene]") {
  TempScene t(edited("orientation = [1.0, 0.0, 0.0, 1.0]", "orientation = [1e300, 0.0, 0.0, 1e300]"));
  const Scene s = load_scene(t.path());
  const Quat q = s.god_object.pose.q;
  CHECK(q.w == Approx(std::sqrt(0.5)));
  CHECK(q.z == Approx(std::sqrt(0.5)));
  CHECK(std::isfinite(q.x));
}

TEST_CASE("an inside-out closed obstacle is flipped with a warning", "[scene]") {
  // The box with every face wound the other way: closed, manifold, negative volume.
  std::string inside_out;
  std::istringstream in(kBoxObj);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("f ", 0) == 0) {
      int a, b, c;
      std::sscanf(line.c_str(), "f %d %d %d", &a, &b, &c);
      line = "f " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(b);
    }
    inside_out += line + "\n";
  }
  TempScene t(edited("mesh = \"box.obj\"", "mesh = \"inside_out.obj\""));
  std::ofstream(t.dir / "inside_out.obj") << inside_out;
  const Scene s = load_scene(t.path());
  REQUIRE(s.warnings.size() == 1);
  CHECK_THAT(s.warnings[0], Catch::Contains("obstacle[0].mesh") && Catch::Contains("inside out") &&
                                Catch::Contains("faces flipped"));
  MassProperties mp;
  REQUIRE(compute_mass_properties(s.obstacles[0].mesh, 1.0, &mp, nullptr));
  CHECK(mp.volume == Approx(1.0));
  // The shipped box is not touched.
  TempScene clean(kScene);
  CHECK(load_scene(clean.path()).warnings.empty());
}
