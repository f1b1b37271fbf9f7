#include "soup_ccd.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace tetseg::tools::soup {
namespace {

struct Box {
  std::array<double, 3> lo{INFINITY, INFINITY, INFINITY};
  std::array<double, 3> hi{-INFINITY, -INFINITY, -INFINITY};
  void add(const Box& b) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], b.lo[k]);
      hi[k] = std::max(hi[k], b.hi[k]);
    }
  }
  bool overlaps(const Box& b) const {  // closed boxes; exact comparisons
    for (int k = 0; k < 3; ++k)
      if (lo[k] > b.hi[k] || b.lo[k] > hi[k]) return false;
    return true;
  }
};

struct Node {
  Box box;
  std::uint32_t begin = 0, end = 0;  // leaf range in the order array
  std::int32_t left = -1, right = -1;
};

constexpr std::uint32_t kLeafSize = 4;

struct Bvh {
  std::vector<Node> nodes;
  std::vector<std::uint32_t> order;
  const std::vector<Box>* boxes = nullptr;

  std::int32_t build(std::uint32_t begin, std::uint32_t end) {
    Node node;
    node.begin = begin;
    node.end = end;
    Box centroids;
    for (std::uint32_t i = begin; i < end; ++i) {
      const Box& b = (*boxes)[order[i]];
      node.box.add(b);
      Box c;
      for (int k = 0; k < 3; ++k) c.lo[k] = c.hi[k] = 0.5 * b.lo[k] + 0.5 * b.hi[k];
      centroids.add(c);
    }
    const auto index = static_cast<std::int32_t>(nodes.size());
    nodes.push_back(node);
    if (end - begin <= kLeafSize) return index;
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (centroids.hi[k] - centroids.lo[k] > centroids.hi[axis] - centroids.lo[axis]) axis = k;
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [&](std::uint32_t a, std::uint32_t b) {
                       const Box& x = (*boxes)[a];
                       const Box& y = (*boxes)[b];
                       return x.lo[axis] + x.hi[axis] < y.lo[axis] + y.hi[axis];
                     });
    const std::int32_t left = build(begin, mid);
    const std::int32_t right = build(mid, end);
    nodes[static_cast<std::size_t>(index)].left = left;
    nodes[static_cast<std::size_t>(index)].right = right;
    return index;
  }
};

bool shares(const std::array<std::uint32_t, 3>& f, std::uint32_t v) {
  return f[0] == v || f[1] == v || f[2] == v;
}

}  // namespace

std::vector<Contact> find_contacts(const std::vector<std::array<double, 3>>& x0,
                                   const std::vector<std::array<double, 3>>& x1,
                                   const std::vector<std::array<std::uint32_t, 3>>& faces,
                                   const CcdOptions& options, bool brute) {
  const double delta = options.min_separation > 0 ? options.min_separation : 0.0;
  // Swept vertex boxes, enlarged by the minimum separation (rounded outwards).
  std::vector<Box> vertex_boxes(x0.size());
  for (std::size_t v = 0; v < x0.size(); ++v) {
    for (int k = 0; k < 3; ++k) {
      vertex_boxes[v].lo[k] = std::min(x0[v][k], x1[v][k]);
      vertex_boxes[v].hi[k] = std::max(x0[v][k], x1[v][k]);
      if (delta > 0) {
        vertex_boxes[v].lo[k] = std::nextafter(vertex_boxes[v].lo[k] - delta, -INFINITY);
        vertex_boxes[v].hi[k] = std::nextafter(vertex_boxes[v].hi[k] + delta, INFINITY);
      }
    }
  }
  std::vector<Box> face_boxes(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (auto v : faces[f]) face_boxes[f].add(vertex_boxes[v]);

  Bvh bvh;
  bvh.boxes = &face_boxes;
  bvh.order.resize(faces.size());
  std::iota(bvh.order.begin(), bvh.order.end(), 0u);
  if (!faces.empty()) bvh.build(0, static_cast<std::uint32_t>(faces.size()));

  std::vector<std::array<std::uint32_t, 2>> vf_pairs;  // vertex, face
  std::vector<std::array<std::uint32_t, 4>> ee_pairs;  // a < b, c < d, (a,b) < (c,d)
  auto edge_box = [&](std::uint32_t a, std::uint32_t b) {
    Box box = vertex_boxes[a];
    box.add(vertex_boxes[b]);
    return box;
  };
  auto face_pair = [&](std::uint32_t f, std::uint32_t g) {
    const auto& ff = faces[f];
    const auto& gg = faces[g];
    for (auto v : ff)
      if (!shares(gg, v) && vertex_boxes[v].overlaps(face_boxes[g])) vf_pairs.push_back({v, g});
    for (auto v : gg)
      if (!shares(ff, v) && vertex_boxes[v].overlaps(face_boxes[f])) vf_pairs.push_back({v, f});
    for (int i = 0; i < 3; ++i) {
      std::uint32_t a = ff[i], b = ff[(i + 1) % 3];
      if (a > b) std::swap(a, b);
      const Box ea = edge_box(a, b);
      for (int j = 0; j < 3; ++j) {
        std::uint32_t c = gg[j], d = gg[(j + 1) % 3];
        if (c > d) std::swap(c, d);
        if (a == c || a == d || b == c || b == d) continue;
        if (!ea.overlaps(edge_box(c, d))) continue;
        if (std::make_pair(a, b) < std::make_pair(c, d))
          ee_pairs.push_back({a, b, c, d});
        else
          ee_pairs.push_back({c, d, a, b});
      }
    }
  };
  auto leaf_pairs = [&](const Node& p, const Node& q, bool same) {
    for (std::uint32_t i = p.begin; i < p.end; ++i)
      for (std::uint32_t j = same ? i + 1 : q.begin; j < q.end; ++j) {
        const std::uint32_t f = bvh.order[i], g = bvh.order[j];
        if (face_boxes[f].overlaps(face_boxes[g])) face_pair(f, g);
      }
  };
  if (brute) {
    for (std::uint32_t f = 0; f < faces.size(); ++f)
      for (std::uint32_t g = f + 1; g < faces.size(); ++g)
        if (face_boxes[f].overlaps(face_boxes[g])) face_pair(f, g);
  }
  std::vector<std::pair<std::int32_t, std::int32_t>> stack;
  if (!bvh.nodes.empty() && !brute) stack.push_back({0, 0});
  while (!stack.empty()) {
    const auto [pi, qi] = stack.back();
    stack.pop_back();
    const Node& p = bvh.nodes[static_cast<std::size_t>(pi)];
    const Node& q = bvh.nodes[static_cast<std::size_t>(qi)];
    if (pi == qi) {
      if (p.left < 0) {
        leaf_pairs(p, p, true);
      } else {
        stack.push_back({p.left, p.left});
        stack.push_back({p.right, p.right});
        stack.push_back({p.left, p.right});
      }
      continue;
    }
    if (!p.box.overlaps(q.box)) continue;
    if (p.left < 0 && q.left < 0) {
      leaf_pairs(p, q, false);
    } else if (q.left < 0 || (p.left >= 0 && p.end - p.begin >= q.end - q.begin)) {
      stack.push_back({p.left, qi});
      stack.push_back({p.right, qi});
    } else {
      stack.push_back({pi, q.left});
      stack.push_back({pi, q.right});
    }
  }
  std::sort(vf_pairs.begin(), vf_pairs.end());
  vf_pairs.erase(std::unique(vf_pairs.begin(), vf_pairs.end()), vf_pairs.end());
  std::sort(ee_pairs.begin(), ee_pairs.end());
  ee_pairs.erase(std::unique(ee_pairs.begin(), ee_pairs.end()), ee_pairs.end());

  std::vector<Contact> contacts;
  for (const auto& [v, f] : vf_pairs) {
    const auto& face = faces[f];
    const CcdResult r = vertex_face_ccd(x0[v], x0[face[0]], x0[face[1]], x0[face[2]], x1[v],
                                        x1[face[0]], x1[face[1]], x1[face[2]], options);
    if (r.hit()) contacts.push_back({true, {v, face[0], face[1], face[2]}, r.toi});
  }
  for (const auto& e : ee_pairs) {
    const CcdResult r = edge_edge_ccd(x0[e[0]], x0[e[1]], x0[e[2]], x0[e[3]], x1[e[0]], x1[e[1]],
                                      x1[e[2]], x1[e[3]], options);
    if (r.hit()) contacts.push_back({false, e, r.toi});
  }
  return contacts;
}

}  // namespace tetseg::tools::soup
