#pragma once
/// \file
/// The closed boundary surface of a tet mesh, and the checks that make it safe to use.

#include <string>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess {

/// Faces of exactly one tet, wound outward, in tet-mesh node ids; plus the surface and interior
/// node lists. Deterministic order (sorted by the owning tet, then local face). The winding
/// assumes positively oriented tets (the face opposite vertex i has its normal pointing away
/// from vertex i); faces shared by three or more tets are not boundary faces (validation
/// rejects them). Never throws on bad indices (they may appear in triangles; validate first).
/// Nodes used by no tet are listed as interior. Cost: O(T), faces matched by blocks of node
/// ids with a hash table per block, on OpenMP threads (about 0.6 s of CPU for 4.8 M tets);
/// throws std::length_error at 2^30 tets or more. Thread-safe.
Surface extract_surface(const TetMesh& mesh);

/// Validates a tet mesh and its boundary (`surface`, normally extract_surface(mesh)), in this
/// order: at least one tet; finite coordinates; indices in range; every node used by a tet;
/// no degenerate tet (|6 volume| <= 1e-12 x longest edge^3) and no inverted tet (counts and
/// the first index are reported); no face shared by more than two tets; then the surface:
/// closed (border edges counted), edge-manifold, consistently oriented, vertex-manifold (one
/// fan of triangles per vertex), free of self-intersection at rest (a median-split BVH over
/// the triangles' boxes, then CGAL's exact predicates on the pairs whose boxes touch: the same
/// pairs as CGAL's self_intersections, tested); no boundary triangle too thin for the charge
/// solver (area at most 1e-12 x the longest boundary edge^2 or 1e-10 x its own longest edge^2:
/// what charge would refuse); then per component (nodes joined through tets; a mesh may have
/// several): bounded by exactly one closed surface (no cavity), not inside another
/// component (docs/segmentation.md, "Several components").
/// Throws InputError(`file`, message) naming the first defect found, e.g. "surface is not
/// closed (3 border edges, first between vertices 4 and 7)". Cost: the face matching of
/// extract_surface with the O(T) checks of the tets made in its counting pass, O(B log B)
/// checks of the B boundary triangles and the self-intersection test (about 1.2 s of CPU for
/// 4.8 M tets / 104k triangles with the extraction; docs/benchmarks-history.md, "Scale").
/// Thread-safe.
void validate_tet_mesh(const TetMesh& mesh, const Surface& surface, const std::string& file);

/// extract_surface then validate_tet_mesh (same result, same InputError), matching the faces
/// once instead of twice: what every tool stage that reads a tet mesh runs. Thread-safe.
Surface extract_valid_surface(const TetMesh& mesh, const std::string& file);

/// The same surface checks for a triangle mesh that is about to be tetrahedralised or used as
/// a conductor: finite coordinates, indices in range, no zero-area triangle (|2 area| <=
/// 1e-12 x longest edge^2, or a repeated vertex), then closed, edge-manifold, consistently
/// oriented, vertex-manifold, one component (several with `allow_components`, as
/// tetrahedralize accepts: it meshes each closed component and refuses nested ones), no
/// self-intersection. Orientation (inward or outward) is not checked. Throws
/// InputError(`file`, message). Thread-safe.
void validate_closed_surface(const TriangleMesh& mesh, const std::string& file,
                             bool allow_components = false);

/// Signed volume enclosed by outward triangles (positive for a valid surface).
double enclosed_volume(const std::vector<Vec3>& points, const std::vector<Tri>& triangles);

/// Sum of tet volumes (positive for positively oriented tets).
double total_tet_volume(const TetMesh& mesh);

}  // namespace tetseg::preprocess
