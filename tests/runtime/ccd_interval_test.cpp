// The rigorous interval types of the elementary CCD tests (runtime/src/ccd_interval.hpp):
// every enclosure must contain the value computed in 113-bit quad precision (whose own error
// is far below the radii charged), on random expressions with wide exponent ranges and heavy
// cancellation; double-double must be much tighter than double.

#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "../../runtime/src/ccd_interval.hpp"

namespace {

using namespace tetseg::ccd_detail;
#if defined(__SIZEOF_FLOAT128__)
__extension__ typedef __float128 Quad;
#else
typedef long double Quad;  // IEEE quad on the 64-bit ARM ABIs
#endif

template <class I>
bool contains(const I& x, Quad q) {
  return static_cast<Quad>(lower(x)) <= q && q <= static_cast<Quad>(upper(x));
}

/// A random double with a random exponent in [-40, 40] and random sign.
double random_double(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> mant(1.0, 2.0);
  std::uniform_int_distribution<int> ex(-40, 40);
  std::bernoulli_distribution neg(0.5);
  const double v = std::ldexp(mant(rng), ex(rng));
  return neg(rng) ? -v : v;
}

struct Triple {
  Iv iv;
  Dd dd;
  Quad q;
};

Triple leaf(double x) {
  return {exact(x), exact_dd(x), static_cast<Quad>(x)};
}

Triple combine(const Triple& a, const Triple& b, int op) {
  switch (op) {
    case 0:
      return {a.iv + b.iv, a.dd + b.dd, a.q + b.q};
    case 1:
      return {a.iv - b.iv, a.dd - b.dd, a.q - b.q};
    default:
      return {a.iv * b.iv, a.dd * b.dd, a.q * b.q};
  }
}

}  // namespace

TEST_CASE("Interval enclosures contain the quad-precision value of random expressions.",
          "[ccd][interval]") {
  std::mt19937_64 rng(99);
  std::uniform_int_distribution<int> pick_op(0, 2);
  int tight = 0;
  int nonzero = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    CAPTURE(trial);
    // A chain of 6 operations over fresh leaves, plus a cancellation a*b - a*b' (b' close to b).
    Triple chain = leaf(random_double(rng));
    for (int k = 0; k < 6; ++k) chain = combine(chain, leaf(random_double(rng)), pick_op(rng));
    const Triple acc = chain;
    const double a = random_double(rng), b = random_double(rng);
    const double b2 = std::nextafter(b, 0.0);
    const Triple cancel = combine(combine(leaf(a), leaf(b), 2), combine(leaf(a), leaf(b2), 2), 1);
    const Triple total = combine(acc, cancel, pick_op(rng));
    for (const Triple* t : {&acc, &cancel, &total}) {
      REQUIRE(contains(t->iv, t->q));
      REQUIRE(contains(t->dd, t->q));
      // Division by small integers, as used for Bernstein coefficients.
      for (double k : {2.0, 3.0, 4.0, 6.0}) {
        REQUIRE(contains(divide(t->iv, k), t->q / static_cast<Quad>(k)));
        REQUIRE(contains(divide(t->dd, k), t->q / static_cast<Quad>(k)));
      }
    }
    // The cancellation a*b - a*nextafter(b) loses 53 bits: doubles keep none of the result
    // (width about |result|), double-double must keep it to about 2^-43 relative.
    if (cancel.q != 0) {
      ++nonzero;
      const double width_dd = upper(cancel.dd) - lower(cancel.dd);
      if (width_dd < 1e-11 * std::fabs(static_cast<double>(cancel.q))) ++tight;
      CHECK(width_dd * 1e4 <= upper(cancel.iv) - lower(cancel.iv));
    }
  }
  CHECK(nonzero > 19000);
  CHECK(tight == nonzero);
}

TEST_CASE("Interval decisions are never made on NaN or infinity.", "[ccd][interval]") {
  const Iv nan_iv{std::nan(""), 0.0};
  CHECK_FALSE(lower(nan_iv) > 0.0);
  CHECK_FALSE(upper(nan_iv) < 0.0);
  const Dd big = exact_dd(1e300) * exact_dd(1e300);
  CHECK_FALSE(lower(big - big) > 0.0);
  CHECK_FALSE(upper(big - big) < 0.0);
  CHECK(std::isnan(min_nan(1.0, std::nan(""))));
  CHECK(std::isnan(max_nan(std::nan(""), 1.0)));
}
