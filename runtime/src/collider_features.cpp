// kFeatures broad phase (docs/runtime.md, "Features mode"): BVHs in the Morton order of the
// box centres over the swept boxes of the surface vertices, triangles and edges, rebuilt every
// step, with float bounds rounded outwards (feature_bounds.hpp: boxes and ten slab directions,
// a 26-DOP) and traversed four-wide; vertex-face candidates from the vertex tree against the
// triangle tree, edge-edge candidates from the edge tree against itself; each candidate once (a
// vertex and a face meet in one leaf pair, an edge pair in one leaf or leaf pair), pairs
// sharing a node skipped; then the same filters and elementary tests as every mode
// (process_vertex_face / process_edge_edge). No triangle pairs, no orphan sets, nothing built
// per shape.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <type_traits>
#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(TETSEG_HAVE_OPENMP)
#include <omp.h>
#endif

#include "collider_impl.hpp"

namespace tetseg {

namespace {

// The builds' stack: the binary pass keeps one task per level (depth < kMedianBvhStack), the
// four-wide pass up to three per level.
constexpr std::size_t kFeatureBuildStack = 4 * kMedianBvhStack;

// Room for n T (trivial types), not written: only what a build writes is ever touched. A large
// array is aligned to 2 MiB and, on Linux, asks for transparent huge pages: a build writes tens
// of MB that are new to the process, and first touches of 4 KiB pages (a fault each) cost more
// than the writes themselves (docs/benchmarks.md, "Contact-rich steps", issue25l).
template <class T>
T* large_array(std::size_t n) {
  static_assert(std::is_trivially_default_constructible<T>::value, "not written");
  constexpr std::size_t kHuge = std::size_t(2) << 20;
  std::size_t bytes = std::max<std::size_t>(n, 1) * sizeof(T);
  const std::size_t align = bytes >= kHuge ? kHuge : alignof(T);
  bytes = (bytes + align - 1) / align * align;
  void* p = std::aligned_alloc(align, bytes);
  if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (align == kHuge) madvise(p, bytes, MADV_HUGEPAGE);  // advice only: failure is harmless
#endif
  return static_cast<T*>(p);
}

}  // namespace

void Collider::Impl::reserve_feature_trees() {
  const std::size_t counts[3] = {topo->surf_nodes.size(), tri_count, topo->edges.size()};
  FeatureTree* trees[3] = {&vertex_tree, &face_tree, &edge_tree};
  std::size_t leaves = 0, most = 0;
  for (const std::size_t n : counts) {
    leaves += FeatureTree::leaf_capacity(n);
    most = std::max(most, n);
  }
  feature_nodes.reset(large_array<FeatureNode>(2 * FeatureTree::leaf_capacity(most) - 1));
  feature_leaves.reset(large_array<FeatureLeaf>(leaves));
  feature_wides.reset(large_array<FeatureWide>(leaves));
  std::size_t first = 0;
  for (int t = 0; t < 3; ++t) {
    trees[t]->nodes = feature_nodes.get();
    trees[t]->leaves = feature_leaves.get() + first;
    trees[t]->wides = feature_wides.get() + first;
    first += FeatureTree::leaf_capacity(counts[t]);
  }
  feature_key.resize(most);
  feature_key_scratch.resize(most);
  vslabs.resize(counts[0]);
  feature_build_stack.resize(kFeatureBuildStack);
  // The traversal pushes at most 16 pairs per pair it pops, one level further down one tree
  // or both; a tree is less than kMedianBvhStack levels deep (build).
  if (opt.traversal_stack == 0)
    for (Worker& w : workers) w.stack.resize(std::max(w.stack.size(), 16 * 2 * kMedianBvhStack));
  // Parallel: 32 tasks per worker, with room for the last expansion.
  if (workers.size() > 1) feature_frontier.reserve(64 * workers.size() + 16);
}

namespace {

// The 10 low bits of v spread to every third bit (Morton code of one axis).
inline std::uint32_t spread_bits(std::uint32_t v) noexcept {
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

}  // namespace

namespace {

// Leaf `f` of the items key[0, n) (n <= 4, Morton code and item id each) and its node's lanes.
template <class ItemBox, class ItemSlabs>
void fill_leaf(const std::uint64_t* key, std::uint32_t n, const ItemBox& item_box,
               const ItemSlabs& item_slabs, bool slabs, double margin,
               const std::uint32_t* item_nodes, int nodes_per_item, FeatureLeaf& f,
               FeatureNode& node) noexcept {
  f.bounds.lanes = (1u << n) - 1;
  for (int k = 0; k < kNodeLanes; ++k) {
    node.lo[k] = INFINITY;
    node.hi[k] = -INFINITY;
  }
  for (std::uint32_t j = 0; j < 4; ++j) {
    if (j >= n) {  // an empty lane overlaps nothing (and `lanes` masks it out)
      for (int k = 0; k < kLeafLanes; ++k) {
        f.bounds.lo[k][j] = INFINITY;
        f.bounds.hi[k][j] = -INFINITY;
      }
      f.item[j] = kNone;
      for (int r = 0; r < 3; ++r) f.node[r][j] = kNone;
      continue;
    }
    const auto item = static_cast<std::uint32_t>(key[j]);
    const Box b = item_box(item);
    for (int k = 0; k < 3; ++k) {
      f.bounds.lo[k][j] = float_down(b.lo[k]);
      f.bounds.hi[k][j] = float_up(b.hi[k] + margin);  // the sum boxes_overlap compares
    }
    Slabs d;
    if (slabs) d = item_slabs(item);
    for (int k = 0; k < kSlabs; ++k) {
      f.bounds.lo[3 + k][j] = slabs ? d.lo[k] : -INFINITY;
      f.bounds.hi[3 + k][j] = slabs ? d.hi[k] : INFINITY;
    }
    f.item[j] = item;
    for (int r = 0; r < 3; ++r)
      f.node[r][j] =
          r < nodes_per_item ? item_nodes[std::size_t(item) * nodes_per_item + r] : kNone;
    for (int k = 0; k < kNodeLanes; ++k) {
      node.lo[k] = std::min(node.lo[k], f.bounds.lo[k][j]);
      node.hi[k] = std::max(node.hi[k], f.bounds.hi[k][j]);
    }
  }
}

}  // namespace

template <class ItemBox, class ItemSlabs>
void FeatureTree::build(const ItemBox& item_box, const ItemSlabs& item_slabs, bool slabs,
                        double margin, std::uint32_t items, const std::uint32_t* item_nodes,
                        int nodes_per_item, std::uint64_t* key, std::uint64_t* key_scratch,
                        MedianBvhTask* stack) noexcept {
  constexpr std::uint32_t kLeafSize = 4;  // a FeatureLeaf's lanes
  count = leaf_count = 0;
  if (items == 0) return;
  // Items in the Morton order of their box centres (30 bits over the centres' bounding box,
  // ties by item id: a pure function of the boxes).
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (std::uint32_t i = 0; i < items; ++i) {
    const Box b = item_box(i);
    for (int k = 0; k < 3; ++k) {
      const double c = b.lo[k] + b.hi[k];
      lo[k] = std::min(lo[k], c);
      hi[k] = std::max(hi[k], c);
    }
  }
  double scale[3];
  for (int k = 0; k < 3; ++k) scale[k] = hi[k] > lo[k] ? 1023.0 / (hi[k] - lo[k]) : 0.0;
  for (std::uint32_t i = 0; i < items; ++i) {
    const Box b = item_box(i);
    std::uint32_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double q = (b.lo[k] + b.hi[k] - lo[k]) * scale[k];
      code |= spread_bits(static_cast<std::uint32_t>(std::min(1023.0, std::max(0.0, q)))) << k;
    }
    key_scratch[i] = (std::uint64_t(code) << 32) | i;
  }
  // Sorted by code, ties by id: a stable radix sort of the codes (three passes of 10 bits)
  // over the keys in id order. The result lands in `key`.
  std::uint64_t* from = key_scratch;
  std::uint64_t* to = key;
  for (int shift = 32; shift < 62; shift += 10) {
    std::uint32_t start[1025] = {};
    for (std::uint32_t i = 0; i < items; ++i) ++start[((from[i] >> shift) & 1023) + 1];
    for (int d = 0; d < 1024; ++d) start[d + 1] += start[d];
    for (std::uint32_t i = 0; i < items; ++i) to[start[(from[i] >> shift) & 1023]++] = from[i];
    std::swap(from, to);
  }
  if (from != key) std::copy(from, from + items, key);
  // Top down: a range splits where its highest differing Morton bit turns on (in the middle
  // when all its codes are equal); at most four items make a leaf. Depth <= 2 * 30 +
  // log2(items) + 1 < kMedianBvhStack (two levels per bit at most, below).
  count = 1;
  std::size_t top = 0;
  stack[top++] = {0, 0, items};
  while (top > 0) {
    const MedianBvhTask task = stack[--top];
    const std::uint32_t begin = task.begin, end = task.end;
    FeatureNode& node = nodes[task.node];
    if (end - begin <= kLeafSize) {
      fill_leaf(key + begin, end - begin, item_box, item_slabs, slabs, margin, item_nodes,
                nodes_per_item, leaves[leaf_count], node);
      node.a = leaf_count++;
      node.b = 0;
      continue;
    }
    const std::uint32_t first = static_cast<std::uint32_t>(key[begin] >> 32);
    const std::uint32_t last = static_cast<std::uint32_t>(key[end - 1] >> 32);
    std::uint32_t mid = begin + (end - begin) / 2;
    if (first != last) {
      const std::uint32_t bit = 0x80000000u >> __builtin_clz(first ^ last);
      const std::uint64_t* split = std::partition_point(
          key + begin, key + end, [&](std::uint64_t k) { return ((k >> 32) & bit) == 0; });
      mid = static_cast<std::uint32_t>(split - key);
    }
    // Full leaves: the split moved to the nearest multiple of four items from `begin`, so every
    // leaf but the last holds four. A child then holds at most two items from the other side
    // of the bit (more only in a leaf of four): its next split, on the same bit, leaves them
    // in a leaf. So at most two levels per Morton bit.
    mid =
        begin + std::min((mid - begin + 2) / kLeafSize, (end - begin - 1) / kLeafSize) * kLeafSize;
    mid = std::max(mid, begin + kLeafSize);
    node.a = count;  // left child; the right one is count + 1
    node.b = end - begin;
    count += 2;
    stack[top++] = {node.a + 1, mid, end};
    stack[top++] = {node.a, begin, mid};
  }
  // Inner nodes' lanes: children come after their parents, so reverse order is bottom-up.
  for (std::uint32_t i = count; i-- > 0;) {
    FeatureNode& n = nodes[i];
    if (n.b == 0) continue;
    const FeatureNode& l = nodes[n.a];
    const FeatureNode& r = nodes[n.a + 1];
    for (int k = 0; k < kNodeLanes; ++k) {
      n.lo[k] = std::min(l.lo[k], r.lo[k]);
      n.hi[k] = std::max(l.hi[k], r.hi[k]);
    }
  }
  // Four-wide: from the root down, an inner node's slots are its children, the inner slot with
  // most items expanded into its two children while fewer than four; each inner slot in turn
  // (its FeatureWide numbered when it is queued, in the task's `begin`). Depth first: at most
  // three slots wait per level, 3 * depth + 1 < kFeatureBuildStack.
  auto id_of = [&](std::uint32_t node, std::uint32_t wide) {
    return nodes[node].b == 0 ? kFeatureLeafBit | nodes[node].a : wide;
  };
  wide_count = 0;
  top = 0;
  root = id_of(0, 0);
  if (nodes[0].b != 0) stack[top++] = {0, wide_count++, 0};
  while (top > 0) {
    const MedianBvhTask task = stack[--top];
    const FeatureNode& n = nodes[task.node];
    std::uint32_t slot[4] = {n.a, n.a + 1, 0, 0};
    int used = 2;
    while (used < 4) {
      int widest = -1;
      for (int j = 0; j < used; ++j)
        if (nodes[slot[j]].b != 0 && (widest < 0 || nodes[slot[j]].b > nodes[slot[widest]].b))
          widest = j;
      if (widest < 0) break;
      const std::uint32_t left = nodes[slot[widest]].a;
      slot[widest] = left;
      slot[used++] = left + 1;
    }
    FeatureWide& wide = wides[task.begin];
    wide.bounds.lanes = (1u << used) - 1;
    for (int j = 0; j < 4; ++j) {
      const bool in_use = j < used;
      for (int k = 0; k < kNodeLanes; ++k) {
        wide.bounds.lo[k][j] = in_use ? nodes[slot[j]].lo[k] : INFINITY;
        wide.bounds.hi[k][j] = in_use ? nodes[slot[j]].hi[k] : -INFINITY;
      }
      wide.child[j] = kNone;
      if (!in_use) continue;
      wide.child[j] = id_of(slot[j], wide_count);
      if (nodes[slot[j]].b != 0) stack[top++] = {slot[j], wide_count++, 0};
    }
  }
}

namespace {

// Projections of point p on the ten directions of Slabs, merged into `d` as floats that hold
// the exact projections: with m = |x| + |y| + |z|, a sum of two or three doubles errs by at
// most 2^-52 m and its rounding to float by at most 2^-24 (m + w) (2^-149 below the normal
// range), both inside the widening w = 2^-21 m + 1e-30.
inline void add_slabs(const double* p, Slabs& d) noexcept {
  const double x = p[0], y = p[1], z = p[2];
  const double w = 0x1p-21 * (std::fabs(x) + std::fabs(y) + std::fabs(z)) + 1e-30;
  const double s[kSlabs] = {x + y + z, x + y - z, x - y + z, -x + y + z, x + y,
                            x - y,     x + z,     x - z,     y + z,      y - z};
  for (int k = 0; k < kSlabs; ++k) {
    d.lo[k] = std::min(d.lo[k], static_cast<float>(s[k] - w));
    d.hi[k] = std::max(d.hi[k], static_cast<float>(s[k] + w));
  }
}

inline void merge_slabs(Slabs& a, const Slabs& b) noexcept {
  for (int k = 0; k < kSlabs; ++k) {
    a.lo[k] = std::min(a.lo[k], b.lo[k]);
    a.hi[k] = std::max(a.hi[k], b.hi[k]);
  }
}

bool is_leaf(std::uint32_t id) noexcept {
  return (id & kFeatureLeafBit) != 0;
}

// One pair `it` of nodes of trees a and b (self: of one tree), each of whose lanes overlap:
// a pair of leaves goes to leaves(leaf_a, leaf_b, same_leaf); otherwise its overlapping pairs
// of descendants (at most 16) to push(item), each pair of leaves of the two once in the end.
// Nodes are checked four at a time (FeatureWide); an inner node against a leaf, by the leaf's
// items.
template <class Push, class Leaves>
void expand_pair(const FeatureTree& a, const FeatureTree& b, bool self, StackItem it, Push&& push,
                 Leaves&& leaves) noexcept {
  const bool leaf_a = is_leaf(it.a), leaf_b = is_leaf(it.b);
  if (leaf_a && leaf_b) {
    leaves(a.leaves[it.a & ~kFeatureLeafBit], b.leaves[it.b & ~kFeatureLeafBit],
           self && it.a == it.b);
  } else if (self && it.a == it.b) {
    const FeatureWide& wa = a.wides[it.a];
    for (int i = 0; i < 4 && (wa.bounds.lanes >> i & 1u); ++i) {
      push(StackItem{wa.child[i], wa.child[i]});
      for (unsigned m =
               slot_overlap_mask<0, kNodeLanes>(wa.bounds, i, wa.bounds) & (~0u << (i + 1));
           m != 0; m &= m - 1)
        push(StackItem{wa.child[i], wa.child[__builtin_ctz(m)]});
    }
  } else if (!leaf_a && !leaf_b) {  // up to four against four
    const FeatureWide& wa = a.wides[it.a];
    const FeatureWide& wb = b.wides[it.b];
    for (int i = 0; i < 4 && (wa.bounds.lanes >> i & 1u); ++i)
      for (unsigned m = slot_overlap_mask<0, kNodeLanes>(wa.bounds, i, wb.bounds); m != 0;
           m &= m - 1)
        push(StackItem{wa.child[i], wb.child[__builtin_ctz(m)]});
  } else if (!leaf_a) {  // an inner node against the items of a leaf
    const FeatureWide& wa = a.wides[it.a];
    const FeatureSlots<kLeafLanes>& lb = b.leaves[it.b & ~kFeatureLeafBit].bounds;
    unsigned m = 0;
    for (int i = 0; i < 4 && (lb.lanes >> i & 1u); ++i)
      m |= slot_overlap_mask<0, kNodeLanes>(lb, i, wa.bounds);
    for (; m != 0; m &= m - 1) push(StackItem{wa.child[__builtin_ctz(m)], it.b});
  } else {
    const FeatureSlots<kLeafLanes>& la = a.leaves[it.a & ~kFeatureLeafBit].bounds;
    const FeatureWide& wb = b.wides[it.b];
    unsigned m = 0;
    for (int i = 0; i < 4 && (la.lanes >> i & 1u); ++i)
      m |= slot_overlap_mask<0, kNodeLanes>(la, i, wb.bounds);
    for (; m != 0; m &= m - 1) push(StackItem{it.a, wb.child[__builtin_ctz(m)]});
  }
}

// Every pair of leaves under the pair `first` (expand_pair), each once, on w's stack. False
// when the stack is too small.
template <class Leaves>
bool overlapping_leaves(const FeatureTree& a, const FeatureTree& b, bool self, StackItem first,
                        Worker& w, Leaves&& leaves) noexcept {
  StackItem* stack = w.stack.data();
  const std::size_t cap = w.stack.size();
  std::size_t top = 0;
  stack[top++] = first;
  auto prefetch = [&](const FeatureTree& t, std::uint32_t id) {
    const void* p = is_leaf(id) ? static_cast<const void*>(&t.leaves[id & ~kFeatureLeafBit])
                                : static_cast<const void*>(&t.wides[id]);
    __builtin_prefetch(p);
    __builtin_prefetch(static_cast<const char*>(p) + 64);
    __builtin_prefetch(static_cast<const char*>(p) + 128);
    __builtin_prefetch(static_cast<const char*>(p) + 192);
  };
  while (top > 0 && !w.stop) {
    const StackItem it = stack[--top];
    if (top > 0) {  // the next pair's blocks, while this one is checked
      prefetch(a, stack[top - 1].a);
      prefetch(b, stack[top - 1].b);
    }
    ++w.stats.node_pairs_visited;
    if (top + 16 > cap) return false;
    expand_pair(
        a, b, self, it, [&](StackItem c) { stack[top++] = c; }, leaves);
  }
  return true;
}

}  // namespace

bool Collider::Impl::feature_pairs(Worker& w0, bool parallel) noexcept {
  const double margin = opt.ccd.min_separation;
  const std::uint32_t nv = static_cast<std::uint32_t>(topo->surf_nodes.size());
  const std::uint32_t ne = static_cast<std::uint32_t>(topo->edges.size());
  // Slabs (exact contact only; with a minimum separation the boxes alone cull).
  const bool slabs = margin <= 0;
  if (slabs) {
    for (std::uint32_t i = 0; i < nv; ++i) {
      Slabs d;
      add_slabs(pos0(topo->surf_nodes[i]), d);
      add_slabs(pos1(topo->surf_nodes[i]), d);
      vslabs[i] = d;
    }
  }
  std::uint64_t* key = feature_key.data();
  std::uint64_t* key_scratch = feature_key_scratch.data();
  MedianBvhTask* build_stack = feature_build_stack.data();
  vertex_tree.build([&](std::uint32_t i) -> const Box& { return vbox[i]; },
                    [&](std::uint32_t i) -> const Slabs& { return vslabs[i]; }, slabs, margin, nv,
                    topo->surf_nodes.data(), 1, key, key_scratch, build_stack);
  face_tree.build([&](std::uint32_t t) -> const Box& { return tbox[t]; },
                  [&](std::uint32_t t) {
                    const std::array<std::uint32_t, 3>& tv = topo->tri_verts[t];
                    Slabs d = vslabs[tv[0]];
                    merge_slabs(d, vslabs[tv[1]]);
                    merge_slabs(d, vslabs[tv[2]]);
                    return d;
                  },
                  slabs, margin, tri_count, tri_count ? tris[0].data() : nullptr, 3, key,
                  key_scratch, build_stack);
  edge_tree.build([&](std::uint32_t e) { return edge_box(e); },
                  [&](std::uint32_t e) {
                    const std::array<std::uint32_t, 2>& ev = topo->edge_verts[e];
                    Slabs d = vslabs[ev[0]];
                    merge_slabs(d, vslabs[ev[1]]);
                    return d;
                  },
                  slabs, margin, ne, ne ? topo->edges[0].data() : nullptr, 2, key, key_scratch,
                  build_stack);

  // Vertex-face: a vertex and a face meet in one leaf pair of the two trees. The node lanes,
  // then the shared node, then the other lanes: a superset of the double box check
  // (feature_bounds.hpp), which process_vertex_face repeats.
  auto vertex_faces = [this](Worker& w, const FeatureLeaf& va, const FeatureLeaf& fb, bool) {
    for (int i = 0; i < 4 && (va.bounds.lanes >> i & 1u); ++i) {
      const std::uint32_t p = va.node[0][i];
      unsigned m =
          slot_overlap_mask<0, kNodeLanes>(va.bounds, i, fb.bounds) & ~items_holding(p, fb, 3);
      if (m != 0) m &= slot_overlap_mask<kNodeLanes, kLeafLanes>(va.bounds, i, fb.bounds);
      for (; m != 0; m &= m - 1) process_vertex_face(w, *this, p, *this, fb.item[__builtin_ctz(m)]);
    }
  };
  // Edge-edge: a pair of edges meets in one leaf (lanes i < j) or one leaf pair; the double box
  // check here (process_edge_edge's box overload expects it done), the still rule there.
  auto edge_edges = [this, margin](Worker& w, const FeatureLeaf& ea, const FeatureLeaf& eb,
                                   bool same) {
    for (int i = 0; i < 4 && (ea.bounds.lanes >> i & 1u); ++i) {
      unsigned m = slot_overlap_mask<0, kNodeLanes>(ea.bounds, i, eb.bounds) &
                   ~(items_holding(ea.node[0][i], eb, 2) | items_holding(ea.node[1][i], eb, 2));
      if (same) m &= ~0u << (i + 1);
      if (m != 0) m &= slot_overlap_mask<kNodeLanes, kLeafLanes>(ea.bounds, i, eb.bounds);
      if (m == 0) continue;
      const std::uint32_t e1 = ea.item[i];
      const Box box1 = edge_box(e1);
      for (; m != 0; m &= m - 1) {
        const std::uint32_t e2 = eb.item[__builtin_ctz(m)];
        const Box box2 = edge_box(e2);
        if (boxes_overlap(box1, box2, margin))
          process_edge_edge(w, *this, e1, box1, *this, e2, box2);
      }
    }
  };
  // One task: the pairs under one pair of nodes of the vertex and face trees, or of the edge
  // tree with itself.
  auto run = [&](Worker& w, const FeatureTask& task) {
    if (task.edges)
      return overlapping_leaves(edge_tree, edge_tree, true, task.item, w,
                                [&](const FeatureLeaf& x, const FeatureLeaf& y, bool same) {
                                  edge_edges(w, x, y, same);
                                });
    return overlapping_leaves(vertex_tree, face_tree, false, task.item, w,
                              [&](const FeatureLeaf& x, const FeatureLeaf& y, bool same) {
                                vertex_faces(w, x, y, same);
                              });
  };
  const bool vf = vertex_tree.count > 0 && face_tree.count > 0;
  const bool ee = edge_tree.count > 0;
  (void)parallel;  // without OpenMP there is one worker
#if defined(TETSEG_HAVE_OPENMP)
  if (parallel && feature_frontier.capacity() > 0) {
    // The top of both traversals breadth first on this thread, into tasks; the tasks on the
    // workers (each pair of leaves once, whoever takes it: the serial pairs and counts).
    std::vector<FeatureTask>& tasks = feature_frontier;
    tasks.clear();
    if (vf) tasks.push_back({{vertex_tree.root, face_tree.root}, false});
    if (ee) tasks.push_back({{edge_tree.root, edge_tree.root}, true});
    const std::size_t enough = feature_frontier.capacity() - 16;  // room for one expansion
    std::size_t i = 0;
    while (i < tasks.size() && tasks.size() < enough / 2) {
      const FeatureTask task = tasks[i];
      if (is_leaf(task.item.a) && is_leaf(task.item.b)) {
        ++i;
        continue;
      }
      tasks[i] = tasks.back();
      tasks.pop_back();
      ++w0.stats.node_pairs_visited;
      auto push = [&](StackItem c) { tasks.push_back({c, task.edges}); };
      auto none = [](const FeatureLeaf&, const FeatureLeaf&, bool) {};
      if (task.edges)
        expand_pair(edge_tree, edge_tree, true, task.item, push, none);
      else
        expand_pair(vertex_tree, face_tree, false, task.item, push, none);
    }
    const auto count = static_cast<std::int64_t>(tasks.size());
#pragma omp parallel num_threads(static_cast <int>(workers.size()))
    {
      Worker& wt = workers[static_cast<std::size_t>(omp_get_thread_num())];
      if (omp_get_thread_num() == 0)
        stats.traversal_threads = static_cast<std::uint32_t>(omp_get_num_threads());
#pragma omp for schedule(dynamic, 1)
      for (std::int64_t k = 0; k < count; ++k)
        if (!wt.stop && !run(wt, tasks[static_cast<std::size_t>(k)])) wt.overflow = true;
    }
    return true;
  }
#endif
  if (vf && !run(w0, {{vertex_tree.root, face_tree.root}, false})) return false;
  return !ee || run(w0, {{edge_tree.root, edge_tree.root}, true});
}

}  // namespace tetseg
