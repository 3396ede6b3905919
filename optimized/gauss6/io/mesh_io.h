// Mesh files (OBJ, OFF, PLY, STL) and the self-intersection test, both through
// CGAL (optimized/gauss6/io/, one translation unit each). Scene-load time only:
// never called from a real-time loop.
#pragma once

#include <string>

#include "gauss6/io/load_error.h"
#include "gauss6/geometry/mesh.h"

namespace gauss6 {

// Errors are MeshFileError (load_error.h) for a missing, unreadable or malformed
// mesh file; what() names the file and the problem ("bunny.obj: face 12 has 4
// corners; only triangles are supported").

// Reads a triangle mesh by extension (.obj .off .ply .stl, case-insensitive).
// OBJ, OFF and PLY keep the file's vertex numbering; STL corners with exactly equal
// coordinates are merged into shared vertices. Sets source = path. Throws
// MeshFileError for a missing or empty file, unparsable content, a face that is not
// a triangle, a vertex index out of range or a non-finite coordinate. Does not
// validate the mesh (see validate_mesh() and count_self_intersections()).
TriangleMesh read_mesh(const std::string& path);
// The vertex normals a mesh file gives, one row per vertex as stored (not
// normalised), or an empty matrix when it gives none. PLY: the vertex element's
// nx, ny, nz properties (all three), read with CGAL's point-set PLY reader. NOFF:
// the normal after each vertex's coordinates, read with CGAL's OFF reader. OBJ:
// the `vn` record the vertex's face corners name (CGAL 5.5's OBJ reader discards
// them, so a strict reader of v, vn and f records, every index bounds-checked);
// corners of one vertex naming records with different numbers are refused (a
// crease), and with vn records every corner must name one. Plain OFF, OBJ
// without vn and STL: none. Call after read_mesh() succeeded on the same path.
// Throws MeshFileError.
MatrixX3d read_vertex_normals(const std::string& path);
// Writes by extension (.obj .off .ply .stl). OBJ/OFF are text with 17 significant
// digits and PLY is binary (both round-trip doubles exactly); binary STL stores
// 32-bit floats. Throws MeshFileError.
void write_mesh(const std::string& path, const TriangleMesh& m);

// Number of pairs of triangles that intersect other than along a shared edge or
// vertex (CGAL exact predicates); a degenerate triangle counts as one pair (f, f).
// Meant for meshes that pass validate_mesh(): at non-manifold vertices and edges,
// triangles that only touch there are counted too. Throws std::invalid_argument
// for a non-finite coordinate or a bad (out-of-range or repeated) index.
int count_self_intersections(const TriangleMesh& m);

}  // namespace gauss6
