#pragma once
// Private: the face matching shared by extract_surface and validate_tet_mesh, and the CGAL
// self-intersection test (kept in its own translation unit).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "components.hpp"
#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess::detail {

/// A tet is degenerate when |6 volume| <= kDegenerateTetVolume x (longest edge)^3.
inline constexpr double kDegenerateTetVolume = 1e-12;

/// The checks of each tet that validate_tet_mesh reports, made while matching faces (the one
/// pass that reads every tet's nodes).
struct TetChecks {
  std::size_t first_out_of_range = SIZE_MAX;  ///< smallest tet with a node id out of range
  std::size_t unused = 0;                     ///< nodes used by no tet
  std::uint32_t first_unused = 0;
  /// Degenerate and inverted tets (among those with ids in range), and the first of each.
  std::size_t degenerate = 0, inverted = 0;
  std::size_t first_degenerate = SIZE_MAX, first_inverted = SIZE_MAX;
};

/// The faces of a tet mesh matched by their node sets (surface.cpp).
struct FaceMatch {
  /// Per tet: bit f set when face f (opposite vertex f) belongs to no other tet.
  std::vector<std::uint8_t> boundary;
  /// Distinct faces shared by three or more tets, and the smallest of them (sorted node ids,
  /// compared lexicographically).
  std::size_t crowded = 0;
  std::array<std::uint32_t, 3> first_crowded{};
  /// Whether `tets` was filled (match_faces with check_tets).
  bool tets_checked = false;
  TetChecks tets;
  /// With check_tets and every node id in range: tet_node_roots (components.hpp), computed
  /// by one thread while the others match faces.
  std::vector<std::uint32_t> node_roots;
};

/// Matches the faces of every tet in O(T): a counting sort into blocks of smallest-node ids,
/// then a hash table per block. With `check_tets`, the counting pass also fills
/// FaceMatch::tets (node ranges, node use, degenerate and inverted tets; each tet's nodes are
/// read once, prefetched a few tets ahead since a mesh's node order rarely follows its tets)
/// and the hashing pass FaceMatch::node_roots.
/// Any indices (out-of-range ones included); throws std::length_error at 2^30 tets or more.
/// Uses OpenMP threads when built with them; the result does not depend on their number.
FaceMatch match_faces(const TetMesh& mesh, bool check_tets);

/// The Surface (order, winding, node lists) described by extract_surface, from `match`.
Surface surface_from_faces(const TetMesh& mesh, const FaceMatch& match);

/// validate_tet_mesh given the face matching of `mesh` (made with check_tets). Returns each
/// node's component, as check_components found them.
NodeParts validate_tet_mesh(const TetMesh& mesh, const Surface& surface, const FaceMatch& match,
                            const std::string& file);

/// extract_valid_surface, also giving each node's component (for split_surface).
Surface extract_valid_surface(const TetMesh& mesh, const std::string& file, NodeParts& parts);

/// Pairs of intersecting triangles (indices into `triangles`; empty when none) of a closed,
/// edge- and vertex-manifold, consistently oriented triangle surface whose indices are in
/// range. Triangles sharing a vertex or an edge only count if they overlap beyond it.
std::vector<std::pair<std::size_t, std::size_t>> self_intersecting_pairs(
    const std::vector<Vec3>& points, const std::vector<Tri>& triangles);

/// Throws InputError naming `file` and the first point (`noun` i) with a NaN or infinite
/// coordinate.
void check_finite(const std::vector<Vec3>& points, const std::string& file, const char* noun);
/// Throws InputError naming `file` and the first triangle referring to a vertex out of range.
void check_triangle_indices(const TriangleMesh& mesh, const std::string& file);

/// Options of the surface checks shared by validate_closed_surface and tetrahedralize.
struct SurfaceCheck {
  /// Accept vertices where several fans touch at one point (a "pinch", e.g. two vertices of
  /// a modelled surface that coincide): the Mesh_3 domain oracle handles them, and triangle
  /// pairs that only meet at such a point are not reported as self-intersections.
  bool allow_pinched_vertices = false;
  /// Accept several connected components (tet-mesh boundaries: check_components then checks
  /// that each component is one closed surface and none lies inside another).
  bool allow_components = false;
};

/// validate_closed_surface with options. When pinches are allowed and found, `split`
/// (if not null) receives the surface with every pinched vertex duplicated once per fan, so
/// it can be turned into a manifold polygon mesh.
void validate_closed_surface(const TriangleMesh& mesh, const std::string& file,
                             const SurfaceCheck& options, TriangleMesh* split);

}  // namespace tetseg::preprocess::detail
