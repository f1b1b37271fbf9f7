// Detector nodes per cluster (Wong & Yeh, section IV-C) and the visibility improvement
// described in docs/segmentation.md.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "tetseg/preprocess/segmentation.hpp"
#include "vec3_math.hpp"

namespace tetseg::preprocess {
namespace {

using detail::cross;
using detail::distance2;
using detail::dot;
using detail::sub;

/// The `k` interior nodes nearest `point`, ordered by (distance, id).
std::vector<std::uint32_t> nearest_nodes(const std::vector<Vec3>& nodes,
                                         const std::vector<std::uint32_t>& interior,
                                         const Vec3& point, std::size_t k) {
  std::vector<std::pair<double, std::uint32_t>> keyed;
  keyed.reserve(interior.size());
  for (std::uint32_t id : interior) keyed.emplace_back(distance2(nodes[id], point), id);
  k = std::min(k, keyed.size());
  std::partial_sort(keyed.begin(), keyed.begin() + static_cast<std::ptrdiff_t>(k), keyed.end());
  std::vector<std::uint32_t> out;
  out.reserve(k);
  for (std::size_t i = 0; i < k; ++i) out.push_back(keyed[i].second);
  return out;
}

/// A point inside (or near) the cluster's rest kernel: starting at the centroid, averaged
/// projections onto the violated half-spaces n.(p - a) <= -margin (Cimmino-like relaxation),
/// keeping the iterate with the fewest violations.
Vec3 kernel_estimate(const std::vector<Vec3>& nodes, const std::vector<Tri>& triangles,
                     const std::vector<std::uint32_t>& ids, const Vec3& start, double margin) {
  struct Plane {
    Vec3 n;
    double offset;  // n.a
  };
  std::vector<Plane> planes;
  planes.reserve(ids.size());
  for (std::uint32_t id : ids) {
    const Tri& t = triangles[id];
    Vec3 n = cross(sub(nodes[t[1]], nodes[t[0]]), sub(nodes[t[2]], nodes[t[0]]));
    const double len = std::sqrt(dot(n, n));
    if (!(len > 0.0)) continue;
    n = {n[0] / len, n[1] / len, n[2] / len};
    planes.push_back({n, dot(n, nodes[t[0]])});
  }
  Vec3 p = start;
  Vec3 best = start;
  std::size_t best_violations = planes.size() + 1;
  constexpr int kIterations = 64;
  for (int it = 0; it < kIterations; ++it) {
    Vec3 step{0.0, 0.0, 0.0};
    std::size_t violations = 0;
    for (const Plane& pl : planes) {
      const double d = dot(pl.n, p) - pl.offset + margin;
      if (d > 0.0) {
        ++violations;
        for (int k = 0; k < 3; ++k) step[k] -= d * pl.n[k];
      }
    }
    if (violations < best_violations) {
      best_violations = violations;
      best = p;
    }
    if (violations == 0) break;
    for (int k = 0; k < 3; ++k) p[k] += step[k] / static_cast<double>(violations);
    if (!std::isfinite(p[0] + p[1] + p[2])) break;
  }
  return best;
}

/// Area-weighted centroid (vertex average when every triangle is degenerate) and bounding box
/// of a non-empty set of triangles.
struct ClusterGeometry {
  Vec3 centroid{0.0, 0.0, 0.0};
  Vec3 lo{0.0, 0.0, 0.0};
  Vec3 hi{0.0, 0.0, 0.0};
};

ClusterGeometry cluster_geometry(const std::vector<Vec3>& nodes, const std::vector<Tri>& triangles,
                                 const std::vector<std::uint32_t>& ids) {
  ClusterGeometry g;
  Vec3 average{0.0, 0.0, 0.0};
  g.lo = nodes[triangles[ids[0]][0]];
  g.hi = g.lo;
  double area = 0.0;
  for (std::uint32_t id : ids) {
    const Tri& t = triangles[id];
    const Vec3 n = cross(sub(nodes[t[1]], nodes[t[0]]), sub(nodes[t[2]], nodes[t[0]]));
    const double a = 0.5 * std::sqrt(dot(n, n));
    for (int k = 0; k < 3; ++k) {
      const double m = (nodes[t[0]][k] + nodes[t[1]][k] + nodes[t[2]][k]) / 3.0;
      g.centroid[k] += a * m;
      average[k] += m;
      for (std::uint32_t v : t) {
        g.lo[k] = std::min(g.lo[k], nodes[v][k]);
        g.hi[k] = std::max(g.hi[k], nodes[v][k]);
      }
    }
    area += a;
  }
  for (int k = 0; k < 3; ++k)
    g.centroid[k] =
        area > 0.0 ? g.centroid[k] / area : average[k] / static_cast<double>(ids.size());
  return g;
}

bool in_box(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  return p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && p[2] >= lo[2] &&
         p[2] <= hi[2];
}

/// Candidates of the visibility search among `points` (ids into `position`): the
/// kDetectorNearCentroid nearest the centroid, the kDetectorNearKernel nearest `kernel`, and up
/// to kDetectorInBox inside the box (evenly spread in id order), ordered by (distance to the
/// centroid, id), without repeats.
std::vector<std::uint32_t> visibility_candidates(const std::vector<Vec3>& position,
                                                 const std::vector<std::uint32_t>& points,
                                                 const ClusterGeometry& g, const Vec3& kernel) {
  std::vector<std::uint32_t> candidates =
      nearest_nodes(position, points, g.centroid, kDetectorNearCentroid);
  const std::vector<std::uint32_t> near_kernel =
      nearest_nodes(position, points, kernel, kDetectorNearKernel);
  candidates.insert(candidates.end(), near_kernel.begin(), near_kernel.end());
  std::vector<std::uint32_t> boxed;
  for (std::uint32_t id : points)
    if (in_box(position[id], g.lo, g.hi)) boxed.push_back(id);
  const std::size_t stride =
      std::max<std::size_t>(1, (boxed.size() + kDetectorInBox - 1) / kDetectorInBox);
  for (std::size_t i = 0; i < boxed.size(); i += stride) candidates.push_back(boxed[i]);
  std::vector<std::pair<double, std::uint32_t>> keyed;
  for (std::uint32_t id : candidates) keyed.emplace_back(distance2(position[id], g.centroid), id);
  std::sort(keyed.begin(), keyed.end());
  keyed.erase(std::unique(keyed.begin(), keyed.end()), keyed.end());
  std::vector<std::uint32_t> out;
  out.reserve(keyed.size());
  for (const auto& entry : keyed) out.push_back(entry.second);
  return out;
}

}  // namespace

bool triangle_positive_from(const std::vector<Vec3>& nodes, const Tri& t, const Vec3& point) {
  const Vec3 a = sub(nodes[t[0]], point);
  const Vec3 b = sub(nodes[t[1]], point);
  const Vec3 c = sub(nodes[t[2]], point);
  return dot(a, cross(b, c)) > 0.0;
}

std::uint32_t count_positive_triangles(const std::vector<Vec3>& nodes,
                                       const std::vector<Tri>& triangles,
                                       const std::vector<std::uint32_t>& triangle_ids,
                                       const Vec3& point) {
  std::uint32_t count = 0;
  for (std::uint32_t id : triangle_ids)
    count += triangle_positive_from(nodes, triangles[id], point) ? 1 : 0;
  return count;
}

Detector best_detector(const std::vector<Vec3>& nodes, const Surface& surface,
                       const std::vector<std::uint32_t>& triangle_ids, DetectorStrategy strategy) {
  const std::vector<std::uint32_t>& ids = triangle_ids;
  Detector det;
  det.triangle_count = static_cast<std::uint32_t>(ids.size());
  if (ids.empty()) {
    // Fallback point for an empty set: the surface's vertex average.
    Vec3 center{0.0, 0.0, 0.0};
    for (std::uint32_t v : surface.surface_nodes)
      for (int k = 0; k < 3; ++k) center[k] += nodes[v][k];
    if (!surface.surface_nodes.empty())
      for (int k = 0; k < 3; ++k) center[k] /= static_cast<double>(surface.surface_nodes.size());
    det.node = nearest_nodes(nodes, surface.interior_nodes, center, 1).front();
    det.rest_positive_fraction = 1.0f;
    return det;
  }
  const ClusterGeometry g = cluster_geometry(nodes, surface.triangles, ids);
  const Vec3& centroid = g.centroid;
  const Vec3& lo = g.lo;
  const Vec3& hi = g.hi;

  const std::vector<std::uint32_t> near =
      nearest_nodes(nodes, surface.interior_nodes, centroid,
                    strategy == DetectorStrategy::kNearestCentroid ? 1 : kDetectorNearCentroid);
  std::uint32_t best_node = near.front();
  std::uint32_t best_count =
      count_positive_triangles(nodes, surface.triangles, ids, nodes[best_node]);

  if (strategy == DetectorStrategy::kVisibility && best_count < ids.size()) {
    const double diagonal = std::sqrt(distance2(lo, hi));
    const Vec3 kernel = kernel_estimate(nodes, surface.triangles, ids, centroid, 1e-3 * diagonal);
    // Ordered by (distance to the centroid, id) so the first best wins ties.
    const std::vector<std::uint32_t> candidates =
        visibility_candidates(nodes, surface.interior_nodes, g, kernel);
    best_count = 0;
    best_node = candidates.front();
    for (std::uint32_t id : candidates) {
      const std::uint32_t count =
          count_positive_triangles(nodes, surface.triangles, ids, nodes[id]);
      if (count > best_count) {
        best_count = count;
        best_node = id;
        if (count == ids.size()) break;
      }
    }
  }
  det.node = best_node;
  det.positive_triangles = best_count;
  det.rest_positive_fraction =
      static_cast<float>(static_cast<double>(best_count) / static_cast<double>(ids.size()));
  return det;
}

std::vector<Detector> choose_detectors(const std::vector<Vec3>& nodes, const Surface& surface,
                                       const std::vector<std::uint32_t>& triangle_cluster,
                                       std::uint32_t cluster_count, DetectorStrategy strategy) {
  if (surface.interior_nodes.empty())
    throw InputError("", "the tet mesh has no interior node: no detector node can be chosen");
  if (triangle_cluster.size() != surface.triangles.size())
    throw std::invalid_argument("choose_detectors: one cluster id per surface triangle expected");
  for (std::uint32_t id : surface.interior_nodes)
    if (id >= nodes.size()) throw std::invalid_argument("choose_detectors: node id out of range");
  for (const Tri& t : surface.triangles)
    for (std::uint32_t v : t)
      if (v >= nodes.size()) throw std::invalid_argument("choose_detectors: node id out of range");

  std::vector<std::vector<std::uint32_t>> members(cluster_count);
  for (std::uint32_t t = 0; t < triangle_cluster.size(); ++t) {
    if (triangle_cluster[t] >= cluster_count)
      throw std::invalid_argument("choose_detectors: cluster id out of range");
    members[triangle_cluster[t]].push_back(t);
  }
  std::vector<Detector> out(cluster_count);
  for (std::uint32_t c = 0; c < cluster_count; ++c)
    out[c] = best_detector(nodes, surface, members[c], strategy);
  return out;
}

namespace {

/// Centroids of the tets with four distinct nodes and non-zero volume (`ids`: their tet ids;
/// `centroids` is indexed by tet id).
void tet_centroids(const TetMesh& mesh, std::vector<Vec3>& centroids,
                   std::vector<std::uint32_t>& ids) {
  centroids.assign(mesh.tets.size(), Vec3{0.0, 0.0, 0.0});
  ids.clear();
  for (std::uint32_t t = 0; t < mesh.tets.size(); ++t) {
    const Tet& tet = mesh.tets[t];
    bool distinct = true;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) distinct = distinct && tet[i] != tet[j];
    if (!distinct) continue;
    const Vec3& a = mesh.nodes[tet[0]];
    const double volume = dot(sub(mesh.nodes[tet[1]], a),
                              cross(sub(mesh.nodes[tet[2]], a), sub(mesh.nodes[tet[3]], a)));
    if (!(std::fabs(volume) > 0.0)) continue;
    for (int k = 0; k < 3; ++k)
      centroids[t][k] = 0.25 * (mesh.nodes[tet[0]][k] + mesh.nodes[tet[1]][k] +
                                mesh.nodes[tet[2]][k] + mesh.nodes[tet[3]][k]);
    ids.push_back(t);
  }
}

DetectorChoice node_choice(const std::vector<Vec3>& nodes, const Detector& d) {
  DetectorChoice c;
  c.point = format::DetectorPoint::at_node(d.node);
  c.position = nodes[d.node];
  c.triangle_count = d.triangle_count;
  c.positive_triangles = d.positive_triangles;
  return c;
}

DetectorChoice tet_choice(const TetMesh& mesh, const std::vector<Vec3>& centroids,
                          std::uint32_t tet) {
  DetectorChoice c;
  for (int i = 0; i < 4; ++i) c.point.nodes[i] = mesh.tets[tet][i];
  c.point.weights = {0.25, 0.25, 0.25, 0.25};
  c.point.tet = tet;
  c.position = centroids[tet];
  return c;
}

}  // namespace

std::vector<DetectorChoice> choose_detector_points(
    const TetMesh& mesh, const Surface& surface, const std::vector<std::uint32_t>& triangle_cluster,
    std::uint32_t cluster_count, DetectorStrategy strategy, double min_visibility) {
  const std::vector<Vec3>& nodes = mesh.nodes;
  if (triangle_cluster.size() != surface.triangles.size())
    throw std::invalid_argument("choose_detector_points: one cluster id per surface triangle");
  for (const Tet& tet : mesh.tets)
    for (std::uint32_t v : tet)
      if (v >= nodes.size())
        throw std::invalid_argument("choose_detector_points: node id out of range");
  std::vector<Vec3> centroids;
  std::vector<std::uint32_t> tets;
  tet_centroids(mesh, centroids, tets);
  const bool have_nodes = !surface.interior_nodes.empty();
  if (!have_nodes && tets.empty())
    throw InputError("",
                     "the tet mesh has no interior node and no tet of non-zero volume: no "
                     "detector point can be chosen");
  std::vector<std::vector<std::uint32_t>> members(cluster_count);
  for (std::uint32_t t = 0; t < triangle_cluster.size(); ++t) {
    if (triangle_cluster[t] >= cluster_count)
      throw std::invalid_argument("choose_detector_points: cluster id out of range");
    members[triangle_cluster[t]].push_back(t);
  }
  std::vector<Detector> by_node;
  if (have_nodes)
    by_node = choose_detectors(nodes, surface, triangle_cluster, cluster_count, strategy);

  std::vector<DetectorChoice> out(cluster_count);
  for (std::uint32_t c = 0; c < cluster_count; ++c) {
    const std::vector<std::uint32_t>& ids = members[c];
    DetectorChoice& best = out[c];
    if (have_nodes) best = node_choice(nodes, by_node[c]);
    if (ids.empty()) {
      if (!have_nodes) {
        Vec3 center{0.0, 0.0, 0.0};
        for (std::uint32_t v : surface.surface_nodes)
          for (int k = 0; k < 3; ++k) center[k] += nodes[v][k];
        if (!surface.surface_nodes.empty())
          for (int k = 0; k < 3; ++k)
            center[k] /= static_cast<double>(surface.surface_nodes.size());
        best = tet_choice(mesh, centroids, nearest_nodes(centroids, tets, center, 1).front());
      }
      best.rest_positive_fraction = 1.0f;
      continue;
    }
    const auto total = static_cast<std::uint32_t>(ids.size());
    if (!have_nodes ||
        (strategy == DetectorStrategy::kVisibility && best.positive_triangles < total)) {
      const ClusterGeometry g = cluster_geometry(nodes, surface.triangles, ids);
      std::vector<std::uint32_t> candidates;
      if (strategy == DetectorStrategy::kVisibility) {
        const double diagonal = std::sqrt(distance2(g.lo, g.hi));
        const Vec3 kernel =
            kernel_estimate(nodes, surface.triangles, ids, g.centroid, 1e-3 * diagonal);
        candidates = visibility_candidates(centroids, tets, g, kernel);
      } else {
        candidates = nearest_nodes(centroids, tets, g.centroid, 1);
      }
      bool have_best = have_nodes;
      for (std::uint32_t tet : candidates) {
        const std::uint32_t count =
            count_positive_triangles(nodes, surface.triangles, ids, centroids[tet]);
        if (!have_best || count > best.positive_triangles) {
          best = tet_choice(mesh, centroids, tet);
          best.positive_triangles = count;
          have_best = true;
          if (count == total) break;
        }
      }
    }
    best.triangle_count = total;
    best.rest_positive_fraction = static_cast<float>(static_cast<double>(best.positive_triangles) /
                                                     static_cast<double>(total));
    best.overlap_only = static_cast<double>(best.rest_positive_fraction) < min_visibility;
  }
  return out;
}

}  // namespace tetseg::preprocess
