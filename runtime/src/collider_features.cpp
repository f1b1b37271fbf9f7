// kFeatures broad phase (docs/runtime.md, "Features mode"): median-split BVHs over the swept
// boxes of the surface vertices, triangles and edges, rebuilt every step; vertex-face
// candidates from the vertex tree against the triangle tree, edge-edge candidates from the
// edge tree against itself; each candidate once (a vertex and a face meet in one leaf pair,
// an edge pair in one leaf or leaf pair, in the leaf order), pairs sharing a node skipped;
// then the same filters and elementary tests as every mode (process_vertex_face /
// process_edge_edge). No triangle pairs, no orphan sets, nothing built per shape.

#include <algorithm>

#include "collider_impl.hpp"

namespace tetseg {

void FeatureTree::reserve(std::uint32_t items) {
  const std::size_t cap = items == 0 ? 1 : 2 * std::size_t(items) - 1;
  nodes.resize(cap);
  leaf.resize(items);
  centroid.resize(std::size_t(items) * 3);
  box.resize(cap);
  size.assign(cap, 0);
}

void FeatureTree::build(const Box* item_box, std::uint32_t items, std::uint32_t leaf_size,
                        MedianBvhTask* stack) noexcept {
  for (std::uint32_t i = 0; i < items; ++i) {
    leaf[i] = i;
    for (int k = 0; k < 3; ++k)
      centroid[std::size_t(i) * 3 + k] = 0.5 * (item_box[i].lo[k] + item_box[i].hi[k]);
  }
  count = build_median_bvh(centroid.data(), leaf.data(), items, leaf_size, nodes.data(), stack,
                           kMedianBvhStack);
  // Children come after their parents: reverse order is bottom-up.
  for (std::uint32_t i = count; i-- > 0;) {
    const format::BvhNode& n = nodes[i];
    if (n.count > 0) {
      Box b = item_box[leaf[n.first]];
      for (std::uint32_t k = 1; k < n.count; ++k) box_union(b, item_box[leaf[n.first + k]]);
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
  MedianBvhTask* build_stack = feature_build_stack.data();
  vertex_tree.build(vbox.data(), nv, kLeafSize, build_stack);
  face_tree.build(tbox.data(), tri_count, kLeafSize, build_stack);
  edge_tree.build(ebox.data(), ne, kLeafSize, build_stack);

  // Vertex-face: a vertex and a face meet in one leaf pair of the two trees.
  const bool vf_ok = overlapping_leaves(
      vertex_tree, face_tree, false, margin, w,
      [&](std::uint32_t fa, std::uint32_t na, std::uint32_t fb, std::uint32_t nb, bool) {
        for (std::uint32_t i = fa; i < fa + na; ++i) {
          const std::uint32_t v = vertex_tree.leaf[i];
          const Box& bv = vbox[v];
          const std::uint32_t p = topo->surf_nodes[v];
          for (std::uint32_t j = fb; j < fb + nb; ++j) {
            const std::uint32_t f = face_tree.leaf[j];
            if (!boxes_overlap(bv, tbox[f], margin)) continue;
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
          const Box& b1 = ebox[e1];
          const std::array<std::uint32_t, 2>& E1 = topo->edges[e1];
          for (std::uint32_t j = same ? i + 1 : fb; j < fb + nb; ++j) {
            const std::uint32_t e2 = edge_tree.leaf[j];
            const Box& b2 = ebox[e2];
            if (!boxes_overlap(b1, b2, margin)) continue;
            const std::array<std::uint32_t, 2>& E2 = topo->edges[e2];
            if (E1[0] == E2[0] || E1[0] == E2[1] || E1[1] == E2[0] || E1[1] == E2[1]) continue;
            process_edge_edge(w, *this, e1, b1, *this, e2, b2);
          }
        }
      });
}

}  // namespace tetseg
