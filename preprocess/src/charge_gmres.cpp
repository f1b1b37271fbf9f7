// Restarted GMRES with right preconditioning, the dense matrix helpers and the residual against
// the exact matrix (the preconditioners: charge_preconditioners.cpp).

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>

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
                         int max_iterations, int restart, const IterationFn& on_iteration,
                         const RelaxedProduct& relaxed) {
  GmresOutcome out;
  restart = std::max(restart, 1);
  const double bnorm = norm2(b);
  if (bnorm == 0.0) {
    std::fill(x.begin(), x.end(), 0.0);
    out.converged = true;
    return out;
  }
  std::vector<double> r(n), w(n), z(n);
  // Krylov vectors are allocated when first used: a solve that converges in a few iterations
  // needs a few of the restart + 1 vectors (81 x 8 bytes per unknown).
  std::vector<std::vector<double>> basis(static_cast<std::size_t>(restart) + 1);
  const std::size_t m = static_cast<std::size_t>(restart);
  std::vector<double> h((m + 1) * m), arnoldi((m + 1) * m), cs(m), sn(m), g(m + 1), y(m);
  auto hh = [&](std::size_t i, std::size_t j) -> double& { return h[i * m + j]; };
  // The Hessenberg matrix before the rotations: A M^-1 V_k = V_(k+1) H_k holds to rounding
  // whatever the orthogonality of V, so r - V_(k+1) H_k y is the true residual of the update
  // (with relaxed products: of the products taken, within the relaxed budget of the true one).
  auto ha = [&](std::size_t i, std::size_t j) -> double& { return arnoldi[i * m + j]; };
  bool recompute = true;  // false after a converging cycle left r = b - A x in place
  // Relaxed products since r was last exact, as the sum of the residual norms they were taken at.
  double relaxed_spent = 0.0;
  const double relaxed_allowance = kRelaxedBudget * tolerance * bnorm;
  // A zero start needs no product for its residual.
  bool zero_start = std::all_of(x.begin(), x.end(), [](double v) { return v == 0.0; });
  for (;;) {
    if (zero_start) {
      r = b;
      zero_start = false;
      relaxed_spent = 0.0;
    } else if (recompute) {
      apply(x.data(), r.data());
      for (std::size_t i = 0; i < n; ++i) r[i] = b[i] - r[i];
      relaxed_spent = 0.0;  // r is exact again
    }
    recompute = true;
    const double beta = norm2(r);
    out.residual = beta / bnorm;
    if (!std::isfinite(out.residual)) return out;
    if (out.residual <= tolerance) {
      out.converged = true;
      return out;
    }
    if (out.iterations >= max_iterations) return out;
    basis[0].resize(n);
    for (std::size_t i = 0; i < n; ++i) basis[0][i] = r[i] / beta;
    std::fill(g.begin(), g.end(), 0.0);
    g[0] = beta;
    std::size_t k = 0;
    bool converging = false;
    for (; k < m && out.iterations < max_iterations; ++k) {
      precondition(basis[k].data(), z.data());
      // |g[k]|: the residual norm before this step.
      const double spend = relaxed.relative_error * (relaxed_spent + std::abs(g[k]));
      if (relaxed.apply && spend <= relaxed_allowance) {
        relaxed_spent += std::abs(g[k]);
        relaxed.apply(z.data(), w.data());
        ++out.relaxed_products;
      } else {
        apply(z.data(), w.data());
      }
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
      for (std::size_t j = 0; j <= k + 1; ++j) ha(j, k) = hh(j, k);
      if (wn > 0.0) {
        basis[k + 1].resize(n);
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
        converging = true;
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
    // The cycle's estimate says converged: the new residual r - V_(k+1) (H_k y) without a
    // product (at 5k one product was a fifth of the solve). Restarts recompute b - A x.
    if (converging) {
      for (std::size_t i = 0; i <= k; ++i) {
        if (i < k || ha(i, k - 1) != 0.0) {
          double t = 0.0;
          for (std::size_t j = (i == 0 ? 0 : i - 1); j < k; ++j) t += ha(i, j) * y[j];
          const auto& v = basis[i];
          for (std::size_t e = 0; e < n; ++e) r[e] -= t * v[e];
        }
      }
      recompute = false;
    }
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
