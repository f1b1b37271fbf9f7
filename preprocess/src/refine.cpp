// Visibility-driven cluster refinement (beyond the paper): split clusters that no interior node
// sees whole at rest along minimum cuts, merge neighbours that one node sees whole.
// Decisions and measurements: docs/segmentation.md, "Refinement".

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

#include "min_cut.hpp"
#include "segment_topology.hpp"
#include "tetseg/preprocess/segmentation.hpp"

namespace tetseg::preprocess {

using detail::HalfEdges;
using detail::kNone;

namespace {

using detail::cross;
using detail::dot;
using detail::norm;
using detail::sub;

/// A cluster under refinement: its triangles (ascending) and its best detector.
struct Part {
  std::vector<std::uint32_t> triangles;
  Detector detector;
  std::uint32_t serial = 0;  ///< unique per part contents (merge cache key)
  bool settled = false;      ///< a split was tried and rejected

  std::uint32_t non_positive() const {
    return static_cast<std::uint32_t>(triangles.size()) - detector.positive_triangles;
  }
  double visibility() const {
    return triangles.empty() ? 1.0
                             : static_cast<double>(detector.positive_triangles) /
                                   static_cast<double>(triangles.size());
  }
};

class Refiner {
 public:
  Refiner(const std::vector<Vec3>& nodes, const Surface& surface,
          const std::vector<double>& equalized, const RefinementOptions& options,
          std::uint32_t min_cluster)
      : m_nodes(nodes),
        m_surface(surface),
        m_density(equalized),
        m_options(options),
        m_min_cluster(min_cluster),
        m_mesh(surface.triangles),
        m_local(surface.triangles.size(), kNone) {
    const std::size_t n = surface.triangles.size();
    m_normal.resize(n);
    m_centroid.resize(n);
    double length_sum = 0.0;
    for (std::size_t t = 0; t < n; ++t) {
      const Tri& tri = surface.triangles[t];
      Vec3 normal = cross(sub(nodes[tri[1]], nodes[tri[0]]), sub(nodes[tri[2]], nodes[tri[0]]));
      const double len = norm(normal);
      if (len > 0.0)
        for (double& x : normal) x /= len;
      m_normal[t] = normal;
      for (int k = 0; k < 3; ++k)
        m_centroid[t][k] = (nodes[tri[0]][k] + nodes[tri[1]][k] + nodes[tri[2]][k]) / 3.0;
      for (std::uint32_t k = 0; k < 3; ++k)
        length_sum += m_mesh.length(nodes, 3 * static_cast<std::uint32_t>(t) + k);
    }
    m_mean_edge = n > 0 ? length_sum / static_cast<double>(3 * n) : 1.0;
  }

  Segmentation run(const Segmentation& charge, RefinementCounts& counts);

 private:
  /// Cut cost of the edge of half-edge h: length x (0.05 + mean equalised density) x concavity
  /// factor (1 on convex or flat edges, 1 / (1 + 8 bend) on concave ones, bend = (1 - n1.n2)/2).
  double cut_weight(std::uint32_t h) const {
    const std::uint32_t a = h / 3;
    const std::uint32_t b = m_mesh.neighbor(h);
    auto density = [&](std::uint32_t t) {
      const double d = m_density[t];
      return std::isfinite(d) ? std::clamp(d, 0.0, 1.0) : 1.0;
    };
    const double charge = 0.05 + 0.5 * (density(a) + density(b));
    const bool concave = dot(m_normal[a], sub(m_centroid[b], m_centroid[a])) > 0.0;
    const double bend = 0.5 * (1.0 - dot(m_normal[a], m_normal[b]));
    const double shape = concave ? 1.0 / (1.0 + 8.0 * bend) : 1.0;
    return m_mesh.length(m_nodes, h) * charge * shape;
  }

  Part make_part(std::vector<std::uint32_t> triangles) {
    std::sort(triangles.begin(), triangles.end());
    Part part;
    part.triangles = std::move(triangles);
    part.detector =
        best_detector(m_nodes, m_surface, part.triangles, DetectorStrategy::kVisibility);
    part.serial = m_next_serial++;
    return part;
  }

  bool try_split(const Part& part, Part& first, Part& second);
  void make_connected(const std::vector<std::uint32_t>& triangles,
                      std::vector<std::uint8_t>& label) const;
  void merge(std::vector<Part>& parts, RefinementCounts& counts);

  const std::vector<Vec3>& m_nodes;
  const Surface& m_surface;
  const std::vector<double>& m_density;
  const RefinementOptions& m_options;
  const std::uint32_t m_min_cluster;
  HalfEdges m_mesh;
  std::vector<Vec3> m_normal, m_centroid;
  double m_mean_edge = 1.0;
  std::vector<std::uint32_t> m_local;  // triangle -> index in the part being split, else kNone
  std::uint32_t m_next_serial = 0;
};

// Flips the smallest stray component (not the largest of its label) to the other label until
// each label is one edge-connected component inside the part. Each flip joins the component to
// a neighbour of the other label, so the number of components drops every round.
void Refiner::make_connected(const std::vector<std::uint32_t>& triangles,
                             std::vector<std::uint8_t>& label) const {
  const std::uint32_t m = static_cast<std::uint32_t>(triangles.size());
  std::vector<std::uint32_t> component(m);
  std::vector<std::uint32_t> stack;
  for (;;) {
    std::fill(component.begin(), component.end(), kNone);
    std::vector<std::uint32_t> size;
    std::vector<std::uint8_t> component_label;
    for (std::uint32_t seed = 0; seed < m; ++seed) {
      if (component[seed] != kNone) continue;
      const std::uint32_t id = static_cast<std::uint32_t>(size.size());
      size.push_back(0);
      component_label.push_back(label[seed]);
      component[seed] = id;
      stack.assign(1, seed);
      while (!stack.empty()) {
        const std::uint32_t i = stack.back();
        stack.pop_back();
        ++size[id];
        for (std::uint32_t k = 0; k < 3; ++k) {
          const std::uint32_t nb = m_mesh.neighbor(3 * triangles[i] + k);
          if (nb == kNone) continue;
          const std::uint32_t j = m_local[nb];
          if (j == kNone || component[j] != kNone || label[j] != label[i]) continue;
          component[j] = id;
          stack.push_back(j);
        }
      }
    }
    // Largest component per label (first wins ties), then the smallest other one.
    std::uint32_t largest[2] = {kNone, kNone};
    for (std::uint32_t c = 0; c < size.size(); ++c) {
      std::uint32_t& l = largest[component_label[c]];
      if (l == kNone || size[c] > size[l]) l = c;
    }
    std::uint32_t stray = kNone;
    for (std::uint32_t c = 0; c < size.size(); ++c) {
      if (c == largest[component_label[c]]) continue;
      if (stray == kNone || size[c] < size[stray]) stray = c;
    }
    if (stray == kNone) return;
    for (std::uint32_t i = 0; i < m; ++i)
      if (component[i] == stray) label[i] ^= 1;
  }
}

// One split of `part`: label 0 = seen from the part's detector, label 1 = seen from the node
// that sees most of the rest. A minimum cut trades triangles that their label's node does not
// see (cost `invisibility_cost` mean edge lengths each) against cut edges (cut_weight). Kept
// when both pieces reach the minimum size and the non-positive count drops by at least
// `gain_per_cut_edge` per cut edge.
bool Refiner::try_split(const Part& part, Part& first, Part& second) {
  const std::vector<std::uint32_t>& tris = part.triangles;
  const std::uint32_t m = static_cast<std::uint32_t>(tris.size());
  if (part.non_positive() == 0 || m < 2 * m_min_cluster) return false;
  const Vec3& seen_from = m_nodes[part.detector.node];
  std::vector<std::uint8_t> positive_first(m), positive_second(m);
  std::vector<std::uint32_t> unseen;
  for (std::uint32_t i = 0; i < m; ++i) {
    positive_first[i] = triangle_positive_from(m_nodes, m_surface.triangles[tris[i]], seen_from);
    if (!positive_first[i]) unseen.push_back(tris[i]);
  }
  const Detector other = best_detector(m_nodes, m_surface, unseen, DetectorStrategy::kVisibility);
  if (other.node == part.detector.node) return false;
  for (std::uint32_t i = 0; i < m; ++i)
    positive_second[i] =
        triangle_positive_from(m_nodes, m_surface.triangles[tris[i]], m_nodes[other.node]);

  for (std::uint32_t i = 0; i < m; ++i) m_local[tris[i]] = i;
  const double lambda = m_options.invisibility_cost * m_mean_edge;
  detail::MinCut graph(m + 2);
  const std::uint32_t source = m, sink = m + 1;
  for (std::uint32_t i = 0; i < m; ++i) {
    // Seen by exactly one of the two nodes: pay lambda for the other label.
    if (positive_first[i] && !positive_second[i]) graph.add_edge(source, i, lambda, 0.0);
    if (!positive_first[i] && positive_second[i]) graph.add_edge(i, sink, lambda, 0.0);
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t h = 3 * tris[i] + k;
      const std::uint32_t nb = m_mesh.neighbor(h);
      if (nb == kNone || nb < tris[i] || m_local[nb] == kNone) continue;
      const double w = cut_weight(h);
      graph.add_edge(i, m_local[nb], w, w);
    }
  }
  const double epsilon = 1e-12 * lambda;
  graph.run(source, sink, epsilon);
  const std::vector<std::uint8_t> side = graph.source_side(source, epsilon);
  std::vector<std::uint8_t> label(m);
  for (std::uint32_t i = 0; i < m; ++i) label[i] = side[i] ? 0 : 1;
  make_connected(tris, label);

  std::vector<std::uint32_t> piece[2];
  std::uint32_t cut_edges = 0;
  for (std::uint32_t i = 0; i < m; ++i) {
    piece[label[i]].push_back(tris[i]);
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t nb = m_mesh.neighbor(3 * tris[i] + k);
      if (nb != kNone && nb > tris[i] && m_local[nb] != kNone && label[m_local[nb]] != label[i])
        ++cut_edges;
    }
  }
  for (std::uint32_t t : tris) m_local[t] = kNone;
  if (piece[0].size() < m_min_cluster || piece[1].size() < m_min_cluster) return false;

  first = make_part(std::move(piece[0]));
  second = make_part(std::move(piece[1]));
  const double gain = static_cast<double>(part.non_positive()) -
                      static_cast<double>(first.non_positive() + second.non_positive());
  return gain >= std::max(1.0, m_options.gain_per_cut_edge * static_cast<double>(cut_edges));
}

// Greedy: merge the neighbouring pair whose union is seen best, as long as the union is seen
// at least `min_visibility` positive and has no more non-positive triangles than the two
// apart. Unions are evaluated once per pair of part contents (cached by serial).
void Refiner::merge(std::vector<Part>& parts, RefinementCounts& counts) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, Part> cache;
  std::vector<std::uint32_t> part_of(m_surface.triangles.size(), 0);
  for (;;) {
    for (std::uint32_t p = 0; p < parts.size(); ++p)
      for (std::uint32_t t : parts[p].triangles) part_of[t] = p;
    std::set<std::pair<std::uint32_t, std::uint32_t>> neighbours;
    for (std::uint32_t h = 0; h < m_mesh.size(); ++h) {
      const std::uint32_t nb = m_mesh.neighbor(h);
      if (nb == kNone) continue;
      const std::uint32_t a = part_of[h / 3], b = part_of[nb];
      if (a < b) neighbours.emplace(a, b);
    }
    std::pair<std::uint32_t, std::uint32_t> best{kNone, kNone};
    double best_visibility = -1.0;
    for (const auto& [a, b] : neighbours) {
      const auto key = std::make_pair(parts[a].serial, parts[b].serial);
      auto it = cache.find(key);
      if (it == cache.end()) {
        std::vector<std::uint32_t> both = parts[a].triangles;
        both.insert(both.end(), parts[b].triangles.begin(), parts[b].triangles.end());
        it = cache.emplace(key, make_part(std::move(both))).first;
      }
      const Part& u = it->second;
      if (u.visibility() < m_options.min_visibility) continue;
      if (u.non_positive() > parts[a].non_positive() + parts[b].non_positive()) continue;
      if (u.visibility() > best_visibility) {
        best_visibility = u.visibility();
        best = {a, b};
      }
    }
    if (best.first == kNone) return;
    const auto key = std::make_pair(parts[best.first].serial, parts[best.second].serial);
    parts[best.first] = cache.at(key);
    parts.erase(parts.begin() + best.second);
    ++counts.merges;
  }
}

Segmentation Refiner::run(const Segmentation& charge, RefinementCounts& counts) {
  const std::uint32_t n = static_cast<std::uint32_t>(m_surface.triangles.size());
  std::vector<std::vector<std::uint32_t>> members(charge.cluster_count);
  for (std::uint32_t t = 0; t < n; ++t) members[charge.triangle_cluster[t]].push_back(t);
  std::vector<Part> parts;
  for (auto& ids : members) parts.push_back(make_part(std::move(ids)));
  counts.clusters_before = charge.cluster_count;

  // Splits: always the part with the most non-positive triangles first.
  while (parts.size() < m_options.max_clusters) {
    std::uint32_t pick = kNone;
    for (std::uint32_t p = 0; p < parts.size(); ++p) {
      const Part& part = parts[p];
      if (part.settled || part.visibility() >= m_options.min_visibility) continue;
      if (pick == kNone || part.non_positive() > parts[pick].non_positive()) pick = p;
    }
    if (pick == kNone) break;
    Part first, second;
    if (try_split(parts[pick], first, second)) {
      parts[pick] = std::move(first);
      parts.push_back(std::move(second));
      ++counts.splits;
    } else {
      parts[pick].settled = true;
    }
  }
  if (m_options.merge) merge(parts, counts);

  // Clusters numbered by smallest triangle id; loops: the distinct closed contours.
  std::sort(parts.begin(), parts.end(),
            [](const Part& a, const Part& b) { return a.triangles.front() < b.triangles.front(); });
  Segmentation out;
  out.cluster_count = static_cast<std::uint32_t>(parts.size());
  out.triangle_cluster.assign(n, 0);
  out.min_cluster_triangles = m_min_cluster;
  out.counts = charge.counts;
  std::vector<std::uint8_t> in_set(n, 0);
  std::set<std::vector<std::uint64_t>> seen_loops;
  for (std::uint32_t c = 0; c < parts.size(); ++c) {
    for (std::uint32_t t : parts[c].triangles) {
      out.triangle_cluster[t] = c;
      in_set[t] = 1;
    }
    for (const detail::Contour& contour :
         detail::trace_contours(m_mesh, m_nodes, in_set, parts[c].triangles)) {
      if (!contour.closed || contour.half_edges.size() < 3) continue;
      std::vector<std::uint64_t> edges;
      std::vector<std::uint32_t> loop;
      for (std::uint32_t h : contour.half_edges) {
        const std::uint64_t u = m_mesh.from(h), v = m_mesh.to(h);
        edges.push_back(std::min(u, v) << 32 | std::max(u, v));
        loop.push_back(m_mesh.from(h));
      }
      std::sort(edges.begin(), edges.end());
      if (!seen_loops.insert(edges).second) continue;
      out.boundary_loops.push_back(std::move(loop));
      out.boundary_lengths.push_back(contour.length);
    }
    for (std::uint32_t t : parts[c].triangles) in_set[t] = 0;
  }
  out.counts.clusters = out.cluster_count;
  out.counts.boundaries = static_cast<std::uint32_t>(out.boundary_loops.size());
  return out;
}

}  // namespace

Segmentation refine_clusters(const std::vector<Vec3>& nodes, const Surface& surface,
                             const std::vector<double>& equalized, const Segmentation& charge,
                             const RefinementOptions& options, RefinementCounts* counts) {
  if (surface.interior_nodes.empty())
    throw InputError("", "the tet mesh has no interior node: clusters cannot be refined");
  const std::size_t n = surface.triangles.size();
  if (equalized.size() != n || charge.triangle_cluster.size() != n)
    throw std::invalid_argument(
        "refine_clusters: one density and cluster id per triangle expected");
  for (std::uint32_t c : charge.triangle_cluster)
    if (c >= charge.cluster_count) throw std::invalid_argument("refine_clusters: bad cluster id");
  for (const Tri& t : surface.triangles)
    for (std::uint32_t v : t)
      if (v >= nodes.size()) throw std::invalid_argument("refine_clusters: node id out of range");
  const std::uint32_t min_cluster =
      options.min_cluster_triangles > 0
          ? options.min_cluster_triangles
          : std::max(charge.min_cluster_triangles, derived_min_cluster_triangles(n));
  RefinementCounts local;
  Refiner refiner(nodes, surface, equalized, options, std::max<std::uint32_t>(1, min_cluster));
  Segmentation out = refiner.run(charge, counts ? *counts : local);
  return out;
}

}  // namespace tetseg::preprocess
