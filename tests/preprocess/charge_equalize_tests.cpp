// Histogram equalisation (paper Eq. 1) and its rank and log-binned variants.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "tetseg/preprocess/charge.hpp"
#include "tetseg/preprocess/names.hpp"

using namespace tetseg::preprocess;

namespace {

/// The paper's definition written out directly: bin of each value over [min, max] in `bins`
/// equal bins, CDF[i] = number of values whose bin is <= i, new value CDF[bin] / N.
std::vector<double> paper_histogram(const std::vector<double>& v, int bins) {
  const double lo = *std::min_element(v.begin(), v.end());
  const double hi = *std::max_element(v.begin(), v.end());
  std::vector<int> bin(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    int b = static_cast<int>((v[i] - lo) / (hi - lo) * bins);
    bin[i] = std::min(b, bins - 1);
  }
  std::vector<double> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    std::size_t count = 0;
    for (const int b : bin) count += b <= bin[i] ? 1 : 0;
    out[i] = static_cast<double>(count) / static_cast<double>(v.size());
  }
  return out;
}

}  // namespace

TEST_CASE("Histogram equalisation follows the paper's CDF rule", "[charge][equalize]") {
  std::mt19937 rng(7);
  std::lognormal_distribution<double> dist(0.0, 1.0);
  std::vector<double> v(2000);
  for (auto& x : v) x = dist(rng);
  SECTION("It equals the brute-force CDF[bin] / N with 256 bins.") {
    const auto eq = equalize(v, Equalization::kHistogram);
    const auto ref = paper_histogram(v, 256);
    for (std::size_t i = 0; i < v.size(); ++i) REQUIRE(eq[i] == ref[i]);
  }
  SECTION("The maximum maps to 1 and the order is kept.") {
    const auto eq = equalize(v, Equalization::kHistogram);
    const auto imax = std::max_element(v.begin(), v.end()) - v.begin();
    CHECK(eq[static_cast<std::size_t>(imax)] == 1.0);
    for (std::size_t i = 0; i < v.size(); ++i) {
      for (std::size_t j = 0; j < v.size(); j += 37) {
        if (v[i] < v[j]) REQUIRE(eq[i] <= eq[j]);
      }
    }
  }
  SECTION("A positive rescaling leaves the result unchanged.") {
    std::vector<double> scaled = v;
    for (auto& x : scaled) x *= 8.0;  // a power of two keeps the bins bit-exact
    CHECK(equalize(scaled, Equalization::kHistogram) == equalize(v, Equalization::kHistogram));
  }
  SECTION("Equal densities map to 1 everywhere.") {
    const auto eq = equalize(std::vector<double>(10, 3.5), Equalization::kHistogram);
    CHECK(eq == std::vector<double>(10, 1.0));
  }
  SECTION("Non-finite input and zero bins are rejected; empty input gives empty output.") {
    CHECK_THROWS_AS(equalize({1.0, NAN}, Equalization::kHistogram), std::invalid_argument);
    CHECK_THROWS_AS(equalize({1.0, 2.0}, Equalization::kHistogram, 0), std::invalid_argument);
    CHECK(equalize({}, Equalization::kRank).empty());
  }
}

TEST_CASE("The rank and log variants resolve heavy tails", "[charge][equalize]") {
  SECTION("Ranks are (count of values <= v) / N with ties sharing the largest rank.") {
    const std::vector<double> v = {5.0, 1.0, 3.0, 3.0, 9.0};
    const auto eq = equalize(v, Equalization::kRank);
    CHECK(eq == std::vector<double>{0.8, 0.2, 0.6, 0.6, 1.0});
  }
  SECTION("One sharp tip squeezes the paper's bins but not the rank or log variants.") {
    // 999 values spread over [1, 2] and one tip at 1000: linear bins put all 999 in bin 0.
    std::vector<double> v;
    for (int i = 0; i < 999; ++i) v.push_back(1.0 + i / 998.0);
    v.push_back(1000.0);
    const auto hist = equalize(v, Equalization::kHistogram);
    const auto rank = equalize(v, Equalization::kRank);
    const auto logh = equalize(v, Equalization::kLogHistogram);
    CHECK(hist[0] == Approx(0.999));
    CHECK(hist[500] == Approx(0.999));
    CHECK(rank[0] == Approx(0.001));
    CHECK(rank[500] == Approx(0.501));
    // log bins: [0, log 1000] in 256 bins of 0.027; log 2 = 0.69 spans ~25 bins.
    CHECK(logh[0] < 0.1);
    CHECK(logh[998] == Approx(0.999));
    int distinct = 0;
    for (std::size_t i = 1; i < 999; ++i) distinct += logh[i] != logh[i - 1] ? 1 : 0;
    CHECK(distinct >= 20);
  }
  SECTION("Log bins put non-positive values in the lowest bin.") {
    const auto eq = equalize({-1.0, 0.0, 1.0, 10.0}, Equalization::kLogHistogram);
    CHECK(eq[0] == 0.5);
    CHECK(eq[1] == 0.5);
    CHECK(eq[3] == 1.0);
  }
  SECTION("Names parse and print back; the old spelling log is an alias.") {
    for (const char* name : {"histogram", "rank", "log-histogram"}) {
      Equalization e{};
      REQUIRE(parse_name(name, e));
      CHECK(std::string(name_of(e)) == name);
    }
    Equalization e = Equalization::kHistogram;
    REQUIRE(parse_name("log", e));
    CHECK(e == Equalization::kLogHistogram);
    CHECK_FALSE(parse_name("linear", e));
    CHECK(name_list<Equalization>() == "histogram|rank|log-histogram");
  }
}
