// kFeatures broad phase (docs/runtime.md, "Features mode"): BVHs in the Morton order of the
// box centres over the swept boxes of the surface vertices, triangles and edges, rebuilt every
// step; vertex-face candidates from the vertex tree against the triangle tree, edge-edge
// candidates from the edge tree against itself; each candidate once (a vertex and a face meet
// in one leaf pair, an edge pair in one leaf or leaf pair, in the leaf order), pairs sharing a
// node skipped; then the same filters and elementary tests as every mode (process_vertex_face /
// process_edge_edge). No triangle pairs, no orphan sets, nothing built per shape.

#include <algorithm>
#include <cmath>

#include "collider_impl.hpp"

namespace tetseg {

void FeatureTree::reserve(std::uint32_t items) {
  const std::size_t cap = items == 0 ? 1 : 2 * std::size_t(items) - 1;
  nodes.resize(cap);
  leaf.resize(items);
  leaf_box.resize(items);
  leaf_diag.resize(items);
  key.resize(items);
  box.resize(cap);
  size.assign(cap, 0);
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

void FeatureTree::build(const Box* item_box, std::uint32_t items, std::uint32_t leaf_size,
                        MedianBvhTask* stack) noexcept {
  count = 0;
  if (items == 0) return;
  // Items in the Morton order of their box centres (30 bits over the centres' bounding box,
  // ties by item id: a pure function of the boxes).
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (std::uint32_t i = 0; i < items; ++i)
    for (int k = 0; k < 3; ++k) {
      const double c = item_box[i].lo[k] + item_box[i].hi[k];
      lo[k] = std::min(lo[k], c);
      hi[k] = std::max(hi[k], c);
    }
  double scale[3];
  for (int k = 0; k < 3; ++k) scale[k] = hi[k] > lo[k] ? 1023.0 / (hi[k] - lo[k]) : 0.0;
  for (std::uint32_t i = 0; i < items; ++i) {
    std::uint32_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double q = (item_box[i].lo[k] + item_box[i].hi[k] - lo[k]) * scale[k];
      code |= spread_bits(static_cast<std::uint32_t>(std::min(1023.0, std::max(0.0, q)))) << k;
    }
    key[i] = (std::uint64_t(code) << 32) | i;
  }
  std::sort(key.begin(), key.begin() + items);
  for (std::uint32_t i = 0; i < items; ++i) {
    leaf[i] = static_cast<std::uint32_t>(key[i]);
    leaf_box[i] = item_box[leaf[i]];
  }
  // Top down: a range splits where its highest differing Morton bit turns on (in the middle
  // when all its codes are equal); at most `leaf_size` items make a leaf. Children follow
  // their parent, so reverse order is bottom-up. Depth <= 30 + log2(items) < kMedianBvhStack.
  count = 1;
  std::size_t top = 0;
  stack[top++] = {0, 0, items};
  while (top > 0) {
    const MedianBvhTask task = stack[--top];
    const std::uint32_t begin = task.begin, end = task.end;
    if (end - begin <= leaf_size) {
      nodes[task.node] = {begin, 0, end - begin};
      continue;
    }
    const std::uint32_t first = static_cast<std::uint32_t>(key[begin] >> 32);
    const std::uint32_t last = static_cast<std::uint32_t>(key[end - 1] >> 32);
    std::uint32_t mid = begin + (end - begin) / 2;
    if (first != last) {
      const std::uint32_t bit = 0x80000000u >> __builtin_clz(first ^ last);
      const std::uint64_t* split =
          std::partition_point(key.data() + begin, key.data() + end,
                               [&](std::uint64_t k) { return ((k >> 32) & bit) == 0; });
      mid = static_cast<std::uint32_t>(split - key.data());
    }
    const std::uint32_t left = count, right = count + 1;
    count += 2;
    nodes[task.node] = {left, right, 0};
    stack[top++] = {right, mid, end};
    stack[top++] = {left, begin, mid};
  }
  // Children come after their parents: reverse order is bottom-up.
  for (std::uint32_t i = count; i-- > 0;) {
    const format::BvhNode& n = nodes[i];
    if (n.count > 0) {
      Box b = leaf_box[n.first];
      for (std::uint32_t k = 1; k < n.count; ++k) box_union(b, leaf_box[n.first + k]);
      box[i] = b;
      size[i] = n.count;
    } else {
      Box b = box[n.first];
      box_union(b, box[n.second]);
      box[i] = b;
      size[i] = size[n.first] + size[n.second];
    }
  }
}

namespace {

constexpr std::uint32_t kLeafSize = 4;

// Projections of point p on the four diagonals (1,1,1), (1,1,-1), (1,-1,1), (-1,1,1), merged
// into `d` (lo[4], hi[4]) as floats that hold the exact projections: with m = |x| + |y| + |z|,
// a sum of three doubles errs by at most 2^-52 m and its rounding to float by at most 2^-24
// (m + w) (2^-149 below the normal range), both inside the widening w = 2^-21 m + 1e-30.
inline void add_diagonals(const double* p, Diagonals& d) noexcept {
  const double x = p[0], y = p[1], z = p[2];
  const double w = 0x1p-21 * (std::fabs(x) + std::fabs(y) + std::fabs(z)) + 1e-30;
  const double s[4] = {x + y + z, x + y - z, x - y + z, -x + y + z};
  for (int k = 0; k < 4; ++k) {
    d.lo[k] = std::min(d.lo[k], static_cast<float>(s[k] - w));
    d.hi[k] = std::max(d.hi[k], static_cast<float>(s[k] + w));
  }
}

inline void merge_diagonals(Diagonals& a, const Diagonals& b) noexcept {
  for (int k = 0; k < 4; ++k) {
    a.lo[k] = std::min(a.lo[k], b.lo[k]);
    a.hi[k] = std::max(a.hi[k], b.hi[k]);
  }
}

// The diagonal slabs of two swept features overlap (each holds the convex hull of its nodes'
// positions at both ends of the step, which holds the feature at every t).
inline bool diagonals_overlap(const Diagonals& a, const Diagonals& b) noexcept {
  bool apart = false;
  for (int k = 0; k < 4; ++k) apart |= (a.lo[k] > b.hi[k]) | (b.lo[k] > a.hi[k]);
  return !apart;
}

// Every pair of leaves of trees a and b (a == b: every pair of leaves of one tree, a leaf with
// itself included) whose node boxes overlap (with `margin`), each once: leaves(first_a,
// count_a, first_b, count_b, same_leaf). False when `stack` (capacity `cap`) is too small.
template <class Leaves>
bool overlapping_leaves(const FeatureTree& a, const FeatureTree& b, bool self, double margin,
                        Worker& w, Leaves&& leaves) noexcept {
  if (a.count == 0 || b.count == 0) return true;
  StackItem* stack = w.stack.data();
  const std::size_t cap = w.stack.size();
  std::size_t top = 0;
  if (self || boxes_overlap(a.box[0], b.box[0], margin)) stack[top++] = {0, 0};
  while (top > 0 && !w.stop) {
    const StackItem it = stack[--top];
    ++w.stats.node_pairs_visited;
    const format::BvhNode& na = a.nodes[it.a];
    const format::BvhNode& nb = b.nodes[it.b];
    if (top + 3 > cap) return false;
    if (self && it.a == it.b) {
      if (na.count > 0) {
        leaves(na.first, na.count, na.first, na.count, true);
        continue;
      }
      stack[top++] = {na.first, na.first};
      stack[top++] = {na.second, na.second};
      if (boxes_overlap(a.box[na.first], a.box[na.second], margin))
        stack[top++] = {na.first, na.second};
      continue;
    }
    if (na.count > 0 && nb.count > 0) {
      leaves(na.first, na.count, nb.first, nb.count, false);
      continue;
    }
    const bool split_a = nb.count > 0 || (na.count == 0 && a.size[it.a] >= b.size[it.b]);
    if (split_a) {
      if (boxes_overlap(a.box[na.second], b.box[it.b], margin)) stack[top++] = {na.second, it.b};
      if (boxes_overlap(a.box[na.first], b.box[it.b], margin)) stack[top++] = {na.first, it.b};
    } else {
      if (boxes_overlap(a.box[it.a], b.box[nb.second], margin)) stack[top++] = {it.a, nb.second};
      if (boxes_overlap(a.box[it.a], b.box[nb.first], margin)) stack[top++] = {it.a, nb.first};
    }
  }
  return true;
}

}  // namespace

bool Collider::Impl::feature_pairs(Worker& w) noexcept {
  const double margin = opt.ccd.min_separation;
  const std::uint32_t nv = static_cast<std::uint32_t>(topo->surf_nodes.size());
  const std::uint32_t ne = static_cast<std::uint32_t>(topo->edges.size());
  for (std::uint32_t e = 0; e < ne; ++e) ebox[e] = edge_box(e);
  // Diagonal slabs (exact contact only; with a minimum separation the boxes alone cull).
  const bool diagonals = margin <= 0;
  if (diagonals) {
    for (std::uint32_t i = 0; i < nv; ++i) {
      Diagonals d;
      add_diagonals(pos0(topo->surf_nodes[i]), d);
      add_diagonals(pos1(topo->surf_nodes[i]), d);
      vdiag[i] = d;
    }
  }
  MedianBvhTask* build_stack = feature_build_stack.data();
  vertex_tree.build(vbox.data(), nv, kLeafSize, build_stack);
  face_tree.build(tbox.data(), tri_count, kLeafSize, build_stack);
  edge_tree.build(ebox.data(), ne, kLeafSize, build_stack);
  if (diagonals) {  // the trees' slabs in leaf order
    for (std::uint32_t i = 0; i < nv; ++i) vertex_tree.leaf_diag[i] = vdiag[vertex_tree.leaf[i]];
    for (std::uint32_t i = 0; i < tri_count; ++i) {
      const std::array<std::uint32_t, 3>& tv = topo->tri_verts[face_tree.leaf[i]];
      Diagonals d = vdiag[tv[0]];
      merge_diagonals(d, vdiag[tv[1]]);
      merge_diagonals(d, vdiag[tv[2]]);
      face_tree.leaf_diag[i] = d;
    }
    for (std::uint32_t i = 0; i < ne; ++i) {
      const std::array<std::uint32_t, 2>& ev = topo->edge_verts[edge_tree.leaf[i]];
      Diagonals d = vdiag[ev[0]];
      merge_diagonals(d, vdiag[ev[1]]);
      edge_tree.leaf_diag[i] = d;
    }
  }

  // Vertex-face: a vertex and a face meet in one leaf pair of the two trees.
  const bool vf_ok = overlapping_leaves(
      vertex_tree, face_tree, false, margin, w,
      [&](std::uint32_t fa, std::uint32_t na, std::uint32_t fb, std::uint32_t nb, bool) {
        for (std::uint32_t i = fa; i < fa + na; ++i) {
          const Box& bv = vertex_tree.leaf_box[i];
          const std::uint32_t p = topo->surf_nodes[vertex_tree.leaf[i]];
          for (std::uint32_t j = fb; j < fb + nb; ++j) {
            if (!boxes_overlap(bv, face_tree.leaf_box[j], margin)) continue;
            if (diagonals && !diagonals_overlap(vertex_tree.leaf_diag[i], face_tree.leaf_diag[j]))
              continue;
            const std::uint32_t f = face_tree.leaf[j];
            const format::Triangle& tri = tris[f];
            if (p == tri[0] || p == tri[1] || p == tri[2]) continue;
            process_vertex_face(w, *this, p, *this, f);
          }
        }
      });
  if (!vf_ok) return false;

  // Edge-edge: a pair of edges meets in one leaf (positions i < j) or one leaf pair.
  return overlapping_leaves(
      edge_tree, edge_tree, true, margin, w,
      [&](std::uint32_t fa, std::uint32_t na, std::uint32_t fb, std::uint32_t nb, bool same) {
        for (std::uint32_t i = fa; i < fa + na; ++i) {
          const std::uint32_t e1 = edge_tree.leaf[i];
          const Box& b1 = edge_tree.leaf_box[i];
          const std::array<std::uint32_t, 2>& E1 = topo->edges[e1];
          for (std::uint32_t j = same ? i + 1 : fb; j < fb + nb; ++j) {
            const Box& b2 = edge_tree.leaf_box[j];
            if (!boxes_overlap(b1, b2, margin)) continue;
            const std::uint32_t e2 = edge_tree.leaf[j];
            const std::array<std::uint32_t, 2>& E2 = topo->edges[e2];
            if (E1[0] == E2[0] || E1[0] == E2[1] || E1[1] == E2[0] || E1[1] == E2[1]) continue;
            if (diagonals && !diagonals_overlap(edge_tree.leaf_diag[i], edge_tree.leaf_diag[j]))
              continue;
            process_edge_edge(w, *this, e1, b1, *this, e2, b2);
          }
        }
      });
}

}  // namespace tetseg
