#pragma once
/// \file
/// The tetseg asset: everything the runtime needs to cull and query self-collisions of one
/// deformable object (a tet mesh, or since 1.2 a surface without tets: `BodyKind`), and nothing
/// it does not. Plain structs, written by the preprocessor (`tetseg build`) and read by the
/// runtime. The byte layout is in docs/format.md.
///
/// All indices are 0-based. "Node" means a node of the body: a tet-mesh node (kTet) or a vertex
/// of the input surface (kSurface). The runtime receives positions of all nodes each step, so
/// surface triangles and detectors refer to node ids.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace tetseg::format {

/// Asset format version. Major must match to load; an asset with an older or equal minor
/// version loads, a newer minor does not. 1.1 added detector points inside tets and the
/// overlap-only cluster flag; 1.2 added surface bodies and detectors carried by surface
/// weights or bones. `write_asset` writes the oldest minor version the asset needs.
inline constexpr std::uint16_t kVersionMajor = 1;
inline constexpr std::uint16_t kVersionMinor = 2;

/// Documented limits, checked on load (docs/format.md). They bound memory for hostile input.
inline constexpr std::uint32_t kMaxNodes = 1u << 26;              ///< 67,108,864 tet-mesh nodes
inline constexpr std::uint32_t kMaxTriangles = 1u << 25;          ///< 33,554,432 surface triangles
inline constexpr std::uint32_t kMaxClusters = 1u << 20;           ///< 1,048,576 clusters
inline constexpr std::uint32_t kMaxBoundaryLoops = 1u << 20;      ///< segment-boundary loops
inline constexpr std::uint32_t kMaxStringBytes = 1u << 16;        ///< one provenance string
inline constexpr std::uint32_t kMaxProvenanceOptions = 1024;      ///< provenance key/value pairs
inline constexpr std::uint32_t kMaxBvhNodes = 2 * kMaxTriangles;  ///< all clusters' BVH nodes
inline constexpr std::uint32_t kMaxBoundaryNodes = 3 * kMaxTriangles;  ///< all loops' node ids
inline constexpr std::uint32_t kMaxDetectorTerms = 256;  ///< terms of one cluster's detector (1.2)
inline constexpr std::uint32_t kMaxBones = 1u << 16;     ///< bones of a kBones asset (1.2)
/// Entries of `source_vertex_nodes` (1.2): three corners per triangle, as an STL file has.
inline constexpr std::uint32_t kMaxSourceVertices = 3 * kMaxTriangles;

using Triangle = std::array<std::uint32_t, 3>;  ///< tet-mesh node ids, wound outward

/// One node of a cluster's bounding-volume hierarchy. Node indices are local to the cluster
/// (0 = root). A leaf has `count > 0` and covers `Cluster` triangles
/// `[first, first + count)` of the cluster's triangle list (local positions, BVH leaf order).
/// An inner node has `count == 0` and children `first` and `second`, both with a larger index
/// than the node itself, so iterating nodes in reverse order refits bottom-up.
struct BvhNode {
  std::uint32_t first = 0;   ///< leaf: first local triangle; inner: left child
  std::uint32_t second = 0;  ///< leaf: unused (0); inner: right child
  std::uint32_t count = 0;   ///< leaf: triangle count (> 0); inner: 0
};

/// Input tet id of a detector that is not traced to a tet (node form, or unknown).
inline constexpr std::uint32_t kNoTet = 0xFFFFFFFFu;

/// Largest |sum of a detector's weights - 1| that validation accepts (docs/format.md).
inline constexpr double kDetectorWeightSumTolerance = 1e-9;

/// The point radial views are taken from: a barycentric combination of four tet-mesh nodes,
/// `sum weights[i] * x[nodes[i]]`, evaluated by the runtime from each step's positions (so it
/// moves with its tet). Two forms (docs/format.md, "Detectors"):
/// - node form: all four ids equal, weights exactly (1, 0, 0, 0): the node itself, an
///   interior node (not on the surface), read bit for bit as in format 1.0;
/// - point form: four distinct ids (the nodes of one tet), weights finite, >= 0, summing to 1
///   within kDetectorWeightSumTolerance.
struct DetectorPoint {
  std::array<std::uint32_t, 4> nodes{};
  std::array<double, 4> weights{1.0, 0.0, 0.0, 0.0};
  std::uint32_t tet = kNoTet;  ///< input tet id, for tracing only (the asset stores no tets)

  /// The node form at `node`.
  static DetectorPoint at_node(std::uint32_t node) {
    DetectorPoint d;
    d.nodes = {node, node, node, node};
    return d;
  }
  /// True for the node form (four equal ids, weights exactly 1, 0, 0, 0).
  bool is_node() const {
    return nodes[1] == nodes[0] && nodes[2] == nodes[0] && nodes[3] == nodes[0] &&
           weights[0] == 1.0 && weights[1] == 0.0 && weights[2] == 0.0 && weights[3] == 0.0;
  }
};

/// The detector's position given all node positions `xyz` (node_count x 3 doubles): for the
/// node form the node's position bit for bit, else `w0 x0 + w1 x1 + w2 x2 + w3 x3` evaluated in
/// this order. The one evaluation every reader uses (runtime per step, tools at rest).
inline std::array<double, 3> detector_position(const DetectorPoint& d, const double* xyz) {
  const double* p0 = xyz + 3 * std::size_t(d.nodes[0]);
  if (d.is_node()) return {p0[0], p0[1], p0[2]};
  std::array<double, 3> out{};
  for (int k = 0; k < 3; ++k) {
    double sum = d.weights[0] * p0[k];
    for (int i = 1; i < 4; ++i) sum += d.weights[i] * xyz[3 * std::size_t(d.nodes[i]) + k];
    out[k] = sum;
  }
  return out;
}

/// What the asset's nodes are (1.2; 1.0 and 1.1 assets are kTet).
enum class BodyKind : std::uint32_t {
  /// Nodes of a tet mesh (surface vertices and interior nodes, `Cluster::detector` in tets).
  kTet = 0,
  /// A surface body, built with no tets behind it (`tetseg build --body surface`): node i is
  /// vertex i of the input surface, in the input's order, and `triangles` are the input's
  /// triangles in the input's order, so frames of the same simulation apply unchanged. When
  /// the reader merged vertices (glTF/FBX seams, STL corners), `Asset::source_vertex_nodes`
  /// maps the file's vertices to nodes (`gather_node_positions`).
  kSurface = 1,
};

/// How the clusters' detector points move (1.2; one form per asset; 1.0 and 1.1 are kTetPoint).
enum class DetectorForm : std::uint32_t {
  /// `Cluster::detector`: a node or a point of one tet (kTet bodies only).
  kTetPoint = 0,
  /// A fixed combination of nodes, `sum weight * x[index]` over the cluster's
  /// `detector_terms` (index: node id), evaluated by the runtime from each step's positions.
  kSurfaceWeights = 1,
  /// Carried by bones: `Cluster::detector_rest` moved by linear blend skinning with the
  /// cluster's `detector_terms` (index: bone id, into `Asset::bone_names`). The application
  /// poses its skeleton and passes every detector's position at both ends of each step.
  kBones = 2,
};

/// One term of a kSurfaceWeights or kBones detector: a node id or a bone id, and its weight
/// (finite, >= 0; a cluster's weights sum to 1 within kDetectorWeightSumTolerance; indices of
/// one cluster distinct).
struct DetectorTerm {
  std::uint32_t index = 0;
  double weight = 0.0;
};

/// A kSurfaceWeights detector's position given all node positions `xyz` (node_count x 3
/// doubles): `sum weight * x[index]` over `terms[0, count)`, evaluated in term order. The one
/// evaluation every reader uses (runtime per step, tools at rest); indices must be valid
/// (validated assets).
inline std::array<double, 3> weighted_detector_position(const DetectorTerm* terms,
                                                        std::uint32_t count, const double* xyz) {
  std::array<double, 3> out{0.0, 0.0, 0.0};
  for (std::uint32_t i = 0; i < count; ++i) {
    const double* p = xyz + 3 * std::size_t(terms[i].index);
    for (int k = 0; k < 3; ++k) out[k] += terms[i].weight * p[k];
  }
  return out;
}

/// Cluster flag: no detector point sees the cluster well at rest, so it is culled by BVH
/// overlap only (its triangles are never classified by orientation).
inline constexpr std::uint32_t kClusterOverlapOnly = 1u;
/// Every cluster flag this version defines; other bits are invalid content.
inline constexpr std::uint32_t kKnownClusterFlags = kClusterOverlapOnly;

/// A cluster: a connected patch of the surface bounded by segment boundaries, culled with
/// radial views from its detector point (or by overlap only when flagged).
struct Cluster {
  /// kTetPoint assets: the detector. Other forms: the node form at node 0, never read.
  DetectorPoint detector;
  std::uint32_t flags = 0;              ///< kClusterOverlapOnly or 0
  float rest_positive_fraction = 0.0f;  ///< in [0,1]: share of triangles positive at rest
  std::uint32_t triangle_offset = 0;    ///< into Asset::cluster_triangles
  std::uint32_t triangle_count = 0;     ///< > 0
  std::uint32_t bvh_offset = 0;         ///< into Asset::bvh_nodes
  std::uint32_t bvh_count = 0;          ///< > 0; 2 * leaves - 1
  /// kSurfaceWeights and kBones (1.2): the detector's terms, `Asset::detector_terms`
  /// `[detector_term_offset ..+ detector_term_count)`, stored contiguously in cluster order
  /// like triangles; 1..kMaxDetectorTerms terms, or 0 for an overlap-only cluster.
  /// kTetPoint: both 0.
  std::uint32_t detector_term_offset = 0;
  std::uint32_t detector_term_count = 0;
  /// The detector's rest position (1.2; finite): kSurfaceWeights: the combination at rest;
  /// kBones: the point the bones move. kTetPoint: unused (0).
  std::array<double, 3> detector_rest{};
};

/// A segment boundary: a closed edge loop of surface nodes (consecutive nodes share a surface
/// edge, and the last connects back to the first).
struct BoundaryLoop {
  std::uint32_t node_offset = 0;  ///< into Asset::boundary_nodes
  std::uint32_t node_count = 0;   ///< >= 3
};

/// Where an asset came from: enough to rebuild it byte for byte.
struct Provenance {
  std::string tool_version;                                  ///< e.g. "tetseg 0.1.0"
  std::string source;                                        ///< input file name (no directories)
  std::vector<std::pair<std::string, std::string>> options;  ///< strictly increasing keys
};

/// The whole asset. Clusters are stored contiguously, in order and without gaps (cluster 0
/// starts at offset 0, each next one where the previous ends): cluster c owns
/// `cluster_triangles[clusters[c].triangle_offset ..+ triangle_count]` (surface triangle ids,
/// in BVH leaf order) and `bvh_nodes[clusters[c].bvh_offset ..+ bvh_count]`.
struct Asset {
  std::uint32_t node_count = 0;  ///< tet-mesh nodes the runtime expects per step
  /// Rest positions of all nodes (length units of the input), or empty when stripped
  /// (`tetseg build --no-rest-positions`). Used for the `bvh` mode's initial topology, the
  /// rest-intersection check and by tools that draw the asset; never required per frame.
  std::vector<std::array<double, 3>> rest_positions;
  std::vector<Triangle> triangles;              ///< surface triangles, outward winding
  std::vector<std::uint32_t> triangle_cluster;  ///< per triangle: its cluster id
  std::vector<Cluster> clusters;
  std::vector<std::uint32_t> cluster_triangles;  ///< surface triangle ids grouped by cluster
  std::vector<BvhNode> bvh_nodes;                ///< all clusters' BVH nodes, grouped
  std::vector<BoundaryLoop> boundaries;
  std::vector<std::uint32_t> boundary_nodes;  ///< loops' node ids, grouped, in loop order
  Provenance provenance;
  // 1.2 (an asset with kTet and kTetPoint is written as 1.1 or 1.0):
  BodyKind body_kind = BodyKind::kTet;
  DetectorForm detector_form = DetectorForm::kTetPoint;
  std::vector<DetectorTerm> detector_terms;  ///< all clusters' detector terms, grouped
  /// kBones: the skeleton's bone names (from the input's skin), indexed by bone id; the
  /// application maps its bones to these. Empty for other forms.
  std::vector<std::string> bone_names;
  /// kSurface, optional: for each vertex of the input file, in the file's order, the node it
  /// became, written only when the reader merged or renumbered vertices (glTF and FBX split
  /// vertices at UV and normal seams, STL repeats every corner). Every entry is below
  /// node_count and every node appears at least once. Empty: node i is vertex i of the file.
  /// `gather_node_positions` turns positions in the file's vertex order into node positions.
  std::vector<std::uint32_t> source_vertex_nodes;
};

/// A cluster's detector at rest, as tools draw and print it: kTetPoint: `detector_position` of
/// the rest positions (which must be present); other forms: `detector_rest`.
inline std::array<double, 3> rest_detector_position(const Asset& asset, const Cluster& cluster) {
  if (asset.detector_form != DetectorForm::kTetPoint) return cluster.detector_rest;
  return detector_position(cluster.detector, asset.rest_positions.front().data());
}

/// Every cluster's `detector_rest` (clusters x 3 doubles): the detector positions a tool passes
/// for a kBones asset when it has no pose (exact, culls less than a posed skeleton).
inline std::vector<double> rest_detector_positions(const Asset& asset) {
  std::vector<double> out;
  out.reserve(3 * asset.clusters.size());
  for (const Cluster& c : asset.clusters)
    out.insert(out.end(), c.detector_rest.begin(), c.detector_rest.end());
  return out;
}

}  // namespace tetseg::format
