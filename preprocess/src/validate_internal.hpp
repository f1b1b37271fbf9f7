#pragma once
// Private: the face matching shared by extract_surface and validate_tet_mesh, and the CGAL
// self-intersection test (kept in its own translation unit).

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess::detail {

/// The faces of a tet mesh matched by their node sets (surface.cpp).
struct FaceMatch {
  /// Per tet: bit f set when face f (opposite vertex f) belongs to no other tet.
  std::vector<std::uint8_t> boundary;
  /// Distinct faces shared by three or more tets, and the smallest of them (sorted node ids,
  /// compared lexicographically).
  std::size_t crowded = 0;
  std::array<std::uint32_t, 3> first_crowded{};
};

/// Matches the faces of every tet in O(T): a counting sort into blocks of smallest-node ids,
/// then a hash table per block. Any indices (out-of-range ones included); throws
/// std::length_error at 2^30 tets or more. Uses OpenMP threads when built with them; the
/// result does not depend on their number.
FaceMatch match_faces(const TetMesh& mesh);

/// The Surface (order, winding, node lists) described by extract_surface, from `match`.
Surface surface_from_faces(const TetMesh& mesh, const FaceMatch& match);

/// validate_tet_mesh given the face matching of `mesh`.
void validate_tet_mesh(const TetMesh& mesh, const Surface& surface, const FaceMatch& match,
                       const std::string& file);

/// Pairs of intersecting triangles (indices into `triangles`; empty when none) of a closed,
/// edge- and vertex-manifold, consistently oriented triangle surface whose indices are in
/// range. Triangles sharing a vertex or an edge only count if they overlap beyond it.
std::vector<std::pair<std::size_t, std::size_t>> self_intersecting_pairs(
    const std::vector<Vec3>& points, const std::vector<Tri>& triangles);

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
