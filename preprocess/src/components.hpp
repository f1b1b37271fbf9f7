#pragma once
// Private: the topology of tet meshes and surfaces with several components (bodies). A
// component is a set of nodes connected through tets; each becomes its own set of clusters,
// charge and detectors in one asset that keeps the input's node numbering
// (docs/segmentation.md, "Several components"; the per-part stages: part_stages.hpp).
// Validation, surface extraction and meshing use it: it includes no charge or segmentation
// header.

#include <cstdint>
#include <string>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess::detail {

/// The surface of one component: its triangles (global node ids) with their ids in the whole
/// surface, ascending, and its surface and interior nodes.
struct SurfacePart {
  std::vector<std::uint32_t> triangles;  ///< ids into the whole surface, ascending
  std::vector<std::uint32_t> tets;       ///< the component's tet ids, ascending; empty when
                                         ///< it is the only one (then: every tet)
  Surface surface;                       ///< those triangles; sorted surface / interior nodes
};

/// Each node's component (nodes joined through tets), numbered in order of the components'
/// first surface triangle; kNoPart for a node of no tet.
struct NodeParts {
  static constexpr std::uint32_t kNoPart = 0xffffffffu;
  std::vector<std::uint32_t> part;
  std::uint32_t count = 0;
};

/// Per node, the smallest id of the nodes joined to it through tets (union-find over the
/// tets). Every tet's node ids must be in range.
std::vector<std::uint32_t> tet_node_roots(const TetMesh& mesh);

/// Splits `surface` (extract_surface(mesh) of a validated mesh) by component (`parts`, as
/// check_components returned them), parts ordered by their smallest triangle id. One part (a
/// copy of `surface`, no tet list) for a connected mesh.
std::vector<SurfacePart> split_surface(const TetMesh& mesh, const Surface& surface,
                                       const NodeParts& parts);

/// The checks that make a mesh with several components meaningful, after the surface checks:
/// each component is bounded by exactly one closed surface (no cavity), and no component lies
/// inside another one (their volumes would overlap at rest; tested with the winding number of
/// one surface node of each component). Throws InputError(file, ...) naming the component.
/// `roots` are tet_node_roots(mesh). Returns the components found.
NodeParts check_components(const TetMesh& mesh, const Surface& surface,
                           const std::vector<std::uint32_t>& roots, const std::string& file);

/// Throws InputError(file, ...) when a surface node of one component (triangles labelled
/// 0..count-1 by `triangle_component`) lies inside the closed, oriented surface of another
/// (generalised winding number above 1/2; only components whose box holds the node are
/// summed). O(count x triangles) at worst.
void check_not_nested(const std::vector<Vec3>& points, const std::vector<Tri>& triangles,
                      const std::vector<std::uint32_t>& triangle_component, std::uint32_t count,
                      const std::string& file);

/// check_not_nested for a validated closed surface whose components are its triangles joined
/// through shared vertices (the input of tetrahedralize).
void check_surface_not_nested(const TriangleMesh& mesh, const std::string& file);

}  // namespace tetseg::preprocess::detail
