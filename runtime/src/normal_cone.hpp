#pragma once
// Private data of the collider's normal cones (normal_cone.cpp): ColliderMode::kCone, a
// baseline in the spirit of ICCD (Tang et al. 2009) over the kBvh mode's global BVH. The
// functions take any BVH (`ConeTree`); a per-cluster use (a "hybrid" mode) was measured and
// removed, docs/benchmarks.md. Not installed.

#include <cstdint>
#include <vector>

#include "tetseg/format/asset.hpp"

namespace tetseg {

/// Contour tests are skipped (node not culled) for nodes with more boundary edges than this.
inline constexpr std::uint32_t kMaxContourEdges = 256;
/// Leaves with more triangles than this get no cone (never culled).
inline constexpr std::uint32_t kMaxConeLeaf = 16;

/// One BVH whose nodes carry cones: `nodes[i]` has cone index `base + i`; leaf ranges index
/// `leaf` (global triangle ids), `leaf_count` entries.
struct ConeTree {
  const format::BvhNode* nodes = nullptr;
  const std::uint32_t* leaf = nullptr;
  std::uint32_t count = 0;
  std::uint32_t leaf_count = 0;
  std::uint32_t base = 0;
};

struct ConeData {
  bool topology_built = false;
  /// Sizes every per-node array for `node_count` nodes (all wide, no loop).
  void init(std::uint32_t node_count) {
    bnd_begin.assign(node_count, 0);
    bnd_end.assign(node_count, 0);
    bnd_edges.clear();
    loop_ok.assign(node_count, 0);
    axis.assign(std::size_t(node_count) * 3, 0.0);
    angle.assign(node_count, 4.0);
  }
  // Static, per global BVH node: its boundary edges (edges with exactly one incident
  // triangle in the node) and whether they form one simple closed loop of <= kMaxContourEdges.
  std::vector<std::uint32_t> bnd_begin, bnd_end;  // per node: range in bnd_edges
  std::vector<std::uint32_t> bnd_edges;           // edge ids
  std::vector<std::uint8_t> loop_ok;
  // Per step, per node: a cone containing the three Bernstein control normals of every
  // triangle of the node (axis unit vector, half-angle in radians; >= pi/2 means "wide").
  std::vector<double> axis;  // 3 per node
  std::vector<double> angle;
};

}  // namespace tetseg
