#include "mesh_topology.hpp"

#include <algorithm>
#include <array>

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
