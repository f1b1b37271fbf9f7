#pragma once
// Float bounds of the features mode's trees (collider_features.cpp; docs/runtime.md, "Features
// mode"): per item and per node, seven lanes of [lo, hi]: the swept box along x, y, z and the
// slabs along the four diagonals (1,1,1), (1,1,-1), (1,-1,1), (-1,1,1).
//
// Contract (conservative): a float check may only reject what the exact double check rejects.
// The double check of two items a, b is `a.lo > fl(b.hi + margin)` or `b.lo > fl(a.hi + margin)`
// along an axis (boxes_overlap), or their double-derived float slabs apart (the slabs are
// already floats rounded outwards, add_diagonals). Here lo is rounded down to float and
// hi_m = fl(hi + margin), the very double boxes_overlap compares, is rounded up: then
// float a.lo <= a.lo and float hi_m >= fl(b.hi + margin), so `float a.lo > float b.hi_m`
// implies the double rejection. No arithmetic is done in float; comparisons are closed, so
// items touching exactly at a box or slab end overlap. A node's lanes are the min of its
// items' lo and the max of their hi_m: a node pair is rejected only when every item pair
// under it is. With a minimum separation the slabs are off (lanes -inf, +inf).

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace tetseg {

inline constexpr int kFeatureLanes = 7;  // x, y, z, four diagonals

/// The largest float <= d (d not NaN; beyond the float range: -inf or the largest float).
inline float float_down(double d) noexcept {
  constexpr float kMax = std::numeric_limits<float>::max();
  if (d >= kMax) return kMax;
  if (d < -kMax) return -INFINITY;
  float f = static_cast<float>(d);
  if (static_cast<double>(f) > d) {  // one step towards -inf
    std::uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    bits = f > 0 ? bits - 1 : (f < 0 ? bits + 1 : 0x80000001u);  // 0: the negative denormal
    std::memcpy(&f, &bits, sizeof bits);
  }
  return f;
}

/// The smallest float >= d (d not NaN).
inline float float_up(double d) noexcept { return -float_down(-d); }

/// A node of the binary tree a build makes first: lanes 0-6 of `lo` / `hi`, then (lane 7) `a`
/// and `b`: a leaf has b = 0 and a = its FeatureLeaf; an inner node b = the items under it and
/// a = its left child (the right one is a + 1).
struct alignas(64) FeatureNode {
  float lo[kFeatureLanes];
  std::uint32_t a;
  float hi[kFeatureLanes];
  std::uint32_t b;
};

/// Up to four slots in structure-of-arrays form (lane k of slot j: lo[k][j], hi[k][j]);
/// `lanes`: a bit per slot in use (the first n; an unused slot also overlaps nothing).
struct alignas(64) FeatureSlots {
  float lo[kFeatureLanes][4];
  float hi[kFeatureLanes][4];
  std::uint32_t lanes;
};

/// A leaf: its items' lanes, their ids and their nodes (vertex: node[0]; edge: node[0..1];
/// face: node[0..2]).
struct FeatureLeaf {
  FeatureSlots bounds;
  std::uint32_t item[4];
  std::uint32_t node[3][4];
};

/// A traversal's id of a leaf: kFeatureLeafBit | its index (else: a FeatureWide's index).
inline constexpr std::uint32_t kFeatureLeafBit = 0x80000000u;

/// An inner node seen four-wide: the lanes of up to four descendant nodes (its children, the
/// larger ones expanded into theirs) and their ids (a FeatureWide, or kFeatureLeafBit | leaf).
struct FeatureWide {
  FeatureSlots bounds;
  std::uint32_t child[4];
};

/// Bit j set when the lanes `lo[k * stride]`, `hi[k * stride]` (k < 7) overlap slot j of `b`
/// in all seven lanes (closed intervals), for the slots in use.
inline unsigned slots_overlap_mask(const float* lo, const float* hi, int stride,
                                   const FeatureSlots& b) noexcept {
#if defined(__SSE2__)
  // All seven lanes without a branch (whether the box lanes alone reject is hard to predict).
  auto apart_in = [&](int k) {
    const __m128 l = _mm_set1_ps(lo[k * stride]), h = _mm_set1_ps(hi[k * stride]);
    return _mm_or_ps(_mm_cmpgt_ps(l, _mm_load_ps(b.hi[k])), _mm_cmpgt_ps(_mm_load_ps(b.lo[k]), h));
  };
  const __m128 box = _mm_or_ps(apart_in(0), _mm_or_ps(apart_in(1), apart_in(2)));
  const __m128 slabs =
      _mm_or_ps(_mm_or_ps(apart_in(3), apart_in(4)), _mm_or_ps(apart_in(5), apart_in(6)));
  return ~static_cast<unsigned>(_mm_movemask_ps(_mm_or_ps(box, slabs))) & b.lanes;
#else
  unsigned mask = 0;
  for (int j = 0; j < 4; ++j) {
    bool apart = false;
    for (int k = 0; k < kFeatureLanes; ++k)
      apart |= (lo[k * stride] > b.hi[k][j]) | (b.lo[k][j] > hi[k * stride]);
    mask |= apart ? 0u : 1u << j;
  }
  return mask & b.lanes;
#endif
}

/// Slot i of `a` against the slots of `b`.
inline unsigned slot_overlap_mask(const FeatureSlots& a, int i, const FeatureSlots& b) noexcept {
  return slots_overlap_mask(&a.lo[0][i], &a.hi[0][i], 4, b);
}

/// A node's lanes against the slots of `b`.
inline unsigned node_overlap_mask(const FeatureNode& a, const FeatureSlots& b) noexcept {
  return slots_overlap_mask(a.lo, a.hi, 1, b);
}

/// The lanes of two nodes overlap (closed intervals).
inline bool nodes_overlap(const FeatureNode& a, const FeatureNode& b) noexcept {
  bool apart = false;
  for (int k = 0; k < kFeatureLanes; ++k) apart |= (a.lo[k] > b.hi[k]) | (b.lo[k] > a.hi[k]);
  return !apart;
}

}  // namespace tetseg
