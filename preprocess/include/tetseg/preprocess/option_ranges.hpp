#pragma once
/// \file
/// The accepted range of every numeric option of the offline jobs, declared once: the CLI's
/// checks (CLI::Range over min and max), Python's argument checks and the library's own
/// validation (check_option; validate_options in jobs.hpp) all read these. Names are the
/// options' Python / provenance spellings ("refine_visibility"; the CLI writes '-' for '_').

#include <limits>

namespace tetseg::preprocess {

/// A range of accepted values: [min, max], or (min, max] when min_exclusive.
struct OptionRange {
  const char* name;
  double min;
  double max;
  bool min_exclusive = false;
};

namespace option_ranges {

inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

// ChargeOptions (tetseg build, tetseg charge). Tolerance and theta: 0 = automatic. A relative
// residual above 0.5 leaves a density no better than a guess, and theta near 1 makes the
// expansions converge too slowly to be of use (error ~ theta^(order + 1)), so the library
// refuses what the front ends always refused (it accepted up to 1 before).
inline constexpr OptionRange kTolerance{"tolerance", 0.0, 0.5};
inline constexpr OptionRange kMaxIterations{"max_iterations", 1, 100000};
inline constexpr OptionRange kTheta{"theta", 0.0, 0.95};
inline constexpr OptionRange kOrder{"order", -1, 16};    ///< -1: automatic
inline constexpr OptionRange kBins{"bins", 1, 1 << 20};  ///< equalisation histogram bins

// SegmentationOptions and RefinementOptions (tetseg build).
inline constexpr OptionRange kAlpha{"alpha", 0.0, 1.0};
inline constexpr OptionRange kBetaDivisor{"beta_divisor", 0.0, kUnbounded, true};
inline constexpr OptionRange kGrowthBound{"growth_bound", 0.0, 1.0};
inline constexpr OptionRange kMinVisibility{"min_visibility", 0.0, 1.0};
inline constexpr OptionRange kRefineVisibility{"refine_visibility", 0.0, 1.0};
inline constexpr OptionRange kRefineMaxClusters{"refine_max_clusters", 1, 100000};
inline constexpr OptionRange kRefineGain{"refine_gain", 0.0, kUnbounded};

// MeshingOptions (surface input of tetseg build, tetseg tetrahedralize). Sizes: 0 = derived.
inline constexpr OptionRange kCellSize{"cell_size", 0.0, kUnbounded};
inline constexpr OptionRange kFacetSize{"facet_size", 0.0, kUnbounded};
inline constexpr OptionRange kFacetDistance{"facet_distance", 0.0, kUnbounded};
inline constexpr OptionRange kThreads{"threads", 0, 4096};  ///< 0: one per hardware thread
inline constexpr OptionRange kWrapAlpha{"wrap_alpha", 1e-4, 1.0};
inline constexpr OptionRange kWrapOffset{"wrap_offset", 1e-4, 1.0};
inline constexpr OptionRange kWrapSheetOffset{"wrap_sheet_offset", 1e-4, 1.0};
inline constexpr OptionRange kMaxDeviation{"max_deviation", 1e-4, 1.0};

// tetseg build and tetseg tetrahedralize: seconds before the job is refused (0: no limit).
inline constexpr OptionRange kTimeLimit{"time_limit", 0.0, 1e7};

}  // namespace option_ranges

/// Whether `value` lies in `range` (NaN never does).
bool in_range(const OptionRange& range, double value);

/// Throws std::invalid_argument("<name> must be in [min, max], got <value>", or "<name> must
/// be positive, got <value>" for (0, inf]) unless in_range(range, value).
void check_option(const OptionRange& range, double value);

}  // namespace tetseg::preprocess
