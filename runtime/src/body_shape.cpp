// BodyShape: the immutable surface topology of a body, built once (body_shape.hpp).

#include <algorithm>
#include <new>

#include "body_shape_data.hpp"

namespace tetseg {

namespace {
constexpr std::uint32_t kNoVertex = 0xffffffffu;
}  // namespace

BodyShape::BodyShape() noexcept = default;
BodyShape::~BodyShape() = default;

std::uint32_t BodyShape::node_count() const noexcept {
  return m_data->node_count;
}
std::uint32_t BodyShape::triangle_count() const noexcept {
  return m_data->tri_count;
}
bool BodyShape::has_clusters() const noexcept {
  return m_data->asset != nullptr;
}

void BodyShape::Data::build() {
  // Surface vertices and vertex -> triangle adjacency.
  surf_index.assign(node_count, kNoVertex);
  for (std::uint32_t t = 0; t < tri_count; ++t)
    for (std::uint32_t v : triangles[t]) surf_index[v] = 0;
  for (std::uint32_t n = 0; n < node_count; ++n) {
    if (surf_index[n] == 0) {
      surf_index[n] = static_cast<std::uint32_t>(surf_nodes.size());
      surf_nodes.push_back(n);
    }
  }
  const std::size_t nv = surf_nodes.size();
  vt_offset.assign(nv + 1, 0);
  for (std::uint32_t t = 0; t < tri_count; ++t)
    for (std::uint32_t v : triangles[t]) ++vt_offset[surf_index[v] + 1];
  for (std::size_t i = 0; i < nv; ++i) vt_offset[i + 1] += vt_offset[i];
  vt_list.resize(vt_offset[nv]);
  {
    std::vector<std::uint32_t> fill(vt_offset.begin(), vt_offset.end() - 1);
    for (std::uint32_t t = 0; t < tri_count; ++t)
      for (std::uint32_t v : triangles[t]) vt_list[fill[surf_index[v]]++] = t;
  }

  // Unique edges and edge -> triangle adjacency.
  std::vector<std::array<std::uint32_t, 3>> half;  // lo, hi, triangle*3+slot
  half.reserve(std::size_t(tri_count) * 3);
  for (std::uint32_t t = 0; t < tri_count; ++t) {
    for (std::uint32_t s = 0; s < 3; ++s) {
      std::uint32_t u = triangles[t][s], v = triangles[t][(s + 1) % 3];
      if (u > v) std::swap(u, v);
      half.push_back({u, v, t * 3 + s});
    }
  }
  std::sort(half.begin(), half.end());
  tri_edges.assign(tri_count, {0, 0, 0});
  et_offset.clear();
  for (std::size_t i = 0; i < half.size(); ++i) {
    if (i == 0 || half[i][0] != half[i - 1][0] || half[i][1] != half[i - 1][1]) {
      edges.push_back({half[i][0], half[i][1]});
      et_offset.push_back(static_cast<std::uint32_t>(i));
    }
    const std::uint32_t e = static_cast<std::uint32_t>(edges.size() - 1);
    tri_edges[half[i][2] / 3][half[i][2] % 3] = e;
    et_list.push_back(half[i][2] / 3);
  }
  et_offset.push_back(static_cast<std::uint32_t>(half.size()));
  tri_verts.resize(tri_count);
  for (std::uint32_t t = 0; t < tri_count; ++t)
    for (int k = 0; k < 3; ++k) tri_verts[t][k] = surf_index[triangles[t][k]];
  edge_verts.resize(edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e)
    edge_verts[e] = {surf_index[edges[e][0]], surf_index[edges[e][1]]};

  if (!asset) return;
  // Per-node static triangle counts and BVH depth (children have larger indices).
  const format::Asset& fa = *asset;
  const std::size_t nn = fa.bvh_nodes.size();
  cluster_node_ntris.assign(nn, 0);
  std::vector<std::uint32_t> depth(nn, 0);
  for (const auto& c : fa.clusters) {
    const format::BvhNode* nodes = fa.bvh_nodes.data() + c.bvh_offset;
    std::uint32_t* cnt = cluster_node_ntris.data() + c.bvh_offset;
    std::uint32_t* dep = depth.data() + c.bvh_offset;
    for (std::uint32_t i = 0; i < c.bvh_count; ++i) {
      if (nodes[i].count == 0) {
        dep[nodes[i].first] = dep[i] + 1;
        dep[nodes[i].second] = dep[i] + 1;
      }
      max_depth = std::max(max_depth, dep[i]);
    }
    for (std::uint32_t i = c.bvh_count; i-- > 0;) {
      cnt[i] = nodes[i].count > 0 ? nodes[i].count : cnt[nodes[i].first] + cnt[nodes[i].second];
    }
  }
  build_wide_bvhs();
}

namespace {

// Collapses one binary cluster BVH into 4-wide nodes appended to `out` (parents first).
struct WideBuilder {
  const format::BvhNode* nodes;
  const std::uint32_t* leaf;  // global triangle ids in leaf order
  std::vector<WideNode>& out;
  std::uint32_t depth = 0;

  std::uint32_t add(std::uint32_t level) {
    depth = std::max(depth, level);
    out.push_back(WideNode{{kWideEmpty, kWideEmpty, kWideEmpty, kWideEmpty}});
    return static_cast<std::uint32_t>(out.size() - 1);
  }
  // A wide node over leaf positions [first, first + count): up to four triangles, else up to
  // four nearly equal consecutive runs.
  std::uint32_t range(std::uint32_t first, std::uint32_t count, std::uint32_t level) {
    const std::uint32_t id = add(level);
    const std::uint32_t per = count <= 4 ? 1 : (count + 3) / 4;
    for (std::uint32_t k = 0, at = first; at < first + count; ++k, at += per) {
      const std::uint32_t n = std::min(per, first + count - at);
      const std::uint32_t child = n == 1 ? kWideLeaf | leaf[at] : range(at, n, level + 1);
      out[id].child[k] = child;  // after the call: it may have grown `out`
    }
    return id;
  }
  // The child slot of binary node n: its triangle when it is a one-triangle leaf, else a node.
  std::uint32_t slot(std::uint32_t n, std::uint32_t level) {
    const format::BvhNode& b = nodes[n];
    if (b.count == 1) return kWideLeaf | leaf[b.first];
    return node(n, level);
  }
  // The wide node of binary node n: its grandchildren (a child leaf stands for itself).
  std::uint32_t node(std::uint32_t n, std::uint32_t level) {
    const format::BvhNode& b = nodes[n];
    if (b.count > 0) return range(b.first, b.count, level);
    const std::uint32_t id = add(level);
    std::uint32_t k = 0;
    for (std::uint32_t c : {b.first, b.second}) {
      const format::BvhNode& cb = nodes[c];
      const std::uint32_t grand[2] = {cb.count > 0 ? c : cb.first, cb.second};
      for (int g = 0; g < (cb.count > 0 ? 1 : 2); ++g) {
        const std::uint32_t child = slot(grand[g], level + 1);
        out[id].child[k++] = child;  // after the call: it may have grown `out`
      }
    }
    return id;
  }
};

}  // namespace

void BodyShape::Data::build_wide_bvhs() {
  const format::Asset& fa = *asset;
  wide_nodes.clear();
  wide_root.assign(fa.clusters.size(), kWideEmpty);
  wide_depth = 0;
  for (std::size_t c = 0; c < fa.clusters.size(); ++c) {
    const format::Cluster& cl = fa.clusters[c];
    if (cl.bvh_count == 0) continue;
    WideBuilder b{fa.bvh_nodes.data() + cl.bvh_offset,
                  fa.cluster_triangles.data() + cl.triangle_offset, wide_nodes};
    wide_root[c] = b.node(0, 0);
    wide_depth = std::max(wide_depth, b.depth);
  }
}

std::shared_ptr<const BodyShape> BodyShape::from_asset(const Asset& asset) noexcept {
  try {
    std::shared_ptr<BodyShape> shape(new BodyShape());
    shape->m_data = std::make_unique<Data>();
    Data& d = *shape->m_data;
    const format::Asset& fa = asset.data();
    d.asset = &fa;
    d.node_count = fa.node_count;
    d.triangles = fa.triangles.data();
    d.tri_count = static_cast<std::uint32_t>(fa.triangles.size());
    d.build();
    return shape;
  } catch (...) {
    return nullptr;
  }
}

std::shared_ptr<const BodyShape> BodyShape::from_triangles(const std::uint32_t* triangles,
                                                           std::size_t triangle_count,
                                                           std::uint32_t node_count) noexcept {
  if (triangle_count > 0 && !triangles) return nullptr;
  if (triangle_count >= (std::size_t(1) << 30)) return nullptr;
  for (std::size_t t = 0; t < triangle_count; ++t) {
    const std::uint32_t* v = triangles + 3 * t;
    if (v[0] >= node_count || v[1] >= node_count || v[2] >= node_count) return nullptr;
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) return nullptr;
  }
  try {
    std::shared_ptr<BodyShape> shape(new BodyShape());
    shape->m_data = std::make_unique<Data>();
    Data& d = *shape->m_data;
    d.node_count = node_count;
    d.own_triangles.resize(triangle_count);
    for (std::size_t t = 0; t < triangle_count; ++t)
      d.own_triangles[t] = {triangles[3 * t], triangles[3 * t + 1], triangles[3 * t + 2]};
    d.triangles = d.own_triangles.data();
    d.tri_count = static_cast<std::uint32_t>(triangle_count);
    d.build();
    return shape;
  } catch (...) {
    return nullptr;
  }
}

}  // namespace tetseg
