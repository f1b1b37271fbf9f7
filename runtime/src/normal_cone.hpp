#pragma once
// Private data of the collider's normal-cone mode (ColliderMode::kCone, normal_cone.cpp), a
// baseline in the spirit of ICCD (Tang et al. 2009) over the kBvh mode's global BVH.
// Not installed.

#include <cstdint>
#include <vector>

namespace tetseg {

/// Contour tests are skipped (node not culled) for nodes with more boundary edges than this.
inline constexpr std::uint32_t kMaxContourEdges = 256;

struct ConeData {
  bool topology_built = false;
  // Static, per global BVH node: its boundary edges (edges with exactly one incident
  // triangle in the node) and whether they form one simple closed loop of <= kMaxContourEdges.
  std::vector<std::uint32_t> bnd_offset;  // CSR, gnode_count + 1
  std::vector<std::uint32_t> bnd_edges;   // edge ids
  std::vector<std::uint8_t> loop_ok;
  // Per step, per node: a cone containing the three Bernstein control normals of every
  // triangle of the node (axis unit vector, half-angle in radians; >= pi/2 means "wide").
  std::vector<double> axis;  // 3 per node
  std::vector<double> angle;
};

}  // namespace tetseg
