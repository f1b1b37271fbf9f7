// Object decomposition (Wong & Yeh, section IV-B): boundary segments from low equalised charge,
// segment growing and shrinking, segment boundaries, clusters. Decisions: docs/segmentation.md.

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>

#include "segment_topology.hpp"
#include "tetseg/preprocess/segmentation.hpp"

namespace tetseg::preprocess {

using detail::Contour;
using detail::HalfEdges;
using detail::kNone;
using detail::UnionFind;

std::uint32_t derived_min_cluster_triangles(std::size_t triangle_count) {
  const std::size_t derived = std::max<std::size_t>(8, (triangle_count + 199) / 200);
  return static_cast<std::uint32_t>(std::min(derived, triangle_count));
}

namespace {

class Segmenter {
 public:
  Segmenter(const std::vector<Vec3>& nodes, const Surface& surface,
            const std::vector<double>& equalized, const SegmentationOptions& options)
      : m_nodes(nodes),
        m_tris(surface.triangles),
        m_density(equalized),
        m_options(options),
        m_mesh(surface.triangles),
        m_n(static_cast<std::uint32_t>(surface.triangles.size())),
        m_in_set(m_n, 0),
        m_kept_cut(3 * static_cast<std::size_t>(m_n), 0) {
    m_min_cluster = options.min_cluster_triangles > 0 ? options.min_cluster_triangles
                                                      : derived_min_cluster_triangles(m_n);
  }

  Segmentation run();

 private:
  double edge_length(std::uint32_t h) const { return m_mesh.length(m_nodes, h); }
  void set_flags(const std::vector<std::uint32_t>& tris, std::uint8_t value) {
    for (std::uint32_t t : tris) m_in_set[t] = value;
  }
  bool separates(std::vector<std::uint32_t>& set);
  bool grow(std::vector<std::uint32_t>& set);
  void shrink(std::vector<std::uint32_t>& set);
  bool pick_boundary(const std::vector<std::uint32_t>& set, const std::vector<std::uint32_t>& band);
  std::vector<std::uint32_t> tighten(std::vector<std::uint32_t> loop,
                                     const std::vector<std::uint32_t>& band) const;
  bool accept_loop(const std::vector<std::uint32_t>& loop);
  std::vector<std::uint32_t> cluster_labels(const std::vector<std::uint8_t>& active,
                                            std::uint32_t& pieces);
  void make_clusters(Segmentation& out);

  const std::vector<Vec3>& m_nodes;
  const std::vector<Tri>& m_tris;
  const std::vector<double>& m_density;
  const SegmentationOptions& m_options;
  HalfEdges m_mesh;
  std::uint32_t m_n;
  std::uint32_t m_min_cluster = 1;
  std::vector<std::uint8_t> m_in_set;                  // the segment being processed
  std::vector<std::uint8_t> m_kept_cut;                // per half-edge: on a kept boundary
  std::vector<std::vector<std::uint32_t>> m_loops;     // half-edges of chosen boundaries
  std::vector<std::uint32_t> m_segment_of;             // per triangle: marked segment or kNone
  std::vector<std::vector<std::uint32_t>> m_segments;  // triangles of each marked segment
  std::vector<std::uint32_t> m_absorbed;  // per segment: == m_stamp when in the growing set
  std::uint32_t m_stamp = 0;              // 1 + the segment being processed
  std::vector<std::uint32_t> m_labels;    // scratch
  SegmentationCounts m_counts;
};

// Does the set (flags in m_in_set, triangles sorted in `set`) separate the surface? Complement
// pieces smaller than the minimum cluster size are filled into the set first (a ring of marked
// triangles around a few unmarked ones separates nothing useful). Each contour borders one
// complement component, so fewer than two closed contours cannot separate: checked first, in
// O(|set|), before the O(N) component count.
bool Segmenter::separates(std::vector<std::uint32_t>& set) {
  const std::vector<Contour> contours = detail::trace_contours(m_mesh, m_nodes, m_in_set, set);
  std::size_t closed = 0;
  for (const Contour& c : contours) closed += c.closed ? 1 : 0;
  if (closed < 2) return false;
  std::vector<std::uint8_t> complement(m_n);
  for (std::uint32_t t = 0; t < m_n; ++t) complement[t] = m_in_set[t] ? 0 : 1;
  const std::uint32_t count = detail::label_components(m_mesh, complement, nullptr, m_labels);
  std::vector<std::uint32_t> sizes(count, 0);
  for (std::uint32_t t = 0; t < m_n; ++t)
    if (m_labels[t] != kNone) ++sizes[m_labels[t]];
  std::uint32_t big = 0;
  for (std::uint32_t s : sizes) big += s >= m_min_cluster ? 1 : 0;
  bool filled = false;
  for (std::uint32_t t = 0; t < m_n; ++t)
    if (m_labels[t] != kNone && sizes[m_labels[t]] < m_min_cluster) {
      m_in_set[t] = 1;
      set.push_back(t);
      filled = true;
    }
  if (filled) std::sort(set.begin(), set.end());
  return big >= 2;
}

// Segment growing: add the ring of triangles adjacent to the set until it separates. Fails
// when the ring is empty (the set covers its component) or the set exceeds the growth bound.
bool Segmenter::grow(std::vector<std::uint32_t>& set) {
  const double limit = m_options.growth_bound * static_cast<double>(m_n);
  std::vector<std::uint32_t> frontier = set;
  while (true) {
    std::vector<std::uint32_t> ring;
    for (std::uint32_t t : frontier)
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::uint32_t u = m_mesh.neighbor(3 * t + k);
        if (u != kNone && !m_in_set[u]) ring.push_back(u);
      }
    if (m_options.grow_through_marked) {
      // A ring that touches another marked segment takes all of it: the low-charge band it
      // belongs to is one structure, split only by a few triangles above alpha.
      const std::size_t direct = ring.size();
      for (std::size_t i = 0; i < direct; ++i) {
        const std::uint32_t other = m_segment_of[ring[i]];
        if (other == kNone || m_absorbed[other] == m_stamp) continue;
        m_absorbed[other] = m_stamp;
        for (std::uint32_t t : m_segments[other])
          if (!m_in_set[t]) ring.push_back(t);
      }
    }
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    if (ring.empty()) return false;
    set_flags(ring, 1);
    std::vector<std::uint32_t> merged;
    merged.reserve(set.size() + ring.size());
    std::merge(set.begin(), set.end(), ring.begin(), ring.end(), std::back_inserter(merged));
    set.swap(merged);
    frontier.swap(ring);
    if (static_cast<double>(set.size()) > limit) return false;
    if (separates(set)) return true;
  }
}

// Segment shrinking: peel triangles that touch the complement, highest density first (then by
// id), keeping cutting triangles: those whose removal would join two complement components
// (tracked with union-find, so the set keeps separating). Stops when a pass removes nothing.
void Segmenter::shrink(std::vector<std::uint32_t>& set) {
  UnionFind uf(m_n);
  for (std::uint32_t t = 0; t < m_n; ++t) {
    if (m_in_set[t]) continue;
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t u = m_mesh.neighbor(3 * t + k);
      if (u != kNone && !m_in_set[u]) uf.unite(t, u);
    }
  }
  while (true) {
    std::vector<std::uint32_t> candidates;
    for (std::uint32_t t : set)
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::uint32_t u = m_mesh.neighbor(3 * t + k);
        if (u != kNone && !m_in_set[u]) {
          candidates.push_back(t);
          break;
        }
      }
    std::sort(candidates.begin(), candidates.end(), [&](std::uint32_t a, std::uint32_t b) {
      const double da = std::isnan(m_density[a]) ? 2.0 : m_density[a];
      const double db = std::isnan(m_density[b]) ? 2.0 : m_density[b];
      return da != db ? da > db : a < b;
    });
    bool removed = false;
    for (std::uint32_t t : candidates) {
      std::uint32_t root = kNone;
      bool cutting = false;
      for (std::uint32_t k = 0; k < 3 && !cutting; ++k) {
        const std::uint32_t u = m_mesh.neighbor(3 * t + k);
        if (u == kNone || m_in_set[u]) continue;
        const std::uint32_t r = uf.find(u);
        if (root == kNone)
          root = r;
        else if (r != root)
          cutting = true;
      }
      if (cutting || root == kNone) continue;
      m_in_set[t] = 0;
      uf.unite(t, root);
      removed = true;
    }
    if (!removed) break;
    set.erase(std::remove_if(set.begin(), set.end(), [&](std::uint32_t t) { return !m_in_set[t]; }),
              set.end());
  }
}

// Loop tightening: while some triangle of the band has two consecutive loop edges a-b, b-c
// (an "ear", on either side of the loop) and b occurs once in the loop and edge a-c is not on
// it, move the triangle to the other side: the loop takes a-c instead, strictly shorter. The
// zig-zag contour of a shrunk strip becomes a taut loop that stays inside the low-charge band
// (only band triangles move). Scans in loop order until nothing changes: deterministic.
std::vector<std::uint32_t> Segmenter::tighten(std::vector<std::uint32_t> loop,
                                              const std::vector<std::uint32_t>& band) const {
  auto in_band = [&](std::uint32_t t) { return std::binary_search(band.begin(), band.end(), t); };
  for (bool changed = true; changed && loop.size() > 3;) {
    changed = false;
    std::map<std::uint32_t, std::uint32_t> visits;
    std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (std::uint32_t h : loop) {
      ++visits[m_mesh.from(h)];
      edges.emplace(std::min(m_mesh.from(h), m_mesh.to(h)), std::max(m_mesh.from(h), m_mesh.to(h)));
    }
    for (std::size_t i = 0; i < loop.size() && loop.size() > 3; ++i) {
      const std::size_t j = (i + 1) % loop.size();
      const std::uint32_t h1 = loop[i], h2 = loop[j];
      const std::uint32_t a = m_mesh.from(h1), b = m_mesh.to(h1), c = m_mesh.to(h2);
      if (visits[b] != 1 || a == c || edges.count({std::min(a, c), std::max(a, c)})) continue;
      std::uint32_t shortcut = kNone, moved = kNone;
      if (h1 / 3 == h2 / 3) {  // ear on the loop's left side
        moved = h1 / 3;
        shortcut = m_mesh.twin(HalfEdges::next(h2));
      } else if (m_mesh.twin(h1) != kNone && m_mesh.twin(h2) != kNone &&
                 m_mesh.twin(h1) / 3 == m_mesh.twin(h2) / 3) {  // ear on the right side
        moved = m_mesh.twin(h1) / 3;
        shortcut = HalfEdges::next(m_mesh.twin(h1));
      }
      if (shortcut == kNone || !in_band(moved)) continue;
      --visits[b];
      edges.erase({std::min(a, b), std::max(a, b)});
      edges.erase({std::min(b, c), std::max(b, c)});
      edges.emplace(std::min(a, c), std::max(a, c));
      loop[i] = shortcut;
      loop.erase(loop.begin() + static_cast<std::ptrdiff_t>(j));
      if (j < i) i = loop.size();  // the loop wrapped: rescan from the start
      changed = true;
    }
  }
  return loop;
}

// Keeps `loop` as a segment boundary if (a) alone it splits the surface with its two sides in
// different pieces and (b) with the boundaries kept so far every edge of it lies between two
// different pieces of at least the minimum cluster size (no sliver clusters between nearby
// loops).
bool Segmenter::accept_loop(const std::vector<std::uint32_t>& loop) {
  if (loop.size() < 3) return false;
  const std::vector<std::uint8_t> all(m_n, 1);
  std::vector<std::uint8_t> cut(3 * static_cast<std::size_t>(m_n), 0);
  for (std::uint32_t h : loop) {
    cut[h] = 1;
    if (m_mesh.twin(h) != kNone) cut[m_mesh.twin(h)] = 1;
  }
  std::vector<std::uint32_t> labels;
  if (detail::label_components(m_mesh, all, &cut, labels) < 2) return false;
  const std::uint32_t right = m_mesh.neighbor(loop.front());
  if (right == kNone || labels[right] == labels[loop.front() / 3]) return false;
  for (std::size_t h = 0; h < cut.size(); ++h) cut[h] |= m_kept_cut[h];
  const std::uint32_t count = detail::label_components(m_mesh, all, &cut, labels);
  std::vector<std::uint32_t> sizes(count, 0);
  for (std::uint32_t t = 0; t < m_n; ++t) ++sizes[labels[t]];
  for (std::uint32_t h : loop) {
    const std::uint32_t u = m_mesh.neighbor(h);
    const std::uint32_t a = labels[h / 3];
    if (u == kNone || labels[u] == a || sizes[a] < m_min_cluster ||
        sizes[labels[u]] < m_min_cluster)
      return false;
  }
  for (std::uint32_t h : loop) {
    m_kept_cut[h] = 1;
    m_kept_cut[m_mesh.twin(h)] = 1;
  }
  m_loops.push_back(loop);
  return true;
}

// The segment boundary: the closed contours of the shrunk set, shortest first (ties: first
// traced); each is tightened inside the band and tried, then tried as it is; the first loop
// accepted is the boundary. Returns false when none is.
bool Segmenter::pick_boundary(const std::vector<std::uint32_t>& set,
                              const std::vector<std::uint32_t>& band) {
  std::vector<Contour> contours = detail::trace_contours(m_mesh, m_nodes, m_in_set, set);
  std::stable_sort(contours.begin(), contours.end(),
                   [](const Contour& a, const Contour& b) { return a.length < b.length; });
  for (const Contour& c : contours) {
    if (!c.closed || c.half_edges.size() < 3) continue;
    if (accept_loop(tighten(c.half_edges, band))) return true;
    if (accept_loop(c.half_edges)) return true;
  }
  return false;
}

// Clusters: components of the surface cut along the active boundaries; clusters smaller than
// the minimum merge into the neighbour sharing the longest boundary (smallest cluster first,
// ties by id). Returns the label per triangle (not yet renumbered); `pieces` receives the
// number of components before merging.
std::vector<std::uint32_t> Segmenter::cluster_labels(const std::vector<std::uint8_t>& active,
                                                     std::uint32_t& pieces) {
  std::vector<std::uint8_t> cut(3 * static_cast<std::size_t>(m_n), 0);
  for (std::size_t l = 0; l < m_loops.size(); ++l) {
    if (!active[l]) continue;
    for (std::uint32_t h : m_loops[l]) {
      cut[h] = 1;
      if (m_mesh.twin(h) != kNone) cut[m_mesh.twin(h)] = 1;
    }
  }
  const std::vector<std::uint8_t> all(m_n, 1);
  std::vector<std::uint32_t> labels;
  const std::uint32_t count = detail::label_components(m_mesh, all, &cut, labels);
  pieces = count;
  std::vector<std::vector<std::uint32_t>> members(count);
  for (std::uint32_t t = 0; t < m_n; ++t) members[labels[t]].push_back(t);
  std::vector<std::uint8_t> alive(count, 1), stuck(count, 0);
  std::uint32_t alive_count = count;
  while (alive_count > 1) {
    std::uint32_t small = kNone;
    for (std::uint32_t c = 0; c < count; ++c)
      if (alive[c] && !stuck[c] && members[c].size() < m_min_cluster &&
          (small == kNone || members[c].size() < members[small].size()))
        small = c;
    if (small == kNone) break;
    std::map<std::uint32_t, double> shared;
    for (std::uint32_t t : members[small])
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::uint32_t u = m_mesh.neighbor(3 * t + k);
        if (u != kNone && labels[u] != small) shared[labels[u]] += edge_length(3 * t + k);
      }
    if (shared.empty()) {
      stuck[small] = 1;  // a whole small component of the surface: nothing to merge into
      continue;
    }
    std::uint32_t target = shared.begin()->first;
    for (const auto& [c, length] : shared)
      if (length > shared[target]) target = c;
    for (std::uint32_t t : members[small]) labels[t] = target;
    std::vector<std::uint32_t> merged;
    std::merge(members[target].begin(), members[target].end(), members[small].begin(),
               members[small].end(), std::back_inserter(merged));
    members[target].swap(merged);
    members[small].clear();
    alive[small] = 0;
    --alive_count;
  }
  return labels;
}

// Clusters and the boundaries that remain. A boundary some edge of which ends up inside one
// cluster (after merging, or when boundaries overlap) is dropped and the clusters are
// recomputed from the remaining boundaries, until every remaining boundary edge lies between
// two different clusters; then clusters differ only across boundary edges. Duplicate loops
// (same edge set) are dropped first.
void Segmenter::make_clusters(Segmentation& out) {
  std::vector<std::uint8_t> active(m_loops.size(), 1);
  std::set<std::vector<std::pair<std::uint32_t, std::uint32_t>>> seen;
  for (std::size_t l = 0; l < m_loops.size(); ++l) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (std::uint32_t h : m_loops[l])
      edges.emplace_back(std::min(m_mesh.from(h), m_mesh.to(h)),
                         std::max(m_mesh.from(h), m_mesh.to(h)));
    std::sort(edges.begin(), edges.end());
    if (!seen.insert(edges).second) active[l] = 0;
  }
  std::vector<std::uint32_t> labels;
  std::uint32_t initial_pieces = 0;
  for (bool first = true;; first = false) {
    std::uint32_t pieces = 0;
    labels = cluster_labels(active, pieces);
    if (first) initial_pieces = pieces;
    bool dropped = false;
    for (std::size_t l = 0; l < m_loops.size(); ++l) {
      if (!active[l]) continue;
      for (std::uint32_t h : m_loops[l]) {
        const std::uint32_t u = m_mesh.neighbor(h);
        if (u == kNone || labels[u] == labels[h / 3]) {
          active[l] = 0;
          dropped = true;
          break;
        }
      }
    }
    if (!dropped) break;
  }
  // Renumber by smallest triangle id.
  std::vector<std::uint32_t> renumber(m_n, kNone);
  std::uint32_t next = 0;
  out.triangle_cluster.assign(m_n, 0);
  for (std::uint32_t t = 0; t < m_n; ++t) {
    if (renumber[labels[t]] == kNone) renumber[labels[t]] = next++;
    out.triangle_cluster[t] = renumber[labels[t]];
  }
  out.cluster_count = next;
  m_counts.clusters_merged = initial_pieces - next;
  for (std::size_t l = 0; l < m_loops.size(); ++l) {
    if (!active[l]) continue;
    std::vector<std::uint32_t> nodes;
    double length = 0.0;
    for (std::uint32_t h : m_loops[l]) {
      nodes.push_back(m_mesh.from(h));
      length += edge_length(h);
    }
    out.boundary_loops.push_back(std::move(nodes));
    out.boundary_lengths.push_back(length);
  }
}

Segmentation Segmenter::run() {
  Segmentation out;
  out.min_cluster_triangles = m_min_cluster;
  if (m_n == 0) return out;
  std::vector<std::uint8_t> marked(m_n, 0);
  for (std::uint32_t t = 0; t < m_n; ++t) marked[t] = m_density[t] < m_options.alpha ? 1 : 0;
  const std::uint32_t segments = detail::label_components(m_mesh, marked, nullptr, m_segment_of);
  m_counts.segments_found = segments;
  m_segments.assign(segments, {});
  for (std::uint32_t t = 0; t < m_n; ++t)
    if (m_segment_of[t] != kNone) m_segments[m_segment_of[t]].push_back(t);
  m_absorbed.assign(segments, 0);

  const double beta =
      m_options.beta_divisor > 0.0 ? static_cast<double>(m_n) / m_options.beta_divisor : 0.0;
  for (std::uint32_t s = 0; s < segments; ++s) {
    std::vector<std::uint32_t> set = m_segments[s];
    set_flags(set, 1);
    m_stamp = s + 1;
    m_absorbed[s] = m_stamp;
    bool ok = separates(set);
    if (!ok && static_cast<double>(set.size()) > beta) {
      ok = grow(set);
      if (ok) ++m_counts.segments_grown;
    }
    if (ok) {
      const std::vector<std::uint32_t> band = set;  // the (grown) segment before shrinking
      shrink(set);
      ++m_counts.segments_shrunk;
      pick_boundary(set, band);
    }
    set_flags(set, 0);
  }
  make_clusters(out);
  m_counts.boundaries = static_cast<std::uint32_t>(out.boundary_loops.size());
  m_counts.clusters = out.cluster_count;
  out.counts = m_counts;
  return out;
}

}  // namespace

Segmentation segment_surface(const std::vector<Vec3>& nodes, const Surface& surface,
                             const std::vector<double>& equalized,
                             const SegmentationOptions& options) {
  if (equalized.size() != surface.triangles.size())
    throw std::invalid_argument("segment_surface: one equalised density per triangle expected");
  for (const Tri& t : surface.triangles)
    for (std::uint32_t v : t)
      if (v >= nodes.size()) throw std::invalid_argument("segment_surface: node id out of range");
  Segmenter segmenter(nodes, surface, equalized, options);
  return segmenter.run();
}

}  // namespace tetseg::preprocess
