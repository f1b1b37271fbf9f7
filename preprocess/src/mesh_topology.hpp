#pragma once
/// \file
/// Internal: adjacency of triangle surfaces (half-edges, edge-connected components) and
/// union-find, shared by validation, repair, components and segmentation. Not installed.

#include <cstdint>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"
#include "vec3_math.hpp"

namespace tetseg::preprocess::detail {

inline constexpr std::uint32_t kNone = 0xffffffffu;

/// Half-edge h = 3 * t + k runs from triangles[t][k] to triangles[t][(k + 1) % 3]. Twins pair
/// the two half-edges of a manifold edge (opposite directions); edges with one or more than
/// two triangles, or two with the same direction, stay unpaired (kNone) so that corrupt
/// surfaces degrade results instead of crashing.
class HalfEdges {
 public:
  explicit HalfEdges(const std::vector<Tri>& triangles);

  std::uint32_t triangle_count() const { return static_cast<std::uint32_t>(m_tris->size()); }
  std::uint32_t size() const { return static_cast<std::uint32_t>(m_twin.size()); }
  std::uint32_t twin(std::uint32_t h) const { return m_twin[h]; }
  std::uint32_t from(std::uint32_t h) const { return (*m_tris)[h / 3][h % 3]; }
  std::uint32_t to(std::uint32_t h) const { return (*m_tris)[h / 3][(h % 3 + 1) % 3]; }
  static std::uint32_t next(std::uint32_t h) { return h - h % 3 + (h % 3 + 1) % 3; }
  static std::uint32_t prev(std::uint32_t h) { return h - h % 3 + (h % 3 + 2) % 3; }
  /// Length of the edge of half-edge h at positions `nodes`.
  double length(const std::vector<Vec3>& nodes, std::uint32_t h) const {
    return distance_between(nodes[from(h)], nodes[to(h)]);
  }
  /// Triangle across half-edge h, or kNone.
  std::uint32_t neighbor(std::uint32_t h) const {
    return m_twin[h] == kNone ? kNone : m_twin[h] / 3;
  }

 private:
  const std::vector<Tri>* m_tris;
  std::vector<std::uint32_t> m_twin;
};

/// Edge-connected components of the triangles with `include[t]`, not crossing half-edges with
/// `cut[h]` (when `cut` is non-null). Labels are 0.. in order of the smallest triangle id;
/// excluded triangles get kNone. Returns the number of components.
std::uint32_t label_components(const HalfEdges& mesh, const std::vector<std::uint8_t>& include,
                               const std::vector<std::uint8_t>* cut,
                               std::vector<std::uint32_t>& labels);

/// Union-find with path halving; unions attach the larger root to the smaller (deterministic).
class UnionFind {
 public:
  explicit UnionFind(std::uint32_t n);
  std::uint32_t find(std::uint32_t x) {
    while (m_parent[x] != x) {
      m_parent[x] = m_parent[m_parent[x]];
      x = m_parent[x];
    }
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a < b) m_parent[b] = a;
    if (b < a) m_parent[a] = b;
  }
  /// A hint that x is about to be looked up (large sets visited in an order of their own).
  void prefetch(std::uint32_t x) const {
#if defined(__GNUC__)
    __builtin_prefetch(m_parent.data() + x);
#endif
  }

 private:
  std::vector<std::uint32_t> m_parent;
};

}  // namespace tetseg::preprocess::detail
