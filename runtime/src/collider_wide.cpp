// 4-wide cluster BVHs (docs/runtime.md, "4-wide cluster BVHs"): the per-step refit and sign
// bits of the wide trees built at load (body_shape.cpp), and the traversal that hands each
// non-culled triangle pair of a cluster or cluster pair to process_non_culled_pair.

#include <algorithm>

#include "collider_impl.hpp"

namespace tetseg {

namespace {

inline bool wide_leaf(std::uint32_t slot) noexcept {
  return (slot & kWideLeaf) != 0;
}
inline std::uint32_t wide_triangle(std::uint32_t slot) noexcept {
  return slot & ~kWideLeaf;
}

// Bit k set when child k of `s` has a swept box overlapping `b` (margin ms): boxes_overlap's
// comparisons, lane by lane (the child as its first box). An empty slot overlaps nothing.
inline unsigned overlap_mask(const WideStep& s, const Box& b, double ms) noexcept {
#if defined(__SSE2__)
  const __m128d m = _mm_set1_pd(ms);
  __m128d apart01 = _mm_setzero_pd(), apart23 = _mm_setzero_pd();
  for (int k = 0; k < 3; ++k) {
    const __m128d bhi = _mm_set1_pd(b.hi[k] + ms);
    const __m128d blo = _mm_set1_pd(b.lo[k]);
    apart01 = _mm_or_pd(apart01, _mm_cmpgt_pd(_mm_load_pd(s.lo[k]), bhi));
    apart23 = _mm_or_pd(apart23, _mm_cmpgt_pd(_mm_load_pd(s.lo[k] + 2), bhi));
    apart01 = _mm_or_pd(apart01, _mm_cmpgt_pd(blo, _mm_add_pd(_mm_load_pd(s.hi[k]), m)));
    apart23 = _mm_or_pd(apart23, _mm_cmpgt_pd(blo, _mm_add_pd(_mm_load_pd(s.hi[k] + 2), m)));
  }
  const unsigned apart = unsigned(_mm_movemask_pd(apart01)) | unsigned(_mm_movemask_pd(apart23))
                                                                  << 2;
  return ~apart & 0xfu;
#else
  unsigned mask = 0;
  for (int i = 0; i < 4; ++i) {
    const bool apart = (s.lo[0][i] > b.hi[0] + ms) | (b.lo[0] > s.hi[0][i] + ms) |
                       (s.lo[1][i] > b.hi[1] + ms) | (b.lo[1] > s.hi[1][i] + ms) |
                       (s.lo[2][i] > b.hi[2] + ms) | (b.lo[2] > s.hi[2][i] + ms);
    mask |= apart ? 0u : 1u << i;
  }
  return mask;
#endif
}

inline Box slot_box(const WideStep& s, int k) noexcept {
  return {{s.lo[0][k], s.lo[1][k], s.lo[2][k]}, {s.hi[0][k], s.hi[1][k], s.hi[2][k]}};
}

// Moves the oldest half of stack[0, top) (the shallowest items: the largest subtrees left)
// into the queue for a hungry worker, as far as the queue has room; returns the new top.
std::size_t hand_over(WideQueue& q, StackItem* stack, std::size_t top, bool orient,
                      bool seam) noexcept {
  std::size_t moved = 0;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp critical(tetseg_wide_queue)
#endif
  {
    const std::size_t count = q.count.load(std::memory_order_relaxed);
    moved = std::min(top / 2, q.capacity - count);
    for (std::size_t k = 0; k < moved; ++k) q.items[count + k] = {stack[k], orient, seam};
    q.count.store(count + moved, std::memory_order_relaxed);
    q.hungry.store(false, std::memory_order_relaxed);
  }
  std::copy(stack + moved, stack + top, stack);
  return top - moved;
}

}  // namespace

void Collider::Impl::refit_wide() noexcept {
  // Local pointers: the byte stores cannot then be taken to alias the collider's members.
  const WideNode* nodes = topo->wide_nodes.data();
  const Box* tb = tbox.data();
  const std::uint8_t* tm = tmov.data();
  WideStep* step = wstep.data();
  Box* nbox_w = wbox.data();
  std::uint8_t* nmov_w = wmov.data();
  for (std::size_t i = topo->wide_nodes.size(); i-- > 0;) {
    WideStep& s = step[i];
    std::uint8_t mov = 0;
    for (int k = 0; k < 4; ++k) {
      const std::uint32_t c = nodes[i].child[k];
      if (c == kWideEmpty) break;
      const bool leaf = wide_leaf(c);
      const Box& b = leaf ? tb[wide_triangle(c)] : nbox_w[c];
      for (int a = 0; a < 3; ++a) {
        s.lo[a][k] = b.lo[a];
        s.hi[a][k] = b.hi[a];
      }
      mov |= std::uint8_t((leaf ? tm[wide_triangle(c)] : nmov_w[c]) << k);
    }
    s.mov = mov;
    nmov_w[i] = mov != 0;
    // The node's box: the children's, reduced over the lanes (empty slots are neutral).
    Box& own = nbox_w[i];
    for (int a = 0; a < 3; ++a) {
#if defined(__SSE2__)
      const __m128d lo = _mm_min_pd(_mm_load_pd(s.lo[a]), _mm_load_pd(s.lo[a] + 2));
      const __m128d hi = _mm_max_pd(_mm_load_pd(s.hi[a]), _mm_load_pd(s.hi[a] + 2));
      _mm_store_sd(&own.lo[a], _mm_min_sd(lo, _mm_unpackhi_pd(lo, lo)));
      _mm_store_sd(&own.hi[a], _mm_max_sd(hi, _mm_unpackhi_pd(hi, hi)));
#else
      own.lo[a] = std::min(std::min(s.lo[a][0], s.lo[a][1]), std::min(s.lo[a][2], s.lo[a][3]));
      own.hi[a] = std::max(std::max(s.hi[a][0], s.hi[a][1]), std::max(s.hi[a][2], s.hi[a][3]));
#endif
    }
  }
}

void Collider::Impl::sign_wide() noexcept {
  // Local pointers, as in refit_wide.
  const WideNode* nodes = topo->wide_nodes.data();
  const std::uint8_t* cls = tcls.data();
  WideStep* step = wstep.data();
  std::uint8_t* nsign_w = wsign.data();
  for (std::size_t i = topo->wide_nodes.size(); i-- > 0;) {
    WideStep& s = step[i];
    std::uint8_t pos = 0, neg = 0, own = kNodeAllPositive | kNodeAllNegative;
    for (int k = 0; k < 4; ++k) {
      const std::uint32_t c = nodes[i].child[k];
      if (c == kWideEmpty) break;
      const std::uint8_t sign = wide_leaf(c) ? class_sign_bits(cls[wide_triangle(c)]) : nsign_w[c];
      pos |= std::uint8_t((sign & kNodeAllPositive) << k);
      neg |= std::uint8_t(((sign & kNodeAllNegative) >> 1) << k);
      own &= sign;
    }
    s.pos = pos;
    s.neg = neg;
    nsign_w[i] = own;
  }
}

// Items are child slots (a wide node or a triangle); a pair item holds at least one node, a
// self item {node, kNone} stands for every triangle pair under the node. Items are tested
// before they are pushed (not both still unless in the rest check, boxes overlap, and with
// `orient` not of one sign), so popped items are live; a live pair of two triangles is
// processed where it is found. Its test is non_culled's (the slot boxes and bits are the
// triangles'), so outside the rest check it is a non-culled pair.
bool Collider::Impl::traverse_wide(Worker& w, StackItem first, bool orient, bool seam,
                                   WideQueue* queue) const noexcept {
  const WideNode* nodes = topo->wide_nodes.data();
  const double ms = opt.ccd.min_separation;
  const bool use_mov = !rest_mode;
  // Across clusters (`seam`: items of a pair of roots) a pair sharing a node is culled too
  // (non_culled's seam rule; its feature pairs are the seam orphans').
  seam = seam && !rest_mode;
  auto triangle_pair = [&](std::uint32_t t1, std::uint32_t t2) {
    if (rest_mode) {
      process_triangle_pair(w, t1, t2);
    } else if (!seam || !share_node(tris[t1], tris[t2])) {
      process_non_culled_pair(w, t1, t2);
    }
  };
  // Children of node n live against a slot with box b, moving flag mov and sign bits sign.
  auto live_children = [&](std::uint32_t n, const Box& b, bool mov, std::uint8_t sign) {
    const WideStep& s = wstep[n];
    unsigned live = overlap_mask(s, b, ms);
    if (use_mov && !mov) live &= s.mov;
    if (orient) {
      const unsigned clash =
          ((sign & kNodeAllPositive) ? s.pos : 0u) | ((sign & kNodeAllNegative) ? s.neg : 0u);
      // Bits set in 0..15 (no popcount instruction on the baseline target).
      static constexpr std::uint8_t kBits[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
      w.stats.node_pairs_orientation_culled += kBits[live & clash];
      live &= ~clash;
    }
    return live;
  };
  StackItem* stack = w.stack.data();
  const std::size_t cap = w.stack.size();
  std::size_t top = 0;
  // Child k of node n against the children of node m selected by `select`: live pairs of two
  // triangles processed, other live pairs pushed.
  auto child_against_children = [&](std::uint32_t n, int k, std::uint32_t m, unsigned select) {
    const WideStep& s = wstep[n];
    const std::uint32_t c = nodes[n].child[k];
    const std::uint8_t sign = std::uint8_t(((s.pos >> k) & 1u) | (((s.neg >> k) & 1u) << 1));
    unsigned live = live_children(m, slot_box(s, k), (s.mov >> k) & 1u, sign) & select;
    while (live != 0) {
      const std::uint32_t c2 = nodes[m].child[__builtin_ctz(live)];
      live &= live - 1;
      if (wide_leaf(c) && wide_leaf(c2)) {
        triangle_pair(wide_triangle(c), wide_triangle(c2));
      } else {
        stack[top++] = {c, c2};
      }
    }
  };
  if (cap == 0) return false;
  stack[top++] = first;
  while (top > 0 && !w.stop) {
    if (queue != nullptr && top >= 2 && queue->hungry.load(std::memory_order_relaxed))
      top = hand_over(*queue, stack, top, orient, seam);
    const StackItem it = stack[--top];
    ++w.stats.node_pairs_visited;
    if (top + 16 > cap) return false;  // a pair of nodes pushes up to 4 x 4 items
    if (it.b == kNone) {
      const WideNode& nd = nodes[it.a];
      const WideStep& s = wstep[it.a];
      for (int k = 0; k < 4; ++k) {
        const std::uint32_t c = nd.child[k];
        if (c == kWideEmpty) break;
        const unsigned bit = 1u << k;
        const bool mov = (s.mov & bit) != 0;
        if (!wide_leaf(c) && (mov || !use_mov)) {
          if (orient && ((s.pos | s.neg) & bit)) {
            ++w.stats.node_pairs_orientation_culled;
          } else {
            stack[top++] = {c, kNone};
          }
        }
        // The later siblings (none after the last occupied slot: no overlap test then).
        if (k < 3 && nd.child[k + 1] != kWideEmpty)
          child_against_children(it.a, k, it.a, ~((bit << 1) - 1));
      }
      continue;
    }
    // A pair with a triangle: the node's children against the triangle.
    if (wide_leaf(it.a) || wide_leaf(it.b)) {
      const bool a_leaf = wide_leaf(it.a);
      const std::uint32_t node = a_leaf ? it.b : it.a, t = wide_triangle(a_leaf ? it.a : it.b);
      const WideNode& nd = nodes[node];
      unsigned live = live_children(node, tbox[t], tmov[t] != 0, triangle_sign(t));
      while (live != 0) {
        const std::uint32_t c = nd.child[__builtin_ctz(live)];
        live &= live - 1;
        if (!wide_leaf(c)) {
          stack[top++] = a_leaf ? StackItem{it.a, c} : StackItem{c, it.b};
        } else if (a_leaf) {
          triangle_pair(t, wide_triangle(c));
        } else {
          triangle_pair(wide_triangle(c), t);
        }
      }
      continue;
    }
    // Two nodes: both descend at once. A's children against B, then each live child of A
    // against B's children.
    unsigned live_a = live_children(it.a, wbox[it.b], wmov[it.b] != 0, wsign[it.b]);
    while (live_a != 0) {
      const int k = __builtin_ctz(live_a);
      live_a &= live_a - 1;
      child_against_children(it.a, k, it.b, 0xfu);
    }
  }
  return true;
}

}  // namespace tetseg
