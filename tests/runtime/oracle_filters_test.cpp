// The collider's feature filters (still rule, swept boxes, the coplanarity cubics with their
// static error bounds, the plane filters) against the independent oracles (support/compare.hpp):
// contacts that are exactly coplanar while the floating-point cubics are rounding noise, where a
// filter without its error bound would prove a strict sign and drop the contact.

#include <array>
#include <random>
#include <vector>

#include <catch2/catch.hpp>

#include "runtime/support/compare.hpp"
#include "tetseg/runtime/body_shape.hpp"
#include "tetseg/runtime/collider.hpp"

using namespace tetseg;
using namespace tetseg::test;

TEST_CASE("A vertex sliding into a face within its plane is found by every mode",
          "[collider][oracle][filters]") {
  // Two triangles of one surface-only body: F = (0, 1, 2) in the plane x + y + z = 1 and
  // G = (3, 4, 5) whose node 3 slides within that plane from outside F to inside it. The
  // coordinates are random multiples of 2^-30, so the plane holds them exactly while every
  // floating-point orientation product rounds.
  std::mt19937_64 rng(26);
  std::uniform_int_distribution<std::int64_t> grid(1, (std::int64_t{1} << 29) - 1);
  auto coordinate = [&] { return std::ldexp(double(grid(rng)), -30); };  // in (0, 0.5)
  auto in_plane = [](double x, double y) { return std::array<double, 3>{x, y, 1.0 - x - y}; };
  const std::uint32_t tris[] = {0, 1, 2, 3, 4, 5};
  const std::vector<format::Triangle> triangles = {{0, 1, 2}, {3, 4, 5}};
  const auto shape = BodyShape::from_triangles(tris, 2, 6);
  REQUIRE(shape);
  int contacts = 0;
  for (int trial = 0; trial < 300; ++trial) {
    CAPTURE(trial);
    // F spans (x, y) in a triangle around (0.25, 0.25); node 3 moves from (-0.5, ...) inside.
    const double cx = 0.25 + coordinate() / 8, cy = 0.25 + coordinate() / 8;  // exact
    std::vector<double> x0(18), x1(18);
    auto put = [](std::vector<double>& x, int node, const std::array<double, 3>& p) {
      for (int k = 0; k < 3; ++k) x[3 * node + k] = p[k];
    };
    for (auto* x : {&x0, &x1}) {
      put(*x, 0, in_plane(cx - 0.125 - coordinate() / 8, cy - 0.125 - coordinate() / 8));
      put(*x, 1, in_plane(cx + 0.25 + coordinate() / 8, cy - 0.125));
      put(*x, 2, in_plane(cx - 0.125, cy + 0.25 + coordinate() / 8));
      put(*x, 4, {-1.0 - coordinate(), -1.0, 3.0});  // G's other nodes far off the plane
      put(*x, 5, {-1.0, -1.0 - coordinate(), 3.0});
    }
    x1 = x0;
    put(x0, 3, in_plane(cx - 0.5 - coordinate(), cy + coordinate() / 16));
    put(x1, 3, in_plane(cx + coordinate() / 16, cy + coordinate() / 16));
    const OracleBody body{triangles.data(), triangles.size(), x0.data(), x1.data(), true};
    const StepTruth truth = step_truth(body);
    REQUIRE_FALSE(truth.required.empty());  // the slide does reach the face, exactly
    ++contacts;
    for (ColliderMode mode : {ColliderMode::kBrute, ColliderMode::kBvh, ColliderMode::kCone}) {
      CAPTURE(to_string(mode));
      ColliderOptions options;
      options.mode = mode;
      Collider collider(shape, options);
      REQUIRE(collider.status() == ColliderStatus::kOk);
      require_matches_oracle(answer(collider, x0.data(), x1.data()), truth, Expect::kAllContacts);
    }
  }
  CHECK(contacts == 300);
}
