#pragma once
/// \file
/// Surface charge density of a closed surface treated as a perfect conductor (Wong & Yeh,
/// section IV-A), and its histogram equalisation (section IV-B). Formulation, solvers and
/// costs: docs/charge.md.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess {

enum class ChargeSolver { kAuto, kDirect, kGmres, kFast };

struct ChargeOptions {
  ChargeSolver solver = ChargeSolver::kAuto;
  double tolerance = 1e-6;      ///< relative residual for iterative solvers
  int max_iterations = 500;
  /// Called now and then during long stages with (stage, fraction done in [0,1]).
  std::function<void(const char* stage, double fraction)> progress;
};

struct ChargeResult {
  std::vector<double> density;  ///< per triangle, relative: 1 everywhere on a sphere
  double capacitance = 0.0;     ///< in the input's length units (a sphere of radius r gives r)
  std::string solver;           ///< the solver actually used: "direct", "gmres" or "fast"
  int iterations = 0;
  double residual = 0.0;        ///< final relative residual
  double assembly_seconds = 0.0;
  double solve_seconds = 0.0;
};

/// Computes the relative charge density of the closed outward surface `triangles` over
/// `points`. Throws InputError(file, ...) for degenerate (zero-area) triangles.
ChargeResult compute_charge(const std::vector<Vec3>& points, const std::vector<Tri>& triangles,
                            const ChargeOptions& options, const std::string& file = {});

enum class Equalization {
  kHistogram,     ///< the paper's: 256 bins, value = CDF[bin] / N
  kRank,          ///< exact ranks: (rank + 1) / N, ties share the largest rank
  kLogHistogram,  ///< 256 bins over log(density)
};

/// Maps densities to (0,1] (docs/charge.md). Deterministic.
std::vector<double> equalize(const std::vector<double>& density, Equalization method,
                             int bins = 256);

}  // namespace tetseg::preprocess
