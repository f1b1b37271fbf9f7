#include "segment_topology.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

namespace tetseg::preprocess::detail {

HalfEdges::HalfEdges(const std::vector<Tri>& triangles) : m_tris(&triangles) {
  const std::uint32_t n = static_cast<std::uint32_t>(triangles.size()) * 3;
  m_twin.assign(n, kNone);
  // (min node, max node, half-edge) sorted: equal edges become neighbours in the list.
  std::vector<std::array<std::uint32_t, 3>> keyed(n);
  for (std::uint32_t h = 0; h < n; ++h) {
    const std::uint32_t a = from(h);
    const std::uint32_t b = to(h);
    keyed[h] = {std::min(a, b), std::max(a, b), h};
  }
  std::sort(keyed.begin(), keyed.end());
  for (std::uint32_t i = 0; i < n;) {
    std::uint32_t j = i;
    while (j < n && keyed[j][0] == keyed[i][0] && keyed[j][1] == keyed[i][1]) ++j;
    if (j - i == 2 && keyed[i][0] != keyed[i][1]) {
      const std::uint32_t h0 = keyed[i][2];
      const std::uint32_t h1 = keyed[i + 1][2];
      if (from(h0) == to(h1) && to(h0) == from(h1)) {
        m_twin[h0] = h1;
        m_twin[h1] = h0;
      }
    }
    i = j;
  }
}

std::vector<Contour> trace_contours(const HalfEdges& mesh, const std::vector<Vec3>& nodes,
                                    const std::vector<std::uint8_t>& in_set,
                                    const std::vector<std::uint32_t>& set_triangles) {
  const std::uint32_t n = mesh.size();
  auto is_border = [&](std::uint32_t h) {
    if (!in_set[h / 3]) return false;
    const std::uint32_t t = mesh.neighbor(h);
    return t == kNone || !in_set[t];
  };
  // The border half-edge that follows h: rotate around its head through the triangles
  // outside the set until the first triangle inside it.
  auto follow = [&](std::uint32_t h) -> std::uint32_t {
    std::uint32_t g = mesh.twin(h);
    for (std::uint32_t guard = 0; g != kNone && guard < n; ++guard) {
      const std::uint32_t o = mesh.twin(HalfEdges::prev(g));
      if (o == kNone) return kNone;
      if (in_set[o / 3]) return o;
      g = o;
    }
    return kNone;
  };

  std::vector<std::uint32_t> border;  // sorted: triangles ascending, then local edge
  for (std::uint32_t t : set_triangles)
    for (std::uint32_t k = 0; k < 3; ++k)
      if (is_border(3 * t + k)) border.push_back(3 * t + k);
  std::vector<std::uint8_t> visited(border.size(), 0);
  auto slot = [&](std::uint32_t h) -> std::size_t {
    const auto it = std::lower_bound(border.begin(), border.end(), h);
    return (it != border.end() && *it == h) ? static_cast<std::size_t>(it - border.begin())
                                            : border.size();
  };

  std::vector<Contour> contours;
  for (std::size_t i = 0; i < border.size(); ++i) {
    if (visited[i]) continue;
    const std::uint32_t start = border[i];
    Contour c;
    std::uint32_t h = start;
    std::size_t s = i;
    while (true) {
      visited[s] = 1;
      c.half_edges.push_back(h);
      c.length += mesh.length(nodes, h);
      const std::uint32_t nh = follow(h);
      if (nh == start) break;
      s = nh == kNone ? border.size() : slot(nh);
      if (s == border.size() || visited[s]) {
        c.closed = false;
        break;
      }
      h = nh;
    }
    contours.push_back(std::move(c));
  }
  return contours;
}

std::uint32_t label_components(const HalfEdges& mesh, const std::vector<std::uint8_t>& include,
                               const std::vector<std::uint8_t>* cut,
                               std::vector<std::uint32_t>& labels) {
  const std::uint32_t nt = mesh.triangle_count();
  labels.assign(nt, kNone);
  std::uint32_t count = 0;
  std::vector<std::uint32_t> stack;
  for (std::uint32_t seed = 0; seed < nt; ++seed) {
    if (!include[seed] || labels[seed] != kNone) continue;
    labels[seed] = count;
    stack.push_back(seed);
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::uint32_t h = 3 * t + k;
        if (cut && (*cut)[h]) continue;
        const std::uint32_t u = mesh.neighbor(h);
        if (u == kNone || !include[u] || labels[u] != kNone) continue;
        labels[u] = count;
        stack.push_back(u);
      }
    }
    ++count;
  }
  return count;
}

UnionFind::UnionFind(std::uint32_t n) : m_parent(n) {
  for (std::uint32_t i = 0; i < n; ++i) m_parent[i] = i;
}

}  // namespace tetseg::preprocess::detail
