// Mesh files (OBJ, OFF, PLY, STL) through CGAL's polygon-soup readers and
// writers (and a strict reader of OBJ vn normals, which CGAL 5.5 discards), with
// every failure turned into a MeshFileError that names the file and the problem.
// Scene-load time only. Only the four format headers are included,
// to keep this translation unit cheap to compile.
#include "gauss6/io/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include <CGAL/Simple_cartesian.h>
#include <CGAL/IO/OBJ.h>
#include <CGAL/IO/OFF.h>
#include <CGAL/IO/PLY.h>
#include <CGAL/IO/STL.h>
#include <CGAL/IO/read_ply_points.h>
#include <CGAL/property_map.h>

#include "mesh_file_checks.h"

namespace gauss6 {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;  // coordinates only: no predicates needed here
using Point = Kernel::Point_3;
using Polygon = std::vector<std::size_t>;

// Larger mesh files are refused before they are read (the bunny is 2 MB).
constexpr std::uintmax_t kMaxMeshFileBytes = std::uintmax_t(1) << 30;

enum class Format { kObj, kOff, kPly, kStl };

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw MeshFileError(path, what);
}

// The format named by the file's extension (case-insensitive).
Format format_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (ext == ".obj") return Format::kObj;
  if (ext == ".off") return Format::kOff;
  if (ext == ".ply") return Format::kPly;
  if (ext == ".stl") return Format::kStl;
  fail(path, "unknown mesh format '" + ext + "' (expected .obj, .off, .ply or .stl)");
}

const char* format_name(Format f) {
  switch (f) {
    case Format::kObj: return "OBJ";
    case Format::kOff: return "OFF";
    case Format::kPly: return "PLY";
    case Format::kStl: return "STL";
  }
  return "?";
}

}  // namespace

TriangleMesh read_mesh(const std::string& path) {
  const Format format = format_of(path);

  // Missing, unreadable and empty files get their own messages (CGAL's readers
  // only say "false").
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    fail(path, "no such file (or not a regular file)");
  if (!std::ifstream(path, std::ios::binary).good()) fail(path, "cannot open the file for reading");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (size == 0) fail(path, "the file is empty");
  if (size > kMaxMeshFileBytes)
    fail(path, "the file has " + std::to_string(size) + " bytes, more than the " +
                   std::to_string(kMaxMeshFileBytes) + " a mesh file may have");

  // Headers checked and every count bounded by the file's size before CGAL's
  // readers allocate anything from them (mesh_file_checks.h).
  {
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    switch (format) {
      case Format::kObj: break;  // no counts
      case Format::kOff: detail::check_off_structure(path, bytes); break;
      case Format::kPly: detail::check_ply_structure(path, bytes); break;
      case Format::kStl: detail::check_stl_structure(path, bytes); break;
    }
  }

  std::vector<Point> points;
  std::vector<Polygon> polygons;
  const auto quiet = CGAL::parameters::verbose(false);
  bool parsed = false;
  try {
    switch (format) {
      case Format::kObj: parsed = CGAL::IO::read_OBJ(path, points, polygons, quiet); break;
      case Format::kOff: parsed = CGAL::IO::read_OFF(path, points, polygons, quiet); break;
      case Format::kPly: parsed = CGAL::IO::read_PLY(path, points, polygons, quiet); break;
      // CGAL's STL reader already shares exactly equal corners between facets (it
      // indexes points through a std::map), which is the duplicate-point merge STL
      // needs; other formats keep the file's own vertex numbering.
      case Format::kStl: parsed = CGAL::IO::read_STL(path, points, polygons, quiet); break;
    }
  } catch (const std::bad_alloc&) {
    fail(path, "out of memory while reading the file");
  } catch (const std::exception& e) {
    fail(path, std::string("cannot parse as ") + format_name(format) + ": " + e.what());
  }
  if (!parsed)
    fail(path, std::string("cannot parse as ") + format_name(format) +
                   " (malformed line, non-numeric or non-finite coordinate, bad face index, "
                   "or no faces)");
  if (points.empty() || polygons.empty()) fail(path, "no vertices or no faces: the mesh is empty");
  if (points.size() > static_cast<std::size_t>(std::numeric_limits<int32_t>::max()) ||
      polygons.size() > static_cast<std::size_t>(std::numeric_limits<int32_t>::max()))
    fail(path, "more than 2^31 - 1 vertices or faces");

  // Copy into the library's arrays, checking each face and coordinate.
  TriangleMesh m;
  m.source = path;
  m.V.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point& p = points[i];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
      fail(path, "vertex " + std::to_string(i) + " has a non-finite coordinate");
    m.V.row(static_cast<Eigen::Index>(i)) << p.x(), p.y(), p.z();
  }
  m.F.resize(static_cast<Eigen::Index>(polygons.size()), 3);
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const Polygon& poly = polygons[f];
    if (poly.size() != 3)
      fail(path, "face " + std::to_string(f) + " has " + std::to_string(poly.size()) +
                     " corners; only triangles are supported");
    for (int k = 0; k < 3; ++k) {
      if (poly[k] >= points.size())
        fail(path, "face " + std::to_string(f) + " refers to vertex " +
                       std::to_string(static_cast<long long>(poly[k])) + " but there are " +
                       std::to_string(points.size()) + " vertices (0-based)");
      m.F(static_cast<Eigen::Index>(f), k) = static_cast<int32_t>(poly[k]);
    }
  }
  return m;
}

namespace {

// One OBJ index token ("7", "-1"): 1-based, or negative counting back from the
// last record of its kind read so far. Returns the 0-based index, or -1 when the
// token is not an integer or falls outside [0, count).
long long obj_index(const std::string& token, long long count) {
  if (token.empty()) return -1;
  std::size_t used = 0;
  long long k = 0;
  try {
    k = std::stoll(token, &used);
  } catch (const std::exception&) {
    return -1;
  }
  if (used != token.size() || k == 0) return -1;
  const long long i = k > 0 ? k - 1 : count + k;
  return (i >= 0 && i < count) ? i : -1;
}

// OBJ vertex normals from `vn` records and the corners of `f` records that
// reference them ("f v//vn" or "f v/vt/vn"). Only v, vn and f records are
// looked at; read_mesh() already read the vertices and faces. Rule: a vertex's
// normal is the one its face corners reference; corners of one vertex may name
// different vn records only if those hold the same three numbers, otherwise the
// file is refused (the vertex is on a crease, which per-vertex normals cannot
// express). With vn records, every vertex must be on a corner that gives one.
// No vn record: empty matrix (computed normals are used).
// Not tinyobjloader (Debian's libtinyobjloader-dev 2.0.0~rc10, tried): it
// accepted, with no error or warning, "vn 0 abc 1" (read as 0 0 1), "vn 0 0 1
// 5", a corner "1x//1" (atoi: read as 1) and corners naming vertex 7 or -9 of 3
// (returned as indices 6 and -6); the refusals below would need a second pass
// over the text anyway.
MatrixX3d read_obj_normals(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open the file for reading");
  std::vector<Kernel::Vector_3> vn;
  std::vector<long long> of_vertex;  // vn index per vertex, -1 when none yet
  std::vector<long long> first_face;  // face that set it, for messages
  long long nv = 0, nf = 0, line_no = 0;
  bool corner_without_normal = false;
  long long bare_face = -1, bare_vertex = -1;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    std::istringstream words(line);
    std::string kind;
    if (!(words >> kind)) continue;
    const std::string at = "line " + std::to_string(line_no) + ": ";
    if (kind == "v") {
      ++nv;
      of_vertex.push_back(-1);
      first_face.push_back(-1);
    } else if (kind == "vn") {
      std::string word;
      double c[3];
      for (double& x : c) {
        if (!(words >> word)) fail(path, at + "a vn record needs 3 numbers");
        std::size_t used = 0;
        try {
          x = std::stod(word, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != word.size() || !std::isfinite(x))
          fail(path, at + "vn component '" + word + "' is not a finite number");
      }
      if (words >> word) fail(path, at + "a vn record has more than 3 numbers");
      vn.emplace_back(c[0], c[1], c[2]);
    } else if (kind == "f") {
      for (std::string corner; words >> corner;) {
        const std::size_t s1 = corner.find('/');
        const long long v = obj_index(corner.substr(0, s1), nv);
        if (v < 0)
          fail(path, at + "face " + std::to_string(nf) + " corner '" + corner +
                         "' names no vertex (there are " + std::to_string(nv) + " so far)");
        const std::size_t s2 = s1 == std::string::npos ? s1 : corner.find('/', s1 + 1);
        if (s2 == std::string::npos) {
          if (!corner_without_normal) bare_face = nf, bare_vertex = v;
          corner_without_normal = true;
          continue;
        }
        const long long n = obj_index(corner.substr(s2 + 1), static_cast<long long>(vn.size()));
        if (n < 0)
          fail(path, at + "face " + std::to_string(nf) + " corner '" + corner +
                         "' names no vertex normal (there are " + std::to_string(vn.size()) + " so far)");
        long long& mine = of_vertex[static_cast<std::size_t>(v)];
        if (mine >= 0 && mine != n && vn[static_cast<std::size_t>(mine)] != vn[static_cast<std::size_t>(n)])
          fail(path, at + "vertex " + std::to_string(v) + " has different normals on its face corners (vn " +
                         std::to_string(mine + 1) + " on face " + std::to_string(first_face[static_cast<std::size_t>(v)]) +
                         ", vn " + std::to_string(n + 1) + " on face " + std::to_string(nf) +
                         "); a vertex takes one normal");
        if (mine < 0) mine = n, first_face[static_cast<std::size_t>(v)] = nf;
      }
      ++nf;
    }
  }
  if (vn.empty()) return {};
  if (corner_without_normal)
    fail(path, "face " + std::to_string(bare_face) + " gives vertex " + std::to_string(bare_vertex) +
                   " no normal, but the file has vn records: every face corner must name one");
  MatrixX3d N(static_cast<Eigen::Index>(nv), 3);
  for (long long v = 0; v < nv; ++v) {
    const long long n = of_vertex[static_cast<std::size_t>(v)];
    if (n < 0) fail(path, "vertex " + std::to_string(v) + " is on no face corner, so it has no normal");
    const Kernel::Vector_3& d = vn[static_cast<std::size_t>(n)];
    N.row(static_cast<Eigen::Index>(v)) << d.x(), d.y(), d.z();
  }
  return N;
}

// NOFF vertex normals (a normal after each vertex's coordinates), through CGAL's
// OFF reader; empty for plain OFF.
MatrixX3d read_noff_normals(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open the file for reading");
  std::string header;
  in >> header;
  if (header != "NOFF") return {};
  in.clear();
  in.seekg(0);
  std::vector<Point> points;
  std::vector<Polygon> polygons;
  std::vector<Kernel::Vector_3> normals;
  bool parsed = false;
  try {
    parsed = CGAL::IO::read_OFF(in, points, polygons,
                                CGAL::parameters::vertex_normal_output_iterator(std::back_inserter(normals))
                                    .verbose(false));
  } catch (const std::bad_alloc&) {
    fail(path, "out of memory while reading the vertex normals");
  } catch (const std::exception& e) {
    fail(path, std::string("cannot read the vertex normals: ") + e.what());
  }
  if (!parsed) fail(path, "cannot read the vertex normals (NOFF)");
  MatrixX3d N(static_cast<Eigen::Index>(normals.size()), 3);
  for (std::size_t i = 0; i < normals.size(); ++i)
    N.row(static_cast<Eigen::Index>(i)) << normals[i].x(), normals[i].y(), normals[i].z();
  return N;
}

}  // namespace

MatrixX3d read_vertex_normals(const std::string& path) {
  const Format format = format_of(path);
  if (format == Format::kObj) return read_obj_normals(path);
  if (format == Format::kOff) return read_noff_normals(path);
  if (format != Format::kPly) return {};
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open the file for reading");
  // The header (checked by read_mesh): does the vertex element have nx, ny and nz?
  bool in_vertex = false;
  int found = 0;
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string first, type, name;
    words >> first;
    if (first == "end_header") break;
    if (first == "element") {
      words >> name;
      in_vertex = name == "vertex" || name == "vertices";
    } else if (first == "property" && in_vertex && words >> type >> name) {
      if (name == "nx" || name == "ny" || name == "nz") ++found;
    }
  }
  if (found != 3) return {};
  using PointNormal = std::pair<Point, Kernel::Vector_3>;
  std::vector<PointNormal> read;
  in.clear();
  in.seekg(0);
  bool parsed = false;
  try {
    parsed = CGAL::IO::read_PLY_with_properties(
        in, std::back_inserter(read), CGAL::IO::make_ply_point_reader(CGAL::First_of_pair_property_map<PointNormal>()),
        CGAL::IO::make_ply_normal_reader(CGAL::Second_of_pair_property_map<PointNormal>()));
  } catch (const std::bad_alloc&) {
    fail(path, "out of memory while reading the vertex normals");
  } catch (const std::exception& e) {
    fail(path, std::string("cannot read the vertex normals: ") + e.what());
  }
  if (!parsed) fail(path, "cannot read the vertex normals (nx, ny, nz)");
  MatrixX3d N(static_cast<Eigen::Index>(read.size()), 3);
  for (std::size_t i = 0; i < read.size(); ++i) {
    const Kernel::Vector_3& n = read[i].second;
    N.row(static_cast<Eigen::Index>(i)) << n.x(), n.y(), n.z();
  }
  return N;
}

void write_mesh(const std::string& path, const TriangleMesh& m) {
  const Format format = format_of(path);
  const int nv = num_vertices(m);
  std::vector<Point> points;
  points.reserve(static_cast<std::size_t>(nv));
  for (int i = 0; i < nv; ++i) points.emplace_back(m.V(i, 0), m.V(i, 1), m.V(i, 2));
  std::vector<Polygon> polygons;
  polygons.reserve(static_cast<std::size_t>(num_triangles(m)));
  for (int f = 0; f < num_triangles(m); ++f) {
    for (int k = 0; k < 3; ++k)
      if (m.F(f, k) < 0 || m.F(f, k) >= nv)
        fail(path, "cannot write: triangle " + std::to_string(f) + " has vertex index " +
                       std::to_string(m.F(f, k)) + " out of range");
    polygons.push_back({static_cast<std::size_t>(m.F(f, 0)), static_cast<std::size_t>(m.F(f, 1)),
                        static_cast<std::size_t>(m.F(f, 2))});
  }

  // OBJ and OFF are text: 17 significant digits make doubles round-trip exactly.
  // PLY is written in binary (doubles, exact). Binary STL stores 32-bit floats.
  const auto exact_text = CGAL::parameters::stream_precision(17);
  bool written = false;
  switch (format) {
    case Format::kObj: written = CGAL::IO::write_OBJ(path, points, polygons, exact_text); break;
    case Format::kOff: written = CGAL::IO::write_OFF(path, points, polygons, exact_text); break;
    case Format::kPly: written = CGAL::IO::write_PLY(path, points, polygons); break;
    case Format::kStl: written = CGAL::IO::write_STL(path, points, polygons); break;
  }
  if (!written) fail(path, std::string("cannot write ") + format_name(format) + " file");
}

}  // namespace gauss6
