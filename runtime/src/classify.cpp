#include "tetseg/runtime/classify.hpp"

#include <cmath>

namespace tetseg {
namespace {

// Forward error of a 3x3 determinant of rounded differences, relative to its permanent.
// Shewchuk's orient3d bound is (7 + 56 eps) eps; 16 eps also absorbs the two additions of
// the trilinear sums for k1 and k2 and leaves margin.
constexpr double kEps = 1.1102230246251565e-16;  // 2^-53
constexpr double kRelErr = 16.0 * kEps;
// Absolute slack for gradual underflow in the products (a few subnormal ulps per operation).
constexpr double kAbsErr = 1e-300;

struct V3 {
  double x, y, z;
};

inline V3 sub(const double* a, const double* b) noexcept {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

inline void det_perm(const V3& u, const V3& v, const V3& w, double& det, double& perm) noexcept {
  const double m0 = v.y * w.z - v.z * w.y;
  const double m1 = v.x * w.z - v.z * w.x;
  const double m2 = v.x * w.y - v.y * w.x;
  det = u.x * m0 - u.y * m1 + u.z * m2;
  perm = std::fabs(u.x) * (std::fabs(v.y * w.z) + std::fabs(v.z * w.y)) +
         std::fabs(u.y) * (std::fabs(v.x * w.z) + std::fabs(v.z * w.x)) +
         std::fabs(u.z) * (std::fabs(v.x * w.y) + std::fabs(v.y * w.x));
}

}  // namespace

BernsteinCubic orientation_bernstein(const double* o0, const double* a0, const double* b0,
                                     const double* c0, const double* o1, const double* a1,
                                     const double* b1, const double* c1) noexcept {
  const V3 u0 = sub(a0, o0), v0 = sub(b0, o0), w0 = sub(c0, o0);
  const V3 u1 = sub(a1, o1), v1 = sub(b1, o1), w1 = sub(c1, o1);
  BernsteinCubic r;
  double d[3], p[3];
  det_perm(u0, v0, w0, r.k[0], p[0]);
  r.err[0] = kRelErr * p[0] + kAbsErr;
  det_perm(u1, v0, w0, d[0], p[0]);
  det_perm(u0, v1, w0, d[1], p[1]);
  det_perm(u0, v0, w1, d[2], p[2]);
  r.k[1] = d[0] + d[1] + d[2];
  r.err[1] = kRelErr * (p[0] + p[1] + p[2]) + kAbsErr;
  det_perm(u0, v1, w1, d[0], p[0]);
  det_perm(u1, v0, w1, d[1], p[1]);
  det_perm(u1, v1, w0, d[2], p[2]);
  r.k[2] = d[0] + d[1] + d[2];
  r.err[2] = kRelErr * (p[0] + p[1] + p[2]) + kAbsErr;
  det_perm(u1, v1, w1, r.k[3], p[0]);
  r.err[3] = kRelErr * p[0] + kAbsErr;
  return r;
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
