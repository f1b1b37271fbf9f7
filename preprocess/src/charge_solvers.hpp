#pragma once
// Internal: the linear solvers behind compute_charge (dense LU, restarted GMRES with right
// preconditioning: Jacobi, block Jacobi, near-field Schwarz) and the dense collocation matrix.

#include <functional>
#include <memory>
#include <vector>

#include "charge_potential.hpp"
#include "charge_tree.hpp"

namespace tetseg::preprocess::charge_detail {

/// y = A x for vectors of length n.
using ApplyFn = std::function<void(const double* x, double* y)>;
/// Called after each iteration with (iteration, relative residual estimate).
using IterationFn = std::function<void(int iteration, double residual)>;

struct GmresOutcome {
  int iterations = 0;
  int relaxed_products = 0;  ///< iterations whose product was RelaxedProduct::apply
  double residual = 0.0;     ///< relative residual ||b - A x|| / ||b|| at exit (solve_gmres)
  bool converged = false;
};

/// A cheaper product for the late iterations of solve_gmres: ||apply(x) - A x|| is assumed at
/// most relative_error * ||A x||.
struct RelaxedProduct {
  ApplyFn apply;
  double relative_error = 0.0;
};

/// Restarted right-preconditioned GMRES(restart) with modified Gram-Schmidt and Givens
/// rotations; `precondition` applies an approximate inverse. Starts from the given x. Stops when
/// the relative residual is <= tolerance or after max_iterations matrix products. The residual
/// is b - A x recomputed with a product at every restart; when a cycle's estimate says
/// converged it is r - V_(k+1) H_k y instead (the Arnoldi relation A M^-1 V_k = V_(k+1) H_k,
/// which holds to rounding however orthogonal V is), which saves one product per solve.
///
/// Relaxed products (inexact Krylov: Bouras & Fraysse 2005, Simoncini & Szyld 2003): a
/// product's error perturbs the residual by about its size times the residual norm at that
/// step, so once the residual is small a less accurate product does as well. Step k uses
/// relaxed.apply while relative_error * (sum of ||r_(j-1)|| over the relaxed steps j <= k)
/// stays <= kRelaxedBudget * tolerance * ||b||, the sum restarting wherever b - A x is
/// recomputed (with `apply`); the true residual then exceeds GMRES's by about that budget at
/// most (docs/charge.md, "Relaxed products").
GmresOutcome solve_gmres(std::size_t n, const ApplyFn& apply, const ApplyFn& precondition,
                         const std::vector<double>& b, std::vector<double>& x, double tolerance,
                         int max_iterations, int restart, const IterationFn& on_iteration,
                         const RelaxedProduct& relaxed = {});

/// The share of the tolerance that solve_gmres's relaxed products may spend.
constexpr double kRelaxedBudget = 0.5;

/// compute_charge's relaxed products (docs/charge.md, "Relaxed products"): a second FMM of
/// this order and opening parameter, whose error against the automatic operators was at most
/// 2.7e-4 of the product on GMRES's vectors at 5k (elephant, femur, dino) and 4.8e-4 at
/// 20k-327k (ellipsoid, dino); it promises kRelaxedError (tested on random-sign vectors).
constexpr int kRelaxedOrder = 4;
constexpr double kRelaxedTheta = 0.5;
constexpr double kRelaxedError = 1e-3;

/// The Schwarz set cap compute_charge uses for n triangles: `requested` if positive, else the
/// automatic one (ChargeOptions::schwarz_set).
std::size_t schwarz_set_for(std::size_t n, int requested);

/// Block-Jacobi preconditioner: the exact inverse of the collocation matrix restricted to
/// each leaf of the cluster tree (leaf_size^2 doubles per leaf).
class BlockJacobi {
 public:
  BlockJacobi(const PanelSet& panels, const ClusterTree& tree);
  void apply(const double* in, double* out) const;

 private:
  const ClusterTree& m_tree;
  std::vector<std::size_t> m_offset;
  std::vector<double> m_inverse;
};

/// Restricted additive Schwarz preconditioner on the exact near field: for each cluster-tree
/// leaf L, the set S = L plus the near-field columns j of L's rows with the largest score
/// sum over members i of A_i A_j / |c_i - c_j|^3 (at most `max_set` in all); M_SS (analytic
/// near entries, point charges elsewhere) is factorised once and the preconditioner returns,
/// on L only, (M_SS^-1 r_S)|_L. Storage: |L| x |S| floats per leaf.
class NearFieldSchwarz {
 public:
  NearFieldSchwarz(const PanelSet& panels, const ClusterTree& tree, const NearField& near,
                   std::size_t max_set);
  void apply(const double* in, double* out) const;
  double mean_set() const { return m_mean_set; }

 private:
  const ClusterTree& m_tree;
  std::vector<std::size_t> m_set_start;   ///< per leaf (CSR) into m_set
  std::vector<std::uint32_t> m_set;       ///< global ids, the leaf's members first
  std::vector<std::size_t> m_rows_start;  ///< per leaf into m_rows
  std::vector<float> m_rows;              ///< per leaf, member a: row a of M_SS^-1 (|S| floats)
  double m_mean_set = 0.0;
};

/// Two-level preconditioner: a coarse correction on K tree clusters (the nodes at one depth,
/// K <= max_coarse), applied first, then the near-field Schwarz on the remaining residual:
///   u = C^-1 Z^T r,  out = Z u + Schwarz(r - (M Z) u),
/// with Z the cluster indicators (piecewise-constant densities) and C = Z^T (M Z) (dense LU,
/// K x K). M Z is never stored whole: for the clusters J near a target's cluster I (not
/// separated by (rho_I + rho_J) < kCoarseOpening |g_I - g_J|, or holding one of the target's
/// near-field columns) the entries (M Z)_iJ come from a Barnes-Hut sum over J's subtree plus
/// the analytic near-field corrections (|I| x |near(I)| floats per cluster); the far clusters
/// act as point charges A_J u_J at their area centroids g_J, summed per target cluster into a
/// second-order Taylor expansion about g_I (K^2 work per application) that is evaluated at
/// the targets. C is the Galerkin product of Z with exactly this approximation, so the coarse
/// correction is exact for it; the approximation only makes the preconditioner less exact,
/// never the solution.
class TwoLevelSchwarz {
 public:
  TwoLevelSchwarz(const PanelSet& panels, const ClusterTree& tree, const NearField& near,
                  std::size_t max_set, std::size_t max_coarse);
  ~TwoLevelSchwarz();
  void apply(const double* in, double* out) const;
  std::size_t coarse_size() const { return m_k; }

 private:
  struct CoarseLu;
  NearFieldSchwarz m_local;
  const ClusterTree& m_tree;
  std::size_t m_n = 0, m_k = 0;
  std::vector<std::uint32_t> m_cluster;       ///< per triangle: its coarse cluster
  std::vector<std::uint32_t> m_begin, m_end;  ///< per cluster: its range of tree.order
  std::vector<double> m_area;                 ///< per cluster: A_J
  std::vector<double> m_gx, m_gy, m_gz;       ///< per cluster: area centroid g_J
  std::vector<std::size_t> m_near_start;      ///< per cluster (CSR) into m_near
  std::vector<std::uint32_t> m_near;          ///< near clusters of each cluster
  std::vector<std::size_t> m_block_start;     ///< per cluster into m_block
  std::vector<float> m_block;  ///< per cluster I, member a (tree order): (M Z)_aJ, J in near(I)
  std::vector<std::uint8_t> m_far;       ///< k x k: 1 where I and J interact by point charges
  std::vector<double> m_wx, m_wy, m_wz;  ///< per tree position: c_i - g_I of its cluster I
  std::unique_ptr<CoarseLu> m_lu;
  mutable std::vector<double> m_residual;
};

/// ||b - M y|| / ||b|| with the exact collocation matrix (point charges plus the analytic
/// near field), matrix-free: O(N^2) time, OpenMP over rows.
double exact_residual(const PanelSet& panels, const NearField& near, const std::vector<double>& b,
                      const std::vector<double>& y);

/// Dense row-major collocation matrix: far entries A_j / r_ij, near entries and the diagonal
/// from `near`. n * n doubles.
std::vector<double> assemble_dense(const PanelSet& panels, const NearField& near);

/// y = M x for a dense row-major n x n matrix (OpenMP over rows).
void dense_apply(const std::vector<double>& m, std::size_t n, const double* x, double* y);

/// Solves M x = b by LU with partial pivoting (Eigen). Returns false if M is singular.
bool solve_dense_lu(const std::vector<double>& m, std::size_t n, const std::vector<double>& b,
                    std::vector<double>& x);

}  // namespace tetseg::preprocess::charge_detail
