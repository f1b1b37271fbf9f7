#pragma once
/// \file
/// Internal: minimum s-t cut of a small capacitated graph (Dinic's max-flow, iterative, no
/// recursion). Used by cluster refinement to cut a cluster along cheap (concave, low-charge)
/// edges. Not installed.

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace tetseg::preprocess::detail {

class MinCut {
 public:
  /// A graph of `vertex_count` vertices and no edges.
  explicit MinCut(std::uint32_t vertex_count) : m_head(vertex_count, -1) {}

  /// Adds the arc u -> v with capacity `forward` and v -> u with `backward` (both >= 0, finite).
  void add_edge(std::uint32_t u, std::uint32_t v, double forward, double backward) {
    m_arcs.push_back({v, m_head[u], forward});
    m_head[u] = static_cast<std::int32_t>(m_arcs.size() - 1);
    m_arcs.push_back({u, m_head[v], backward});
    m_head[v] = static_cast<std::int32_t>(m_arcs.size() - 1);
  }

  /// Runs max-flow from `source` to `sink` and returns the flow (= the minimum cut's capacity).
  /// Residual capacities at or below `epsilon` count as saturated.
  double run(std::uint32_t source, std::uint32_t sink, double epsilon) {
    const std::uint32_t n = static_cast<std::uint32_t>(m_head.size());
    double total = 0.0;
    std::vector<std::int32_t> level(n), next(n);
    std::vector<std::int32_t> path;  // arc ids from source
    std::vector<std::uint32_t> queue;
    for (;;) {
      // Level graph by breadth-first search.
      std::fill(level.begin(), level.end(), -1);
      queue.assign(1, source);
      level[source] = 0;
      for (std::size_t q = 0; q < queue.size(); ++q) {
        const std::uint32_t u = queue[q];
        for (std::int32_t a = m_head[u]; a >= 0; a = m_arcs[a].next) {
          if (m_arcs[a].capacity > epsilon && level[m_arcs[a].to] < 0) {
            level[m_arcs[a].to] = level[u] + 1;
            queue.push_back(m_arcs[a].to);
          }
        }
      }
      if (level[sink] < 0) return total;
      next = m_head;
      // Blocking flow: advance along level arcs, retreat from dead ends.
      path.clear();
      std::uint32_t u = source;
      for (;;) {
        if (u == sink) {
          double bottleneck = std::numeric_limits<double>::infinity();
          for (std::int32_t a : path) bottleneck = std::min(bottleneck, m_arcs[a].capacity);
          for (std::int32_t a : path) {
            m_arcs[a].capacity -= bottleneck;
            m_arcs[a ^ 1].capacity += bottleneck;
          }
          total += bottleneck;
          path.clear();
          u = source;
          continue;
        }
        std::int32_t& a = next[u];
        while (a >= 0 && !(m_arcs[a].capacity > epsilon && level[m_arcs[a].to] == level[u] + 1))
          a = m_arcs[a].next;
        if (a >= 0) {
          path.push_back(a);
          u = m_arcs[a].to;
          continue;
        }
        if (u == source) break;
        level[u] = -1;  // dead end
        const std::int32_t back = path.back();
        path.pop_back();
        u = m_arcs[back ^ 1].to;
        next[u] = m_arcs[next[u]].next;
      }
    }
  }

  /// After run(): 1 for the vertices reachable from `source` through unsaturated arcs.
  std::vector<std::uint8_t> source_side(std::uint32_t source, double epsilon) const {
    std::vector<std::uint8_t> seen(m_head.size(), 0);
    std::vector<std::uint32_t> stack{source};
    seen[source] = 1;
    while (!stack.empty()) {
      const std::uint32_t u = stack.back();
      stack.pop_back();
      for (std::int32_t a = m_head[u]; a >= 0; a = m_arcs[a].next) {
        if (m_arcs[a].capacity > epsilon && !seen[m_arcs[a].to]) {
          seen[m_arcs[a].to] = 1;
          stack.push_back(m_arcs[a].to);
        }
      }
    }
    return seen;
  }

 private:
  struct Arc {
    std::uint32_t to;
    std::int32_t next;  // next arc out of the same vertex, or -1
    double capacity;    // residual
  };
  std::vector<std::int32_t> m_head;
  std::vector<Arc> m_arcs;
};

}  // namespace tetseg::preprocess::detail
