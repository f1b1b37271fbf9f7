#include <algorithm>
#include <cstdint>
#include <vector>

#include "tetseg/preprocess/segmentation.hpp"
#include "tetseg/runtime/median_bvh.hpp"

namespace tetseg::preprocess {

ClusterBvh build_cluster_bvh(const std::vector<Vec3>& nodes, const std::vector<Tri>& triangles,
                             std::vector<std::uint32_t> cluster_triangle_ids) {
  ClusterBvh bvh;
  if (cluster_triangle_ids.empty()) return bvh;
  std::sort(cluster_triangle_ids.begin(), cluster_triangle_ids.end());
  // Items are local positions in the sorted id list: the builder's tie-break by item id is
  // the tie-break by triangle id.
  const auto count = static_cast<std::uint32_t>(cluster_triangle_ids.size());
  std::vector<double> centroids(std::size_t(count) * 3, 0.0);
  std::vector<std::uint32_t> items(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    items[i] = i;
    for (const std::uint32_t v : triangles[cluster_triangle_ids[i]]) {
      for (int k = 0; k < 3; ++k) centroids[std::size_t(i) * 3 + k] += nodes[v][k] / 3.0;
    }
  }
  bvh.nodes.resize(2 * std::size_t(count) - 1);
  std::vector<MedianBvhTask> stack(kMedianBvhStack);
  const std::uint32_t node_count = build_median_bvh(centroids.data(), items.data(), count, 1,
                                                    bvh.nodes.data(), stack.data(), stack.size());
  bvh.nodes.resize(node_count);
  bvh.triangles.reserve(count);
  for (const std::uint32_t i : items) bvh.triangles.push_back(cluster_triangle_ids[i]);
  return bvh;
}

}  // namespace tetseg::preprocess
