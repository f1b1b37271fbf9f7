// Collider construction: the feature pairs that only triangle pairs sharing a node hold, listed
// once from the topology: the orphan sets of the whole-surface modes (docs/runtime.md,
// "Adjacent triangle pairs: orphan sets") and rvbc's seam orphans ("Across clusters: seam
// pairs"). Their per-step tests are in collider_traverse.cpp (test_orphans,
// test_seam_orphans).

#include <algorithm>
#include <vector>

#include "collider_impl.hpp"

namespace tetseg {

template <typename VertexFace, typename EdgeEdge>
void Collider::Impl::for_each_adjacent_feature_pair(bool across_clusters, VertexFace&& vertex_face,
                                                    EdgeEdge&& edge_edge) const {
  const BodyShape::Data& T = *topo;
  std::vector<std::uint32_t> near, candidates;
  // Appends the triangles sharing a node with triangle t (t included).
  auto gather_near = [&](std::uint32_t t) {
    for (std::uint32_t n : tris[t]) {
      const std::uint32_t i = T.surf_index[n];
      near.insert(near.end(), T.vt_list.begin() + T.vt_offset[i],
                  T.vt_list.begin() + T.vt_offset[i + 1]);
    }
  };
  // With `across_clusters`, a vertex or edge whose neighbour triangles (its own included) lie
  // in one cluster is skipped: a pair of its holders that shares a node lies among them.
  auto one_cluster = [&]() {
    if (!across_clusters) return false;
    for (std::uint32_t t : near)
      if (asset->triangle_cluster[t] != asset->triangle_cluster[near[0]]) return false;
    return true;
  };
  auto sort_unique = [](std::vector<std::uint32_t>& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  };
  // Vertex-face (p, F), p not in F, F sharing a node with a triangle around p: F is among
  // those triangles' neighbours.
  for (std::uint32_t ip = 0; ip < T.surf_nodes.size(); ++ip) {
    const std::uint32_t p = T.surf_nodes[ip];
    near.clear();
    for (std::uint32_t k = T.vt_offset[ip]; k < T.vt_offset[ip + 1]; ++k) gather_near(T.vt_list[k]);
    if (one_cluster()) continue;
    sort_unique(near);
    for (std::uint32_t f : near) {
      const auto& F = tris[f];
      if (p != F[0] && p != F[1] && p != F[2]) vertex_face(p, f);
    }
  }
  // Edge-edge (e1, e2), e1 < e2, four distinct nodes, a triangle around e2 sharing a node with
  // one around e1: e2 is an edge of a neighbour of a triangle around e1.
  const std::uint32_t ne = static_cast<std::uint32_t>(T.edges.size());
  for (std::uint32_t e1 = 0; e1 < ne; ++e1) {
    near.clear();
    for (std::uint32_t k = T.et_offset[e1]; k < T.et_offset[e1 + 1]; ++k) gather_near(T.et_list[k]);
    if (one_cluster()) continue;
    candidates.clear();
    for (std::uint32_t t : near)
      for (std::uint32_t e2 : T.tri_edges[t])
        if (e2 > e1) candidates.push_back(e2);
    sort_unique(candidates);
    const auto& E1 = T.edges[e1];
    for (std::uint32_t e2 : candidates) {
      const auto& E2 = T.edges[e2];
      if (E1[0] != E2[0] && E1[0] != E2[1] && E1[1] != E2[0] && E1[1] != E2[1]) edge_edge(e1, e2);
    }
  }
}

void Collider::Impl::build_orphan_sets() {
  orphan_vf.clear();
  orphan_ee.clear();
  // Orphans: every holding triangle pair shares a node.
  auto disjoint = [&](std::uint32_t u, std::uint32_t v) { return !share_node(tris[u], tris[v]); };
  for_each_adjacent_feature_pair(
      false,
      [&](std::uint32_t p, std::uint32_t f) {
        if (!any_vertex_face_holder(p, f, disjoint)) orphan_vf.push_back({p, f});
      },
      [&](std::uint32_t e1, std::uint32_t e2) {
        if (!any_edge_edge_holder(e1, e2, disjoint)) orphan_ee.push_back({e1, e2});
      });
}

void Collider::Impl::build_seam_orphans() {
  seam_vf.clear();
  seam_ee.clear();
  // Seam orphans: some holding pair spans two clusters, and every such pair shares a node.
  const auto& cluster = asset->triangle_cluster;
  auto cross = [&](std::uint32_t u, std::uint32_t v) { return cluster[u] != cluster[v]; };
  auto cross_disjoint = [&](std::uint32_t u, std::uint32_t v) {
    return cluster[u] != cluster[v] && !share_node(tris[u], tris[v]);
  };
  for_each_adjacent_feature_pair(
      true,
      [&](std::uint32_t p, std::uint32_t f) {
        if (any_vertex_face_holder(p, f, cross) && !any_vertex_face_holder(p, f, cross_disjoint))
          seam_vf.push_back({p, f});
      },
      [&](std::uint32_t e1, std::uint32_t e2) {
        if (any_edge_edge_holder(e1, e2, cross) && !any_edge_edge_holder(e1, e2, cross_disjoint))
          seam_ee.push_back({e1, e2});
      });
}

}  // namespace tetseg
