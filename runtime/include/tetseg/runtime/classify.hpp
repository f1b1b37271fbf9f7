#pragma once
/// \file
/// Sign of an orientation cubic over a step, from its Bernstein coefficients with forward
/// floating-point error bounds. Used to classify surface triangles against a cluster's
/// detector node (radial-view culling) and as the coplanarity filter of feature pairs.
/// Pure functions: thread-safe, allocation-free, never throw.

#include <cstdint>

namespace tetseg {

/// Sign of `f(t) = det[a(t)-o(t), b(t)-o(t), c(t)-o(t)]` for every t in [0,1], where every
/// point moves linearly `x(t) = (1-t) x0 + t x1`.
enum class Orientation : std::uint8_t {
  kPositive = 0,   ///< f(t) > 0 on the whole step, proven in floating point
  kNegative = 1,   ///< f(t) < 0 on the whole step, proven in floating point
  kUncertain = 2,  ///< not proven either way (may change sign, vanish, or rounding too large)
};

/// The cubic's four Bernstein coefficients on [0,1] (k0 = f(0), k3 = f(1)) each scaled by 3
/// for k1, k2 (no division), with forward error bounds `err[i] >= |computed - exact|`.
struct BernsteinCubic {
  double k[4] = {0, 0, 0, 0};
  double err[4] = {0, 0, 0, 0};
};

/// Bernstein coefficients of `det[a-o, b-o, c-o]` over the step. Inputs are 3 doubles each;
/// suffix 0 = start of step, 1 = end. Non-finite or overflowing inputs give NaN/inf
/// coefficients, which `sign_of` classifies as uncertain.
BernsteinCubic orientation_bernstein(const double* o0, const double* a0, const double* b0,
                                     const double* c0, const double* o1, const double* a1,
                                     const double* b1, const double* c1) noexcept;

/// Positive when every coefficient exceeds its error bound, negative when every one is below
/// minus its bound, otherwise uncertain. Never classifies from k0 and k3 alone.
Orientation sign_of(const BernsteinCubic& cubic) noexcept;

/// `sign_of(orientation_bernstein(...))`.
Orientation classify_orientation(const double* o0, const double* a0, const double* b0,
                                 const double* c0, const double* o1, const double* a1,
                                 const double* b1, const double* c1) noexcept;

}  // namespace tetseg
