#pragma once
// Float bounds of the features mode's trees (collider_features.cpp; docs/runtime.md, "Features
// mode"): lanes of [lo, hi]: the swept box along x, y, z and the slabs along ten directions
// (Slabs); per item all thirteen, per node the first seven.
//
// Contract (conservative): a float check may only reject what the exact double check rejects.
// The double check of two items a, b is `a.lo > fl(b.hi + margin)` or `b.lo > fl(a.hi + margin)`
// along an axis (boxes_overlap), or their slabs apart (the slabs are already floats that hold
// the exact projections, add_slabs in collider_features.cpp). Here lo is rounded down to float and
// hi_m = fl(hi + margin), the very double boxes_overlap compares, is rounded up: then
// float a.lo <= a.lo and float hi_m >= fl(b.hi + margin), so `float a.lo > float b.hi_m`
// implies the double rejection. No arithmetic is done in float; comparisons are closed, so
// items touching exactly at a box or slab end overlap. A node's lanes are the min of its
// items' lo and the max of their hi_m: a node pair is rejected only when every item pair
// under it is. With a minimum separation the slabs are off (lanes -inf, +inf). (Rounding to
// nearest is monotone too, so it would also keep every touching pair; the outward rounding
// keeps the float bounds enclosing the double ones, which the node lanes and any future
// arithmetic on them rely on. tests/runtime/features_mode_test.cpp fails on inward rounding.)

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace tetseg {

inline constexpr int kSlabs = 10;              // the directions of Slabs
inline constexpr int kLeafLanes = 3 + kSlabs;  // a leaf's items: x, y, z, then the slabs
inline constexpr int kNodeLanes = 7;           // nodes: x, y, z and the first four slabs

/// Slabs of a swept feature along the ten directions (1,1,1), (1,1,-1), (1,-1,1), (-1,1,1),
/// (1,1,0), (1,-1,0), (1,0,1), (1,0,-1), (0,1,1), (0,1,-1) (unnormalised projections, floats
/// rounded outwards): with the box, a 26-DOP.
struct Slabs {
  float lo[kSlabs];
  float hi[kSlabs];
  Slabs() noexcept {
    for (int k = 0; k < kSlabs; ++k) {
      lo[k] = INFINITY;
      hi[k] = -INFINITY;
    }
  }
};

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
inline float float_up(double d) noexcept {
  return -float_down(-d);
}

/// A node of the binary tree a build makes first: the first kNodeLanes lanes of `lo` / `hi`,
/// then `a` and `b`: a leaf has b = 0 and a = its FeatureLeaf; an inner node b = the items
/// under it and a = its left child (the right one is a + 1).
struct alignas(64) FeatureNode {
  float lo[kNodeLanes];
  std::uint32_t a;
  float hi[kNodeLanes];
  std::uint32_t b;
};

/// Up to four slots of `Lanes` lanes in structure-of-arrays form (lane k of slot j: lo[k][j],
/// hi[k][j]); `lanes`: a bit per slot in use (the first n; an unused slot overlaps nothing).
template <int Lanes>
struct alignas(16) FeatureSlots {
  float lo[Lanes][4];
  float hi[Lanes][4];
  std::uint32_t lanes;
};

/// A leaf: all lanes of its items, their ids and their nodes (vertex: node[0]; edge:
/// node[0..1]; face: node[0..2]).
struct FeatureLeaf {
  FeatureSlots<kLeafLanes> bounds;
  alignas(16) std::uint32_t item[4];
  alignas(16) std::uint32_t node[3][4];
};

/// A traversal's id of a leaf: kFeatureLeafBit | its index (else: a FeatureWide's index).
inline constexpr std::uint32_t kFeatureLeafBit = 0x80000000u;

/// An inner node seen four-wide: the node lanes of up to four descendant nodes (its children,
/// the larger ones expanded into theirs) and their ids (a FeatureWide, or kFeatureLeafBit |
/// leaf).
struct FeatureWide {
  FeatureSlots<kNodeLanes> bounds;
  std::uint32_t child[4];
};

/// Bit j set when lanes [First, Last) of `lo[k * stride]`, `hi[k * stride]` overlap those of
/// slot j of `b` (closed intervals), for the slots in use. Without a branch.
template <int First, int Last, int Lanes>
inline unsigned slots_overlap_mask(const float* lo, const float* hi, int stride,
                                   const FeatureSlots<Lanes>& b) noexcept {
  static_assert(0 <= First && First < Last && Last <= Lanes, "lanes of the slots");
#if defined(__SSE2__)
  __m128 apart = _mm_setzero_ps();
  for (int k = First; k < Last; ++k) {
    const __m128 l = _mm_set1_ps(lo[k * stride]), h = _mm_set1_ps(hi[k * stride]);
    apart = _mm_or_ps(apart, _mm_or_ps(_mm_cmpgt_ps(l, _mm_load_ps(b.hi[k])),
                                       _mm_cmpgt_ps(_mm_load_ps(b.lo[k]), h)));
  }
  return ~static_cast<unsigned>(_mm_movemask_ps(apart)) & b.lanes;
#else
  unsigned mask = 0;
  for (int j = 0; j < 4; ++j) {
    bool apart = false;
    for (int k = First; k < Last; ++k)
      apart |= (lo[k * stride] > b.hi[k][j]) | (b.lo[k][j] > hi[k * stride]);
    mask |= apart ? 0u : 1u << j;
  }
  return mask & b.lanes;
#endif
}

/// Lanes [First, Last) of slot i of `a` against the slots of `b`.
template <int First, int Last, int LanesA, int LanesB>
inline unsigned slot_overlap_mask(const FeatureSlots<LanesA>& a, int i,
                                  const FeatureSlots<LanesB>& b) noexcept {
  static_assert(Last <= LanesA, "lanes of a");
  return slots_overlap_mask<First, Last>(&a.lo[0][i], &a.hi[0][i], 4, b);
}

/// Bit j set when item j of leaf `b` has `node` among its first `rows` nodes.
inline unsigned items_holding(std::uint32_t node, const FeatureLeaf& b, int rows) noexcept {
#if defined(__SSE2__)
  const __m128i n = _mm_set1_epi32(static_cast<int>(node));
  __m128i hit = _mm_setzero_si128();
  for (int r = 0; r < rows; ++r)
    hit = _mm_or_si128(
        hit, _mm_cmpeq_epi32(n, _mm_load_si128(reinterpret_cast<const __m128i*>(b.node[r]))));
  return static_cast<unsigned>(_mm_movemask_ps(_mm_castsi128_ps(hit)));
#else
  unsigned mask = 0;
  for (int r = 0; r < rows; ++r)
    for (int j = 0; j < 4; ++j) mask |= b.node[r][j] == node ? 1u << j : 0u;
  return mask;
#endif
}

}  // namespace tetseg
