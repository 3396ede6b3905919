// Self-intersection count of a triangle mesh with CGAL's exact predicates
// (Polygon_mesh_processing::self_intersections on a Surface_mesh built from the
// triangle soup). Scene-load time only; kept apart from mesh_io.cpp because this
// translation unit is the expensive one to compile.
#include "gauss6/io/mesh_io.h"

#include <array>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <stdexcept>
#include <utility>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

namespace gauss6 {

int count_self_intersections(const TriangleMesh& m) {
  namespace PMP = CGAL::Polygon_mesh_processing;
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;

  // The soup, with the preconditions CGAL relies on checked here.
  const int nv = num_vertices(m), nf = num_triangles(m);
  if (!m.V.allFinite())
    throw std::invalid_argument("count_self_intersections: '" + m.source +
                                "' has a non-finite vertex coordinate");
  std::vector<Kernel::Point_3> points;
  points.reserve(static_cast<std::size_t>(nv));
  for (int i = 0; i < nv; ++i) points.emplace_back(m.V(i, 0), m.V(i, 1), m.V(i, 2));
  std::vector<std::array<std::size_t, 3>> triangles(static_cast<std::size_t>(nf));
  for (int f = 0; f < nf; ++f) {
    const int a = m.F(f, 0), b = m.F(f, 1), c = m.F(f, 2);
    if (a < 0 || a >= nv || b < 0 || b >= nv || c < 0 || c >= nv || a == b || b == c || c == a)
      throw std::invalid_argument("count_self_intersections: '" + m.source + "' triangle " +
                                  std::to_string(f) + " has a bad vertex index");
    triangles[f] = {static_cast<std::size_t>(a), static_cast<std::size_t>(b),
                    static_cast<std::size_t>(c)};
  }
  if (nf == 0) return 0;

  // A Surface_mesh needs a manifold, consistently oriented soup. Otherwise CGAL
  // re-orients it and duplicates the points at non-manifold vertices and edges;
  // triangles that only touch there then count as intersecting (such a mesh
  // already fails validate_mesh()).
  if (!PMP::is_polygon_soup_a_polygon_mesh(triangles)) PMP::orient_polygon_soup(points, triangles);
  if (!PMP::is_polygon_soup_a_polygon_mesh(triangles))
    throw std::invalid_argument("count_self_intersections: '" + m.source +
                                "' cannot be made into a polygon mesh");
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, triangles, mesh);

  // Pairs of faces meeting other than along a shared edge or at a shared vertex;
  // a degenerate face is reported once, as the pair (f, f).
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  PMP::self_intersections(mesh, std::back_inserter(pairs));
  return static_cast<int>(pairs.size());
}

}  // namespace gauss6
