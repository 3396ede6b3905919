// Mass properties of a closed triangle mesh at a uniform density: volume, mass,
// centre of mass and inertia tensor about the centre of mass (the mesh's frame),
// by the divergence theorem over the triangles (exact for polyhedra, up to rounding).
#pragma once

#include <string>

#include "gauss6/geometry/mesh.h"
#include "gauss6/geometry/pose.h"

namespace gauss6 {

struct MassProperties {
  double volume = 0;
  double mass = 0;
  Vec3 center_of_mass = Vec3::Zero();  // in the mesh's frame
  Mat3 inertia = Mat3::Zero();         // about the centre of mass, mesh's frame axes
};

// density in kg/m^3 (or any consistent unit: mass = density * volume). Requires a
// closed, consistently oriented mesh: every directed edge (a, b) matched by an
// edge (b, a), checked here exactly; outward normals give volume > 0. Moments are
// summed about the vertices' mean, so meshes far from the origin lose no accuracy.
// Returns false, leaves *out untouched and sets *error (if not null) when the mesh
// is empty, has an index out of range or a non-finite coordinate, is not closed
// and consistently oriented, encloses a volume <= 0 (inside out), or when density
// is not positive and finite. Load time only (allocates).
bool compute_mass_properties(const TriangleMesh& m, double density, MassProperties* out,
                             std::string* error);

// The 6x6 generalised mass matrix M = diag(m I3, R I R^T) in the world frame.
Mat6 mass_matrix(const MassProperties& mp, const Mat3& R_WB);

}  // namespace gauss6
