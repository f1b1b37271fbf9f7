// Cluster tree and analytic near field of the charge solvers (build_cluster_tree,
// build_near_field; charge_tree.hpp). The treecode operator over them: charge_tree.cpp.

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <vector>

#include "charge_tree.hpp"

namespace tetseg::preprocess::charge_detail {

ClusterTree build_cluster_tree(const PanelSet& panels, int leaf_size) {
  const std::size_t n = panels.size();
  leaf_size = std::max(leaf_size, 1);
  ClusterTree tree;
  tree.order.resize(n);
  std::iota(tree.order.begin(), tree.order.end(), 0u);
  tree.nodes.reserve(4 * n / static_cast<std::size_t>(leaf_size) + 4);
  Cluster root;
  root.begin = 0;
  root.end = static_cast<std::uint32_t>(n);
  tree.nodes.push_back(root);
  std::vector<std::int32_t> stack = {0};
  while (!stack.empty()) {
    const std::int32_t id = stack.back();
    stack.pop_back();
    Cluster c = tree.nodes[static_cast<std::size_t>(id)];
    Vec3 lo = {1e300, 1e300, 1e300}, hi = {-1e300, -1e300, -1e300};
    double max_d = 0.0;
    for (std::uint32_t k = c.begin; k < c.end; ++k) {
      const std::uint32_t j = tree.order[k];
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], panels.centroid[j][a]);
        hi[a] = std::max(hi[a], panels.centroid[j][a]);
      }
      max_d = std::max(max_d, panels.diameter[j]);
    }
    c.box_min = lo;
    c.box_max = hi;
    c.center = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
    double r2 = 0.0;
    for (std::uint32_t k = c.begin; k < c.end; ++k) {
      const Vec3& p = panels.centroid[tree.order[k]];
      const double dx = p[0] - c.center[0], dy = p[1] - c.center[1], dz = p[2] - c.center[2];
      r2 = std::max(r2, dx * dx + dy * dy + dz * dz);
    }
    c.radius = std::sqrt(r2);
    c.max_diameter = max_d;
    if (c.end - c.begin > static_cast<std::uint32_t>(leaf_size)) {
      int axis = 0;
      for (int a = 1; a < 3; ++a) {
        if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
      }
      const std::uint32_t mid = c.begin + (c.end - c.begin) / 2;
      std::nth_element(tree.order.begin() + c.begin, tree.order.begin() + mid,
                       tree.order.begin() + c.end, [&](std::uint32_t u, std::uint32_t v) {
                         const double cu = panels.centroid[u][axis];
                         const double cv = panels.centroid[v][axis];
                         return cu < cv || (cu == cv && u < v);
                       });
      Cluster left, right;
      left.begin = c.begin;
      left.end = mid;
      right.begin = mid;
      right.end = c.end;
      c.left = static_cast<std::int32_t>(tree.nodes.size());
      tree.nodes.push_back(left);
      c.right = static_cast<std::int32_t>(tree.nodes.size());
      tree.nodes.push_back(right);
      stack.push_back(c.right);
      stack.push_back(c.left);
    }
    tree.nodes[static_cast<std::size_t>(id)] = c;
  }
  // Leaves in left-to-right order (depth-first).
  stack = {0};
  while (!stack.empty()) {
    const std::int32_t id = stack.back();
    stack.pop_back();
    const Cluster& c = tree.nodes[static_cast<std::size_t>(id)];
    if (c.left < 0) {
      tree.leaves.push_back(id);
    } else {
      stack.push_back(c.right);
      stack.push_back(c.left);
    }
  }
  return tree;
}

TreeOrderedPanels in_tree_order(const PanelSet& panels, const ClusterTree& tree) {
  const std::size_t n = panels.size();
  TreeOrderedPanels out;
  out.x.resize(n);
  out.y.resize(n);
  out.z.resize(n);
  out.area.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t j = tree.order[k];
    out.x[k] = panels.centroid[j][0];
    out.y[k] = panels.centroid[j][1];
    out.z[k] = panels.centroid[j][2];
    out.area[k] = panels.area[j];
  }
  return out;
}

NearField build_near_field(const PanelSet& panels, const ClusterTree& tree) {
  const std::size_t n = panels.size();
  const std::size_t leaf_count = tree.leaves.size();
  // Sources in tree order (each leaf contiguous) with their squared near-field radius.
  std::vector<double> sx(n), sy(n), sz(n), slim2(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t j = tree.order[k];
    sx[k] = panels.centroid[j][0];
    sy[k] = panels.centroid[j][1];
    sz[k] = panels.centroid[j][2];
    const double lim = kNearFactor * panels.diameter[j];
    slim2[k] = lim * lim;
  }
  // Per target leaf: its members' rows back to back, and their lengths. A row's columns are
  // in tree order (candidate leaves as the search meets them), not sorted by id: no reader
  // needs sorted rows, and sorting them was 2 % of a 5k solve.
  std::vector<std::vector<std::uint32_t>> leaf_columns(leaf_count);
  std::vector<std::uint32_t> row_length(n);
  std::vector<TriangleKernel> kernels(n);
  NearField near;
  near.row_start.resize(n + 1, 0);
  near.diagonal.resize(n);
  // One parallel region: a fork and join cost more than a stage at 5k triangles.
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel
#endif
  {
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(static) nowait
#endif
    for (std::ptrdiff_t jj = 0; jj < static_cast<std::ptrdiff_t>(n); ++jj) {
      const auto& t = panels.corners[static_cast<std::size_t>(jj)];
      kernels[static_cast<std::size_t>(jj)] = TriangleKernel(t[0], t[1], t[2]);
    }
    // Candidate source leaves of a target leaf by a box-to-box test (no member of a pruned
    // node is within its near-field radius of any member of the target), then the exact
    // per-pair test of the row rule.
    std::vector<std::int32_t> stack, candidates;
    // A leaf's candidate columns, written before they are counted (not zero-filled: at most
    // members x candidate sources, 14 MB in all at 5k, of which about a tenth is used).
    std::unique_ptr<std::uint32_t[]> scratch;
    std::size_t scratch_size = 0;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 1)
#endif
    for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaf_count); ++ll) {
      const Cluster& target = tree.nodes[static_cast<std::size_t>(tree.leaves[ll])];
      candidates.clear();
      stack.assign(1, 0);
      while (!stack.empty()) {
        const Cluster& c = tree.nodes[static_cast<std::size_t>(stack.back())];
        const std::int32_t id = stack.back();
        stack.pop_back();
        double d2 = 0.0;
        for (int a = 0; a < 3; ++a) {
          const double d =
              std::max({c.box_min[a] - target.box_max[a], target.box_min[a] - c.box_max[a], 0.0});
          d2 += d * d;
        }
        const double limit = kNearFactor * c.max_diameter;
        if (d2 > limit * limit) continue;
        if (c.left >= 0) {
          stack.push_back(c.right);
          stack.push_back(c.left);
        } else {
          candidates.push_back(id);
        }
      }
      std::size_t capacity = 0;
      for (const std::int32_t id : candidates) {
        const Cluster& c = tree.nodes[static_cast<std::size_t>(id)];
        capacity += c.end - c.begin;
      }
      capacity *= target.end - target.begin;
      if (capacity > scratch_size) {
        scratch.reset(new std::uint32_t[capacity]);
        scratch_size = capacity;
      }
      std::uint32_t* columns = scratch.get();
      std::size_t used = 0;
      for (std::uint32_t m = target.begin; m < target.end; ++m) {
        const std::uint32_t i = tree.order[m];
        const double px = sx[m], py = sy[m], pz = sz[m];
        const std::size_t first = used;
        for (const std::int32_t id : candidates) {
          const Cluster& c = tree.nodes[static_cast<std::size_t>(id)];
          // The leaf's box is out of reach of this member (the per-row form of the test above).
          double b2 = 0.0;
          const double p3[3] = {px, py, pz};
          for (int a = 0; a < 3; ++a) {
            const double d = std::max({c.box_min[a] - p3[a], p3[a] - c.box_max[a], 0.0});
            b2 += d * d;
          }
          const double limit = kNearFactor * c.max_diameter;
          if (b2 > limit * limit) continue;
          for (std::uint32_t k = c.begin; k < c.end; ++k) {
            const double dx = px - sx[k], dy = py - sy[k], dz = pz - sz[k];
            const std::uint32_t j = tree.order[k];
            columns[used] = j;
            used += (j == i || dx * dx + dy * dy + dz * dz <= slim2[k]) ? 1 : 0;
          }
        }
        row_length[i] = static_cast<std::uint32_t>(used - first);
      }
      leaf_columns[static_cast<std::size_t>(ll)].assign(columns, columns + used);
    }
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp single
#endif
    {
      for (std::size_t i = 0; i < n; ++i) near.row_start[i + 1] = near.row_start[i] + row_length[i];
      const std::size_t nnz = near.row_start[n];
      // Filled below by both threads (no serial zero-fill of about 20 bytes per entry).
      near.column.resize(nnz);
      near.value.resize(nnz);
      near.correction.resize(nnz);
    }
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 1)
#endif
    for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaf_count); ++ll) {
      const Cluster& target = tree.nodes[static_cast<std::size_t>(tree.leaves[ll])];
      auto& columns = leaf_columns[static_cast<std::size_t>(ll)];
      std::size_t from = 0;
      for (std::uint32_t m = target.begin; m < target.end; ++m) {
        const std::size_t i = tree.order[m];
        const Vec3& p = panels.centroid[i];
        std::size_t e = near.row_start[i];
        for (std::size_t f = 0; f < row_length[i]; ++f, ++e) {
          const std::uint32_t j = columns[from + f];
          const auto& t = panels.corners[j];
          double value, point = 0.0;
          if (j == i) {
            value = triangle_self_potential(t[0], t[1], t[2]);
            near.diagonal[i] = value;
          } else {
            const Vec3& q = panels.centroid[j];
            const double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
            const double r2 = dx * dx + dy * dy + dz * dz;
            const double band = kQuadratureFactor * panels.diameter[j];
            value = r2 > band * band ? triangle_potential_quadrature(t, panels.area[j], p)
                                     : kernels[j].potential(p);
            if (r2 > 0.0) point = panels.area[j] / std::sqrt(r2);
          }
          near.column[e] = j;
          near.value[e] = value;
          near.correction[e] = value - point;
        }
        from += row_length[i];
      }
      std::vector<std::uint32_t>().swap(columns);
    }
  }
  return near;
}

}  // namespace tetseg::preprocess::charge_detail
