#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "tetseg/preprocess/segmentation.hpp"

namespace tetseg::preprocess {
namespace {

struct BuildItem {
  std::uint32_t triangle;
  Vec3 centroid;
};

// Builds the subtree over items[begin, end) whose node is `node_index` (already allocated).
// Children are appended after their parent, so every child index exceeds its parent's.
void build_node(std::vector<BuildItem>& items, std::uint32_t begin, std::uint32_t end,
                std::uint32_t node_index, std::vector<format::BvhNode>& nodes) {
  if (end - begin == 1) {
    nodes[node_index] = format::BvhNode{begin, 0, 1};
    return;
  }
  Vec3 lo = items[begin].centroid;
  Vec3 hi = lo;
  for (std::uint32_t i = begin + 1; i < end; ++i) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], items[i].centroid[k]);
      hi[k] = std::max(hi[k], items[i].centroid[k]);
    }
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k) {
    if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
  }
  const std::uint32_t middle = begin + (end - begin) / 2;
  // Ties broken by triangle id: the split is a pure function of the input.
  std::nth_element(items.begin() + begin, items.begin() + middle, items.begin() + end,
                   [axis](const BuildItem& a, const BuildItem& b) {
                     if (a.centroid[axis] != b.centroid[axis]) {
                       return a.centroid[axis] < b.centroid[axis];
                     }
                     return a.triangle < b.triangle;
                   });
  const auto left = static_cast<std::uint32_t>(nodes.size());
  nodes.emplace_back();
  nodes.emplace_back();
  nodes[node_index] = format::BvhNode{left, left + 1, 0};
  build_node(items, begin, middle, left, nodes);
  build_node(items, middle, end, left + 1, nodes);
}

}  // namespace

ClusterBvh build_cluster_bvh(const std::vector<Vec3>& nodes, const std::vector<Tri>& triangles,
                             std::vector<std::uint32_t> cluster_triangle_ids) {
  ClusterBvh bvh;
  if (cluster_triangle_ids.empty()) return bvh;
  std::sort(cluster_triangle_ids.begin(), cluster_triangle_ids.end());
  std::vector<BuildItem> items;
  items.reserve(cluster_triangle_ids.size());
  for (const std::uint32_t t : cluster_triangle_ids) {
    Vec3 c{0.0, 0.0, 0.0};
    for (const std::uint32_t v : triangles[t]) {
      for (int k = 0; k < 3; ++k) c[k] += nodes[v][k] / 3.0;
    }
    items.push_back({t, c});
  }
  bvh.nodes.reserve(2 * items.size() - 1);
  bvh.nodes.emplace_back();
  build_node(items, 0, static_cast<std::uint32_t>(items.size()), 0, bvh.nodes);
  bvh.triangles.reserve(items.size());
  for (const BuildItem& item : items) bvh.triangles.push_back(item.triangle);
  return bvh;
}

}  // namespace tetseg::preprocess
