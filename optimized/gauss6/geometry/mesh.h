// Triangle meshes: vertices, triangles, vertex normals, edge adjacency, and the
// validation report (degenerate triangles, non-finite coordinates, open
// boundaries, non-manifold edges and vertices). Self-intersections need exact
// predicates and live in mesh_io.h (CGAL, scene load time only).
//
// libigl's conventions: V is #V by 3 (doubles, the mesh's own frame), F is #F by
// 3 (vertex indices, counter-clockwise seen from outside, so that face normals
// point out of a closed mesh).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace gauss6 {

using MatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using MatrixX3i = Eigen::Matrix<int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;
using MatrixX2i = Eigen::Matrix<int32_t, Eigen::Dynamic, 2, Eigen::RowMajor>;

// Edge adjacency, built once by build_adjacency(). Edge e joins E(e,0) < E(e,1);
// edges are numbered in lexicographic order of (E(e,0), E(e,1)).
struct MeshAdjacency {
  MatrixX2i E;           // #E by 2: unique undirected edges
  MatrixX3i FE;          // #F by 3: FE(f,k) = the edge from F(f,k) to F(f,(k+1)%3)
  MatrixX2i EF;          // #E by 2: the two lowest-numbered faces of each edge
                         // (-1 where absent: boundary; a non-manifold edge has more)
  std::vector<int32_t> edge_face_count;  // #E: faces using each edge (2 on a closed manifold)
  // Vertex -> incident faces in CSR form: faces of v are VF[VF_start[v] .. VF_start[v+1]).
  std::vector<int32_t> VF_start, VF;
};

struct TriangleMesh {
  MatrixX3d V;   // #V by 3 vertex positions
  MatrixX3i F;   // #F by 3 triangles
  MatrixX3d N;   // #V by 3 unit vertex normals (angle-weighted), empty until computed
  MeshAdjacency adjacency;  // empty until build_adjacency()
  std::string source;       // file it was read from, or a generator's name
};

int num_vertices(const TriangleMesh& m);
int num_triangles(const TriangleMesh& m);

// Fills m->adjacency from m->F. Throws std::invalid_argument if an index is out of
// range (validate_mesh() first to get a report instead). A triangle with a
// repeated index yields an edge (v, v) and is listed once per distinct vertex in VF.
void build_adjacency(TriangleMesh* m);
// Fills m->N with angle-weighted unit vertex normals (zero for isolated vertices).
void compute_vertex_normals(TriangleMesh* m);
// Unit face normal of triangle f, (b - a) x (c - a) normalised (zero vector when
// that cross product is zero or not finite).
Eigen::Vector3d face_normal(const TriangleMesh& m, int f);

// What validate_mesh() found. Index lists are capped at kMaxListed entries each
// (counts are exact). Triangles with bad indices are left out of the edge and
// vertex checks; edge indices follow build_adjacency()'s numbering over the
// remaining triangles (the same numbering when there are no bad triangles).
struct MeshReport {
  static constexpr int kMaxListed = 32;
  int num_vertices = 0, num_triangles = 0, num_edges = 0;
  int num_nonfinite_vertices = 0;      // vertices with a NaN or infinite coordinate
  int num_bad_indices = 0;             // triangles with an index out of range or repeated
  int num_degenerate_triangles = 0;    // zero area: exactly collinear corners, decided by
                                       // exact orientation predicates (not by rounding)
  int num_boundary_edges = 0;          // edges with one face: the mesh is open
  int num_nonmanifold_edges = 0;       // edges with more than two faces
  int num_nonmanifold_vertices = 0;    // vertices whose faces form several fans
  int num_inconsistent_edges = 0;      // edges used twice in the same direction (orientation flips)
  int num_isolated_vertices = 0;       // vertices in no triangle
  int num_self_intersections = -1;     // intersecting triangle pairs; -1: not checked
  std::vector<int> nonfinite_vertices, bad_triangles, degenerate_triangles,
      boundary_edges, nonmanifold_edges, nonmanifold_vertices, inconsistent_edges,
      isolated_vertices;
  bool closed() const { return num_boundary_edges == 0 && num_nonmanifold_edges == 0; }
  bool manifold() const {
    return num_nonmanifold_edges == 0 && num_nonmanifold_vertices == 0 && num_inconsistent_edges == 0;
  }
  // True when the mesh is fit to be a body: at least one triangle, finite, valid
  // indices, no degenerate triangle, no isolated vertex (it would be a phantom
  // contact point), closed, manifold, and no self-intersection (if checked).
  bool ok() const;
  // One line per problem found, naming it and the first indices; empty when ok().
  std::string describe() const;
};

// Combinatorial and floating-point checks (no self-intersection test: see
// count_self_intersections in mesh_io.h).
MeshReport validate_mesh(const TriangleMesh& m);

}  // namespace gauss6
