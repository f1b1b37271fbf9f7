#pragma once
// Independent checks of a Segmentation: partition, connected clusters, closed edge loops that
// separate, and clusters cut only along boundaries. Uses std::map adjacency only.

#include <catch2/catch.hpp>

#include <set>
#include <vector>

#include "preprocess/support/segment_test_shapes.hpp"
#include "tetseg/preprocess/segmentation.hpp"

namespace tetseg::test {

/// `each_loop_separates`: segment_surface keeps only loops that split the surface alone;
/// refine_clusters' loops are cluster contours, which on a surface with handles separate only
/// together (the last check below covers them).
inline void check_segmentation_invariants(const std::vector<preprocess::Tri>& tris,
                                          const preprocess::Segmentation& seg,
                                          bool each_loop_separates = true) {
  const std::size_t n = tris.size();
  REQUIRE(seg.triangle_cluster.size() == n);
  REQUIRE(seg.counts.clusters == seg.cluster_count);
  REQUIRE(seg.counts.boundaries == seg.boundary_loops.size());
  REQUIRE(seg.boundary_lengths.size() == seg.boundary_loops.size());
  // Partition: every id in range, every cluster used and edge-connected.
  std::vector<std::size_t> sizes(seg.cluster_count, 0);
  for (std::uint32_t c : seg.triangle_cluster) {
    REQUIRE(c < seg.cluster_count);
    ++sizes[c];
  }
  for (std::size_t s : sizes) CHECK(s > 0);
  for (std::uint32_t c = 0; c < seg.cluster_count; ++c) {
    std::vector<bool> keep(n);
    for (std::size_t t = 0; t < n; ++t) keep[t] = seg.triangle_cluster[t] == c;
    CAPTURE(c);
    CHECK(count_components(tris, keep, {}) == 1);
  }
  // Loops: closed edge loops of surface edges whose cut separates the surface.
  const auto by_edge = edge_triangles(tris);
  std::set<Edge> all_loop_edges;
  for (std::size_t l = 0; l < seg.boundary_loops.size(); ++l) {
    const auto& loop = seg.boundary_loops[l];
    CAPTURE(l);
    REQUIRE(loop.size() >= 3);
    std::set<Edge> cut;
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const Edge e = edge_key(loop[i], loop[(i + 1) % loop.size()]);
      REQUIRE(by_edge.count(e) == 1);
      cut.insert(e);
    }
    CHECK(cut.size() == loop.size());  // no edge used twice
    all_loop_edges.insert(cut.begin(), cut.end());
    if (each_loop_separates) CHECK(count_components(tris, std::vector<bool>(n, true), cut) >= 2);
  }
  // Clusters are cut only along boundaries: an edge with different clusters is a loop edge.
  for (const auto& [edge, ts] : by_edge) {
    if (ts.size() != 2) continue;
    if (seg.triangle_cluster[ts[0]] != seg.triangle_cluster[ts[1]]) {
      CAPTURE(edge.first, edge.second);
      CHECK(all_loop_edges.count(edge) == 1);
    }
  }
}

}  // namespace tetseg::test
