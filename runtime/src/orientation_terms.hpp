#pragma once
// The arithmetic of orientation_bernstein (classify.cpp), split so that the 2x2 minors of the
// last two columns can be computed once and reused for many first columns (the triangle-pair
// plane filter tests up to three points against one face). Not installed.
//
// det(u, v, w) is expanded along u: det = u.x m0 - u.y m1 + u.z m2 with the minors m of (v, w),
// and its permanent |u.x| s0 + |u.y| s1 + |u.z| s2 with s the sums of absolute minor products.
// Every caller evaluates the same operations in the same order, so a cached-minor result is
// bitwise the one orientation_bernstein computes for the same points.

#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "lanes2.hpp"
#include "tetseg/runtime/classify.hpp"

namespace tetseg {
namespace orientation_detail {

// Forward error of a 3x3 determinant of rounded differences, relative to its permanent.
// Shewchuk's orient3d bound is (7 + 56 eps) eps; 16 eps also absorbs the two additions of
// the trilinear sums for k1 and k2 and leaves margin.
constexpr double kEps = 1.1102230246251565e-16;  // 2^-53
constexpr double kRelErr = 16.0 * kEps;
// Absolute slack for gradual underflow in the products (a few subnormal ulps per operation).
constexpr double kAbsErr = 1e-300;

template <class T>
struct Vec3T {
  T x, y, z;
};
using V3 = Vec3T<double>;

/// |x| (lanes2.hpp: the same for two lanes).
inline double magnitude(double x) noexcept {
  return std::fabs(x);
}
#if defined(TETSEG_HAVE_LANES2)
using tetseg::Lanes2;
using tetseg::magnitude;
#endif

template <class T>
inline Vec3T<T> sub(const Vec3T<T>& a, const Vec3T<T>& b) noexcept {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline V3 sub(const double* a, const double* b) noexcept {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

/// The 2x2 minors of columns (v, w) and the sums of their absolute products.
template <class T>
struct MinorsT {
  T m0, m1, m2;
  T s0, s1, s2;
};
using Minors = MinorsT<double>;

template <class T>
inline MinorsT<T> minors(const Vec3T<T>& v, const Vec3T<T>& w) noexcept {
  return {v.y * w.z - v.z * w.y,
          v.x * w.z - v.z * w.x,
          v.x * w.y - v.y * w.x,
          magnitude(v.y * w.z) + magnitude(v.z * w.y),
          magnitude(v.x * w.z) + magnitude(v.z * w.x),
          magnitude(v.x * w.y) + magnitude(v.y * w.x)};
}

/// det(u, v, w) and its permanent from u and the minors of (v, w).
template <class T>
inline void det_perm(const Vec3T<T>& u, const MinorsT<T>& m, T& det, T& perm) noexcept {
  det = u.x * m.m0 - u.y * m.m1 + u.z * m.m2;
  perm = magnitude(u.x) * m.s0 + magnitude(u.y) * m.s1 + magnitude(u.z) * m.s2;
}

/// Bernstein coefficients and their error bounds, in T (BernsteinCubic for doubles).
template <class T>
struct CubicTerms {
  T k[4];
  T err[4];
};

/// Bernstein coefficients of det(u(t), v(t), w(t)) for linear u, v, w, from u0, u1 and the
/// minors m_jk = minors(v_j, w_k) (j, k = start 0 / end 1 of the step), into r (k and err of
/// T: BernsteinCubic for doubles, CubicTerms<Lanes2> for two cubics at once).
template <class T, class Out>
inline void bernstein_into(const Vec3T<T>& u0, const Vec3T<T>& u1, const MinorsT<T>& m00,
                           const MinorsT<T>& m10, const MinorsT<T>& m01, const MinorsT<T>& m11,
                           Out& r) noexcept {
  T d[3], p[3];
  det_perm(u0, m00, r.k[0], p[0]);
  r.err[0] = kRelErr * p[0] + kAbsErr;
  det_perm(u1, m00, d[0], p[0]);
  det_perm(u0, m10, d[1], p[1]);
  det_perm(u0, m01, d[2], p[2]);
  r.k[1] = d[0] + d[1] + d[2];
  r.err[1] = kRelErr * (p[0] + p[1] + p[2]) + kAbsErr;
  det_perm(u0, m11, d[0], p[0]);
  det_perm(u1, m01, d[1], p[1]);
  det_perm(u1, m10, d[2], p[2]);
  r.k[2] = d[0] + d[1] + d[2];
  r.err[2] = kRelErr * (p[0] + p[1] + p[2]) + kAbsErr;
  det_perm(u1, m11, r.k[3], p[0]);
  r.err[3] = kRelErr * p[0] + kAbsErr;
}

inline BernsteinCubic bernstein(const V3& u0, const V3& u1, const Minors& m00, const Minors& m10,
                                const Minors& m01, const Minors& m11) noexcept {
  BernsteinCubic r;
  bernstein_into(u0, u1, m00, m10, m01, m11, r);
  return r;
}

/// Semi-static error bounds (Shewchuk's filters, per box): when every coordinate difference of
/// the points of a cubic is at most `d[k]` in absolute value on axis k (all points of the step
/// lie in a box of extents d), `err0` bounds the error terms `bernstein` computes for k0 and
/// k3, `err1` those of k1 and k2. The bound evaluates the same rounded operations on the
/// extents instead of the differences' absolute values; rounding is monotone, so each is at
/// least the computed bound it replaces (not a new error analysis).
struct StaticErr {
  double err0, err1;
  static StaticErr of(const double d[3]) noexcept {
    // det_perm(d, minors(d, d)) without the minors: |d.y d.z| + |d.z d.y| = 2 |d.y d.z| (the
    // two rounded products are equal, |fl(x y)| = fl(|x| |y|)), the same value.
    const double ax = magnitude(d[0]), ay = magnitude(d[1]), az = magnitude(d[2]);
    const double yz = ay * az, xz = ax * az, xy = ax * ay;
    const double p = ax * (yz + yz) + ay * (xz + xz) + az * (xy + xy);
    return {kRelErr * p + kAbsErr, kRelErr * (p + p + p) + kAbsErr};
  }
};

/// Bernstein coefficients only (no error terms), the same operations as `bernstein`.
/// Generic in the number type T (double, or a vector of doubles computing lane by lane the
/// same operations): V has members x, y, z and M members m0, m1, m2 of type T.
template <class V, class M, class T>
inline void bernstein_k(const V& u0, const V& u1, const M& m00, const M& m10, const M& m01,
                        const M& m11, T k[4]) noexcept {
  auto det = [](const V& u, const M& m) { return u.x * m.m0 - u.y * m.m1 + u.z * m.m2; };
  k[0] = det(u0, m00);
  k[1] = det(u1, m00) + det(u0, m10) + det(u0, m01);
  k[2] = det(u0, m11) + det(u1, m01) + det(u1, m10);
  k[3] = det(u1, m11);
}

template <class T>
struct MinorTerms {
  T m0, m1, m2;
};

/// The Bernstein coefficients of det[a - o, b - o, c - o] over the step, for the points
/// p0 = {o, a, b, c} at the start and p1 at the end, without error terms: the operations of
/// `bernstein_k` over the `minors` m terms, in T (double, or a vector of doubles).
template <class T>
inline void orientation_k(const Vec3T<T> p0[4], const Vec3T<T> p1[4], T k[4]) noexcept {
  auto d = [](const Vec3T<T>& a, const Vec3T<T>& b) {
    return Vec3T<T>{a.x - b.x, a.y - b.y, a.z - b.z};
  };
  auto m = [](const Vec3T<T>& v, const Vec3T<T>& w) {
    return MinorTerms<T>{v.y * w.z - v.z * w.y, v.x * w.z - v.z * w.x, v.x * w.y - v.y * w.x};
  };
  const Vec3T<T> v0 = d(p0[2], p0[0]), w0 = d(p0[3], p0[0]), v1 = d(p1[2], p1[0]),
                 w1 = d(p1[3], p1[0]);
  bernstein_k(d(p0[1], p0[0]), d(p1[1], p1[0]), m(v0, w0), m(v1, w0), m(v0, w1), m(v1, w1), k);
}

/// The sign `sign(bernstein(...))` would give, decided from the coefficients and a static bound
/// when it can be: a definite sign when all four clear `e`, uncertain when two clear it with
/// opposite signs (then they clear the smaller computed bounds too). kUncertain with
/// `decided = false` otherwise: the caller computes the full cubic.
inline Orientation static_sign(const double k[4], const StaticErr& e, bool& decided) noexcept {
  // Bit i of `above` (`below`): k[i] > err[i] (k[i] < -err[i]); NaN sets neither.
#if defined(__SSE2__)
  // The same eight comparisons, two per packed instruction.
  const __m128d err01 = _mm_set_pd(e.err1, e.err0), err23 = _mm_set_pd(e.err0, e.err1);
  const __m128d k01 = _mm_loadu_pd(k), k23 = _mm_loadu_pd(k + 2);
  const __m128d zero = _mm_setzero_pd();
  const int above =
      _mm_movemask_pd(_mm_cmpgt_pd(k01, err01)) | (_mm_movemask_pd(_mm_cmpgt_pd(k23, err23)) << 2);
  const int below = _mm_movemask_pd(_mm_cmplt_pd(k01, _mm_sub_pd(zero, err01))) |
                    (_mm_movemask_pd(_mm_cmplt_pd(k23, _mm_sub_pd(zero, err23))) << 2);
#else
  const double err[4] = {e.err0, e.err1, e.err1, e.err0};
  int above = 0, below = 0;
  for (int i = 0; i < 4; ++i) {
    above |= int(k[i] > err[i]) << i;
    below |= int(k[i] < -err[i]) << i;
  }
#endif
  decided = above == 15 || below == 15 || (above != 0 && below != 0);
  return above == 15   ? Orientation::kPositive
         : below == 15 ? Orientation::kNegative
                       : Orientation::kUncertain;
}

#if defined(TETSEG_HAVE_LANES2)
/// A point (or difference) at the start and the end of the step: lane 0 / lane 1.
using Ends = Vec3T<Lanes2>;
inline Ends ends(const double* p0, const double* p1) noexcept {
  return {Lanes2{p0[0], p1[0]}, Lanes2{p0[1], p1[1]}, Lanes2{p0[2], p1[2]}};
}
inline Lanes2 swapped(Lanes2 x) noexcept {
  return Lanes2{x[1], x[0]};
}
inline Ends swapped(const Ends& p) noexcept {
  return {swapped(p.x), swapped(p.y), swapped(p.z)};
}
inline MinorTerms<Lanes2> swapped(const MinorTerms<Lanes2>& m) noexcept {
  return {swapped(m.m0), swapped(m.m1), swapped(m.m2)};
}
/// The m terms of `minors`, lane by lane.
inline MinorTerms<Lanes2> minor_terms(const Ends& v, const Ends& w) noexcept {
  return {v.y * w.z - v.z * w.y, v.x * w.z - v.z * w.x, v.x * w.y - v.y * w.x};
}

/// bernstein_k on two lanes: from u = (u0, u1), ma = (m00, m11), mb = (m10, m01) and
/// mc = (m01, m10) (lanes of minor_terms(v, w), minor_terms(swapped(v), w) and its swap: the
/// same products), k03 = (k0, k3) and k12 = (k1, k2). Lane 0 performs bernstein_k's operations
/// for k0 and k1 in their order, lane 1 those of k3 and k2 (the mirror image, the ends
/// swapped), so every coefficient is bitwise the scalar one.
inline void bernstein_k2(const Ends& u, const MinorTerms<Lanes2>& ma, const MinorTerms<Lanes2>& mb,
                         const MinorTerms<Lanes2>& mc, Lanes2& k03, Lanes2& k12) noexcept {
  auto det = [](const Ends& w, const MinorTerms<Lanes2>& m) {
    return w.x * m.m0 - w.y * m.m1 + w.z * m.m2;
  };
  k03 = det(u, ma);
  k12 = det(swapped(u), ma) + det(u, mb) + det(u, mc);
}

/// The Bernstein coefficients of det[a - o, b - o, c - o] over the step (orientation_k's),
/// as k03 = (k0, k3) and k12 = (k1, k2): bitwise orientation_k's values.
inline void orientation_k2(const double* o0, const double* a0, const double* b0, const double* c0,
                           const double* o1, const double* a1, const double* b1, const double* c1,
                           Lanes2& k03, Lanes2& k12) noexcept {
  const Ends o = ends(o0, o1);
  const Ends v = sub(ends(b0, b1), o), w = sub(ends(c0, c1), o);
  const MinorTerms<Lanes2> mb = minor_terms(swapped(v), w);
  bernstein_k2(sub(ends(a0, a1), o), minor_terms(v, w), mb, swapped(mb), k03, k12);
}

/// static_sign of the coefficients {k03[0], k12[0], k12[1], k03[1]}: the same eight
/// comparisons (NaN failing each), on the lanes.
inline Orientation static_sign(Lanes2 k03, Lanes2 k12, const StaticErr& e, bool& decided) noexcept {
  const Lanes2 e0{e.err0, e.err0}, e1{e.err1, e.err1};
  const int above = sign_bits(k03 > e0) | (sign_bits(k12 > e1) << 2);
  const int below = sign_bits(k03 < -e0) | (sign_bits(k12 < -e1) << 2);
  decided = above == 15 || below == 15 || (above != 0 && below != 0);
  return above == 15   ? Orientation::kPositive
         : below == 15 ? Orientation::kNegative
                       : Orientation::kUncertain;
}
#endif

/// The sign of a cubic proven by its four Bernstein coefficients (sign_of in classify.cpp).
inline Orientation sign(const BernsteinCubic& c) noexcept {
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

/// orientation_bernstein, inline.
inline BernsteinCubic cubic(const double* o0, const double* a0, const double* b0, const double* c0,
                            const double* o1, const double* a1, const double* b1,
                            const double* c1) noexcept {
  const V3 v0 = sub(b0, o0), w0 = sub(c0, o0), v1 = sub(b1, o1), w1 = sub(c1, o1);
  return bernstein(sub(a0, o0), sub(a1, o1), minors(v0, w0), minors(v1, w0), minors(v0, w1),
                   minors(v1, w1));
}

/// `cubic` of two sets of points at once: out[i] is bitwise cubic(p[i][0], ..., p[i][7]) (the
/// points o0, a0, b0, c0, o1, a1, b1, c1), both computed lane by lane where the compiler has
/// vector extensions (SSE2 on x86-64: two doubles per instruction).
inline void cubic2(const double* const (&p)[2][8], BernsteinCubic (&out)[2]) noexcept {
#if defined(TETSEG_HAVE_LANES2)
  Vec3T<Lanes2> q[8];
  for (int j = 0; j < 8; ++j)
    q[j] = {Lanes2{p[0][j][0], p[1][j][0]}, Lanes2{p[0][j][1], p[1][j][1]},
            Lanes2{p[0][j][2], p[1][j][2]}};
  const Vec3T<Lanes2> v0 = sub(q[2], q[0]), w0 = sub(q[3], q[0]), v1 = sub(q[6], q[4]),
                      w1 = sub(q[7], q[4]);
  CubicTerms<Lanes2> r;
  bernstein_into(sub(q[1], q[0]), sub(q[5], q[4]), minors(v0, w0), minors(v1, w0), minors(v0, w1),
                 minors(v1, w1), r);
  for (int i = 0; i < 2; ++i)
    for (int k = 0; k < 4; ++k) {
      out[i].k[k] = r.k[k][i];
      out[i].err[k] = r.err[k][i];
    }
#else
  for (int i = 0; i < 2; ++i)
    out[i] = cubic(p[i][0], p[i][1], p[i][2], p[i][3], p[i][4], p[i][5], p[i][6], p[i][7]);
#endif
}

}  // namespace orientation_detail

/// classify_orientation, inline (the runtime's hot loops: classification, feature filters).
inline Orientation orientation_of(const double* o0, const double* a0, const double* b0,
                                  const double* c0, const double* o1, const double* a1,
                                  const double* b1, const double* c1) noexcept {
  using namespace orientation_detail;
  return sign(cubic(o0, a0, b0, c0, o1, a1, b1, c1));
}

/// `orientation_of` for points whose coordinate differences are bounded by the extents that
/// gave `e` (StaticErr::of): bitwise the same answer, without the error terms when the static
/// bound decides.
inline Orientation orientation_of(const double* o0, const double* a0, const double* b0,
                                  const double* c0, const double* o1, const double* a1,
                                  const double* b1, const double* c1,
                                  const orientation_detail::StaticErr& e) noexcept {
  using namespace orientation_detail;
  bool decided;
#if defined(TETSEG_HAVE_LANES2)
  Lanes2 k03, k12;
  orientation_k2(o0, a0, b0, c0, o1, a1, b1, c1, k03, k12);
  const Orientation o = static_sign(k03, k12, e, decided);
#else
  auto p = [](const double* q) { return Vec3T<double>{q[0], q[1], q[2]}; };
  const Vec3T<double> p0[4] = {p(o0), p(a0), p(b0), p(c0)}, p1[4] = {p(o1), p(a1), p(b1), p(c1)};
  double k[4];
  orientation_k(p0, p1, k);
  const Orientation o = static_sign(k, e, decided);
#endif
  return decided ? o : sign(cubic(o0, a0, b0, c0, o1, a1, b1, c1));
}

/// The four minor sets of a moving triangle's edge vectors b - a, c - a (start, end and
/// crossed): everything of its plane that does not depend on the point tested. A collider
/// computes them once per triangle and step (refit) and shares them read-only.
struct FacePlaneMinors {
  orientation_detail::Minors m00, m10, m01, m11;
  static FacePlaneMinors of(const double* a0, const double* b0, const double* c0, const double* a1,
                            const double* b1, const double* c1) noexcept {
    using namespace orientation_detail;
    const V3 v0 = sub(b0, a0), w0 = sub(c0, a0), v1 = sub(b1, a1), w1 = sub(c1, a1);
    return {minors(v0, w0), minors(v1, w0), minors(v0, w1), minors(v1, w1)};
  }
  /// Bitwise `classify_orientation(a0, p0, b0, c0, a1, p1, b1, c1)` for the triangle (a, b, c)
  /// these minors were computed from: the sign of det[b - a, c - a, p - a] over the step.
  Orientation side(const double* a0, const double* a1, const double* p0,
                   const double* p1) const noexcept {
    using namespace orientation_detail;
    return sign(bernstein(sub(p0, a0), sub(p1, a1), m00, m10, m01, m11));
  }
};

/// The plane of a moving triangle (a, b, c) prepared for the static-bound side of many points:
/// its node a at both ends and the m terms of its minors (FacePlaneMinors without the sums of
/// absolute products), laid out for `static_side`. A collider's workers cache one per triangle
/// and step (the plane filters).
struct FacePlaneStatic {
#if defined(TETSEG_HAVE_LANES2)
  // Two lanes, each lane bitwise the scalar operations of FacePlaneMinors::of: lane 0 / 1 of
  // `a` hold a0 / a1; of `ma` m00 / m11, of `mb` m10 / m01, of `mc` m01 / m10 (mb's lanes
  // swapped: the same products; bernstein_k2's).
  orientation_detail::Ends a;
  orientation_detail::MinorTerms<orientation_detail::Lanes2> ma, mb, mc;
#else
  double a0[3], a1[3];
  orientation_detail::Minors m00, m10, m01, m11;
#endif
  static FacePlaneStatic of(const double* a0, const double* b0, const double* c0, const double* a1,
                            const double* b1, const double* c1) noexcept {
    using namespace orientation_detail;
    FacePlaneStatic f;
#if defined(TETSEG_HAVE_LANES2)
    f.a = ends(a0, a1);
    const Ends v = sub(ends(b0, b1), f.a), w = sub(ends(c0, c1), f.a);  // (v0, v1), (w0, w1)
    f.ma = minor_terms(v, w);                                           // (m00, m11)
    f.mb = minor_terms(swapped(v), w);                                  // (m10, m01)
    f.mc = swapped(f.mb);
#else
    const FacePlaneMinors full = FacePlaneMinors::of(a0, b0, c0, a1, b1, c1);
    for (int k = 0; k < 3; ++k) {
      f.a0[k] = a0[k];
      f.a1[k] = a1[k];
    }
    f.m00 = full.m00;
    f.m10 = full.m10;
    f.m01 = full.m01;
    f.m11 = full.m11;
#endif
    return f;
  }
#if defined(TETSEG_HAVE_LANES2)
  /// The cubic's Bernstein coefficients for point p (orientation_k2's layout: k03 = (k0, k3),
  /// k12 = (k1, k2)), bitwise those of FacePlaneMinors::side's cubic.
  void coefficients(const double* p0, const double* p1, orientation_detail::Lanes2& k03,
                    orientation_detail::Lanes2& k12) const noexcept {
    using namespace orientation_detail;
    bernstein_k2(sub(ends(p0, p1), a), ma, mb, mc, k03, k12);
  }
#endif
  /// FacePlaneMinors::side(a0, a1, p0, p1) of the same triangle when the static bound `e`
  /// decides it (`decided`; e = StaticErr::of the extents of a box holding the triangle and the
  /// point at both ends of the step), found from the coefficients without their error terms;
  /// else kUncertain with `decided = false`: the caller evaluates the full cubic.
  Orientation static_side(const double* p0, const double* p1,
                          const orientation_detail::StaticErr& e, bool& decided) const noexcept {
    using namespace orientation_detail;
#if defined(TETSEG_HAVE_LANES2)
    Lanes2 k03, k12;
    coefficients(p0, p1, k03, k12);
    // The coefficients gathered for the array form: in the plane filters' loops over points
    // this measured fewer instructions than the lanes' form (its bounds are set up once).
    const double k[4] = {k03[0], k12[0], k12[1], k03[1]};
    return static_sign(k, e, decided);
#else
    double k[4];
    bernstein_k(sub(p0, a0), sub(p1, a1), m00, m10, m01, m11, k);
    return static_sign(k, e, decided);
#endif
  }
};

/// The plane of a moving triangle (a, b, c) over a step, prepared for the sides of many points:
/// `side(p0, p1)` is bitwise `classify_orientation(a0, p0, b0, c0, a1, p1, b1, c1)`, the sign
/// of det[p - a, b - a, c - a] = det[b - a, c - a, p - a] over the step.
class FacePlane {
 public:
  FacePlane(const double* a0, const double* b0, const double* c0, const double* a1,
            const double* b1, const double* c1) noexcept
      : a0_(a0), a1_(a1), minors_(FacePlaneMinors::of(a0, b0, c0, a1, b1, c1)) {}
  Orientation side(const double* p0, const double* p1) const noexcept {
    return minors_.side(a0_, a1_, p0, p1);
  }

 private:
  const double* a0_;
  const double* a1_;
  FacePlaneMinors minors_;
};

}  // namespace tetseg
