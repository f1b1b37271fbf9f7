#pragma once
// Contact certificates for the elementary CCD tests when the four points of a query lie in one
// axis-aligned plane at an instant where their positions are exact doubles (the end of the
// step): all four share one coordinate exactly. This is the common degenerate contact of
// simulator steps (a body flattened onto the ground). The contact there is then a 2D question
// on the other two coordinates, decided with a filtered orientation predicate whose sign is
// certain (the classic static error bound of Shewchuk, "Adaptive Precision Floating-Point
// Arithmetic and Fast Robust Geometric Predicates", 1997). Undecided means "no certificate":
// the caller falls back to the interval bisection. Internal to the runtime.

#include <array>
#include <cmath>

namespace tetseg::ccd_detail {

using Point3 = std::array<double, 3>;

/// Relative error bound of the floating-point orientation determinant below, against the sum
/// of the magnitudes of its two products: (3 + 16 eps) eps with eps = 2^-53 (Shewchuk's
/// ccwerrboundA). tests/runtime/ccd_plane_test.cpp shows that half of it gives wrong signs.
constexpr double kOrient2dErrorBound = (3.0 + 16.0 * 0x1p-53) * 0x1p-53;
/// Absolute margin: the relative bound does not cover products that underflow.
constexpr double kOrient2dUnderflowMargin = 0x1p-960;

/// Certain sign (+1, -1) of the 2D orientation of (a, b, c) on the axes (i, j), i.e. of
/// (a - c) x (b - c); 0 when the filter cannot certify it (collinear or nearly so).
/// `bound_scale` scales the error bound (tests only; 1 in production).
inline int orient2d_sign(const Point3& a, const Point3& b, const Point3& c, int i, int j,
                         double bound_scale = 1.0) noexcept {
  const double acx = a[i] - c[i];
  const double bcx = b[i] - c[i];
  const double acy = a[j] - c[j];
  const double bcy = b[j] - c[j];
  const double left = acx * bcy;
  const double right = acy * bcx;
  const double det = left - right;
  const double bound = bound_scale * (kOrient2dErrorBound * (std::fabs(left) + std::fabs(right)) +
                                      kOrient2dUnderflowMargin);
  if (det > bound) return 1;
  if (-det > bound) return -1;
  return 0;  // also NaN
}

/// True when the four points share their coordinate on `axis` exactly.
inline bool share_coordinate(const Point3* const points[4], int axis) noexcept {
  const double v = (*points[0])[axis];
  return (*points[1])[axis] == v && (*points[2])[axis] == v && (*points[3])[axis] == v;
}

/// The first axis along which the four points share their coordinate exactly, or -1.
inline int shared_axis(const Point3* const points[4]) noexcept {
  for (int axis = 0; axis < 3; ++axis)
    if (share_coordinate(points, axis)) return axis;
  return -1;
}

/// The axis orthogonal to a plane in which four points moving linearly from x0 to x1 stay for
/// the whole step (they share that coordinate at both ends, hence at every time), or -1.
inline int axis_plane(const Point3* const x0[4], const Point3* const x1[4]) noexcept {
  for (int axis = 0; axis < 3; ++axis)
    if (share_coordinate(x0, axis) && share_coordinate(x1, axis)) return axis;
  return -1;
}

/// Contact of four points in one axis-aligned plane, as far as the filtered orientations can
/// tell: certainly touching, certainly apart, or unknown (near a boundary or degenerate).
enum class PlaneContact { kApart, kTouching, kUnknown };

/// Vertex p and triangle (a, b, c), all in the plane orthogonal to `axis`: touching when p is
/// certainly strictly inside (three orientations of one sign); apart when the triangle's
/// orientation is certain and p is certainly strictly outside one of its edges.
inline PlaneContact vertex_triangle_2d(const Point3& p, const Point3& a, const Point3& b,
                                       const Point3& c, int axis) noexcept {
  const int i = (axis + 1) % 3;
  const int j = (axis + 2) % 3;
  const int ab = orient2d_sign(a, b, p, i, j);
  const int bc = orient2d_sign(b, c, p, i, j);
  const int ca = orient2d_sign(c, a, p, i, j);
  if (ab != 0 && bc == ab && ca == ab) return PlaneContact::kTouching;
  const int triangle = orient2d_sign(a, b, c, i, j);
  if (triangle != 0 && (ab == -triangle || bc == -triangle || ca == -triangle))
    return PlaneContact::kApart;
  return PlaneContact::kUnknown;
}

/// Segments ab and cd, all in the plane orthogonal to `axis`: touching when they certainly
/// cross at a point interior to both; apart when one segment certainly lies strictly on one
/// side of the other's line.
inline PlaneContact segments_2d(const Point3& a, const Point3& b, const Point3& c, const Point3& d,
                                int axis) noexcept {
  const int i = (axis + 1) % 3;
  const int j = (axis + 2) % 3;
  const int c_side = orient2d_sign(a, b, c, i, j);
  const int d_side = orient2d_sign(a, b, d, i, j);
  if (c_side != 0 && d_side == c_side) return PlaneContact::kApart;
  const int a_side = orient2d_sign(c, d, a, i, j);
  const int b_side = orient2d_sign(c, d, b, i, j);
  if (a_side != 0 && b_side == a_side) return PlaneContact::kApart;
  if (c_side != 0 && d_side == -c_side && a_side != 0 && b_side == -a_side)
    return PlaneContact::kTouching;
  return PlaneContact::kUnknown;
}

}  // namespace tetseg::ccd_detail
