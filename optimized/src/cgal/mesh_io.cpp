// Mesh files (OBJ, OFF, PLY, STL) through CGAL's polygon-soup readers and
// writers, with every failure turned into a MeshFileError that names the file and
// the problem. Scene-load time only. Only the four format headers are included,
// to keep this translation unit cheap to compile.
#include "gauss6/mesh_io.h"

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

#include "load/mesh_file_checks.h"

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

MatrixX3d read_vertex_normals(const std::string& path) {
  if (format_of(path) != Format::kPly) return {};
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
