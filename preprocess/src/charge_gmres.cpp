// Restarted GMRES with Jacobi right preconditioning, and the dense matrix helpers.

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "charge_solvers.hpp"

namespace tetseg::preprocess::charge_detail {
namespace {

double norm2(const std::vector<double>& v) {
  double s = 0.0;
  for (const double e : v) s += e * e;
  return std::sqrt(s);
}

}  // namespace

GmresOutcome solve_gmres(std::size_t n, const ApplyFn& apply, const ApplyFn& precondition,
                         const std::vector<double>& b, std::vector<double>& x, double tolerance,
                         int max_iterations, int restart, const IterationFn& on_iteration) {
  GmresOutcome out;
  restart = std::max(restart, 1);
  const double bnorm = norm2(b);
  if (bnorm == 0.0) {
    std::fill(x.begin(), x.end(), 0.0);
    out.converged = true;
    return out;
  }
  std::vector<double> r(n), w(n), z(n);
  std::vector<std::vector<double>> basis(static_cast<std::size_t>(restart) + 1,
                                         std::vector<double>(n));
  const std::size_t m = static_cast<std::size_t>(restart);
  std::vector<double> h((m + 1) * m), cs(m), sn(m), g(m + 1), y(m);
  auto hh = [&](std::size_t i, std::size_t j) -> double& { return h[i * m + j]; };
  // A zero start needs no product for its residual.
  bool zero_start = std::all_of(x.begin(), x.end(), [](double v) { return v == 0.0; });
  for (;;) {
    if (zero_start) {
      r = b;
      zero_start = false;
    } else {
      apply(x.data(), r.data());
      for (std::size_t i = 0; i < n; ++i) r[i] = b[i] - r[i];
    }
    const double beta = norm2(r);
    out.residual = beta / bnorm;
    if (!std::isfinite(out.residual)) return out;
    if (out.residual <= tolerance) {
      out.converged = true;
      return out;
    }
    if (out.iterations >= max_iterations) return out;
    for (std::size_t i = 0; i < n; ++i) basis[0][i] = r[i] / beta;
    std::fill(g.begin(), g.end(), 0.0);
    g[0] = beta;
    std::size_t k = 0;
    for (; k < m && out.iterations < max_iterations; ++k) {
      precondition(basis[k].data(), z.data());
      apply(z.data(), w.data());
      ++out.iterations;
      for (std::size_t j = 0; j <= k; ++j) {
        double d = 0.0;
        const auto& v = basis[j];
        for (std::size_t i = 0; i < n; ++i) d += w[i] * v[i];
        hh(j, k) = d;
        for (std::size_t i = 0; i < n; ++i) w[i] -= d * v[i];
      }
      const double wn = norm2(w);
      hh(k + 1, k) = wn;
      if (wn > 0.0) {
        for (std::size_t i = 0; i < n; ++i) basis[k + 1][i] = w[i] / wn;
      }
      for (std::size_t j = 0; j < k; ++j) {
        const double t = cs[j] * hh(j, k) + sn[j] * hh(j + 1, k);
        hh(j + 1, k) = -sn[j] * hh(j, k) + cs[j] * hh(j + 1, k);
        hh(j, k) = t;
      }
      const double a = hh(k, k), c = hh(k + 1, k);
      const double rr = std::hypot(a, c);
      cs[k] = rr > 0.0 ? a / rr : 1.0;
      sn[k] = rr > 0.0 ? c / rr : 0.0;
      hh(k, k) = rr;
      hh(k + 1, k) = 0.0;
      g[k + 1] = -sn[k] * g[k];
      g[k] = cs[k] * g[k];
      const double estimate = std::abs(g[k + 1]) / bnorm;
      if (on_iteration) on_iteration(out.iterations, estimate);
      if (estimate <= tolerance || wn == 0.0) {
        ++k;
        break;
      }
    }
    // Back substitution and update x += M^-1 V y.
    for (std::size_t ii = k; ii-- > 0;) {
      double s = g[ii];
      for (std::size_t j = ii + 1; j < k; ++j) s -= hh(ii, j) * y[j];
      y[ii] = hh(ii, ii) != 0.0 ? s / hh(ii, ii) : 0.0;
    }
    std::fill(w.begin(), w.end(), 0.0);
    for (std::size_t j = 0; j < k; ++j) {
      const auto& v = basis[j];
      const double yj = y[j];
      for (std::size_t i = 0; i < n; ++i) w[i] += yj * v[i];
    }
    precondition(w.data(), z.data());
    for (std::size_t i = 0; i < n; ++i) x[i] += z[i];
  }
}

std::vector<double> assemble_dense(const PanelSet& panels, const NearField& near) {
  const std::size_t n = panels.size();
  std::vector<double> m(n * n);
  std::vector<double> cx(n), cy(n), cz(n);
  for (std::size_t j = 0; j < n; ++j) {
    cx[j] = panels.centroid[j][0];
    cy[j] = panels.centroid[j][1];
    cz[j] = panels.centroid[j][2];
  }
  const double* area = panels.area.data();
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(dynamic, 16)
#endif
  for (std::ptrdiff_t ii = 0; ii < static_cast<std::ptrdiff_t>(n); ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    double* row = m.data() + i * n;
    const double x = cx[i], y = cy[i], z = cz[i];
    for (std::size_t j = 0; j < n; ++j) {
      const double dx = x - cx[j], dy = y - cy[j], dz = z - cz[j];
      row[j] = area[j] / std::sqrt(dx * dx + dy * dy + dz * dz + 1e-300);
    }
    for (std::size_t e = near.row_start[i]; e < near.row_start[i + 1]; ++e) {
      row[near.column[e]] = near.value[e];
    }
  }
  return m;
}

void dense_apply(const std::vector<double>& m, std::size_t n, const double* x, double* y) {
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(static)
#endif
  for (std::ptrdiff_t ii = 0; ii < static_cast<std::ptrdiff_t>(n); ++ii) {
    const double* row = m.data() + static_cast<std::size_t>(ii) * n;
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    std::size_t j = 0;
    for (; j + 4 <= n; j += 4) {
      s0 += row[j] * x[j];
      s1 += row[j + 1] * x[j + 1];
      s2 += row[j + 2] * x[j + 2];
      s3 += row[j + 3] * x[j + 3];
    }
    for (; j < n; ++j) s0 += row[j] * x[j];
    y[ii] = (s0 + s1) + (s2 + s3);
  }
}

bool solve_dense_lu(const std::vector<double>& m, std::size_t n, const std::vector<double>& b,
                    std::vector<double>& x) {
  using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Map<const Mat> a(m.data(), static_cast<Eigen::Index>(n),
                                static_cast<Eigen::Index>(n));
  const Eigen::Map<const Eigen::VectorXd> rhs(b.data(), static_cast<Eigen::Index>(n));
  // Eigen's threaded LU was slower than one thread on 2 cores (docs/charge.md).
  const int threads = Eigen::nbThreads();
  Eigen::setNbThreads(1);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(a);
  Eigen::setNbThreads(threads);
  const auto& u = lu.matrixLU();
  for (Eigen::Index i = 0; i < u.rows(); ++i) {
    if (u(i, i) == 0.0 || !std::isfinite(u(i, i))) return false;
  }
  const Eigen::VectorXd sol = lu.solve(rhs);
  x.assign(sol.data(), sol.data() + n);
  for (const double v : x) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

}  // namespace tetseg::preprocess::charge_detail

namespace tetseg::preprocess::charge_detail {

BlockJacobi::BlockJacobi(const PanelSet& panels, const ClusterTree& tree) : m_tree(tree) {
  const std::size_t leaves = tree.leaves.size();
  m_offset.resize(leaves + 1, 0);
  for (std::size_t l = 0; l < leaves; ++l) {
    const Cluster& c = tree.nodes[static_cast<std::size_t>(tree.leaves[l])];
    const std::size_t m = c.end - c.begin;
    m_offset[l + 1] = m_offset[l] + m * m;
  }
  m_inverse.resize(m_offset[leaves]);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(dynamic, 8)
#endif
  for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaves); ++ll) {
    const std::size_t l = static_cast<std::size_t>(ll);
    const Cluster& c = tree.nodes[static_cast<std::size_t>(tree.leaves[l])];
    const Eigen::Index m = c.end - c.begin;
    Eigen::MatrixXd block(m, m);
    for (Eigen::Index a = 0; a < m; ++a) {
      for (Eigen::Index b = 0; b < m; ++b) {
        block(a, b) = matrix_entry(panels, tree.order[c.begin + static_cast<std::size_t>(a)],
                                   tree.order[c.begin + static_cast<std::size_t>(b)]);
      }
    }
    const Eigen::MatrixXd inv = block.partialPivLu().inverse();
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        m_inverse.data() + m_offset[l], m, m) = inv;
  }
}

void BlockJacobi::apply(const double* in, double* out) const {
  const std::size_t leaves = m_tree.leaves.size();
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(static)
#endif
  for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaves); ++ll) {
    const std::size_t l = static_cast<std::size_t>(ll);
    const Cluster& c = m_tree.nodes[static_cast<std::size_t>(m_tree.leaves[l])];
    const std::size_t m = c.end - c.begin;
    const double* inv = m_inverse.data() + m_offset[l];
    for (std::size_t a = 0; a < m; ++a) {
      double s = 0.0;
      for (std::size_t b = 0; b < m; ++b) s += inv[a * m + b] * in[m_tree.order[c.begin + b]];
      out[m_tree.order[c.begin + a]] = s;
    }
  }
}

}  // namespace tetseg::preprocess::charge_detail

namespace tetseg::preprocess::charge_detail {

NearFieldSchwarz::NearFieldSchwarz(const PanelSet& panels, const ClusterTree& tree,
                                   const NearField& near, std::size_t max_set)
    : m_tree(tree) {
  const std::size_t n = panels.size();
  const std::size_t leaves = tree.leaves.size();
  // Pass 1: the extended set of every leaf.
  std::vector<std::vector<std::uint32_t>> sets(leaves);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel
#endif
  {
    std::vector<char> mark(n, 0);
    std::vector<std::pair<double, std::uint32_t>> extra;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 8)
#endif
    for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaves); ++ll) {
      const std::size_t l = static_cast<std::size_t>(ll);
      const Cluster& c = tree.nodes[static_cast<std::size_t>(tree.leaves[l])];
      auto& set = sets[l];
      for (std::uint32_t k = c.begin; k < c.end; ++k) {
        set.push_back(tree.order[k]);
        mark[tree.order[k]] = 1;
      }
      extra.clear();
      for (std::uint32_t k = c.begin; k < c.end; ++k) {
        const std::size_t i = tree.order[k];
        for (std::size_t e = near.row_start[i]; e < near.row_start[i + 1]; ++e) {
          const std::uint32_t j = near.column[e];
          if (mark[j]) continue;
          mark[j] = 1;
          const Vec3& q = panels.centroid[j];
          const double dx = q[0] - c.center[0], dy = q[1] - c.center[1], dz = q[2] - c.center[2];
          extra.push_back({dx * dx + dy * dy + dz * dz, j});
        }
      }
      for (const std::uint32_t j : set) mark[j] = 0;
      for (const auto& e : extra) mark[e.second] = 0;
      const std::size_t room = max_set > set.size() ? max_set - set.size() : 0;
      if (extra.size() > room) {
        std::nth_element(extra.begin(), extra.begin() + static_cast<std::ptrdiff_t>(room),
                         extra.end());
        extra.resize(room);
      }
      std::sort(extra.begin(), extra.end());
      for (const auto& e : extra) set.push_back(e.second);
    }
  }
  m_set_start.assign(leaves + 1, 0);
  m_rows_start.assign(leaves + 1, 0);
  for (std::size_t l = 0; l < leaves; ++l) {
    const Cluster& c = tree.nodes[static_cast<std::size_t>(tree.leaves[l])];
    m_set_start[l + 1] = m_set_start[l] + sets[l].size();
    m_rows_start[l + 1] = m_rows_start[l] + sets[l].size() * (c.end - c.begin);
  }
  m_set.resize(m_set_start[leaves]);
  m_rows.resize(m_rows_start[leaves]);
  m_mean_set =
      static_cast<double>(m_set.size()) / static_cast<double>(std::max<std::size_t>(leaves, 1));
  // Pass 2: factorise M_SS and keep the members' rows of its inverse.
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel
#endif
  {
    std::vector<std::int32_t> pos(n, -1);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 4)
#endif
    for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaves); ++ll) {
      const std::size_t l = static_cast<std::size_t>(ll);
      const Cluster& c = tree.nodes[static_cast<std::size_t>(tree.leaves[l])];
      const auto& set = sets[l];
      std::copy(set.begin(), set.end(),
                m_set.begin() + static_cast<std::ptrdiff_t>(m_set_start[l]));
      const Eigen::Index s = static_cast<Eigen::Index>(set.size());
      const Eigen::Index members = static_cast<Eigen::Index>(c.end - c.begin);
      for (Eigen::Index a = 0; a < s; ++a)
        pos[set[static_cast<std::size_t>(a)]] = static_cast<std::int32_t>(a);
      // The transpose of M_SS, so that the solve below yields rows of M_SS^-1. Single
      // precision: a preconditioner needs a few digits, and the LU is twice as fast.
      Eigen::MatrixXf at(s, s);
      for (Eigen::Index a = 0; a < s; ++a) {
        const std::size_t i = set[static_cast<std::size_t>(a)];
        const Vec3& p = panels.centroid[i];
        for (Eigen::Index b = 0; b < s; ++b) {
          const std::size_t j = set[static_cast<std::size_t>(b)];
          const Vec3& q = panels.centroid[j];
          const double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
          const double r2 = dx * dx + dy * dy + dz * dz;
          at(b, a) = static_cast<float>(r2 > 0.0 ? panels.area[j] / std::sqrt(r2) : 0.0);
        }
        for (std::size_t e = near.row_start[i]; e < near.row_start[i + 1]; ++e) {
          const std::int32_t b = pos[near.column[e]];
          if (b >= 0) at(b, a) = static_cast<float>(near.value[e]);
        }
      }
      for (const std::uint32_t j : set) pos[j] = -1;
      const Eigen::MatrixXf rows =
          at.partialPivLu().solve(Eigen::MatrixXf::Identity(s, members));  // s x members
      Eigen::Map<Eigen::MatrixXf>(m_rows.data() + m_rows_start[l], s, members) = rows;
    }
  }
}

void NearFieldSchwarz::apply(const double* in, double* out) const {
  const std::size_t leaves = m_tree.leaves.size();
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel
#endif
  {
    std::vector<double> gathered;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(static)
#endif
    for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaves); ++ll) {
      const std::size_t l = static_cast<std::size_t>(ll);
      const Cluster& c = m_tree.nodes[static_cast<std::size_t>(m_tree.leaves[l])];
      const std::size_t s = m_set_start[l + 1] - m_set_start[l];
      const std::uint32_t* set = m_set.data() + m_set_start[l];
      gathered.resize(s);
      for (std::size_t b = 0; b < s; ++b) gathered[b] = in[set[b]];
      const float* rows = m_rows.data() + m_rows_start[l];
      for (std::size_t a = 0; a < c.end - c.begin; ++a) {
        const float* row = rows + a * s;
        double s0 = 0.0, s1 = 0.0;
        std::size_t b = 0;
        for (; b + 2 <= s; b += 2) {
          s0 += row[b] * gathered[b];
          s1 += row[b + 1] * gathered[b + 1];
        }
        if (b < s) s0 += row[b] * gathered[b];
        out[set[a]] = s0 + s1;
      }
    }
  }
}

double exact_residual(const PanelSet& panels, const NearField& near, const std::vector<double>& b,
                      const std::vector<double>& y) {
  const std::size_t n = panels.size();
  std::vector<double> cx(n), cy(n), cz(n), q(n);
  for (std::size_t j = 0; j < n; ++j) {
    cx[j] = panels.centroid[j][0];
    cy[j] = panels.centroid[j][1];
    cz[j] = panels.centroid[j][2];
    q[j] = panels.area[j] * y[j];
  }
  double rr = 0.0, bb = 0.0;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : rr, bb)
#endif
  for (std::ptrdiff_t ii = 0; ii < static_cast<std::ptrdiff_t>(n); ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    const double x = cx[i], yy = cy[i], z = cz[i];
    double s = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      const double dx = x - cx[j], dy = yy - cy[j], dz = z - cz[j];
      const double r2 = dx * dx + dy * dy + dz * dz;
      if (r2 > 0.0) s += q[j] / std::sqrt(r2);
    }
    for (std::size_t e = near.row_start[i]; e < near.row_start[i + 1]; ++e) {
      s += near.correction[e] * y[near.column[e]];
    }
    rr += (b[i] - s) * (b[i] - s);
    bb += b[i] * b[i];
  }
  return bb > 0.0 ? std::sqrt(rr / bb) : 0.0;
}

}  // namespace tetseg::preprocess::charge_detail

namespace tetseg::preprocess::charge_detail {

TwoLevelSchwarz::TwoLevelSchwarz(const PanelSet& panels, const ClusterTree& tree,
                                 const NearField& near, std::size_t max_set, std::size_t max_coarse)
    : m_local(panels, tree, near, max_set), m_n(panels.size()) {
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
  for (std::size_t J = 0; J < k; ++J) {
    const Cluster& c = tree.nodes[static_cast<std::size_t>(roots[J])];
    for (std::uint32_t e = c.begin; e < c.end; ++e) {
      m_cluster[tree.order[e]] = static_cast<std::uint32_t>(J);
    }
  }
  // Per node: total area, area centroid, and a radius about it that covers the triangles.
  const std::size_t nodes = tree.nodes.size();
  std::vector<double> area(nodes), cx(nodes), cy(nodes), cz(nodes), radius(nodes);
  for (std::size_t id = nodes; id-- > 0;) {
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
  constexpr double kOpening = 0.5;
  m_mz.assign(n * k, 0.0f);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel
#endif
  {
    std::vector<std::int32_t> stack;
    std::vector<double> row(k);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 64)
#endif
    for (std::ptrdiff_t ii = 0; ii < static_cast<std::ptrdiff_t>(n); ++ii) {
      const std::size_t i = static_cast<std::size_t>(ii);
      const Vec3& p = panels.centroid[i];
      for (std::size_t J = 0; J < k; ++J) {
        double s = 0.0;
        stack.assign(1, roots[J]);
        while (!stack.empty()) {
          const std::size_t id = static_cast<std::size_t>(stack.back());
          stack.pop_back();
          const Cluster& c = tree.nodes[id];
          const double dx = p[0] - cx[id], dy = p[1] - cy[id], dz = p[2] - cz[id];
          const double d2 = dx * dx + dy * dy + dz * dz;
          if (radius[id] * radius[id] < kOpening * kOpening * d2) {
            s += area[id] / std::sqrt(d2);
          } else if (c.left >= 0) {
            stack.push_back(c.left);
            stack.push_back(c.right);
          } else {
            for (std::uint32_t e = c.begin; e < c.end; ++e) {
              const std::uint32_t j = tree.order[e];
              const Vec3& q = panels.centroid[j];
              const double ex = p[0] - q[0], ey = p[1] - q[1], ez = p[2] - q[2];
              const double r2 = ex * ex + ey * ey + ez * ez;
              if (r2 > 0.0) s += panels.area[j] / std::sqrt(r2);
            }
          }
        }
        row[J] = s;
      }
      for (std::size_t e = near.row_start[i]; e < near.row_start[i + 1]; ++e) {
        row[m_cluster[near.column[e]]] += near.correction[e];
      }
      float* out = m_mz.data() + i * k;
      for (std::size_t J = 0; J < k; ++J) out[J] = static_cast<float>(row[J]);
    }
  }
  Eigen::MatrixXd coarse =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(k));
  for (std::size_t i = 0; i < n; ++i) {
    const float* row = m_mz.data() + i * k;
    for (std::size_t J = 0; J < k; ++J) {
      coarse(static_cast<Eigen::Index>(m_cluster[i]), static_cast<Eigen::Index>(J)) += row[J];
    }
  }
  const Eigen::MatrixXd inv = coarse.partialPivLu().inverse();
  m_coarse_inverse.resize(k * k);
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      m_coarse_inverse.data(), static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(k)) = inv;
  m_residual.resize(n);
}

void TwoLevelSchwarz::apply(const double* in, double* out) const {
  const std::size_t n = m_n, k = m_k;
  std::vector<double> t(k, 0.0), u(k, 0.0);
  for (std::size_t i = 0; i < n; ++i) t[m_cluster[i]] += in[i];
  for (std::size_t a = 0; a < k; ++a) {
    double s = 0.0;
    const double* row = m_coarse_inverse.data() + a * k;
    for (std::size_t b = 0; b < k; ++b) s += row[b] * t[b];
    u[a] = s;
  }
  double* r = m_residual.data();
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(static)
#endif
  for (std::ptrdiff_t ii = 0; ii < static_cast<std::ptrdiff_t>(n); ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    const float* row = m_mz.data() + i * k;
    double s = 0.0;
    for (std::size_t J = 0; J < k; ++J) s += static_cast<double>(row[J]) * u[J];
    r[i] = in[i] - s;
  }
  m_local.apply(r, out);
  for (std::size_t i = 0; i < n; ++i) out[i] += u[m_cluster[i]];
}

}  // namespace tetseg::preprocess::charge_detail
