#pragma once
// Private: tet meshes with several components (bodies). A component is a set of nodes
// connected through tets; each becomes its own set of clusters, charge and detectors in one
// asset that keeps the input's node numbering (docs/segmentation.md, "Several components").

#include <cstdint>
#include <string>
#include <vector>

#include "tetseg/preprocess/charge.hpp"
#include "tetseg/preprocess/mesh.hpp"
#include "tetseg/preprocess/segmentation.hpp"

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

/// The values of `whole` (one per surface triangle) at the part's triangles, in order.
std::vector<double> part_values(const std::vector<double>& whole, const SurfacePart& part);

/// compute_charge on each part's surface alone (each component is its own conductor, so it
/// gets the charge, and hence the clusters, it would get in an asset of its own). Densities
/// are gathered into one value per surface triangle; capacitance, area and iterations add up,
/// the residual is the largest, converged only when every part converged.
ChargeResult charge_by_part(const std::vector<Vec3>& nodes, const std::vector<SurfacePart>& parts,
                            std::size_t triangle_count, const ChargeOptions& options,
                            const std::string& file);

/// One segmentation of the whole surface from one per part (in part order, local triangle
/// ids): cluster ids renumbered by their smallest triangle id, loops and counts concatenated.
Segmentation join_segmentations(const std::vector<SurfacePart>& parts,
                                const std::vector<Segmentation>& pieces,
                                std::size_t triangle_count);

/// One cluster per part (--clusters single on a mesh with several components).
Segmentation one_cluster_per_part(const std::vector<SurfacePart>& parts,
                                  std::size_t triangle_count);

/// choose_detector_points for each part on its own (only its interior nodes and tets are
/// candidates), for a segmentation whose clusters never span two parts; one detector per
/// cluster, tet ids those of `mesh`. Copies the node array once when there are several parts.
std::vector<DetectorChoice> detectors_by_part(const TetMesh& mesh,
                                              const std::vector<SurfacePart>& parts,
                                              const Segmentation& segmentation,
                                              DetectorStrategy strategy, double min_visibility);

}  // namespace tetseg::preprocess::detail
