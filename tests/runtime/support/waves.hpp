#pragma once
// Random smooth deformation for collider tests: four sine waves of random wave vector, phase
// and direction, growing linearly with t.

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "common/synthetic_scenes.hpp"

namespace tetseg::test {

struct Waves {
  std::vector<std::array<double, 7>> w;  // k (3), phase, direction (3)
  double amplitude;
  /// Wave vector components uniform in [-wavenumber, wavenumber].
  Waves(unsigned seed, double amp, double wavenumber = 3.0) : amplitude(amp) {
    std::mt19937 rng(seed);
    auto u = [&] { return (rng() / 4294967296.0) * 2 - 1; };
    for (int i = 0; i < 4; ++i)
      w.push_back({wavenumber * u(), wavenumber * u(), wavenumber * u(), 3 * u(), u(), u(), u()});
  }
  P3 operator()(const P3& p, double t) const {
    P3 q = p;
    for (const auto& a : w) {
      const double s = std::sin(a[0] * p[0] + a[1] * p[1] + a[2] * p[2] + a[3]);
      for (int k = 0; k < 3; ++k) q[k] += t * amplitude * s * a[4 + k];
    }
    return q;
  }
};

}  // namespace tetseg::test
