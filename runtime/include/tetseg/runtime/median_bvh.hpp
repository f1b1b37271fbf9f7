#pragma once
/// \file
/// The one median-split BVH builder of tetseg: the asset's per-cluster BVHs (preprocess), the
/// `bvh`/`cone` modes' whole-surface BVH and the BVHs of surface-only scene bodies (runtime).
/// Deterministic (a pure function of its input) and allocation-free.

#include <cstddef>
#include <cstdint>

#include "tetseg/format/asset.hpp"

namespace tetseg {

/// One pending subtree of the builder: node index and item range.
struct MedianBvhTask {
  std::uint32_t node = 0, begin = 0, end = 0;
};

/// Stack capacity that `build_median_bvh` never exceeds for fewer than 2^60 items (the depth
/// of a median split is at most log2(count) + 1).
inline constexpr std::size_t kMedianBvhStack = 128;

/// Builds a BVH over `count` items by recursive median split: the widest axis of the centroid
/// box of a range, split at its median in the order (centroid along that axis, item id)
/// (`std::nth_element`); ranges of at most `leaf_size` (>= 1) items become leaves.
/// `items` holds the item ids on entry (any order; ids index `centroids`, 3 doubles per id)
/// and the leaf order on return: a leaf covers `items[first, first + count)`.
/// `nodes` (capacity >= 2 * count - 1) receives the tree in the asset's layout: root 0, the two
/// children of an inner node allocated together after their parent, depth first, left subtree
/// first. `stack` has room for `stack_capacity` tasks (`kMedianBvhStack` always suffices; when
/// full, a range becomes a leaf). Returns the node count (0 when `count` is 0).
std::uint32_t build_median_bvh(const double* centroids, std::uint32_t* items, std::uint32_t count,
                               std::uint32_t leaf_size, format::BvhNode* nodes,
                               MedianBvhTask* stack, std::size_t stack_capacity) noexcept;

}  // namespace tetseg
