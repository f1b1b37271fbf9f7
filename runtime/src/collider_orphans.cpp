// Collider construction: the feature pairs that only triangle pairs sharing a node hold, listed
// once from the topology: the orphan sets of the whole-surface modes (docs/runtime.md,
// "Adjacent triangle pairs: orphan sets") and rvbc's seam orphans ("Across clusters: seam
// pairs"); and their tests every step (test_orphans, test_seam_orphans).

#include <algorithm>
#include <vector>

#include "collider_impl.hpp"

namespace tetseg {

template <typename Holder>
inline bool Collider::Impl::any_vertex_face_holder(std::uint32_t p, std::uint32_t f,
                                                   Holder&& holder) const noexcept {
  const std::uint32_t ip = topo->surf_index[p];
  for (std::uint32_t k = topo->vt_offset[ip]; k < topo->vt_offset[ip + 1]; ++k)
    if (holder(topo->vt_list[k], f)) return true;
  return false;
}

template <typename Holder>
inline bool Collider::Impl::any_edge_edge_holder(std::uint32_t e1, std::uint32_t e2,
                                                 Holder&& holder) const noexcept {
  const auto& off = topo->et_offset;
  const auto& list = topo->et_list;
  for (std::uint32_t k1 = off[e1]; k1 < off[e1 + 1]; ++k1)
    for (std::uint32_t k2 = off[e2]; k2 < off[e2 + 1]; ++k2)
      if (holder(list[k1], list[k2])) return true;
  return false;
}

template <typename VertexFace, typename EdgeEdge>
void Collider::Impl::for_each_adjacent_feature_pair(bool across_clusters, bool first_holder_only,
                                                    VertexFace&& vertex_face,
                                                    EdgeEdge&& edge_edge) const {
  const BodyShape::Data& T = *topo;
  std::vector<std::uint32_t> near, candidates;
  // Deduplication by stamps: an id is listed once per round (each vertex or edge e1 is a
  // round), then the short unique list is sorted, so pairs come out in ascending order.
  std::vector<std::uint32_t> tri_round(tri_count, 0), edge_round(T.edges.size(), 0);
  std::uint32_t round = 0;
  // Appends the triangles sharing a node with triangle t (t included), each once per round.
  auto gather_near = [&](std::uint32_t t) {
    for (std::uint32_t n : tris[t]) {
      const std::uint32_t i = T.surf_index[n];
      for (std::uint32_t k = T.vt_offset[i]; k < T.vt_offset[i + 1]; ++k) {
        const std::uint32_t u = T.vt_list[k];
        if (tri_round[u] == round) continue;
        tri_round[u] = round;
        near.push_back(u);
      }
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
  // Vertex-face (p, F), p not in F, F sharing a node with a triangle around p: F is among
  // those triangles' neighbours.
  for (std::uint32_t ip = 0; ip < T.surf_nodes.size(); ++ip) {
    const std::uint32_t p = T.surf_nodes[ip];
    near.clear();
    ++round;
    const std::uint32_t end = first_holder_only ? T.vt_offset[ip] + 1 : T.vt_offset[ip + 1];
    for (std::uint32_t k = T.vt_offset[ip]; k < end; ++k) gather_near(T.vt_list[k]);
    if (one_cluster()) continue;
    std::sort(near.begin(), near.end());
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
    ++round;
    const std::uint32_t end = first_holder_only ? T.et_offset[e1] + 1 : T.et_offset[e1 + 1];
    for (std::uint32_t k = T.et_offset[e1]; k < end; ++k) gather_near(T.et_list[k]);
    if (one_cluster()) continue;
    candidates.clear();
    for (std::uint32_t t : near)
      for (std::uint32_t e2 : T.tri_edges[t])
        if (e2 > e1 && edge_round[e2] != round) {
          edge_round[e2] = round;
          candidates.push_back(e2);
        }
    std::sort(candidates.begin(), candidates.end());
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
      false, true,
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
      true, false,
      [&](std::uint32_t p, std::uint32_t f) {
        if (any_vertex_face_holder(p, f, cross) && !any_vertex_face_holder(p, f, cross_disjoint))
          seam_vf.push_back({p, f});
      },
      [&](std::uint32_t e1, std::uint32_t e2) {
        if (any_edge_edge_holder(e1, e2, cross) && !any_edge_edge_holder(e1, e2, cross_disjoint))
          seam_ee.push_back({e1, e2});
      });
}

void Collider::Impl::test_orphans(Worker& w) const noexcept {
  for (std::size_t i = 0; i < orphan_vf.size() && !w.stop; ++i)
    process_vertex_face(w, *this, orphan_vf[i][0], *this, orphan_vf[i][1]);
  for (std::size_t i = 0; i < orphan_ee.size() && !w.stop; ++i)
    process_edge_edge(w, *this, orphan_ee[i][0], *this, orphan_ee[i][1]);
}

void Collider::Impl::test_seam_orphans(Worker& w) const noexcept {
  // Each is tested here only when no holding triangle pair is non-culled (otherwise the
  // smallest such pair tests it): exactly once. The cheap rejections of process_* come first.
  const double ms = opt.ccd.min_separation;
  auto nc = [&](std::uint32_t u, std::uint32_t v) { return non_culled(u, v); };
  for (std::size_t i = 0; i < seam_vf.size() && !w.stop; ++i) {
    const std::uint32_t p = seam_vf[i][0], f = seam_vf[i][1];
    const std::uint32_t ip = topo->surf_index[p];
    if (!vmoved[ip] && !tmov[f]) continue;
    if (!boxes_overlap(vbox[ip], tbox[f], ms)) continue;
    if (!any_vertex_face_holder(p, f, nc)) process_vertex_face(w, *this, p, *this, f);
  }
  for (std::size_t i = 0; i < seam_ee.size() && !w.stop; ++i) {
    const std::uint32_t e1 = seam_ee[i][0], e2 = seam_ee[i][1];
    if (!edge_boxes_overlap(*this, e1, *this, e2)) continue;
    if (!any_edge_edge_holder(e1, e2, nc)) process_edge_edge(w, *this, e1, *this, e2);
  }
}

}  // namespace tetseg
