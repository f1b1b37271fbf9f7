// Self-intersection of a closed surface: a median-split BVH over the triangles' bounding boxes
// (broad phase, tetseg's one BVH builder) and CGAL's exact predicates for the pairs whose boxes
// touch, each pair decided as CGAL's does_self_intersect / self_intersections decide it. The
// only validation unit that includes CGAL.

#include <CGAL/Intersections_3/Segment_3_Triangle_3.h>
#include <CGAL/Intersections_3/Triangle_3_Triangle_3.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "cgal_mesh.hpp"
#include "tetseg/runtime/median_bvh.hpp"
#include "validate_internal.hpp"

namespace tetseg::preprocess::detail {
namespace {

using cgal::Kernel;
using cgal::Point;
using Segment = Kernel::Segment_3;
using Triangle = Kernel::Triangle_3;
using Pair = std::pair<std::size_t, std::size_t>;

struct Box {
  double lo[3], hi[3];
};

Point point(const std::vector<Vec3>& points, std::uint32_t i) {
  return cgal::to_point(points[i]);
}

/// Closed boxes, as CGAL's box intersection uses: touching boxes overlap.
bool overlap(const Box& a, const Box& b) {
  for (int k = 0; k < 3; ++k)
    if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return false;
  return true;
}

void grow(Box& box, const Box& other) {
  for (int k = 0; k < 3; ++k) {
    box.lo[k] = std::min(box.lo[k], other.lo[k]);
    box.hi[k] = std::max(box.hi[k], other.hi[k]);
  }
}

/// The sign of ((b - a) x (f - a)) . ((b - a) x (g - a)) when double arithmetic certifies it,
/// else 0. For four coplanar points (a, b, f not collinear) it is positive exactly when f and
/// g lie on the same side of the line ab. The bound: each cross product component is off by
/// at most 4u times the sum of its two products' magnitudes (u = 2^-53), the dot product by
/// at most 11u times the sum D of those magnitudes' products; 1e-14 D covers it with room.
int certain_side_sign(const Vec3& a, const Vec3& b, const Vec3& f, const Vec3& g) {
  double e[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) {
    e[k] = b[k] - a[k];
    v[k] = f[k] - a[k];
    w[k] = g[k] - a[k];
  }
  double dot = 0.0, bound = 0.0;
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const double nf = e[i] * v[j] - e[j] * v[i];
    const double ng = e[i] * w[j] - e[j] * w[i];
    const double mf = std::abs(e[i] * v[j]) + std::abs(e[j] * v[i]);
    const double mg = std::abs(e[i] * w[j]) + std::abs(e[j] * w[i]);
    dot += nf * ng;
    bound += mf * mg;
  }
  // Outside the range where rounding is relative (overflow, underflow): undecided.
  if (!(bound > 1e-250 && bound < 1e250)) return 0;
  bound *= 1e-14;
  return dot > bound ? 1 : (dot < -bound ? -1 : 0);
}

/// Whether a plane through s certainly separates triangles (s, f1, f2) and (s, g1, g2) but
/// for s: f1 and f2 strictly on its negative side, g1 and g2 strictly on its positive side,
/// with the rounding of each side test bounded (4u times the sum of the magnitudes of its
/// terms; 1e-15 covers it). Then neither triangle meets the other's edge opposite s. The
/// plane's normal is the difference of the two triangles' unit bisectors at s, which
/// separates them whenever their angles at s are disjoint and not too wide (else: undecided).
bool certainly_apart_at_vertex(const Vec3& s, const Vec3& f1, const Vec3& f2, const Vec3& g1,
                               const Vec3& g2) {
  const Vec3* corner[4] = {&f1, &f2, &g1, &g2};
  double d[4][3];
  for (int c = 0; c < 4; ++c) {
    double length2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      d[c][k] = (*corner[c])[k] - s[k];
      length2 += d[c][k] * d[c][k];
    }
    if (!(length2 > 1e-250 && length2 < 1e250)) return false;
  }
  double n[3];
  for (int k = 0; k < 3; ++k) {
    auto unit = [&](int c) {
      return d[c][k] / std::sqrt(d[c][0] * d[c][0] + d[c][1] * d[c][1] + d[c][2] * d[c][2]);
    };
    n[k] = unit(2) + unit(3) - unit(0) - unit(1);
  }
  for (int c = 0; c < 4; ++c) {
    double h = 0.0, magnitude = 0.0;
    for (int k = 0; k < 3; ++k) {
      h += n[k] * d[c][k];
      magnitude += std::abs(n[k] * d[c][k]);
    }
    const double bound = 1e-15 * magnitude;
    if (!(magnitude > 1e-250) || (c < 2 ? !(h < -bound) : !(h > bound))) return false;
  }
  return true;
}

/// Whether triangles f and g meet other than in the vertices or the edge they share: the test
/// of CGAL's Polygon_mesh_processing::internal::do_faces_intersect (CGAL 5.5), with shared
/// vertices and edges found by vertex id instead of through a halfedge mesh (the same thing on
/// a closed, edge-manifold, consistently oriented surface).
bool strictly_intersect(const std::vector<Vec3>& q, const Tri& f, const Tri& g,
                        const Kernel& kernel) {
  bool f_shared[3] = {false, false, false};
  int first_f = -1, first_g = -1, shared = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (f[i] == g[j]) {
        if (!f_shared[i]) ++shared;
        f_shared[i] = true;
        if (first_f < 0) first_f = i, first_g = j;
      }
  if (shared >= 2) {
    // A shared edge ab: CGAL reports the pair when all four points are coplanar and the two
    // apexes lie on the same side of ab (coplanar_orientation POSITIVE). Apexes certainly on
    // opposite sides in the sense of certain_side_sign decide "no" (coplanar or not); certainly
    // on the same side, coplanarity alone decides.
    int i = 0;
    while (!(f_shared[i] && f_shared[(i + 1) % 3])) ++i;
    const std::uint32_t a = f[i], b = f[(i + 1) % 3], apex_f = f[(i + 2) % 3];
    int k = 0;
    while (g[k] == a || g[k] == b) ++k;
    const std::uint32_t apex_g = g[k];
    const int side = certain_side_sign(q[a], q[b], q[apex_f], q[apex_g]);
    if (side < 0) return false;
    if (!CGAL::coplanar(point(q, a), point(q, b), point(q, apex_f), point(q, apex_g))) return false;
    return side > 0 || CGAL::coplanar_orientation(point(q, a), point(q, b), point(q, apex_f),
                                                  point(q, apex_g)) == CGAL::POSITIVE;
  }
  // A shared vertex: a floating-point separating plane settles most pairs without CGAL.
  if (shared == 1 &&
      certainly_apart_at_vertex(q[f[first_f]], q[f[(first_f + 1) % 3]], q[f[(first_f + 2) % 3]],
                                q[g[(first_g + 1) % 3]], q[g[(first_g + 2) % 3]]))
    return false;
  const auto do_intersect = kernel.do_intersect_3_object();
  const Triangle tf(point(q, f[0]), point(q, f[1]), point(q, f[2]));
  const Triangle tg(point(q, g[0]), point(q, g[1]), point(q, g[2]));
  if (shared == 1) {
    // Each triangle against the other's edge opposite the shared vertex.
    const Segment sf(point(q, f[(first_f + 1) % 3]), point(q, f[(first_f + 2) % 3]));
    const Segment sg(point(q, g[(first_g + 1) % 3]), point(q, g[(first_g + 2) % 3]));
    return do_intersect(tf, sg) || do_intersect(tg, sf);
  }
  return do_intersect(tf, tg);
}

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> self_intersecting_pairs(
    const std::vector<Vec3>& points, const std::vector<Tri>& triangles) {
  const Kernel kernel;
  const std::uint32_t count = static_cast<std::uint32_t>(triangles.size());

  // A degenerate (collinear) triangle is reported paired with itself and left out of the
  // broad phase, as CGAL does.
  std::vector<Pair> pairs;
  std::vector<std::uint32_t> items;
  items.reserve(count);
  for (std::uint32_t t = 0; t < count; ++t) {
    const Tri& tri = triangles[t];
    if (CGAL::collinear(point(points, tri[0]), point(points, tri[1]), point(points, tri[2]))) {
      pairs.emplace_back(t, t);
    } else {
      items.push_back(t);
    }
  }
  std::vector<Box> box(count);
  std::vector<double> centroid(std::size_t{count} * 3);
  for (std::uint32_t t : items) {
    const Tri& tri = triangles[t];
    for (int k = 0; k < 3; ++k) {
      const double a = points[tri[0]][k], b = points[tri[1]][k], c = points[tri[2]][k];
      box[t].lo[k] = std::min({a, b, c});
      box[t].hi[k] = std::max({a, b, c});
      centroid[std::size_t{t} * 3 + k] = (a + b + c) / 3.0;
    }
  }
  const std::uint32_t item_count = static_cast<std::uint32_t>(items.size());
  if (item_count == 0) return pairs;
  std::vector<format::BvhNode> nodes(2 * std::size_t{item_count} - 1);
  std::vector<MedianBvhTask> stack(kMedianBvhStack);
  constexpr std::uint32_t kLeafSize = 4;
  nodes.resize(build_median_bvh(centroid.data(), items.data(), item_count, kLeafSize, nodes.data(),
                                stack.data(), stack.size()));
  // Children follow their parent, so one backward sweep gives every node's box.
  std::vector<Box> node_box(nodes.size());
  for (std::size_t n = nodes.size(); n-- > 0;) {
    const format::BvhNode& node = nodes[n];
    if (node.count > 0) {
      node_box[n] = box[items[node.first]];
      for (std::uint32_t i = 1; i < node.count; ++i) grow(node_box[n], box[items[node.first + i]]);
    } else {
      node_box[n] = node_box[node.first];
      grow(node_box[n], node_box[node.second]);
    }
  }

  // Candidate pairs (boxes touching) from a traversal of the tree against itself, tested in
  // batches on OpenMP threads (bounded memory however many boxes touch).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> candidates;
  constexpr std::size_t kBatch = std::size_t{1} << 18;
  auto test_candidates = [&] {
    const std::int64_t size = static_cast<std::int64_t>(candidates.size());
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel
#endif
    {
      std::vector<Pair> found;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 4096) nowait
#endif
      for (std::int64_t i = 0; i < size; ++i) {
        const auto [f, g] = candidates[static_cast<std::size_t>(i)];
        if (strictly_intersect(points, triangles[f], triangles[g], kernel))
          found.emplace_back(std::min(f, g), std::max(f, g));
      }
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp critical(tetseg_self_intersecting_pairs)
#endif
      pairs.insert(pairs.end(), found.begin(), found.end());
    }
    candidates.clear();
  };
  auto leaf_pairs = [&](const format::BvhNode& a, const format::BvhNode& b, bool same) {
    for (std::uint32_t i = 0; i < a.count; ++i) {
      const std::uint32_t f = items[a.first + i];
      for (std::uint32_t j = same ? i + 1 : 0; j < b.count; ++j) {
        const std::uint32_t g = items[b.first + j];
        if (overlap(box[f], box[g])) candidates.emplace_back(f, g);
      }
    }
  };
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pending = {{0u, 0u}};
  while (!pending.empty()) {
    const auto [a, b] = pending.back();
    pending.pop_back();
    const format::BvhNode& na = nodes[a];
    const format::BvhNode& nb = nodes[b];
    if (a == b) {
      if (na.count > 0) {
        leaf_pairs(na, na, true);
      } else {
        pending.emplace_back(na.first, na.second);
        pending.emplace_back(na.second, na.second);
        pending.emplace_back(na.first, na.first);
      }
    } else if (overlap(node_box[a], node_box[b])) {
      if (na.count > 0 && nb.count > 0) {
        leaf_pairs(na, nb, false);
      } else if (na.count > 0) {
        pending.emplace_back(a, nb.first);
        pending.emplace_back(a, nb.second);
      } else {
        pending.emplace_back(na.first, b);
        pending.emplace_back(na.second, b);
      }
    }
    if (candidates.size() >= kBatch) test_candidates();
  }
  test_candidates();
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace tetseg::preprocess::detail
