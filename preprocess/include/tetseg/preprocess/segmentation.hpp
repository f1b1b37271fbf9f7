#pragma once
/// \file
/// From equalised charge density to clusters, segment boundaries, detector nodes and per-cluster
/// BVH topology (Wong & Yeh, section IV-B/C). Decisions on the points the paper leaves open:
/// docs/segmentation.md.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "tetseg/format/asset.hpp"
#include "tetseg/preprocess/charge.hpp"
#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess {

enum class DetectorStrategy {
  kNearestCentroid,  ///< the paper: interior node nearest the cluster centroid
  kVisibility,       ///< among nearby interior nodes, the one seeing most triangles positive
};

/// Parameters of segment_surface. Defaults reproduce the paper (alpha 0.1, beta N/400); the
/// rest fixes points it leaves open (docs/segmentation.md).
struct SegmentationOptions {
  double alpha = 0.1;           ///< triangles with equalised density < alpha are marked
  double beta_divisor = 400.0;  ///< segments larger than N / beta_divisor triangles are grown
  /// How `tetseg build` equalises the density before calling segment_surface (recorded only;
  /// segment_surface takes the equalised values).
  Equalization equalization = Equalization::kHistogram;
  double growth_bound = 0.25;  ///< a grown segment is dropped once it exceeds this share of N
  /// When a growing segment's ring touches another marked segment, take that whole segment
  /// into the ring (not in the paper; joins a low-charge crease broken into pieces).
  bool grow_through_marked = true;
  /// Clusters smaller than this are merged into a neighbour, and complement pieces smaller than
  /// this never count as separated (they are filled into the segment). 0 = derived:
  /// derived_min_cluster_triangles(N).
  std::uint32_t min_cluster_triangles = 0;
  DetectorStrategy detector = DetectorStrategy::kVisibility;  ///< used by choose_detectors
  /// A cluster whose best detector point sees a smaller share of its triangles positive at
  /// rest is flagged overlap-only (culled by BVH overlap only at run time). 0 flags none.
  double min_visibility = 0.5;
};

/// The default minimum cluster size for N surface triangles: max(8, ceil(N / 200)), capped at N.
std::uint32_t derived_min_cluster_triangles(std::size_t triangle_count);

struct SegmentationCounts {
  std::uint32_t segments_found = 0;   ///< connected components of marked triangles
  std::uint32_t segments_grown = 0;   ///< segments that separate only after growing
  std::uint32_t segments_shrunk = 0;  ///< separating segments shrunk to cutting triangles
  std::uint32_t boundaries = 0;       ///< segment boundaries kept (== boundary_loops.size())
  std::uint32_t clusters = 0;         ///< == cluster_count
  /// Pieces of the surface cut along every boundary, minus the final clusters: small clusters
  /// merged into a neighbour, and pieces joined when a boundary was dropped.
  std::uint32_t clusters_merged = 0;
};

struct Segmentation {
  std::vector<std::uint32_t> triangle_cluster;  ///< per surface triangle, < cluster_count
  std::uint32_t cluster_count = 0;              ///< clusters numbered by their smallest triangle id
  /// Closed loops of node ids: consecutive nodes (and last -> first) share a surface edge; a
  /// node may repeat at a pinch. Every edge of a loop has different clusters on its two sides.
  /// segment_surface's loops each split the surface; refine_clusters' loops are the distinct
  /// contours of the clusters, which on a surface with handles separate only together.
  std::vector<std::vector<std::uint32_t>> boundary_loops;
  std::vector<double> boundary_lengths;     ///< per loop, sum of edge lengths at rest
  std::uint32_t min_cluster_triangles = 0;  ///< the minimum actually used
  SegmentationCounts counts;
};

/// Segments the closed outward surface using the equalised density (one value per surface
/// triangle, in (0,1]; NaN counts as unmarked). Deterministic: equal inputs give equal outputs.
/// Every triangle ends in exactly one cluster; a surface without separating segments is one
/// cluster per connected component. Never throws on odd geometry (non-manifold edges are
/// treated as borders); throws std::invalid_argument when `equalized` does not have one value
/// per triangle or a triangle names a node outside `nodes`.
Segmentation segment_surface(const std::vector<Vec3>& nodes, const Surface& surface,
                             const std::vector<double>& equalized,
                             const SegmentationOptions& options);

struct Detector {
  std::uint32_t node = 0;                ///< interior tet-mesh node id
  float rest_positive_fraction = 0.0f;   ///< share of the cluster's triangles positive at rest
  std::uint32_t triangle_count = 0;      ///< triangles of the cluster
  std::uint32_t positive_triangles = 0;  ///< of those, positive from `node` at rest
};

/// Candidate counts of the visibility strategy (docs/segmentation.md, "Detector nodes").
inline constexpr std::uint32_t kDetectorNearCentroid = 24;  ///< nodes nearest the centroid
inline constexpr std::uint32_t kDetectorNearKernel = 24;    ///< nodes nearest the kernel estimate
inline constexpr std::uint32_t kDetectorInBox =
    64;  ///< interior nodes sampled in the cluster's box

/// True when `point` lies strictly on the inner side of the outward triangle's plane:
/// det[a-o, b-o, c-o] > 0 (the triangle is "positive" from the point). Plain double arithmetic.
bool triangle_positive_from(const std::vector<Vec3>& nodes, const Tri& triangle, const Vec3& point);

/// Number of the cluster's triangles (ids in `triangle_ids`) that are positive from `point`:
/// det[a-o, b-o, c-o] > 0 for outward triangles (the point lies strictly on the inner side of
/// the triangle's plane). Plain double arithmetic.
std::uint32_t count_positive_triangles(const std::vector<Vec3>& nodes,
                                       const std::vector<Tri>& triangles,
                                       const std::vector<std::uint32_t>& triangle_ids,
                                       const Vec3& point);

/// One detector per cluster (cluster ids 0..cluster_count-1), chosen among
/// `surface.interior_nodes` from rest positions `nodes`.
/// - kNearestCentroid: the interior node nearest the cluster's area-weighted centroid (the
///   paper).
/// - kVisibility: among the kDetectorNearCentroid interior nodes nearest the centroid, the
///   kDetectorNearKernel nearest an estimate of the cluster's rest kernel (the region from which
///   all its triangles are positive) and up to kDetectorInBox interior nodes inside the
///   cluster's bounding box (evenly spread in id order), the node with the largest share of
///   positive triangles; ties go to the node nearer the centroid, then to the lower id.
/// Every cluster gets a node even when none sees all its triangles positive (the runtime stays
/// correct, only slower). A cluster without triangles gets the node nearest the surface's
/// centroid and fraction 1. Deterministic; O(clusters x interior nodes + candidates x N).
/// Throws InputError("", ...) when there is no interior node, and std::invalid_argument when
/// `triangle_cluster` does not match the surface or holds an id >= cluster_count.
std::vector<Detector> choose_detectors(const std::vector<Vec3>& nodes, const Surface& surface,
                                       const std::vector<std::uint32_t>& triangle_cluster,
                                       std::uint32_t cluster_count, DetectorStrategy strategy);

/// A cluster's detector as stored in the asset: an interior node or a point inside a tet.
struct DetectorChoice {
  format::DetectorPoint point;  ///< node form, or point form: a tet's centroid, tet id set
  Vec3 position{};              ///< rest position of the point
  float rest_positive_fraction = 0.0f;
  std::uint32_t triangle_count = 0;
  std::uint32_t positive_triangles = 0;
  bool overlap_only = false;  ///< rest_positive_fraction < min_visibility
};

/// One detector point per cluster (docs/segmentation.md, "Detector points"). The interior node
/// choose_detectors would pick (when the mesh has interior nodes) is kept unless a tet
/// centroid sees strictly more of the cluster positive at rest. Tet candidates (kVisibility,
/// only for clusters that node does not see whole, or every cluster when there is no interior
/// node): the centroids of non-degenerate tets, chosen like the nodes (kDetectorNearCentroid
/// nearest the cluster's centroid, kDetectorNearKernel nearest its kernel estimate, up to
/// kDetectorInBox in its box), scored exactly, ties to the one nearer the centroid, then the
/// lower tet id. kNearestCentroid without interior nodes: the tet centroid nearest the
/// cluster's centroid. A cluster seen less than `min_visibility` is flagged overlap_only.
/// Deterministic; O(clusters x (interior nodes + tets) + candidates x N). Throws InputError
/// when the mesh has neither an interior node nor a non-degenerate tet, and
/// std::invalid_argument as choose_detectors.
std::vector<DetectorChoice> choose_detector_points(
    const TetMesh& mesh, const Surface& surface, const std::vector<std::uint32_t>& triangle_cluster,
    std::uint32_t cluster_count, DetectorStrategy strategy, double min_visibility);

/// The detector choose_detectors picks for one set of surface triangles (`triangle_ids`, any
/// order). Preconditions (unchecked): at least one interior node, every id in range.
Detector best_detector(const std::vector<Vec3>& nodes, const Surface& surface,
                       const std::vector<std::uint32_t>& triangle_ids, DetectorStrategy strategy);

/// Visibility-driven refinement of a segmentation (beyond the paper; docs/segmentation.md,
/// "Refinement"). Thresholds were picked by measurement (docs/benchmarks.md).
struct RefinementOptions {
  /// A cluster whose best detector sees a smaller share of its triangles positive at rest is
  /// split; two neighbouring clusters whose union is seen at least this well are merged.
  double min_visibility = 0.98;
  /// A split is kept only if it removes at least this many non-positive triangles per edge of
  /// the new cut (a longer cut adds more cross-cluster triangle pairs at run time).
  double gain_per_cut_edge = 0.5;
  /// Cost of a triangle not positive from its part's node, in mean edge lengths of cut (the
  /// cut's edges cost length x (0.05 + equalised density) x concavity factor <= 1).
  double invisibility_cost = 1.0;
  std::uint32_t max_clusters = 32;          ///< no split beyond this many clusters
  std::uint32_t min_cluster_triangles = 0;  ///< 0 = the segmentation's minimum
  bool merge = true;                        ///< merge neighbours seen whole from one node
};

struct RefinementCounts {
  std::uint32_t clusters_before = 0;
  std::uint32_t splits = 0;
  std::uint32_t merges = 0;
};

/// Splits clusters that no interior node sees well at rest into parts that are (nearly)
/// star-shaped from a node of their own, along a minimum cut that prefers short, concave,
/// low-charge edges; then (when `merge`) greedily merges neighbours whose union is seen at
/// least `min_visibility` positive without losing visibility. Uses the kVisibility detector
/// search. Returns the new segmentation: clusters renumbered by smallest triangle id, every
/// cluster edge-connected when its input cluster was, boundary loops recomputed as the
/// distinct contours of the clusters, `counts.clusters` updated. Deterministic.
/// Preconditions as segment_surface, plus at least one interior node (InputError otherwise).
Segmentation refine_clusters(const std::vector<Vec3>& nodes, const Surface& surface,
                             const std::vector<double>& equalized, const Segmentation& charge,
                             const RefinementOptions& options, RefinementCounts* counts = nullptr);

struct ClusterBvh {
  std::vector<std::uint32_t> triangles;  ///< the cluster's surface triangle ids, leaf order
  std::vector<format::BvhNode> nodes;    ///< local indices, root 0, children after parents
};

/// Builds the BVH topology of one cluster from rest positions (deterministic median split on
/// the longest axis of the centroid box; one triangle per leaf).
ClusterBvh build_cluster_bvh(const std::vector<Vec3>& nodes, const std::vector<Tri>& triangles,
                             std::vector<std::uint32_t> cluster_triangle_ids);

}  // namespace tetseg::preprocess
