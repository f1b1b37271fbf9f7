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
  for (;;) {
    apply(x.data(), r.data());
    for (std::size_t i = 0; i < n; ++i) r[i] = b[i] - r[i];
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
