#pragma once
/// \file
/// Internal: the contours of a triangle set that segmentation needs (over the half-edges of
/// mesh_topology.hpp). Not installed.

#include <cstdint>
#include <vector>

#include "mesh_topology.hpp"
#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess::detail {

/// A contour of a triangle set S: border half-edges (in S's triangles, the triangle across
/// not in S) chained head to tail. At a vertex with several border edges (pinch) the chain
/// turns through the triangles outside S, so each contour borders one connected component of
/// the complement. `closed` is false when the chain hit an unpaired edge.
struct Contour {
  std::vector<std::uint32_t> half_edges;
  double length = 0.0;
  bool closed = true;
};

/// Every contour of the set `in_set` (one flag per triangle) whose triangles are listed, sorted
/// ascending, in `set_triangles` (cost O(|set| + border), not O(N)). Each contour starts at the
/// smallest border half-edge not yet visited, so the result is deterministic.
std::vector<Contour> trace_contours(const HalfEdges& mesh, const std::vector<Vec3>& nodes,
                                    const std::vector<std::uint8_t>& in_set,
                                    const std::vector<std::uint32_t>& set_triangles);

}  // namespace tetseg::preprocess::detail
