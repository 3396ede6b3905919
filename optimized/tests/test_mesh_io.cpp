// Tests of mesh_io.h: round trips through OBJ, OFF, PLY and STL, a clear
// MeshFileError naming the file for each kind of bad file, and the CGAL
// self-intersection count.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "gauss6/geometry/mass_properties.h"
#include "gauss6/io/mesh_io.h"
#include "mesh_shapes.h"

using namespace gauss6;
using gauss6::test::concatenate;
using gauss6::test::make_box;
using gauss6::test::make_icosphere;

namespace {

namespace fs = std::filesystem;

// A fresh directory under the system's temporary directory, removed at scope exit.
struct TempDir {
  fs::path path;
  TempDir() {
    std::random_device rd;
    path = fs::temp_directory_path() /
           ("gauss6_meshio_" + std::to_string(rd()) + std::to_string(rd()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
  std::string write(const std::string& name, const std::string& content) const {
    std::ofstream(file(name), std::ios::binary) << content;
    return file(name);
  }
};

double volume_of(const TriangleMesh& m) {
  MassProperties mp;
  std::string error;
  REQUIRE(compute_mass_properties(m, 1.0, &mp, &error));
  return mp.volume;
}

// Reading `path` (the mesh, or with `normals` its vertex normals) must throw a
// MeshFileError whose message names the file (its base name at least) and contains `what`.
void require_file_error(const std::string& path, const std::string& what, bool normals = false) {
  INFO(path);
  try {
    if (normals)
      read_vertex_normals(path);
    else
      read_mesh(path);
    FAIL("no MeshFileError for " << path);
  } catch (const MeshFileError& e) {
    const std::string msg = e.what();
    INFO(msg);
    CHECK(msg.find(fs::path(path).filename().string()) != std::string::npos);
    CHECK(msg.find(what) != std::string::npos);
  }
}

const char* kTriangleObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

}  // namespace

TEST_CASE("Box round trip through OBJ, OFF, PLY and STL", "[meshio]") {
  const TempDir dir;
  // Dyadic sizes and centre: every coordinate is exact in float, so even STL's
  // 32-bit floats keep it exactly.
  const TriangleMesh box = make_box(0.5, 1.25, 2.75, Vec3(1.5, -0.25, 3.0));
  const double volume = volume_of(box);
  for (const char* ext : {"obj", "off", "ply", "stl", "OBJ"}) {
    INFO(ext);
    const std::string path = dir.file(std::string("box.") + ext);
    write_mesh(path, box);
    const TriangleMesh back = read_mesh(path);
    CHECK(back.source == path);
    CHECK(num_vertices(back) == 8);    // STL: shared corners merged back to 8
    CHECK(num_triangles(back) == 12);
    CHECK(volume_of(back) == volume);  // same coordinates, same sums
    CHECK(validate_mesh(back).ok());
  }
}

TEST_CASE("OBJ, OFF and PLY keep doubles and vertex numbering exactly", "[meshio]") {
  const TempDir dir;
  TriangleMesh sphere = make_icosphere(2, 1.0 / 3.0);  // coordinates with full mantissas
  sphere.V.col(0).array() += 0.1;
  for (const char* ext : {"obj", "off", "ply"}) {
    INFO(ext);
    const std::string path = dir.file(std::string("sphere.") + ext);
    write_mesh(path, sphere);
    const TriangleMesh back = read_mesh(path);
    CHECK(back.V == sphere.V);  // bit for bit (17 digits in text, binary doubles in PLY)
    CHECK(back.F == sphere.F);
  }
}

TEST_CASE("Malformed mesh files give a MeshFileError naming the file", "[meshio]") {
  const TempDir dir;
  require_file_error(dir.file("missing.obj"), "no such file");
  require_file_error(dir.write("empty.obj", ""), "empty");
  require_file_error(dir.write("empty.stl", ""), "empty");
  require_file_error(dir.write("blank.stl", "   \n"), "empty");
  require_file_error(dir.write("garbage.obj", "this is not a mesh\n"), "cannot parse as OBJ");
  require_file_error(dir.write("garbage.off", "OFF\n3 1 0\n0 0 zero\n"), "cannot parse as OFF");
  require_file_error(dir.write("garbage.ply", "ply\nformat nonsense\n"), "cannot parse as PLY");
  require_file_error(dir.write("quad.obj", std::string(kTriangleObj) + "v 1 1 0\nf 1 2 4 3\n"),
                     "face 0 has 4 corners; only triangles are supported");
  require_file_error(dir.write("quad.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n"),
                     "face 0 has 4 corners");
  // Index 4 of 3 vertices (1-based), one past the end: CGAL 5.5's OBJ reader lets
  // it through, our own check names it. Farther out, CGAL's readers refuse the file.
  require_file_error(dir.write("index.obj", std::string(kTriangleObj) + "f 1 2 3\nf 1 2 4\n"),
                     "face 1 refers to vertex 3");
  require_file_error(dir.write("index_far.obj", std::string(kTriangleObj) + "f 1 2 9\n"),
                     "cannot parse as OBJ");
  require_file_error(dir.write("index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
                     "cannot parse as OFF");
  require_file_error(dir.write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), "nan.obj");
  require_file_error(dir.write("nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
                     "nan.off");
  require_file_error(dir.write("no_faces.obj", kTriangleObj), "no_faces.obj");
  require_file_error(dir.write("mesh.xyz", "whatever"), "unknown mesh format '.xyz'");
  // Writing to a directory that does not exist fails with the path in the message.
  try {
    write_mesh(dir.file("no/such/dir/box.obj"), make_box(1, 1, 1));
    FAIL("no MeshFileError");
  } catch (const MeshFileError& e) {
    CHECK(std::string(e.what()).find("box.obj") != std::string::npos);
  }
}

TEST_CASE("Self-intersections: none on closed bodies, some on interpenetrating boxes", "[meshio]") {
  CHECK(count_self_intersections(make_box(1, 2, 3)) == 0);
  CHECK(count_self_intersections(make_icosphere(3, 1.0)) == 0);

  const TriangleMesh a = make_box(1, 1, 1);
  const TriangleMesh apart = concatenate(a, make_box(1, 1, 1, Vec3(3, 0, 0)));
  CHECK(count_self_intersections(apart) == 0);

  // Shifted by half a side along x (and a little along y, z so that no faces
  // are coplanar): the faces of each box cross the other's.
  const TriangleMesh overlapping = concatenate(a, make_box(1, 1, 1, Vec3(0.5, 0.25, 0.125)));
  const int pairs = count_self_intersections(overlapping);
  CHECK(pairs > 0);

  // The report's field is filled by the caller from this count.
  MeshReport r = validate_mesh(overlapping);
  CHECK(r.ok());  // every combinatorial check passes: only the exact test sees it
  r.num_self_intersections = pairs;
  CHECK_FALSE(r.ok());
  CHECK(r.describe().find("self-intersecting") != std::string::npos);

  TriangleMesh bad = a;
  bad.F(0, 0) = 99;
  CHECK_THROWS_AS(count_self_intersections(bad), std::invalid_argument);
}

TEST_CASE("Mesh files whose headers are broken or whose counts lie are refused before any reader allocates",
          "[meshio]") {
  const TempDir dir;
  // A `property` line before any `element` line crashed CGAL 5.5's PLY reader.
  require_file_error(dir.write("property_first.ply", "ply\nformat ascii 1.0\nproperty float x\nelement vertex 1\n"
                                                     "end_header\n0\n"),
                     "a 'property' line before any 'element' line");
  // Counts that lie: a few hundred bytes stating billions of items or list entries.
  require_file_error(dir.write("lying_vertices.ply", "ply\nformat ascii 1.0\nelement vertex 4000000000\n"
                                                     "property float x\nproperty float y\nproperty float z\n"
                                                     "end_header\n0 0 0\n"),
                     "more than the file can hold");
  require_file_error(dir.write("lying_list.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                                 "property float y\nproperty float z\nelement face 1\n"
                                                 "property list uint int vertex_indices\nend_header\n"
                                                 "0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n"),
                     "bad list length");
  // ASCII values are whole numbers of their type: CGAL's reader stopped inside
  // "0-4000" and took -4000 as the face's list length (2^32 - 4000: 17 GB; the fuzzer's).
  {
    const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                               "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    require_file_error(dir.write("glued.ply", header + "0 0 0\n1 0 0\n0 1 0-4000 1 2\n"), "'0-4000' is not a value of type float");
    require_file_error(dir.write("hex.ply", header + "0 0 0\n1 0 0\n0 0x1 0\n3 0 1 2\n"), "'0x1' is not a value of type float");
    require_file_error(dir.write("float_index.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n"), "'2.5' is not a value of type int");
    // Signs, exponents and bare points are numbers.
    CHECK(read_mesh(dir.write("numbers.ply", header + "+0 -0. .0\n1e0 0 0E+1\n0 1.0 -2.5e-3\n3 0 1 +2\n")).F.rows() == 1);
  }
  {
    // Binary: a list length of 2^32 - 1 int32 values in a file of 200 bytes.
    std::string ply = "ply\nformat binary_little_endian 1.0\nelement face 1\n"
                      "property list uint int vertex_indices\nend_header\n";
    ply += std::string("\xff\xff\xff\xff", 4) + std::string(12, '\0');
    require_file_error(dir.write("lying_binary_list.ply", ply), "more than the file holds");
  }
  {
    std::string ply = "ply\nformat binary_little_endian 1.0\nelement face 1\n"
                      "property list int int vertex_indices\nend_header\n";
    ply += std::string("\xff\xff\xff\xff", 4);  // -1 as a list length
    require_file_error(dir.write("negative_list.ply", ply), "negative or non-integer list length");
  }
  require_file_error(dir.write("no_properties.ply", "ply\nformat ascii 1.0\nelement vertex 99999999999\nend_header\n"),
                     "but no properties");
  // CGAL doubles the edge count in an int (the fuzzer's 2 * 2087506048).
  require_file_error(dir.write("edges.off", "OFF\n3 1 2087506048\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                     "the edge count 2087506048 is over 1073741823");
  CHECK(read_mesh(dir.write("edges_max.off", "OFF\n3 1 1073741823\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")).F.rows() == 1);
  require_file_error(dir.write("lying.off", "OFF\n2000000000 2000000000 0\n0 0 0\n"), "more than a file of");
  require_file_error(dir.write("short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n"), "the file holds 2");
  require_file_error(dir.write("corners.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n99999999999 0 1 2\n"),
                     "states more corners than the line holds");
  // CGAL casts face indices read as doubles to size_t: 1e26 or -1 was undefined behaviour.
  require_file_error(dir.write("huge_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 155555555555555555555555555\n"),
                     "not a vertex number below 3");
  require_file_error(dir.write("negative_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n"),
                     "not a vertex number below 3");
  // CGAL's header reader swallows the character after the keyword: "OFF#3333" made it
  // read 333,333,330 vertices from the comment and allocate 8 GB (found by the fuzzer).
  require_file_error(dir.write("glued_comment.off", "OFF#333333330 0\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                     "a comment right after 'OFF'");
  require_file_error(dir.write("glued_comment_noff.off", "NOFF#9 9 9\n1 0 0\n0 0 0 0 0 1\n"),
                     "a comment right after 'NOFF'");
  // Set apart by a space, the comment is read as one by both.
  CHECK(read_mesh(dir.write("spaced_comment.off", "OFF #333333330 0\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")).F.rows() == 1);
  require_file_error(dir.write("color.off", "COFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), "variant 'COFF'");
  {
    std::string stl(80, ' ');
    stl += std::string("\xff\xff\xff\x7f", 4) + std::string(50, '\0');  // 2^31 - 1 facets announced, 1 present
    require_file_error(dir.write("lying.stl", stl), "the file holds 1");
  }
}

TEST_CASE("Mesh files holding more records than their headers state are refused, naming the line", "[meshio]") {
  // The readers stop at the stated counts: the rest of the file (faces, vertices,
  // values, facets) was dropped silently, a mesh other than the file's.
  const TempDir dir;
  require_file_error(dir.write("extra_face.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n"),
                     "line 8: more records than the header states (4 vertices, 1 faces)");
  require_file_error(dir.write("extra_after_comment.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n# end\n3 0 1 2\n"),
                     "line 8: more records");
  // Comments and blank lines after the last face are no records.
  CHECK(read_mesh(dir.write("trailing_comment.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n# end\n\n")).F.rows() == 1);
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                             "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  require_file_error(dir.write("extra_face.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n"),
                     "line 14: more values than the header's elements state");
  CHECK(read_mesh(dir.write("trailing_space.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n\n  \n")).F.rows() == 1);
  {
    std::string ply = "ply\nformat binary_little_endian 1.0\nelement face 1\n"
                      "property list uchar int vertex_indices\nend_header\n";
    const std::string face = std::string("\x03", 1) + std::string(12, '\0');
    require_file_error(dir.write("extra_binary.ply", ply + face + face), "13 bytes after the header's elements");
  }
  {
    std::string stl(80, ' ');
    stl += std::string("\x01\0\0\0", 4) + std::string(100, '\0');  // 1 facet stated, 2 held
    require_file_error(dir.write("extra.stl", stl), "the header states 1 facets, the file holds 2");
  }
}

// OBJ `vn` normals reach the vertices through the face corners that reference
// them; NOFF normals follow each vertex's coordinates. Exact comparisons: the
// values are short decimals read from text into doubles, copied unchanged.
TEST_CASE("OBJ vn and NOFF vertex normals are read per vertex", "[meshio]") {
  TempDir dir;
  // A tetrahedron; vn records out of vertex order, the last corner by a negative (relative) index.
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
      "vn 0 0 -2\nvn 1 0 0\nvn 0 1 0\nvn 0.5 0.5 0.5\n"
      "f 1//1 3//3 2//2\nf 1/1/1 2//2 4//4\nf 1//1 4//4 3//3\nf 2//2 3//3 4//-1\n";
  const std::string good = dir.write("tet.obj", obj);
  REQUIRE(read_mesh(good).V.rows() == 4);
  MatrixX3d N = read_vertex_normals(good);
  REQUIRE(N.rows() == 4);
  CHECK(N.row(0) == Eigen::RowVector3d(0, 0, -2));  // as stored, not normalised
  CHECK(N.row(1) == Eigen::RowVector3d(1, 0, 0));
  CHECK(N.row(2) == Eigen::RowVector3d(0, 1, 0));
  CHECK(N.row(3) == Eigen::RowVector3d(0.5, 0.5, 0.5));
  // Two vn records with the same numbers on corners of one vertex are one normal.
  {
    std::string dup = obj;
    dup.replace(dup.find("f 2//2 3//3 4//-1"), 17, "f 2//2 3//3 4//5");
    dup.replace(dup.find("f 1//1"), 0, "vn 0.5 0.5 0.5\n");
    CHECK(read_vertex_normals(dir.write("dup.obj", dup)).row(3) == Eigen::RowVector3d(0.5, 0.5, 0.5));
  }
  // No vn records: none given (the shading computes them).
  CHECK(read_vertex_normals(dir.write("plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")).rows() == 0);
  // Malformed.
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = obj;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  require_file_error(dir.write("range.obj", with("4//-1", "4//9")), "names no vertex normal (there are 4 so far)", true);
  require_file_error(dir.write("zero_index.obj", with("4//-1", "4//0")), "names no vertex normal", true);
  require_file_error(dir.write("vertex_range.obj", with("f 1//1 3//3", "f 7//1 3//3")), "names no vertex", true);
  require_file_error(dir.write("crease.obj", with("4//-1", "4//3")),
                     "vertex 3 has different normals on its face corners (vn 4 on face 1, vn 3 on face 3)", true);
  require_file_error(dir.write("bare.obj", with("4//-1", "4")), "face 3 gives vertex 3 no normal", true);
  require_file_error(dir.write("short_vn.obj", with("vn 0 1 0\n", "vn 0 1\n")), "line 7: a vn record needs 3 numbers", true);
  require_file_error(dir.write("word_vn.obj", with("vn 0 1 0\n", "vn 0 one 0\n")), "vn component 'one' is not a finite number", true);
  require_file_error(dir.write("nan_vn.obj", with("vn 0 1 0\n", "vn 0 nan 0\n")), "is not a finite number", true);
  require_file_error(dir.write("lonely.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nvn 0 0 1\nf 1//1 2//1 3//1\n"),
                     "vertex 3 is on no face corner, so it has no normal", true);

  // NOFF: read_mesh reads the coordinates, read_vertex_normals the normals.
  const std::string noff = "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0.25 1\n0 1 0 0 0 3\n3 0 1 2\n";
  const std::string noff_path = dir.write("tri.off", noff);
  const TriangleMesh m = read_mesh(noff_path);
  REQUIRE(m.V.rows() == 3);
  CHECK(m.V.row(1) == Eigen::RowVector3d(1, 0, 0));
  N = read_vertex_normals(noff_path);
  REQUIRE(N.rows() == 3);
  CHECK(N.row(0) == Eigen::RowVector3d(0, 0, 1));
  CHECK(N.row(1) == Eigen::RowVector3d(0, 0.25, 1));
  CHECK(N.row(2) == Eigen::RowVector3d(0, 0, 3));
  CHECK(read_vertex_normals(dir.write("plain.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")).rows() == 0);
  // A NOFF vertex line without its normal is refused before CGAL reads it.
  require_file_error(dir.write("short.off", "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0\n0 1 0 0 0 1\n3 0 1 2\n"),
                     "line 4: a NOFF vertex needs 3 coordinates and 3 normal components");
}
