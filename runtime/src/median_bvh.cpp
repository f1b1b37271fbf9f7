// The median-split BVH builder (median_bvh.hpp).

#include "tetseg/runtime/median_bvh.hpp"

#include <algorithm>
#include <cmath>

namespace tetseg {

std::uint32_t build_median_bvh(const double* centroids, std::uint32_t* items, std::uint32_t count,
                               std::uint32_t leaf_size, format::BvhNode* nodes,
                               MedianBvhTask* stack, std::size_t stack_capacity) noexcept {
  if (count == 0) return 0;
  if (leaf_size == 0) leaf_size = 1;
  std::uint32_t node_count = 1;
  std::size_t top = 0;
  nodes[0] = {0, 0, 0};
  stack[top++] = {0, 0, count};
  while (top > 0) {
    const MedianBvhTask task = stack[--top];
    const std::uint32_t begin = task.begin, end = task.end;
    if (end - begin <= leaf_size || top + 2 > stack_capacity) {
      nodes[task.node] = {begin, 0, end - begin};
      continue;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (std::uint32_t i = begin; i < end; ++i) {
      for (int k = 0; k < 3; ++k) {
        const double c = centroids[std::size_t(items[i]) * 3 + k];
        lo[k] = std::min(lo[k], c);
        hi[k] = std::max(hi[k], c);
      }
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
    const std::uint32_t mid = begin + (end - begin) / 2;
    // Ties broken by item id: the split is a pure function of the input.
    std::nth_element(items + begin, items + mid, items + end,
                     [centroids, axis](std::uint32_t a, std::uint32_t b) {
                       const double ca = centroids[std::size_t(a) * 3 + axis];
                       const double cb = centroids[std::size_t(b) * 3 + axis];
                       return ca < cb || (ca == cb && a < b);
                     });
    const std::uint32_t left = node_count++, right = node_count++;
    nodes[task.node] = {left, right, 0};
    stack[top++] = {right, mid, end};
    stack[top++] = {left, begin, mid};
  }
  return node_count;
}

}  // namespace tetseg
