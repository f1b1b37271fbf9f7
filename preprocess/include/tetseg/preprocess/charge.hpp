#pragma once
/// \file
/// Surface charge density of a closed surface treated as a perfect conductor (Wong & Yeh,
/// section IV-A), and its histogram equalisation (section IV-B). Formulation, far-field rule,
/// solvers and measured accuracy: docs/charge.md.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess {

/// Linear solver for the collocation system M y = 1.
enum class ChargeSolver {
  kAuto,    ///< direct for N <= 400, gmres while the dense matrix is small and fits, else fast
  kDirect,  ///< dense LU (Eigen PartialPivLU): O(N^3) time, 8 N^2 bytes; a reference
  kGmres,   ///< preconditioned GMRES on the stored dense matrix: 8 N^2 bytes
  kFast,    ///< preconditioned GMRES, matrix-free FMM products, O(N log N) time and memory
};

// Names: enum_names<ChargeSolver>() (tetseg/preprocess/names.hpp).

/// Preconditioner of the iterative solvers.
enum class ChargePreconditioner {
  kJacobi,  ///< the diagonal M_ii
  kBlock,   ///< exact inverses of the diagonal blocks of the cluster-tree leaves
  /// Restricted additive Schwarz on the exact near field: per leaf, a dense LU of the matrix
  /// on the leaf plus its nearest near-field neighbours (docs/charge.md, "Preconditioner").
  kNearField,
  /// kNearField plus a coarse correction on up to 2048 tree clusters of at least ~64
  /// triangles (piecewise-constant densities, Galerkin coarse matrix): removes the smooth
  /// error the local solves leave, so the iteration count stays flat with N.
  kTwoLevel,
};

struct ChargeOptions {
  ChargeSolver solver = ChargeSolver::kAuto;
  /// Relative residual ||1 - M y|| / ||1|| at which the iterative solvers stop, in (0, 0.5]
  /// (option_ranges::kTolerance), or 0 for automatic: 1e-6 below 10,000 triangles, 1e-8 from there
  /// on. The density error left by a given residual grows with N (at 100k triangles 1e-6 leaves ~1
  /// % max error, 1e-8 below 0.1 % on an ellipsoid and the CGAL elephant; docs/charge.md). Negative
  /// values are rejected.
  double tolerance = 0.0;
  int max_iterations = 500;  ///< matrix products, iterative solvers only
  int restart = 80;          ///< GMRES restart length
  ChargePreconditioner preconditioner = ChargePreconditioner::kTwoLevel;
  /// FMM opening parameter: two clusters interact through expansions when
  /// (r_target + r_source) < theta * distance. Smaller is more accurate and slower; (0, 0.95]
  /// (option_ranges::kTheta), or 0 for automatic: 0.4 below 10,000 triangles, 0.45 from there on
  /// (docs/charge.md).
  double fast_theta = 0.0;
  /// Total order of the fast solver's Taylor expansions, 0..16; error ~ theta^(order + 1).
  /// Negative means automatic: 6 below 10,000 triangles (with theta 0.4 the residual against
  /// the exact matrix stays below half the automatic 1e-6 at 5k), 8 from there on (the density
  /// error grows with N for a fixed operator error; docs/charge.md).
  int fast_order = -1;
  int leaf_size = 32;  ///< cluster-tree leaf size (fast solver)
  /// Two-level and near-field preconditioners: at most this many triangles per leaf problem,
  /// or 0 for automatic: 80 below 10,000 triangles, 128 from there on (docs/charge.md).
  int schwarz_set = 0;
  /// Fast solver: once the residual is small, GMRES's products use a cheaper FMM (order 4,
  /// theta 0.5) within half the tolerance's budget (inexact Krylov; docs/charge.md, "Relaxed
  /// products"). False: every product at the requested order and theta.
  bool relaxed_products = true;
  /// Largest dense matrix the solver may store, in bytes; 0 means half of the memory the
  /// operating system reports as available. Explicit direct/gmres requests beyond it fail.
  std::size_t memory_limit_bytes = 0;
  /// Called now and then during long stages with (stage, fraction done in [0,1]); stage is
  /// "assembly" or "solve". Called from the calling thread only.
  std::function<void(const char* stage, double fraction)> progress;
};

struct ChargeResult {
  /// Per triangle, relative density sigma_j * (total area) / Q: 1 everywhere on a sphere,
  /// dimensionless, invariant under scaling of the input. Positive for a valid closed surface.
  std::vector<double> density;
  double capacitance = 0.0;  ///< Q / V in the input's length units (4 pi eps0 = 1): sphere r -> r
  double total_area = 0.0;   ///< sum of triangle areas
  std::string solver;        ///< the solver actually used: "direct", "gmres" or "fast"
  int iterations = 0;        ///< matrix products (0 for direct)
  int relaxed_products = 0;  ///< of those, products by the cheaper FMM (relaxed_products)
  double residual = 0.0;     ///< final relative residual against the solver's operator
  double tolerance = 0.0;    ///< the tolerance used (options.tolerance or the automatic one)
  bool converged = false;    ///< residual <= tolerance (always true for a successful direct)
  std::size_t near_entries = 0;   ///< analytic (near-field) matrix entries
  double assembly_seconds = 0.0;  ///< panels, tree, near field, dense matrix or treecode lists
  double solve_seconds = 0.0;
};

/// Computes the relative charge density of the closed surface `triangles` over `points`
/// (orientation does not matter). Throws InputError(file, ...) for no triangles, an index out
/// of range, a non-finite coordinate or a degenerate (zero-area or needle) triangle; throws
/// std::invalid_argument for a tolerance or fast_theta outside its option range; throws
/// std::runtime_error when the requested dense solver does not fit memory_limit_bytes, when
/// the dense matrix is singular or the iteration produces non-finite values. Non-convergence
/// within max_iterations is not an error: check `converged`. Uses OpenMP threads internally;
/// not reentrant with respect to Eigen's global thread count during direct solves.
ChargeResult compute_charge(const std::vector<Vec3>& points, const std::vector<Tri>& triangles,
                            const ChargeOptions& options, const std::string& file = {});

enum class Equalization {
  kHistogram,     ///< the paper's: bins over [min, max], value = CDF[bin] / N
  kRank,          ///< exact ranks: (number of values <= v) / N, so ties share the largest rank
  kLogHistogram,  ///< the paper's rule on bins over [log min, log max] (needs density > 0)
};

// Names: enum_names<Equalization>() (tetseg/preprocess/names.hpp).

/// Maps densities to (0, 1] so that the order is kept (non-decreasing map). Histogram: bin
/// b = floor((v - min) / (max - min) * bins) clamped to bins - 1, CDF[b] = number of values in
/// bins <= b, result CDF[b] / N; all values equal gives 1 everywhere. Log histogram: the same
/// on log(v); values <= 0 fall into bin 0. Deterministic; empty input gives empty output.
/// Throws std::invalid_argument for a non-finite value or bins < 1.
std::vector<double> equalize(const std::vector<double>& density, Equalization method,
                             int bins = 256);

}  // namespace tetseg::preprocess
