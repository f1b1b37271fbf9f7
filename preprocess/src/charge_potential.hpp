#pragma once
// Internal: closed-form potential of a uniformly charged flat triangle (Wilton et al. 1984,
// Graglia 1993), the collocation self term, and the per-triangle geometry the charge solvers
// share. Not a public header.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"

/// Compiles a function twice, for AVX2 and for the baseline, and picks one at load time
/// (GCC's target_clones): for the charge kernels written as plain loops or vector extensions.
#if defined(__x86_64__) && defined(__GNUC__)
#define TETSEG_CHARGE_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define TETSEG_CHARGE_CLONES
#endif

namespace tetseg::preprocess::charge_detail {

/// Integral over triangle (a, b, c) of 1 / |r - y| dS_y (unit surface density; length units of
/// the input). Finite everywhere, including r on the triangle or on an edge line. Orientation
/// of the triangle does not matter. A zero-area triangle gives 0.
double triangle_potential(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& r);

/// triangle_potential with the triangle's geometry (unit normal, edge directions) computed
/// once, for many evaluation points: the near-field assembly evaluates each triangle ~50
/// times. Same formula (and results to rounding) as triangle_potential, with one atan2 per
/// edge instead of two. Immutable after construction; safe to share between threads.
class TriangleKernel {
 public:
  TriangleKernel() = default;
  TriangleKernel(const Vec3& a, const Vec3& b, const Vec3& c);
  /// Integral over the triangle of 1 / |r - y| dS_y; 0 for a zero-area triangle.
  double potential(const Vec3& r) const;

 private:
  struct Edge {
    Vec3 start{}, dir{}, out{};  ///< first corner, unit direction, dir x normal
    double length = 0.0;
  };
  Vec3 m_corner{}, m_normal{};
  Edge m_edge[3];
  bool m_valid = false;
};

/// The same integral evaluated at the triangle's own centroid (the collocation diagonal),
/// sum_i t_i [asinh(l_i+ / t_i) - asinh(l_i- / t_i)].
double triangle_self_potential(const Vec3& a, const Vec3& b, const Vec3& c);

/// Per-triangle data of a surface, in structure-of-arrays form.
struct PanelSet {
  std::vector<std::array<Vec3, 3>> corners;
  std::vector<Vec3> centroid;
  std::vector<double> area;
  std::vector<double> diameter;  ///< longest edge
  std::size_t size() const { return area.size(); }
};

/// Builds the panels and rejects bad input with InputError(file, ...): no triangles, an index
/// out of range, a non-finite coordinate, or a degenerate triangle (area below 1e-12 times the
/// squared longest edge of the whole mesh, or of the triangle's own squared longest edge
/// times 1e-10: needles are as bad as zero area).
PanelSet make_panels(const std::vector<Vec3>& points, const std::vector<Tri>& triangles,
                     const std::string& file);

/// Far-field rule: entry (i, j) uses the point-charge form A_j / |c_i - c_j| when
/// |c_i - c_j| > kNearFactor * diameter_j, the six-point quadrature below when
/// |c_i - c_j| > kQuadratureFactor * diameter_j, and the closed form otherwise.
constexpr double kNearFactor = 2.0;
/// Between 1 and 2 diameters the six-point rule is within 2.2e-4 of the closed form (max over
/// the 5k ellipsoid's pairs; the point charge just beyond 2 diameters is within 1.9e-2) at a
/// quarter of its cost (docs/charge.md).
constexpr double kQuadratureFactor = 1.0;

/// Integral over triangle (a, b, c) of area `area` of 1 / |r - y| dS_y by the symmetric
/// six-point degree-4 rule (Strang & Fix / Dunavant); for points at least about one triangle
/// size away (kQuadratureFactor).
double triangle_potential_quadrature(const std::array<Vec3, 3>& corners, double area,
                                     const Vec3& r);

/// The collocation matrix entry M_ij (potential at centroid i of unit density on triangle j).
double matrix_entry(const PanelSet& panels, std::size_t i, std::size_t j);

}  // namespace tetseg::preprocess::charge_detail
