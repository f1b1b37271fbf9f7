#pragma once
/// \file
/// The closed boundary surface of a tet mesh, and the checks that make it safe to use.

#include <string>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess {

/// Faces of exactly one tet, wound outward, in tet-mesh node ids; plus the surface and interior
/// node lists. Deterministic order (sorted by the owning tet, then local face).
Surface extract_surface(const TetMesh& mesh);

/// Validates a tet mesh and its boundary: finite coordinates, indices in range, no degenerate
/// or inverted tets, boundary closed (border edges counted), edge- and vertex-manifold, one
/// connected component (the count is reported), free of self-intersection at rest.
/// Throws InputError(`file`, message) naming the first defect found.
void validate_tet_mesh(const TetMesh& mesh, const Surface& surface, const std::string& file);

/// The same surface checks for a triangle mesh that is about to be tetrahedralised or used as
/// a conductor: closed, manifold, one component, no zero-area triangles, no self-intersection.
void validate_closed_surface(const TriangleMesh& mesh, const std::string& file);

/// Signed volume enclosed by outward triangles (positive for a valid surface).
double enclosed_volume(const std::vector<Vec3>& points, const std::vector<Tri>& triangles);

/// Sum of tet volumes (positive for positively oriented tets).
double total_tet_volume(const TetMesh& mesh);

}  // namespace tetseg::preprocess
