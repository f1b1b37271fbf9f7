#include "tetseg/runtime/classify.hpp"

#include "orientation_terms.hpp"

namespace tetseg {
BernsteinCubic orientation_bernstein(const double* o0, const double* a0, const double* b0,
                                     const double* c0, const double* o1, const double* a1,
                                     const double* b1, const double* c1) noexcept {
  return orientation_detail::cubic(o0, a0, b0, c0, o1, a1, b1, c1);
}

Orientation sign_of(const BernsteinCubic& c) noexcept {
  return orientation_detail::sign(c);
}

Orientation classify_orientation(const double* o0, const double* a0, const double* b0,
                                 const double* c0, const double* o1, const double* a1,
                                 const double* b1, const double* c1) noexcept {
  return orientation_of(o0, a0, b0, c0, o1, a1, b1, c1);
}

}  // namespace tetseg
