#pragma once
/// \file
/// Exact real algebra in one variable over the rationals (GMP's mpq_class; link gmpxx and
/// gmp): polynomials, gcds, square-free parts, Sturm sequences, real roots isolated in [0, 1]
/// and the exact sign of a polynomial at such a root. Test-only truth for the runtime's
/// floating-point geometry (exact_ccd.hpp, tests/runtime/detector_point_test.cpp); never used
/// by the product. Header-only; degrees are small (<= 8), so nothing is tuned.

#include <gmpxx.h>

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace tetseg::test::exact {

/// Coefficients, lowest degree first; the zero polynomial is empty (after trim).
using Poly = std::vector<mpq_class>;

inline void trim(Poly& p) {
  while (!p.empty() && p.back() == 0) p.pop_back();
}

/// -1 for the zero polynomial.
inline int degree(const Poly& p) {
  return static_cast<int>(p.size()) - 1;
}

inline mpq_class eval(const Poly& p, const mpq_class& x) {
  mpq_class v = 0;
  for (std::size_t i = p.size(); i-- > 0;) v = v * x + p[i];
  return v;
}

inline Poly add(const Poly& a, const Poly& b) {
  Poly r(std::max(a.size(), b.size()));
  for (std::size_t i = 0; i < a.size(); ++i) r[i] += a[i];
  for (std::size_t i = 0; i < b.size(); ++i) r[i] += b[i];
  trim(r);
  return r;
}

inline Poly sub(const Poly& a, const Poly& b) {
  Poly r(std::max(a.size(), b.size()));
  for (std::size_t i = 0; i < a.size(); ++i) r[i] += a[i];
  for (std::size_t i = 0; i < b.size(); ++i) r[i] -= b[i];
  trim(r);
  return r;
}

inline Poly mul(const Poly& a, const Poly& b) {
  if (a.empty() || b.empty()) return {};
  Poly r(a.size() + b.size() - 1);
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) r[i + j] += a[i] * b[j];
  trim(r);
  return r;
}

inline Poly negated(Poly p) {
  for (mpq_class& c : p) c = -c;
  return p;
}

inline Poly derivative(const Poly& p) {
  Poly d;
  for (std::size_t i = 1; i < p.size(); ++i) d.push_back(p[i] * static_cast<long>(i));
  trim(d);
  return d;
}

/// Remainder of a by b (b nonzero).
inline Poly remainder(Poly a, const Poly& b) {
  trim(a);
  while (a.size() >= b.size() && !a.empty()) {
    const mpq_class q = a.back() / b.back();
    const std::size_t shift = a.size() - b.size();
    for (std::size_t i = 0; i < b.size(); ++i) a[i + shift] -= q * b[i];
    a.pop_back();  // the leading term cancels exactly
    trim(a);
  }
  return a;
}

/// Quotient of a by b (b nonzero); exact division when b divides a.
inline Poly quotient(Poly a, const Poly& b) {
  trim(a);
  if (a.size() < b.size()) return {};
  Poly q(a.size() - b.size() + 1);
  while (a.size() >= b.size() && !a.empty()) {
    const mpq_class c = a.back() / b.back();
    const std::size_t shift = a.size() - b.size();
    q[shift] = c;
    for (std::size_t i = 0; i < b.size(); ++i) a[i + shift] -= c * b[i];
    a.pop_back();
    trim(a);
  }
  trim(q);
  return q;
}

inline Poly monic(Poly p) {
  trim(p);
  if (p.empty()) return p;
  const mpq_class lead = p.back();
  for (mpq_class& c : p) c /= lead;
  return p;
}

/// Monic greatest common divisor; zero only when both are zero.
inline Poly gcd(Poly a, Poly b) {
  trim(a);
  trim(b);
  while (!b.empty()) {
    Poly r = monic(remainder(a, b));
    a = std::move(b);
    b = std::move(r);
  }
  return monic(a);
}

/// p divided by gcd(p, p'): the same roots, each simple (monic; p nonzero).
inline Poly square_free(const Poly& p) {
  const Poly d = derivative(p);
  if (d.empty()) return monic(p);
  return monic(quotient(p, gcd(p, d)));
}

/// The coefficients of q(m + s) in s (Taylor expansion at m).
inline Poly taylor_at(Poly q, const mpq_class& m) {
  const std::size_t n = q.size();
  for (std::size_t k = 0; k + 1 < n; ++k)
    for (std::size_t i = n - 1; i > k; --i) q[i - 1] += m * q[i];
  return q;
}

/// True when no root of p lies in [0, 1] (p nonzero): its Bernstein coefficients on [0, 1]
/// share one strict sign. A cheap exact sufficient test; false says nothing.
inline bool bernstein_no_root_in_unit_interval(const Poly& p) {
  const std::size_t n = p.size();
  if (n == 0) return false;
  // b_k = sum_{i <= k} C(k, i) / C(d, i) a_i, computed as the forward differences' inverse.
  std::vector<mpq_class> b(n);
  const long d = static_cast<long>(n) - 1;
  for (std::size_t i = 0; i < n; ++i) {
    mpq_class binom_d_i = 1;  // C(d, i)
    for (long j = 0; j < static_cast<long>(i); ++j) binom_d_i = binom_d_i * (d - j) / (j + 1);
    b[i] = p[i] / binom_d_i;
  }
  // Now b holds a_i / C(d, i); the Bernstein coefficients are its prefix binomial sums.
  for (std::size_t k = 1; k < n; ++k)
    for (std::size_t i = n - 1; i >= k; --i) b[i] += b[i - 1];
  const int s = sgn(b[0]);
  if (s == 0) return false;
  for (const mpq_class& c : b)
    if (sgn(c) != s) return false;
  return true;
}

/// Sturm sequence of a square-free polynomial: counts its distinct real roots in (l, r].
class SturmSequence {
 public:
  explicit SturmSequence(const Poly& p) {
    seq_.push_back(p);
    Poly d = derivative(p);
    if (d.empty()) return;
    seq_.push_back(d);
    while (true) {
      Poly r = remainder(seq_[seq_.size() - 2], seq_.back());
      if (r.empty()) break;
      seq_.push_back(negated(std::move(r)));
    }
  }
  int sign_changes(const mpq_class& x) const {
    int changes = 0, last = 0;
    for (const Poly& p : seq_) {
      const int s = sgn(eval(p, x));
      if (s == 0) continue;
      if (last != 0 && s != last) ++changes;
      last = s;
    }
    return changes;
  }

 private:
  std::vector<Poly> seq_;
};

/// True when p(t) > 0 for every t in [0, 1], decided exactly.
inline bool positive_on_unit_interval(Poly p) {
  trim(p);
  if (p.empty()) return false;  // identically zero
  if (eval(p, 0) <= 0 || eval(p, 1) <= 0) return false;
  if (degree(p) == 0) return true;
  const Poly q = square_free(p);
  const SturmSequence s(q);
  return s.sign_changes(0) - s.sign_changes(1) == 0;
}

/// A real algebraic number: exactly `value` when `exact`, otherwise the only root of the
/// square-free `poly` in the open interval (lo, hi), where poly changes sign.
struct RealRoot {
  Poly poly;
  mpq_class lo, hi;
  int sign_lo = 0;  // sign of poly(lo)
  bool exact = false;
  mpq_class value;

  static RealRoot rational(const mpq_class& v) {
    RealRoot r;
    r.exact = true;
    r.value = r.lo = r.hi = v;
    return r;
  }
  /// Halves the interval (or finds the root exactly at its middle).
  void bisect() {
    if (exact) return;
    const mpq_class m = (lo + hi) / 2;
    const int s = sgn(eval(poly, m));
    if (s == 0) {
      exact = true;
      value = lo = hi = m;
    } else if (s == sign_lo) {
      lo = m;
    } else {
      hi = m;
    }
  }
};

/// Sign of q at the root, exactly (refines the root's interval as needed).
inline int sign_at(const Poly& q, RealRoot& r) {
  if (q.empty()) return 0;
  bool known_nonzero = false;
  while (true) {
    if (r.exact) return sgn(eval(q, r.value));
    const mpq_class m = (r.lo + r.hi) / 2, h = (r.hi - r.lo) / 2;
    const Poly t = taylor_at(q, m);
    mpq_class bound = 0, hk = 1;
    for (std::size_t k = 1; k < t.size(); ++k) {
      hk *= h;
      bound += abs(t[k]) * hk;
    }
    if (abs(t[0]) > bound) return sgn(t[0]);  // q has the sign of q(m) on all of [lo, hi]
    if (!known_nonzero) {
      // gcd(q, poly) divides the square-free poly: it has the root iff it changes sign.
      const Poly g = gcd(q, r.poly);
      if (degree(g) >= 1 && sgn(eval(g, r.lo)) != sgn(eval(g, r.hi))) return 0;
      known_nonzero = true;
    }
    r.bisect();
  }
}

/// The distinct real roots of p (nonzero) in [0, 1], ascending, each isolated.
inline std::vector<RealRoot> roots_in_unit_interval(const Poly& p) {
  std::vector<RealRoot> roots;
  if (degree(p) < 1) return roots;
  Poly q = square_free(p);
  const bool at_zero = eval(q, 0) == 0, at_one = eval(q, 1) == 0;
  if (at_zero) q = quotient(q, Poly{0, 1});
  if (at_one) q = quotient(q, Poly{-1, 1});
  if (at_zero) roots.push_back(RealRoot::rational(0));
  if (degree(q) >= 1 && !bernstein_no_root_in_unit_interval(q)) {
    const SturmSequence sturm(q);
    struct Range {
      mpq_class l, r;
      int vl, vr;
    };
    std::vector<Range> stack{{0, 1, sturm.sign_changes(0), sturm.sign_changes(1)}};
    while (!stack.empty()) {  // right halves pushed first: roots come out ascending
      Range g = stack.back();
      stack.pop_back();
      const int count = g.vl - g.vr;
      if (count <= 0) continue;
      if (count == 1) {
        RealRoot root;
        root.poly = q;
        root.lo = g.l;
        root.hi = g.r;
        root.sign_lo = sgn(eval(q, g.l));
        roots.push_back(std::move(root));
        continue;
      }
      mpq_class m = (g.l + g.r) / 2;
      for (long k = 3; eval(q, m) == 0; ++k) {  // never split at a root
        mpq_class step = 1;
        mpz_class pow2 = 1;
        pow2 <<= k;
        step /= mpq_class(pow2);
        m = g.l + (g.r - g.l) * (mpq_class(1, 2) + step);
      }
      const int vm = sturm.sign_changes(m);
      stack.push_back({m, g.r, vm, g.vr});
      stack.push_back({g.l, m, g.vl, vm});
    }
  }
  if (at_one) roots.push_back(RealRoot::rational(1));
  return roots;
}

/// The smallest double >= x.
inline double round_up(const mpq_class& x) {
  double d = x.get_d();  // truncates toward zero
  if (mpq_class(d) < x) d = std::nextafter(d, std::numeric_limits<double>::infinity());
  return d;
}

/// The largest double <= x.
inline double round_down(const mpq_class& x) {
  double d = x.get_d();
  if (mpq_class(d) > x) d = std::nextafter(d, -std::numeric_limits<double>::infinity());
  return d;
}

/// Doubles enclosing the root: lower <= root <= upper, the root rounded down and up (equal
/// when the root is a double).
inline std::pair<double, double> enclose(RealRoot& r) {
  while (!r.exact) {
    const double up = round_up(r.hi), down = round_down(r.lo);
    if (round_up(r.lo) == up && round_down(r.hi) == down) break;  // both correctly rounded
    const double only = round_up(r.lo);  // the one double inside (lo, hi), if there is one
    if (only == round_down(r.hi) && eval(r.poly, mpq_class(only)) == 0) {
      r = RealRoot::rational(mpq_class(only));
      break;
    }
    r.bisect();
  }
  if (r.exact) return {round_down(r.value), round_up(r.value)};
  return {round_down(r.lo), round_up(r.hi)};
}

}  // namespace tetseg::test::exact
