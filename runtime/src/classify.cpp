#include "tetseg/runtime/classify.hpp"

#include "orientation_terms.hpp"

namespace tetseg {
BernsteinCubic orientation_bernstein(const double* o0, const double* a0, const double* b0,
                                     const double* c0, const double* o1, const double* a1,
                                     const double* b1, const double* c1) noexcept {
  using namespace orientation_detail;
  const V3 v0 = sub(b0, o0), w0 = sub(c0, o0), v1 = sub(b1, o1), w1 = sub(c1, o1);
  return bernstein(sub(a0, o0), sub(a1, o1), minors(v0, w0), minors(v1, w0), minors(v0, w1),
                   minors(v1, w1));
}

Orientation sign_of(const BernsteinCubic& c) noexcept {
  // Written so that NaN coefficients or bounds fail every comparison: uncertain.
  bool positive = true, negative = true;
  for (int i = 0; i < 4; ++i) {
    positive = positive && (c.k[i] > c.err[i]);
    negative = negative && (c.k[i] < -c.err[i]);
  }
  if (positive) return Orientation::kPositive;
  if (negative) return Orientation::kNegative;
  return Orientation::kUncertain;
}

Orientation classify_orientation(const double* o0, const double* a0, const double* b0,
                                 const double* c0, const double* o1, const double* a1,
                                 const double* b1, const double* c1) noexcept {
  return sign_of(orientation_bernstein(o0, a0, b0, c0, o1, a1, b1, c1));
}

}  // namespace tetseg
