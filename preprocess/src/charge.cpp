// compute_charge: panels, near field, solver choice and read-out (docs/charge.md).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "charge_potential.hpp"
#include "charge_solvers.hpp"
#include "charge_tree.hpp"
#include "tetseg/preprocess/charge.hpp"
#include "tetseg/preprocess/names.hpp"
#include "tetseg/preprocess/option_ranges.hpp"

namespace tetseg::preprocess {
namespace {

using Clock = std::chrono::steady_clock;
using namespace charge_detail;

constexpr std::size_t kAutoDirectMax = 400;
constexpr std::size_t kAutoDenseMax = 3000;
constexpr std::size_t kAutoHighOrderMin = 10000;
constexpr std::size_t kAutoTightToleranceMin = 10000;
constexpr double kAutoTolerance = 1e-6;
/// 1e-8 from 10k since the two-level preconditioner (d68f3e4): at 1e-7 it stopped at 8.5e-8
/// after 7 iterations on the elephant (88,928) with 0.19 % max density error; 1e-8 takes 9
/// iterations (+0.8 s) for 0.08 % (docs/charge.md).
constexpr double kAutoTightTolerance = 1e-8;
/// FMM opening parameter: 0.45 from 10k triangles cut the elephant's (88,928) max density
/// error from 0.23 % to 0.06 % of the mean density for 13 % more time (docs/charge.md).
/// Below 10k, theta 0.4 with order 6 (instead of 0.5 and 7): fewer instructions and half the
/// residual against the exact matrix at 5k (7.2e-7 -> 4.0e-7, elephant 6.5e-7 -> 3.7e-7).
constexpr double kAutoTheta = 0.4;
constexpr int kAutoOrder = 6;
constexpr int kAutoLargeOrder = 8;
constexpr double kAutoLargeTheta = 0.45;
/// Near-field Schwarz: at most this many triangles per leaf problem (the leaf's own and its
/// most strongly coupled near-field neighbours). Measured 64 / 96 / 128 / 160 on the ellipsoid
/// and the elephant at 5k and 100k, and 80 / 96 / 128 with relaxed products on 16 CGAL meshes
/// at two sizes: below 10k triangles 80 takes 15 % less CPU time than 128 for an iteration more
/// (a relaxed one), from 10k on it saves 4 % for 17 % more iterations (docs/charge.md,
/// "Preconditioner").
constexpr std::size_t kSchwarzSet = 128;
constexpr std::size_t kSmallSchwarzSet = 80;
/// Two-level: at most this many coarse clusters (dense LU of K x K), each of at least about
/// kCoarseClusterMin triangles.
constexpr std::size_t kCoarseMax = 2048;
constexpr std::size_t kCoarseClusterMin = 64;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// MemAvailable from /proc/meminfo in bytes, or 4 GiB when unknown.
std::size_t available_memory() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  std::size_t value = 0;
  std::string unit;
  while (in >> key >> value >> unit) {
    if (key == "MemAvailable:") return value * 1024;
  }
  return std::size_t{4} << 30;
}

}  // namespace

namespace charge_detail {

std::size_t schwarz_set_for(std::size_t n, int requested) {
  if (requested > 0) return static_cast<std::size_t>(requested);
  return n < kAutoHighOrderMin ? kSmallSchwarzSet : kSchwarzSet;
}

}  // namespace charge_detail

ChargeResult compute_charge(const std::vector<Vec3>& points, const std::vector<Tri>& triangles,
                            const ChargeOptions& options, const std::string& file) {
  const auto t0 = Clock::now();
  auto progress = [&](const char* stage, double f) {
    if (options.progress) options.progress(stage, f);
  };
  const PanelSet panels = make_panels(points, triangles, file);
  const std::size_t n = panels.size();
  check_option(option_ranges::kTolerance, options.tolerance);  // 0: automatic
  const double tolerance =
      options.tolerance > 0.0 ? options.tolerance
                              : (n < kAutoTightToleranceMin ? kAutoTolerance : kAutoTightTolerance);
  if (options.schwarz_set < 0) {
    throw std::invalid_argument("charge schwarz_set must be positive, or 0 for automatic");
  }
  check_option(option_ranges::kTheta, options.fast_theta);  // 0: automatic
  const std::size_t limit =
      options.memory_limit_bytes ? options.memory_limit_bytes : available_memory() / 2;
  const double dense_bytes = 8.0 * static_cast<double>(n) * static_cast<double>(n);
  ChargeSolver solver = options.solver;
  if (solver == ChargeSolver::kAuto) {
    if (n <= kAutoDirectMax && dense_bytes <= static_cast<double>(limit)) {
      solver = ChargeSolver::kDirect;
    } else if (n <= kAutoDenseMax && dense_bytes <= static_cast<double>(limit)) {
      solver = ChargeSolver::kGmres;
    } else {
      solver = ChargeSolver::kFast;
    }
  }
  if ((solver == ChargeSolver::kDirect || solver == ChargeSolver::kGmres) &&
      dense_bytes > static_cast<double>(limit)) {
    std::ostringstream msg;
    msg << "the dense " << name_of(solver) << " solver needs " << dense_bytes / 1e9 << " GB for "
        << n << " triangles but the limit is " << static_cast<double>(limit) / 1e9
        << " GB; use --solver fast or auto";
    throw std::runtime_error(msg.str());
  }

  ChargeResult result;
  result.solver = name_of(solver);
  result.tolerance = tolerance;
  progress("assembly", 0.0);
  const ClusterTree tree = build_cluster_tree(panels, options.leaf_size);
  NearField near = build_near_field(panels, tree);
  result.near_entries = near.column.size();
  progress("assembly", 0.3);

  std::vector<double> b(n, 1.0), y(n, 0.0);
  std::unique_ptr<BlockJacobi> block;
  std::unique_ptr<NearFieldSchwarz> schwarz;
  std::unique_ptr<TwoLevelSchwarz> two_level;
  if (options.preconditioner == ChargePreconditioner::kBlock && solver != ChargeSolver::kDirect) {
    block = std::make_unique<BlockJacobi>(panels, tree);
  }
  const std::size_t schwarz_set = schwarz_set_for(n, options.schwarz_set);
  if (options.preconditioner == ChargePreconditioner::kNearField &&
      solver != ChargeSolver::kDirect) {
    schwarz = std::make_unique<NearFieldSchwarz>(panels, tree, near, schwarz_set);
  }
  if (options.preconditioner == ChargePreconditioner::kTwoLevel &&
      solver != ChargeSolver::kDirect) {
    const std::size_t k = std::min(kCoarseMax, n / kCoarseClusterMin);
    two_level = std::make_unique<TwoLevelSchwarz>(panels, tree, near, schwarz_set, k);
  }
  const ApplyFn precondition = [&](const double* in, double* out) {
    if (block) {
      block->apply(in, out);
    } else if (schwarz) {
      schwarz->apply(in, out);
    } else if (two_level) {
      two_level->apply(in, out);
    } else {
      for (std::size_t i = 0; i < n; ++i) out[i] = in[i] / near.diagonal[i];
    }
  };
  auto on_iteration = [&](int it, double res) {
    const double f = res > 0.0 ? std::log(res) / std::log(tolerance) : 1.0;
    progress("solve", std::min(1.0, std::max(0.0, f)));
    (void)it;
  };
  if (solver == ChargeSolver::kFast) {
    const int order = options.fast_order >= 0
                          ? options.fast_order
                          : (n < kAutoHighOrderMin ? kAutoOrder : kAutoLargeOrder);
    const double theta = options.fast_theta > 0.0
                             ? options.fast_theta
                             : (n < kAutoHighOrderMin ? kAutoTheta : kAutoLargeTheta);
    // The analytic values served the preconditioner; the FMM needs only the corrections
    // (8 bytes per near entry freed: 0.6 GB at 1.3 M triangles).
    decltype(near.value)().swap(near.value);
    const TreecodeOperator op(panels, tree, near, theta, order);
    // The relaxed operator, when it is cheaper than the main one.
    std::unique_ptr<TreecodeOperator> relaxed_op;
    RelaxedProduct relaxed;
    if (options.relaxed_products && order > kRelaxedOrder && theta < kRelaxedTheta) {
      relaxed_op =
          std::make_unique<TreecodeOperator>(panels, tree, near, kRelaxedTheta, kRelaxedOrder);
      relaxed.apply = [&](const double* x, double* out) { relaxed_op->apply(x, out); };
      relaxed.relative_error = kRelaxedError;
    }
    result.assembly_seconds = seconds_since(t0);
    progress("assembly", 1.0);
    const auto t1 = Clock::now();
    const GmresOutcome g = solve_gmres(
        n, [&](const double* x, double* out) { op.apply(x, out); }, precondition, b, y, tolerance,
        options.max_iterations, options.restart, on_iteration, relaxed);
    result.solve_seconds = seconds_since(t1);
    result.iterations = g.iterations;
    result.relaxed_products = g.relaxed_products;
    result.residual = g.residual;
    result.converged = g.converged;
  } else {
    const std::vector<double> m = assemble_dense(panels, near);
    result.assembly_seconds = seconds_since(t0);
    progress("assembly", 1.0);
    const auto t1 = Clock::now();
    if (solver == ChargeSolver::kDirect) {
      progress("solve", 0.0);
      if (!solve_dense_lu(m, n, b, y)) {
        throw std::runtime_error("the collocation matrix is singular (overlapping triangles?)");
      }
      std::vector<double> r(n);
      dense_apply(m, n, y.data(), r.data());
      double rr = 0.0;
      for (std::size_t i = 0; i < n; ++i) rr += (1.0 - r[i]) * (1.0 - r[i]);
      result.residual = std::sqrt(rr / static_cast<double>(n));
      result.converged = true;
    } else {
      const GmresOutcome g = solve_gmres(
          n, [&](const double* x, double* out) { dense_apply(m, n, x, out); }, precondition, b, y,
          tolerance, options.max_iterations, options.restart, on_iteration);
      result.iterations = g.iterations;
      result.residual = g.residual;
      result.converged = g.converged;
    }
    result.solve_seconds = seconds_since(t1);
  }
  progress("solve", 1.0);

  double capacitance = 0.0, total_area = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    capacitance += panels.area[j] * y[j];
    total_area += panels.area[j];
  }
  if (!std::isfinite(capacitance) || !(capacitance > 0.0)) {
    throw std::runtime_error("the charge solve produced no usable solution (capacitance " +
                             std::to_string(capacitance) + ")");
  }
  result.capacitance = capacitance;
  result.total_area = total_area;
  result.density.resize(n);
  const double scale = total_area / capacitance;
  for (std::size_t j = 0; j < n; ++j) result.density[j] = y[j] * scale;
  return result;
}

}  // namespace tetseg::preprocess
