// Histogram equalisation of charge densities (paper section IV-B, Eq. 1) and two variants.

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "tetseg/preprocess/charge.hpp"

namespace tetseg::preprocess {
namespace {

std::vector<double> histogram_equalize(const std::vector<double>& v, int bins) {
  const std::size_t n = v.size();
  std::vector<double> out(n, 1.0);
  const auto [lo_it, hi_it] = std::minmax_element(v.begin(), v.end());
  const double lo = *lo_it, hi = *hi_it;
  if (!(hi > lo)) return out;
  std::vector<int> bin(n);
  std::vector<std::size_t> cdf(static_cast<std::size_t>(bins), 0);
  const double scale = static_cast<double>(bins) / (hi - lo);
  for (std::size_t i = 0; i < n; ++i) {
    const double f = std::floor((v[i] - lo) * scale);
    bin[i] = static_cast<int>(std::min(static_cast<double>(bins - 1), std::max(0.0, f)));
    ++cdf[static_cast<std::size_t>(bin[i])];
  }
  for (std::size_t b = 1; b < cdf.size(); ++b) cdf[b] += cdf[b - 1];
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = static_cast<double>(cdf[static_cast<std::size_t>(bin[i])]) / static_cast<double>(n);
  }
  return out;
}

}  // namespace

std::vector<double> equalize(const std::vector<double>& density, Equalization method, int bins) {
  if (bins < 1) throw std::invalid_argument("equalize: bins must be at least 1");
  for (const double v : density) {
    if (!std::isfinite(v)) throw std::invalid_argument("equalize: non-finite density");
  }
  const std::size_t n = density.size();
  if (n == 0) return {};
  switch (method) {
    case Equalization::kHistogram:
      return histogram_equalize(density, bins);
    case Equalization::kLogHistogram: {
      double min_positive = 0.0;
      for (const double v : density) {
        if (v > 0.0 && (min_positive == 0.0 || v < min_positive)) min_positive = v;
      }
      std::vector<double> logs(n);
      // Values <= 0 get a log below every positive one, so they land in bin 0.
      const double floor_log = min_positive > 0.0 ? std::log(min_positive) - 1.0 : 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        logs[i] = density[i] > 0.0 ? std::log(density[i]) : floor_log;
      }
      return histogram_equalize(logs, bins);
    }
    case Equalization::kRank: {
      std::vector<std::size_t> idx(n);
      std::iota(idx.begin(), idx.end(), std::size_t{0});
      std::stable_sort(idx.begin(), idx.end(),
                       [&](std::size_t a, std::size_t b) { return density[a] < density[b]; });
      std::vector<double> out(n);
      std::size_t k = 0;
      while (k < n) {
        std::size_t e = k + 1;
        while (e < n && density[idx[e]] == density[idx[k]]) ++e;
        const double value = static_cast<double>(e) / static_cast<double>(n);
        for (std::size_t t = k; t < e; ++t) out[idx[t]] = value;
        k = e;
      }
      return out;
    }
  }
  return histogram_equalize(density, bins);
}

}  // namespace tetseg::preprocess
