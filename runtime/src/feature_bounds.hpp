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

/// A tree node: lanes 0-6 of `lo` / `hi`, then (lane 7) `a` and `b`: inner node: a = left
/// child (the right one is a + 1), b = items under it (> 0); leaf: a = its FeatureLeaf, b = 0.
/// One cache line.
struct alignas(64) FeatureNode {
  float lo[kFeatureLanes];
  std::uint32_t a;
  float hi[kFeatureLanes];
  std::uint32_t b;
};

/// Up to four items of a leaf in structure-of-arrays form (lane k of item i: lo[k][i],
/// hi[k][i]), their item ids and their nodes (vertex: node[0]; edge: node[0..1]; face:
/// node[0..2]); `lanes`: a bit per item (the first n).
struct alignas(64) FeatureLeaf {
  float lo[kFeatureLanes][4];
  float hi[kFeatureLanes][4];
  std::uint32_t item[4];
  std::uint32_t node[3][4];
  std::uint32_t lanes;
};

/// The lanes of two nodes overlap (closed intervals).
inline bool nodes_overlap(const FeatureNode& a, const FeatureNode& b) noexcept {
#if defined(__SSE2__)
  const float* pa = a.lo;
  const float* pb = b.lo;
  const __m128 alo0 = _mm_load_ps(pa), alo1 = _mm_load_ps(pa + 4);
  const __m128 ahi0 = _mm_load_ps(pa + 8), ahi1 = _mm_load_ps(pa + 12);
  const __m128 blo0 = _mm_load_ps(pb), blo1 = _mm_load_ps(pb + 4);
  const __m128 bhi0 = _mm_load_ps(pb + 8), bhi1 = _mm_load_ps(pb + 12);
  const __m128 apart0 = _mm_or_ps(_mm_cmpgt_ps(alo0, bhi0), _mm_cmpgt_ps(blo0, ahi0));
  const __m128 apart1 = _mm_or_ps(_mm_cmpgt_ps(alo1, bhi1), _mm_cmpgt_ps(blo1, ahi1));
  return (_mm_movemask_ps(apart0) | (_mm_movemask_ps(apart1) & 7)) == 0;  // lane 7: a, b
#else
  bool apart = false;
  for (int k = 0; k < kFeatureLanes; ++k) apart |= (a.lo[k] > b.hi[k]) | (b.lo[k] > a.hi[k]);
  return !apart;
#endif
}

/// Bit j set when item i of leaf `a` overlaps item j of leaf `b` in all seven lanes (closed
/// intervals), for the items of b.
inline unsigned leaf_overlap_mask(const FeatureLeaf& a, int i, const FeatureLeaf& b) noexcept {
#if defined(__SSE2__)
  // The box lanes first: most item pairs of overlapping leaves are apart there already.
  auto apart_in = [&](int k) {
    const __m128 lo = _mm_set1_ps(a.lo[k][i]), hi = _mm_set1_ps(a.hi[k][i]);
    return _mm_or_ps(_mm_cmpgt_ps(lo, _mm_load_ps(b.hi[k])),
                     _mm_cmpgt_ps(_mm_load_ps(b.lo[k]), hi));
  };
  const unsigned box = ~static_cast<unsigned>(
                           _mm_movemask_ps(_mm_or_ps(apart_in(0), _mm_or_ps(apart_in(1), apart_in(2))))) &
                       b.lanes;
  if (box == 0) return 0;
  const __m128 slabs =
      _mm_or_ps(_mm_or_ps(apart_in(3), apart_in(4)), _mm_or_ps(apart_in(5), apart_in(6)));
  return ~static_cast<unsigned>(_mm_movemask_ps(slabs)) & box;
#else
  unsigned mask = 0;
  for (int j = 0; j < 4; ++j) {
    bool apart = false;
    for (int k = 0; k < kFeatureLanes; ++k)
      apart |= (a.lo[k][i] > b.hi[k][j]) | (b.lo[k][j] > a.hi[k][i]);
    mask |= apart ? 0u : 1u << j;
  }
  return mask & b.lanes;
#endif
}

}  // namespace tetseg
