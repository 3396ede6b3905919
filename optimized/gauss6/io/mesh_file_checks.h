// Structural checks of mesh files (OFF, PLY, STL) made before CGAL's readers
// see them: headers are checked, and every count or list length the file states
// is bounded by what the rest of the file can hold, so that no reader allocates
// from a count that lies and none runs into a header it cannot handle (a PLY
// `property` line before any `element` line crashes CGAL 5.5's reader). OBJ has
// no counts and needs no check. Internal to gauss6_load (used by mesh_io.cpp).
#pragma once

#include <string>

namespace gauss6::detail {

// Throws MeshFileError(path, problem) when the file's structure is unusable; returns
// normally otherwise (the real parse may still refuse the content). `bytes` is the
// whole file.
void check_off_structure(const std::string& path, const std::string& bytes);
void check_ply_structure(const std::string& path, const std::string& bytes);
void check_stl_structure(const std::string& path, const std::string& bytes);

}  // namespace gauss6::detail
