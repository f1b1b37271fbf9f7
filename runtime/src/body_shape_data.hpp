#pragma once
// Private layout of tetseg::BodyShape: immutable surface topology shared by colliders and
// scene bodies. Not installed.

#include <array>
#include <cstdint>
#include <vector>

#include "tetseg/format/asset.hpp"
#include "tetseg/runtime/body_shape.hpp"

namespace tetseg {

/// A child slot of a 4-wide BVH node: a wide node index, kWideLeaf | triangle id (one
/// triangle), or kWideEmpty (unused slot; unused slots come last).
inline constexpr std::uint32_t kWideLeaf = 0x80000000u;
inline constexpr std::uint32_t kWideEmpty = 0xffffffffu;

/// Topology of a 4-wide BVH node: the asset's binary cluster BVH with every other level
/// collapsed, so each node holds up to four children (docs/runtime.md, "4-wide cluster BVHs").
struct WideNode {
  std::uint32_t child[4];
};

struct BodyShape::Data {
  const format::Asset* asset = nullptr;  // tet body: clusters, detectors, rest positions
  std::uint32_t node_count = 0;
  std::vector<format::Triangle> own_triangles;  // surface-only body (asset: its triangles)
  const format::Triangle* triangles = nullptr;  // tri_count entries
  std::uint32_t tri_count = 0;
  std::vector<std::uint32_t> surf_nodes;                 // surface vertex -> node id (sorted)
  std::vector<std::uint32_t> surf_index;                 // node id -> surface vertex or kNone
  std::vector<std::uint32_t> vt_offset, vt_list;         // surface vertex -> triangles (CSR)
  std::vector<std::array<std::uint32_t, 2>> edges;       // node ids, [0] < [1], sorted
  std::vector<std::array<std::uint32_t, 3>> tri_edges;   // edge ids of each triangle
  std::vector<std::uint32_t> et_offset, et_list;         // edge -> triangles (CSR)
  std::vector<std::array<std::uint32_t, 3>> tri_verts;   // surface vertex ids of each triangle
  std::vector<std::array<std::uint32_t, 2>> edge_verts;  // surface vertex ids of each edge
  std::vector<std::uint32_t> cluster_node_ntris;         // per asset BVH node
  std::uint32_t max_depth = 0;                           // of the asset's cluster BVHs
  // 4-wide form of the cluster BVHs: all clusters' nodes (children after their parent), the
  // root of each cluster (kWideEmpty for a cluster without triangles), and the greatest depth.
  std::vector<WideNode> wide_nodes;
  std::vector<std::uint32_t> wide_root;
  std::uint32_t wide_depth = 0;

  /// Builds everything from `triangles` / `asset` (set before the call). Allocates; may throw.
  void build();
  /// wide_nodes / wide_root / wide_depth from the asset's cluster BVHs (build; may throw).
  void build_wide_bvhs();
};

}  // namespace tetseg
