// BodyShape: the immutable surface topology of a body, built once (body_shape.hpp).

#include <algorithm>
#include <cmath>
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

  // Unique edges and edge -> triangle adjacency: the half edges (lo, hi, triangle*3+slot) in
  // sorted order, by a counting sort on lo (stable: slots ascending within a bucket), then
  // each bucket (the edges around one node: a few) sorted by (hi, slot).
  std::vector<std::array<std::uint32_t, 3>> half(std::size_t(tri_count) * 3);
  {
    std::vector<std::uint32_t> start(std::size_t(node_count) + 1, 0);
    for (std::uint32_t t = 0; t < tri_count; ++t)
      for (std::uint32_t s = 0; s < 3; ++s)
        ++start[std::size_t(std::min(triangles[t][s], triangles[t][(s + 1) % 3])) + 1];
    for (std::size_t n = 0; n < node_count; ++n) start[n + 1] += start[n];
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::uint32_t t = 0; t < tri_count; ++t) {
      for (std::uint32_t s = 0; s < 3; ++s) {
        std::uint32_t u = triangles[t][s], v = triangles[t][(s + 1) % 3];
        if (u > v) std::swap(u, v);
        half[fill[u]++] = {u, v, t * 3 + s};
      }
    }
    for (std::size_t n = 0; n < node_count; ++n)
      std::sort(half.begin() + start[n], half.begin() + start[n + 1]);
  }
  tri_edges.assign(tri_count, {0, 0, 0});
  et_offset.clear();
  edges.reserve(half.size());
  et_offset.reserve(half.size() + 1);
  et_list.reserve(half.size());
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

// Binary BVH over the triangles `order` (global ids; reordered into leaf order), one triangle
// per leaf, split by a binned surface-area heuristic over the triangles' boxes at `rest`;
// below depth 2 log2(n) + 4 by the median centroid instead, so the depth stays under
// 3 log2(n) + 6 whatever the geometry.
void build_sah_bvh(const format::Triangle* tris, const std::array<double, 3>* rest,
                   std::vector<std::uint32_t>& order, std::vector<format::BvhNode>& nodes) {
  struct Item {
    std::uint32_t id;
    double lo[3], hi[3], c[3];
  };
  const std::uint32_t n = static_cast<std::uint32_t>(order.size());
  std::vector<Item> items(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    Item& it = items[i];
    it.id = order[i];
    for (int k = 0; k < 3; ++k) {
      it.lo[k] = INFINITY;
      it.hi[k] = -INFINITY;
      for (std::uint32_t v : tris[it.id]) {
        it.lo[k] = std::min(it.lo[k], rest[v][k]);
        it.hi[k] = std::max(it.hi[k], rest[v][k]);
      }
      it.c[k] = 0.5 * (it.lo[k] + it.hi[k]);
    }
  }
  auto area = [](const double* lo, const double* hi) {
    const double d[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
  };
  constexpr int kBins = 16;
  struct Task {
    std::uint32_t node, begin, end, depth;
  };
  std::uint32_t sah_depth = 4;
  for (std::uint32_t m = n; m > 1; m = (m + 1) / 2) sah_depth += 2;
  nodes.assign(1, format::BvhNode{});
  std::vector<Task> stack{{0, 0, n, 0}};
  while (!stack.empty()) {
    const Task t = stack.back();
    stack.pop_back();
    if (t.end - t.begin <= 1) {
      nodes[t.node] = {t.begin, 0, t.end - t.begin};
      continue;
    }
    double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (std::uint32_t i = t.begin; i < t.end; ++i)
      for (int k = 0; k < 3; ++k) {
        clo[k] = std::min(clo[k], items[i].c[k]);
        chi[k] = std::max(chi[k], items[i].c[k]);
      }
    int best_axis = -1, best_bin = 0;
    double best_cost = INFINITY;
    for (int k = 0; k < 3 && t.depth < sah_depth; ++k) {
      if (!(chi[k] > clo[k])) continue;
      const double scale = kBins / (chi[k] - clo[k]);
      struct Bin {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        std::uint32_t count = 0;
      } bins[kBins];
      for (std::uint32_t i = t.begin; i < t.end; ++i) {
        const int b = std::min(kBins - 1, static_cast<int>((items[i].c[k] - clo[k]) * scale));
        Bin& bin = bins[b];
        ++bin.count;
        for (int a = 0; a < 3; ++a) {
          bin.lo[a] = std::min(bin.lo[a], items[i].lo[a]);
          bin.hi[a] = std::max(bin.hi[a], items[i].hi[a]);
        }
      }
      // Cost of splitting after bin b: area(left) * count(left) + area(right) * count(right).
      double right_cost[kBins] = {};
      Bin acc;
      for (int b = kBins - 1; b > 0; --b) {
        acc.count += bins[b].count;
        for (int a = 0; a < 3; ++a) {
          acc.lo[a] = std::min(acc.lo[a], bins[b].lo[a]);
          acc.hi[a] = std::max(acc.hi[a], bins[b].hi[a]);
        }
        right_cost[b] = acc.count > 0 ? area(acc.lo, acc.hi) * acc.count : 0.0;
      }
      Bin left;
      for (int b = 0; b + 1 < kBins; ++b) {
        left.count += bins[b].count;
        for (int a = 0; a < 3; ++a) {
          left.lo[a] = std::min(left.lo[a], bins[b].lo[a]);
          left.hi[a] = std::max(left.hi[a], bins[b].hi[a]);
        }
        if (left.count == 0 || left.count == t.end - t.begin) continue;
        const double cost = area(left.lo, left.hi) * left.count + right_cost[b + 1];
        if (cost < best_cost) best_cost = cost, best_axis = k, best_bin = b;
      }
    }
    std::uint32_t mid;
    if (best_axis < 0) {  // deep, or all centroids in one point: the median on the longest axis
      mid = t.begin + (t.end - t.begin) / 2;
      int axis = 0;
      for (int k = 1; k < 3; ++k)
        if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
      std::nth_element(items.data() + t.begin, items.data() + mid, items.data() + t.end,
                       [axis](const Item& a, const Item& b) {
                         return a.c[axis] < b.c[axis] || (a.c[axis] == b.c[axis] && a.id < b.id);
                       });
    } else {
      const double scale = kBins / (chi[best_axis] - clo[best_axis]);
      Item* split =
          std::partition(items.data() + t.begin, items.data() + t.end, [&](const Item& it) {
            return std::min(kBins - 1, static_cast<int>((it.c[best_axis] - clo[best_axis]) *
                                                        scale)) <= best_bin;
          });
      mid = static_cast<std::uint32_t>(split - items.data());
    }
    const std::uint32_t left = static_cast<std::uint32_t>(nodes.size());
    nodes.push_back({});
    nodes.push_back({});
    nodes[t.node] = {left, left + 1, 0};
    stack.push_back({left + 1, mid, t.end, t.depth + 1});
    stack.push_back({left, t.begin, mid, t.depth + 1});
  }
  for (std::uint32_t i = 0; i < n; ++i) order[i] = items[i].id;
}

}  // namespace

void BodyShape::Data::build_wide_bvhs() {
  const format::Asset& fa = *asset;
  wide_nodes.clear();
  wide_root.assign(fa.clusters.size(), kWideEmpty);
  wide_depth = 0;
  for (std::size_t c = 0; c < fa.clusters.size(); ++c) {
    const format::Cluster& cl = fa.clusters[c];
    if (cl.bvh_count == 0) continue;
    std::vector<std::uint32_t> order(
        fa.cluster_triangles.begin() + cl.triangle_offset,
        fa.cluster_triangles.begin() + cl.triangle_offset + cl.triangle_count);
    std::vector<format::BvhNode> sah;
    const bool rest = fa.rest_positions.size() == fa.node_count && !order.empty();
    if (rest) build_sah_bvh(fa.triangles.data(), fa.rest_positions.data(), order, sah);
    WideBuilder b{rest ? sah.data() : fa.bvh_nodes.data() + cl.bvh_offset,
                  rest ? order.data() : fa.cluster_triangles.data() + cl.triangle_offset,
                  wide_nodes};
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
