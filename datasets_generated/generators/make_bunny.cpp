// gauss6_make_bunny: the Stanford bunny of METHOD.md section 7 (about 27,000
// triangles), made from glmark2-data's bunny.obj, and the mesh checker used on
// every generated dataset.
//
//   gauss6_make_bunny INPUT OUTPUT.off TARGET_FACES HEIGHT [--comment TEXT]...
//       Reads INPUT (any format CGAL reads), scales it uniformly so that its
//       bounding box is HEIGHT tall along Y (HEIGHT = 0 keeps the coordinates)
//       and centres the box on the origin, removes its self-intersections,
//       decimates it to about TARGET_FACES triangles (Garland-Heckbert plane
//       quadrics, bounded normal change), orients it outward, writes OUTPUT as
//       ASCII OFF ("OFF", one "# TEXT" line per --comment, counts, vertices with
//       17 significant digits: exact doubles, triangles), then reads OUTPUT back
//       and checks it as below.
//   gauss6_make_bunny --check MESH
//       Reads MESH as a polygon soup (CGAL::IO::read_polygon_soup) and checks
//       that it is a closed, 2-manifold, outward-oriented triangle mesh with no
//       degenerate triangle and no self-intersection (exact predicates).
//
// Both print one line of JSON with the mesh's statistics and exit 0 when every
// check passes, 1 (with the failed checks on stderr) otherwise, 2 on bad usage.
// The output is deterministic: the same input and arguments give the same bytes.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_self_intersections.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Polygon_mesh_processing/transform.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_filter.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Aff_transformation_3.h>

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;
namespace SMS = CGAL::Surface_mesh_simplification;

// What the checks found on one mesh.
struct MeshReport {
  std::size_t num_vertices = 0;
  std::size_t num_faces = 0;
  bool triangles_only = true;
  bool soup_is_mesh = false;      // edges shared by <= 2 consistently oriented faces, no pinched vertex
  bool closed = false;
  std::size_t num_non_manifold_vertices = 0;
  std::size_t num_degenerate_faces = 0;
  std::size_t num_self_intersections = 0;  // intersecting face pairs
  double volume = 0.0;            // signed: > 0 when oriented outward (closed meshes only)
  CGAL::Bbox_3 bbox;

  std::vector<std::string> failures() const {
    std::vector<std::string> f;
    if (!triangles_only) f.push_back("a face is not a triangle");
    if (!soup_is_mesh) f.push_back("not a polygon mesh (non-manifold edge/vertex or inconsistent orientation)");
    if (soup_is_mesh && !closed) f.push_back("not closed (open boundary)");
    if (num_non_manifold_vertices) f.push_back(std::to_string(num_non_manifold_vertices) + " non-manifold vertices");
    if (num_degenerate_faces) f.push_back(std::to_string(num_degenerate_faces) + " degenerate triangles");
    if (num_self_intersections) f.push_back(std::to_string(num_self_intersections) + " self-intersecting face pairs");
    if (closed && !(volume > 0.0)) f.push_back("not oriented outward (volume " + std::to_string(volume) + ")");
    return f;
  }
};

// Closedness, manifoldness, degenerate faces, self-intersections, orientation.
void check_mesh(const Mesh& mesh, MeshReport& r) {
  r.num_vertices = num_vertices(mesh);
  r.num_faces = num_faces(mesh);
  r.closed = CGAL::is_closed(mesh);
  std::vector<Mesh::Halfedge_index> nm;
  PMP::non_manifold_vertices(mesh, std::back_inserter(nm));
  r.num_non_manifold_vertices = nm.size();
  for (Mesh::Face_index f : faces(mesh))
    if (PMP::is_degenerate_triangle_face(f, mesh)) ++r.num_degenerate_faces;
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  PMP::self_intersections(mesh, std::back_inserter(pairs));
  r.num_self_intersections = pairs.size();
  if (r.closed) r.volume = CGAL::to_double(PMP::volume(mesh));  // PMP::volume is unsigned: sign it below
  if (r.closed && r.num_self_intersections == 0 && !PMP::is_outward_oriented(mesh)) r.volume = -r.volume;
  r.bbox = PMP::bbox(mesh);
}

// Reads a file as a polygon soup (as the scene loader does) and checks it.
MeshReport check_file(const std::string& path) {
  MeshReport r;
  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
  if (!CGAL::IO::read_polygon_soup(path, points, polygons, CGAL::parameters::verbose(false)) || polygons.empty())
    throw std::runtime_error(path + ": cannot read as a polygon soup");
  for (const auto& p : polygons) r.triangles_only = r.triangles_only && p.size() == 3;
  r.soup_is_mesh = PMP::is_polygon_soup_a_polygon_mesh(polygons);
  r.num_vertices = points.size();
  r.num_faces = polygons.size();
  if (!r.triangles_only || !r.soup_is_mesh) return r;
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  check_mesh(mesh, r);
  return r;
}

// Deterministic ASCII OFF: 17 significant digits round-trip every double exactly.
void write_off(const std::string& path, const Mesh& mesh, const std::vector<std::string>& comments) {
  std::FILE* out = std::fopen(path.c_str(), "wb");
  if (!out) throw std::runtime_error(path + ": cannot open for writing");
  std::fprintf(out, "OFF\n");
  for (const auto& c : comments) std::fprintf(out, "# %s\n", c.c_str());
  std::fprintf(out, "%zu %zu 0\n", static_cast<std::size_t>(num_vertices(mesh)),
               static_cast<std::size_t>(num_faces(mesh)));
  // After collect_garbage() the indices are 0..n-1 in storage order.
  for (Mesh::Vertex_index v : vertices(mesh)) {
    const Point& p = mesh.point(v);
    std::fprintf(out, "%.17g %.17g %.17g\n", p.x() + 0.0, p.y() + 0.0, p.z() + 0.0);  // + 0.0: no "-0"
  }
  for (Mesh::Face_index f : faces(mesh)) {
    std::fprintf(out, "3");
    for (Mesh::Vertex_index v : vertices_around_face(halfedge(f, mesh), mesh))
      std::fprintf(out, " %u", static_cast<unsigned>(v.idx()));
    std::fprintf(out, "\n");
  }
  if (std::fclose(out) != 0) throw std::runtime_error(path + ": write failed");
}

std::string json_report(const MeshReport& r, const std::string& extra) {
  std::ostringstream s;
  s.precision(17);
  s << "{\"vertices\": " << r.num_vertices << ", \"triangles\": " << r.num_faces
    << ", \"closed\": " << (r.closed ? "true" : "false")
    << ", \"manifold\": " << (r.soup_is_mesh && r.num_non_manifold_vertices == 0 ? "true" : "false")
    << ", \"degenerate_triangles\": " << r.num_degenerate_faces
    << ", \"self_intersections\": " << r.num_self_intersections << ", \"volume\": " << r.volume
    << ", \"bbox_min\": [" << r.bbox.xmin() << ", " << r.bbox.ymin() << ", " << r.bbox.zmin() << "]"
    << ", \"bbox_max\": [" << r.bbox.xmax() << ", " << r.bbox.ymax() << ", " << r.bbox.zmax() << "]"
    << extra << "}";
  return s.str();
}

int report_and_exit_code(const std::string& path, const MeshReport& r, const std::string& extra) {
  std::cout << json_report(r, extra) << std::endl;
  const auto failures = r.failures();
  for (const auto& f : failures) std::cerr << path << ": " << f << "\n";
  return failures.empty() ? 0 : 1;
}

int make_bunny(const std::string& input, const std::string& output, long target_faces, double height,
               const std::vector<std::string>& comments) {
  const auto t0 = std::chrono::steady_clock::now();
  Mesh mesh;
  if (!CGAL::IO::read_polygon_mesh(input, mesh, CGAL::parameters::verbose(false)) || is_empty(mesh))
    throw std::runtime_error(input + ": cannot read as a polygon mesh");
  if (!CGAL::is_triangle_mesh(mesh)) throw std::runtime_error(input + ": not a triangle mesh");
  const std::size_t input_faces = num_faces(mesh);

  // Scale to HEIGHT along Y and centre the bounding box on the origin, before any
  // check, so that the checks see the coordinates that are written.
  if (height > 0.0) {
    const CGAL::Bbox_3 b = PMP::bbox(mesh);
    const double s = height / (b.ymax() - b.ymin());
    const double cx = 0.5 * (b.xmin() + b.xmax()), cy = 0.5 * (b.ymin() + b.ymax()),
                 cz = 0.5 * (b.zmin() + b.zmax());
    for (Mesh::Vertex_index v : vertices(mesh)) {
      const Point& p = mesh.point(v);
      mesh.point(v) = Point((p.x() - cx) * s, (p.y() - cy) * s, (p.z() - cz) * s);
    }
  }

  // Remove self-intersections (the glmark2 bunny has two intersecting pairs).
  if (PMP::does_self_intersect(mesh) && !PMP::experimental::remove_self_intersections(mesh))
    throw std::runtime_error(input + ": remove_self_intersections failed");

  // Decimate. Count_stop_predicate counts edges in CGAL 5.5: a closed triangle mesh
  // has E = 3F/2 edges.
  const std::size_t target_edges = static_cast<std::size_t>(target_faces) * 3 / 2;
  SMS::GarlandHeckbert_plane_policies<Mesh, Kernel> gh(mesh);
  SMS::Count_stop_predicate<Mesh> stop(target_edges);
  SMS::Bounded_normal_change_filter<> filter;
  SMS::edge_collapse(mesh, stop,
                     CGAL::parameters::get_cost(gh.get_cost()).get_placement(gh.get_placement()).filter(filter));
  mesh.collect_garbage();

  if (CGAL::is_closed(mesh) && !PMP::does_self_intersect(mesh) && !PMP::is_outward_oriented(mesh))
    PMP::reverse_face_orientations(mesh);
  write_off(output, mesh, comments);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // Check what was written, read back as the loader reads it.
  const MeshReport r = check_file(output);
  std::ostringstream extra;
  extra << ", \"input_triangles\": " << input_faces << ", \"seconds\": " << seconds;
  return report_and_exit_code(output, r, extra.str());
}

int usage() {
  std::cerr << "usage: gauss6_make_bunny INPUT OUTPUT.off TARGET_FACES HEIGHT [--comment TEXT]...\n"
               "       gauss6_make_bunny --check MESH\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc == 3 && std::string(argv[1]) == "--check") {
      const std::string path = argv[2];
      return report_and_exit_code(path, check_file(path), "");
    }
    if (argc < 5) return usage();
    char* end = nullptr;
    const long target_faces = std::strtol(argv[3], &end, 10);
    if (*end != '\0' || target_faces < 4) return usage();
    const double height = std::strtod(argv[4], &end);
    if (*end != '\0' || !(height >= 0.0) || !std::isfinite(height)) return usage();
    std::vector<std::string> comments;
    for (int i = 5; i < argc; i += 2) {
      if (std::string(argv[i]) != "--comment" || i + 1 >= argc) return usage();
      const std::string c = argv[i + 1];
      if (c.find('\n') != std::string::npos) return usage();
      comments.push_back(c);
    }
    return make_bunny(argv[1], argv[2], target_faces, height, comments);
  } catch (const std::exception& e) {
    std::cerr << "gauss6_make_bunny: " << e.what() << "\n";
    return 1;
  }
}
