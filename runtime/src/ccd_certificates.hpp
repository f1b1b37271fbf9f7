#pragma once
// Positive certificates and jumps of the elementary CCD tests (runtime/src/ccd.cpp;
// docs/ccd.md, "Exact contacts at the speed of float"), exact contact only: an interval's
// outcome and its certificate of contact (inside proven and the coplanarity cubic changing
// sign; in an axis plane, the inside conditions), the end-of-step tests of the plane
// certificates, the jump of a crossing to its root's leaf, and the time of impact of a
// certified crossing, each a proof with a rigorous error bound (ccd_bernstein.hpp). Internal to
// the runtime.

#include <cmath>

#include "ccd_bernstein.hpp"
#include "ccd_forms.hpp"
#include "tetseg/runtime/classify.hpp"

namespace tetseg::ccd_detail {
// Internal linkage: ccd.cpp is the only translation unit, and GCC then inlines these as it
// did when they were part of it (external-linkage inline functions cost 1.5-2 % more
// instructions in the elementary tests, callgrind).
namespace {

/// Bernstein coefficients of a polynomial of degree 3 or 4 on an interval (the coplanarity
/// cubic, or an inside condition), from its enclosed sums: the midpoints with the largest
/// radius as error bound.
template <int N>
FloatBernstein float_bernstein(const Sums<Iv, N>& sums) noexcept {
  static_assert(N == 3 || N == 4, "degrees 3 and 4");
  constexpr double kBinomial[2][5] = {{1, 3, 3, 1, 0}, {1, 4, 6, 4, 1}};
  FloatBernstein p{{}, N, 0.0};
  for (int k = 0; k <= N; ++k) {
    const Iv b = (k == 0 || k == N) ? sums.s[k] : divide(sums.s[k], kBinomial[N - 3][k]);
    p.c[k] = b.m;
    p.err = max_nan(p.err, b.r);
  }
  return p;
}

/// The cubic-first descent's jump (exact contact): on a dyadic interval [ta, tb] where the
/// coplanarity cubic p changes sign, the bisection would halve down to the leaf holding p's
/// root, excluding on the way each half where p is one-signed. Instead, the leaf of that grid
/// (width `leaf`, the bisection's own: a power of two) holding a float estimate of the root is
/// taken at once, when p is proven one-signed on the rest of [ta, tb]: before the leaf
/// (left_part) and after it (right_part), so the leaf holds every root. Its ends, and their
/// local parameters, are grid points: exact. Returns false (the caller halves) when a proof
/// fails: a root near a leaf end, several roots, a bound too wide.
inline bool root_leaf(const FloatBernstein& p, double ta, double tb, double leaf, double& lo,
                      double& hi) noexcept {
  const double width = tb - ta;
  const double local_leaf = leaf / width;  // a power of two: exact
  const double estimate = root_estimate(p, 0.25 * local_leaf);
  const double k = std::floor(estimate / local_leaf);
  const double lambda_lo = k * local_leaf;  // exact: k < 2^53, a power-of-two scale
  const double lambda_hi = lambda_lo + local_leaf;
  if (!(lambda_lo >= 0.0 && lambda_hi <= 1.0)) return false;
  if (lambda_lo > 0.0) {
    const FloatBernstein before = left_part(p, lambda_lo);
    if (!proven_positive(before) && !proven_negative(before)) return false;
  }
  if (lambda_hi < 1.0) {
    const FloatBernstein after = right_part(p, lambda_hi);
    if (!proven_positive(after) && !proven_negative(after)) return false;
  }
  lo = ta + lambda_lo * width;  // grid points: exact
  hi = ta + lambda_hi * width;
  return true;
}

/// The coplanarity cubic's Bernstein coefficients on the whole step [0, 1] in plain doubles,
/// from the runtime's floating-point orientation cubic (`orientation_bernstein`, classify.hpp:
/// coefficients k with forward error bounds err, k1 and k2 scaled by 3), with one error bound
/// for all four: k0 and k3 as they are; k1 / 3 and k2 / 3 rounded once (at most 2^-53 of the
/// result, charged 2^-52) with their bound not divided (a third of it would do). The bound is
/// rounded upwards (kBoundRoundUp, kBoundFloor). `bound_scale` scales it (tests only; 1 in
/// production): tests/runtime/ccd_filter_bound_test.cpp checks it against GMP, and that a
/// fraction of it is violated.
inline FloatBernstein step_cubic(const BernsteinCubic& k, double bound_scale = 1.0) noexcept {
  FloatBernstein p{{k.k[0], k.k[1] / 3.0, k.k[2] / 3.0, k.k[3], 0.0}, 3, 0.0};
  const double e1 = k.err[1] + 0x1p-52 * std::fabs(p.c[1]);
  const double e2 = k.err[2] + 0x1p-52 * std::fabs(p.c[2]);
  p.err = bound_scale * max_nan(max_nan(k.err[0], k.err[3]), max_nan(e1, e2)) * kBoundRoundUp +
          kBoundFloor;
  return p;
}

/// True when halving p up to `levels` times proves it of one strict sign on every piece (so
/// it has no root: the pieces share their ends).
inline bool one_signed_by_halving(const FloatBernstein& p, int levels) noexcept {
  if (proven_positive(p) || proven_negative(p)) return true;
  if (levels == 0 || proven_sign_change(p)) return false;
  FloatBernstein left{}, right{};
  split_half(p, left, right);
  return one_signed_by_halving(left, levels - 1) && one_signed_by_halving(right, levels - 1);
}

/// Width of the bisection's leaves below a dyadic interval of width `width`: the first halving
/// not above tol.
inline double leaf_width(double width, double tol) noexcept {
  while (width > tol) width *= 0.5;
  return width;
}

/// Outcome of one interval: excluded, or open (with `inside` when every inside condition is
/// proven strictly positive on it, so that its sub-intervals need only kCoplanarOnly).
/// Exact contact only, a positive certificate: `certified` when a contact certainly exists in
/// the interval, `contact_at_start` when its start is a contact time.
struct IntervalOutcome {
  bool excluded = false;
  bool inside = false;
  bool certified = false;
  bool contact_at_start = false;
  /// Certified in the plane with one inside condition open: on sub-intervals, contact happens
  /// exactly where that condition is >= 0 (the others are proven positive).
  bool open_condition = false;
  /// Exact contact, a check given a leaf width: the coplanarity cubic has its only root on the
  /// interval in the leaf [leaf_lo, leaf_hi] (root_leaf); nothing else was checked.
  bool to_leaf = false;
  double leaf_lo = 0.0, leaf_hi = 0.0;
};

/// True when every Bernstein sum is proven strictly positive (the polynomial > 0 on T).
template <class I, int N>
bool positive(const Sums<I, N>& raw) noexcept {
  return range_of(raw).lo > 0.0;
}

/// True when the polynomial is proven to take both signs on T: its values at the ends (the
/// first and last Bernstein sums) are of strictly opposite signs, so it has a root in T.
template <class I, int N>
bool sign_change(const Sums<I, N>& raw) noexcept {
  return (upper(raw.s[0]) < 0.0 && lower(raw.s[N]) > 0.0) ||
         (lower(raw.s[0]) > 0.0 && upper(raw.s[N]) < 0.0);
}

/// The outcome sending a check to the leaf holding the coplanarity cubic's only root on
/// [ta, tb] (root_leaf), when there is one: `to_leaf` set, else nothing decided.
inline IntervalOutcome crossing_leaf(const Sums<Iv, 3>& f, double ta, double tb,
                                     double leaf) noexcept {
  IntervalOutcome out{};
  out.to_leaf =
      sign_change(f) && root_leaf(float_bernstein(f), ta, tb, leaf, out.leaf_lo, out.leaf_hi);
  return out;
}

/// Positive certificate of an open interval (exact contact), from the coplanarity cubic f and
/// the inside conditions g[0..count) (vertex-face: the three edge-plane quartics; edge-edge:
/// h1..h4), whose joint non-negativity on the plane of the four points means contact (with
/// the triangle non-degenerate, the edges not parallel: implied below by a proven-positive
/// condition, as A e_ab = ... and h1 + h2 = h3 + h4 = |n|^2). `in_plane`: the four points stay
/// in one plane for the whole step (f vanishes identically).
///  - every condition proven positive on T and f changing sign on T: contact at f's root;
///  - in the plane, every condition positive on T: every time of T is a contact (its start);
///  - in the plane, all conditions but one positive on T and that one positive at an end of
///    T: contact at that end (and `open_condition`, its sums copied to *open_condition).
template <class I, int N>
IntervalOutcome certify(const Sums<I, 3>& f, const Sums<I, 4>* const* conditions, bool in_plane,
                        bool inside, Sums<I, 4>* open_condition) noexcept {
  IntervalOutcome out{false, inside, false, false};
  if (inside) {
    out.contact_at_start = in_plane;
    out.certified = in_plane || sign_change(f);
    return out;
  }
  if (!in_plane) return out;
  int open = -1;
  for (int k = 0; k < N; ++k) {
    if (positive(*conditions[k])) continue;
    if (open >= 0) return out;
    open = k;
  }
  const Sums<I, 4>& g = *conditions[open];
  out.contact_at_start = lower(g.s[0]) > 0.0;
  out.certified = out.contact_at_start || lower(g.s[4]) > 0.0;
  out.open_condition = out.certified;
  if (out.certified && open_condition != nullptr) *open_condition = g;
  return out;
}

/// A leaf holding a root of the coplanarity cubic, decided from the inside conditions alone.
enum class LeafOutcome { kApart, kContact, kUndecided };

/// The inside conditions of a leaf (vertex-face: the three edge planes; edge-edge: h1..h4;
/// their joint positivity where the cubic vanishes means contact, as in `certify`), given in
/// turn as enclosures over the whole leaf: one proven negative, apart (the rest need not be
/// computed); all proven positive, the cubic's root in the leaf is a contact; otherwise
/// undecided (the full check runs).
class LeafConditions {
 public:
  /// Adds condition g; true when it is proven negative (the leaf is apart).
  bool apart(Iv g) noexcept {
    inside_ = inside_ && lower(g) > 0.0;
    return upper(g) < 0.0;
  }
  /// The outcome once every condition was added and none was apart.
  LeafOutcome outcome() const noexcept {
    return inside_ ? LeafOutcome::kContact : LeafOutcome::kUndecided;
  }

 private:
  bool inside_ = true;
};

/// True when the coplanarity cubic f, known to vanish at t = 1, is proven nonzero on [0, 1).
/// f = (1 - t) g with g quadratic; g's Bernstein coefficients on [0, 1] are f's sums
/// s0, s1 / 2, s2 (from (1 - t) B_i^2 = C(2,i) / C(3,i) B_i^3), so one strict sign of those three
/// sums makes g, hence f before t = 1, of one sign.
inline bool nonzero_before_end(const Sums<Iv, 3>& f) noexcept {
  const Sums<Iv, 2> g{{f.s[0], f.s[1], f.s[2]}};
  const Range r = range_of(g);
  return r.lo > 0.0 || r.hi < 0.0;
}

/// The same when f vanishes at t = 0: f = t g, g's coefficients are s1, s2 / 2, s3.
inline bool nonzero_after_start(const Sums<Iv, 3>& f) noexcept {
  const Sums<Iv, 2> g{{f.s[1], f.s[2], f.s[3]}};
  const Range r = range_of(g);
  return r.lo > 0.0 || r.hi < 0.0;
}

/// Time of impact for a crossing certified on [ta, tb] (exact contact: the inside proven on
/// it, so contact happens exactly where the coplanarity cubic p vanishes; or in a plane, where
/// the open inside condition p is >= 0, p negative at ta; p of opposite signs at the ends): a
/// time t, about tol / 2 before p's first root, such that p is proven nonzero on [ta, t] (its
/// coefficients there, from one de Casteljau step at the estimated root, are of one sign), rounded
/// down. Everything before ta being contact-free, t is a lower bound of the first contact. -1 when
/// the proof fails (then the caller bisects).
inline double certified_crossing_time(const FloatBernstein& p, double ta, double tb,
                                      double tol) noexcept {
  const double width = tb - ta;
  const double local_tol = tol / width;
  const double lambda = root_estimate(p, 0.25 * local_tol) - 0.5 * local_tol;
  if (!(lambda > 0.0)) return ta;  // the root is within tol of ta
  const FloatBernstein left = left_part(p, lambda);
  if (!proven_positive(left) && !proven_negative(left)) return -1.0;
  const double t = ta + lambda * width;  // two roundings: 2^-51 |t| covers them
  return max_nan(ta, t - std::fabs(t) * 0x1p-51);
}

/// Start of the last leaf of the bisection of [0, 1] down to the tolerance: 1 - 2^-k with
/// 2^-k the first halving not above tol.
inline double last_leaf_start(double tol) noexcept {
  double width = 1.0;
  while (width > tol) width *= 0.5;
  return 1.0 - width;
}

}  // namespace
}  // namespace tetseg::ccd_detail
