// The two-level Schwarz preconditioner of the charge solver: a coarse correction on tree
// clusters with point-charge far interactions, then the near-field Schwarz of each leaf
// (docs/charge.md, "Preconditioner"). The local part: charge_preconditioners.cpp.

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "charge_fmm_kernels.hpp"
#include "charge_solvers.hpp"

namespace tetseg::preprocess::charge_detail {

namespace {

/// Coarse clusters I and J interact through point charges when (rho_I + rho_J) < this times
/// the distance of their area centroids (docs/charge.md, "Preconditioner").
constexpr double kCoarseOpening = 0.4;

}  // namespace

struct TwoLevelSchwarz::CoarseLu {
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;
};

TwoLevelSchwarz::~TwoLevelSchwarz() = default;

TwoLevelSchwarz::TwoLevelSchwarz(const PanelSet& panels, const ClusterTree& tree,
                                 const NearField& near, std::size_t max_set, std::size_t max_coarse)
    : m_local(panels, tree, near, max_set), m_tree(tree), m_n(panels.size()) {
  const std::size_t n = m_n;
  // Coarse clusters: the nodes at depth d (or leaves reached before), 2^d <= max_coarse.
  int depth = 0;
  while ((std::size_t{2} << depth) <= std::max<std::size_t>(max_coarse, 1)) ++depth;
  std::vector<std::int32_t> roots;
  {
    std::vector<std::pair<std::int32_t, int>> stack = {{0, 0}};
    while (!stack.empty()) {
      const auto [id, d] = stack.back();
      stack.pop_back();
      const Cluster& c = tree.nodes[static_cast<std::size_t>(id)];
      if (d == depth || c.left < 0) {
        roots.push_back(id);
      } else {
        stack.push_back({c.right, d + 1});
        stack.push_back({c.left, d + 1});
      }
    }
  }
  m_k = roots.size();
  const std::size_t k = m_k;
  m_cluster.resize(n);
  m_begin.resize(k);
  m_end.resize(k);
  for (std::size_t J = 0; J < k; ++J) {
    const Cluster& c = tree.nodes[static_cast<std::size_t>(roots[J])];
    m_begin[J] = c.begin;
    m_end[J] = c.end;
    for (std::uint32_t e = c.begin; e < c.end; ++e) {
      m_cluster[tree.order[e]] = static_cast<std::uint32_t>(J);
    }
  }
  // Per node: total area, area centroid, and a radius about it that covers the triangles.
  const std::size_t nodes = tree.nodes.size();
  std::vector<double> area(nodes), cx(nodes), cy(nodes), cz(nodes), radius(nodes);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(dynamic, 16)
#endif
  for (std::ptrdiff_t node = 0; node < static_cast<std::ptrdiff_t>(nodes); ++node) {
    const std::size_t id = static_cast<std::size_t>(node);
    const Cluster& c = tree.nodes[id];
    double a = 0.0, x = 0.0, y = 0.0, z = 0.0;
    for (std::uint32_t e = c.begin; e < c.end; ++e) {
      const std::uint32_t j = tree.order[e];
      const double aj = panels.area[j];
      a += aj;
      x += aj * panels.centroid[j][0];
      y += aj * panels.centroid[j][1];
      z += aj * panels.centroid[j][2];
    }
    area[id] = a;
    cx[id] = x / a;
    cy[id] = y / a;
    cz[id] = z / a;
    double r2 = 0.0;
    for (std::uint32_t e = c.begin; e < c.end; ++e) {
      const std::uint32_t j = tree.order[e];
      const Vec3& q = panels.centroid[j];
      const double dx = q[0] - cx[id], dy = q[1] - cy[id], dz = q[2] - cz[id];
      const double h = 0.5 * panels.diameter[j];
      r2 = std::max(r2, dx * dx + dy * dy + dz * dz + h * h);
    }
    radius[id] = std::sqrt(r2);
  }
  m_area.resize(k);
  m_gx.resize(k);
  m_gy.resize(k);
  m_gz.resize(k);
  for (std::size_t J = 0; J < k; ++J) {
    const std::size_t id = static_cast<std::size_t>(roots[J]);
    m_area[J] = area[id];
    m_gx[J] = cx[id];
    m_gy[J] = cy[id];
    m_gz[J] = cz[id];
  }
  // Far pairs, then the near list of each cluster: the clusters that are not far, and those
  // holding a near-field column of one of its members.
  m_far.assign(k * k, 0);
  for (std::size_t I = 0; I < k; ++I) {
    const double ri = radius[static_cast<std::size_t>(roots[I])];
    for (std::size_t J = 0; J < k; ++J) {
      const double rj = radius[static_cast<std::size_t>(roots[J])];
      const double dx = m_gx[I] - m_gx[J], dy = m_gy[I] - m_gy[J], dz = m_gz[I] - m_gz[J];
      const double d2 = dx * dx + dy * dy + dz * dz;
      if (I != J && (ri + rj) * (ri + rj) < kCoarseOpening * kCoarseOpening * d2) {
        m_far[I * k + J] = 1;
      }
    }
    for (std::uint32_t e = m_begin[I]; e < m_end[I]; ++e) {
      const std::size_t i = tree.order[e];
      for (std::size_t f = near.row_start[i]; f < near.row_start[i + 1]; ++f) {
        m_far[I * k + m_cluster[near.column[f]]] = 0;
      }
    }
  }
  m_near_start.assign(k + 1, 0);
  m_block_start.assign(k + 1, 0);
  for (std::size_t I = 0; I < k; ++I) {
    for (std::size_t J = 0; J < k; ++J) {
      if (!m_far[I * k + J]) m_near.push_back(static_cast<std::uint32_t>(J));
    }
    m_near_start[I + 1] = m_near.size();
    m_block_start[I + 1] =
        m_block_start[I] + (m_end[I] - m_begin[I]) * (m_near_start[I + 1] - m_near_start[I]);
  }
  m_block.assign(m_block_start[k], 0.0f);
  // Near blocks: Barnes-Hut over each near cluster's subtree (monopoles at area centroids when
  // the node's radius is below 0.5 times the distance, point charges in leaves otherwise, summed
  // by the FMM's direct kernels), plus the analytic near-field corrections.
  constexpr double kOpening = 0.5;
  const TreeOrderedPanels sources = in_tree_order(panels, tree);
  const double root_radius = tree.nodes[0].radius > 0.0 ? tree.nodes[0].radius : 1.0;
  const double inv_scale2 = 1.0 / (root_radius * root_radius);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel
#endif
  {
    std::vector<std::int32_t> stack, leaves;
    std::vector<std::int32_t> slot(k, -1);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 1)
#endif
    for (std::ptrdiff_t cluster = 0; cluster < static_cast<std::ptrdiff_t>(k); ++cluster) {
      const std::size_t I = static_cast<std::size_t>(cluster);
      const std::size_t first = m_near_start[I], count = m_near_start[I + 1] - first;
      for (std::size_t s = 0; s < count; ++s) slot[m_near[first + s]] = static_cast<int>(s);
      for (std::uint32_t e = m_begin[I]; e < m_end[I]; ++e) {
        const std::size_t i = tree.order[e];
        const Vec3& p = panels.centroid[i];
        float* row = m_block.data() + m_block_start[I] + (e - m_begin[I]) * count;
        for (std::size_t s = 0; s < count; ++s) {
          double sum = 0.0;
          stack.assign(1, roots[m_near[first + s]]);
          leaves.clear();
          while (!stack.empty()) {
            const std::int32_t id = stack.back();
            stack.pop_back();
            const Cluster& c = tree.nodes[static_cast<std::size_t>(id)];
            const std::size_t u = static_cast<std::size_t>(id);
            const double dx = p[0] - cx[u], dy = p[1] - cy[u], dz = p[2] - cz[u];
            const double d2 = dx * dx + dy * dy + dz * dz;
            if (radius[u] * radius[u] < kOpening * kOpening * d2) {
              sum += area[u] / std::sqrt(d2);
            } else if (c.left >= 0) {
              stack.push_back(c.left);
              stack.push_back(c.right);
            } else {
              leaves.push_back(id);
            }
          }
          sum += direct_leaves(p[0], p[1], p[2], sources.x.data(), sources.y.data(),
                               sources.z.data(), sources.area.data(), tree.nodes.data(),
                               leaves.data(), leaves.size(), inv_scale2);
          row[s] = static_cast<float>(sum);
        }
        for (std::size_t f = near.row_start[i]; f < near.row_start[i + 1]; ++f) {
          row[slot[m_cluster[near.column[f]]]] += static_cast<float>(near.correction[f]);
        }
      }
      for (std::size_t s = 0; s < count; ++s) slot[m_near[first + s]] = -1;
    }
  }
  // Galerkin coarse matrix C = Z^T (M Z): near entries sum the blocks; far entries sum the
  // second-order Taylor expansion of A_J / |x - g_J| over I's members, through I's target
  // moments S0 = |I|, S1 = sum w, S2 = sum w w^T (w = c_i - g_I).
  Eigen::MatrixXd coarse =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(k));
  m_wx.resize(n);
  m_wy.resize(n);
  m_wz.resize(n);
  for (std::size_t I = 0; I < k; ++I) {
    const std::size_t first = m_near_start[I], count = m_near_start[I + 1] - first;
    double s0 = 0.0, s1[3] = {0, 0, 0}, s2[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (std::uint32_t e = m_begin[I]; e < m_end[I]; ++e) {
      const float* row = m_block.data() + m_block_start[I] + (e - m_begin[I]) * count;
      for (std::size_t s = 0; s < count; ++s) {
        coarse(static_cast<Eigen::Index>(I), static_cast<Eigen::Index>(m_near[first + s])) +=
            row[s];
      }
      const Vec3& p = panels.centroid[tree.order[e]];
      const double w[3] = {p[0] - m_gx[I], p[1] - m_gy[I], p[2] - m_gz[I]};
      m_wx[e] = w[0];
      m_wy[e] = w[1];
      m_wz[e] = w[2];
      s0 += 1.0;
      for (int a = 0; a < 3; ++a) {
        s1[a] += w[a];
        for (int b = 0; b < 3; ++b) s2[a][b] += w[a] * w[b];
      }
    }
    const double trace = s2[0][0] + s2[1][1] + s2[2][2];
    for (std::size_t J = 0; J < k; ++J) {
      if (!m_far[I * k + J]) continue;
      const double rv[3] = {m_gx[I] - m_gx[J], m_gy[I] - m_gy[J], m_gz[I] - m_gz[J]};
      const double r2 = rv[0] * rv[0] + rv[1] * rv[1] + rv[2] * rv[2];
      const double inv_r = 1.0 / std::sqrt(r2), inv_r3 = inv_r / r2, inv_r5 = inv_r3 / r2;
      double rs1 = 0.0, rs2r = 0.0;
      for (int a = 0; a < 3; ++a) {
        rs1 += rv[a] * s1[a];
        for (int b = 0; b < 3; ++b) rs2r += rv[a] * s2[a][b] * rv[b];
      }
      coarse(static_cast<Eigen::Index>(I), static_cast<Eigen::Index>(J)) =
          m_area[J] * (s0 * inv_r - rs1 * inv_r3 + 0.5 * (3.0 * rs2r - r2 * trace) * inv_r5);
    }
  }
  m_lu = std::make_unique<CoarseLu>();
  m_lu->lu.compute(coarse);
  m_residual.resize(n);
}

void TwoLevelSchwarz::apply(const double* in, double* out) const {
  const std::size_t k = m_k;
  const auto& order = m_tree.order;
  Eigen::VectorXd t = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(k));
  for (std::size_t J = 0; J < k; ++J) {
    double s = 0.0;
    for (std::uint32_t e = m_begin[J]; e < m_end[J]; ++e) s += in[order[e]];
    t[static_cast<Eigen::Index>(J)] = s;
  }
  const Eigen::VectorXd u = m_lu->lu.solve(t);
  double* r = m_residual.data();
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(dynamic, 4)
#endif
  for (std::ptrdiff_t cluster = 0; cluster < static_cast<std::ptrdiff_t>(k); ++cluster) {
    const std::size_t I = static_cast<std::size_t>(cluster);
    // Far clusters: Taylor expansion about g_I of sum_J A_J u_J / |x - g_J|, to second order:
    // value t0 + g.w + w^T H w.
    double t0 = 0.0, g[3] = {0, 0, 0}, h[6] = {0, 0, 0, 0, 0, 0};  // xx xy xz yy yz zz
    const std::uint8_t* far = m_far.data() + I * k;
    for (std::size_t J = 0; J < k; ++J) {
      if (!far[J]) continue;
      const double q = m_area[J] * u[static_cast<Eigen::Index>(J)];
      const double rx = m_gx[I] - m_gx[J], ry = m_gy[I] - m_gy[J], rz = m_gz[I] - m_gz[J];
      const double r2 = rx * rx + ry * ry + rz * rz;
      const double inv_r = 1.0 / std::sqrt(r2), q3 = q * inv_r / r2, q5 = 0.5 * q3 / r2;
      t0 += q * inv_r;
      g[0] -= q3 * rx;
      g[1] -= q3 * ry;
      g[2] -= q3 * rz;
      h[0] += q5 * (3.0 * rx * rx - r2);
      h[1] += q5 * 3.0 * rx * ry;
      h[2] += q5 * 3.0 * rx * rz;
      h[3] += q5 * (3.0 * ry * ry - r2);
      h[4] += q5 * 3.0 * ry * rz;
      h[5] += q5 * (3.0 * rz * rz - r2);
    }
    const std::size_t first = m_near_start[I], count = m_near_start[I + 1] - first;
    double un[512];
    std::vector<double> un_large;
    double* uu = un;
    if (count > 512) {
      un_large.resize(count);
      uu = un_large.data();
    }
    for (std::size_t s = 0; s < count; ++s) uu[s] = u[static_cast<Eigen::Index>(m_near[first + s])];
    for (std::uint32_t e = m_begin[I]; e < m_end[I]; ++e) {
      const double wx = m_wx[e], wy = m_wy[e], wz = m_wz[e];
      double v = t0 + g[0] * wx + g[1] * wy + g[2] * wz + h[0] * wx * wx + h[3] * wy * wy +
                 h[5] * wz * wz + 2.0 * (h[1] * wx * wy + h[2] * wx * wz + h[4] * wy * wz);
      const float* row = m_block.data() + m_block_start[I] + (e - m_begin[I]) * count;
      for (std::size_t s = 0; s < count; ++s) v += static_cast<double>(row[s]) * uu[s];
      const std::size_t i = order[e];
      r[i] = in[i] - v;
    }
  }
  m_local.apply(r, out);
  for (std::size_t i = 0; i < m_n; ++i) {
    out[i] += u[static_cast<Eigen::Index>(m_cluster[i])];
  }
}

}  // namespace tetseg::preprocess::charge_detail
