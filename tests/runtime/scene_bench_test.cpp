// A pile of 16 soft balls: per-step cost through the scene (16 tet bodies, rvbc inside each,
// body pairs culled by body boxes then BVH against BVH) against the `bvh` mode over all balls'
// surfaces merged into one body. Hidden (not part of CI); run:
//   build/tests/tetseg_tests_runtime "[.bench]"
// It prints timings and checks only correctness (both find the same contacts), never speed.
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "tetseg/runtime/scene.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

}  // namespace

TEST_CASE("Benchmark: a pile of 16 soft balls, scene against one merged bvh body",
          "[.bench][scene]") {
  using tetseg::ColliderStatus;
  const int balls = 16, frames = 9, repeats = 3;
  const auto ball = std::make_shared<tetseg::test::Scene>(
      tetseg::test::make_axial_scene(tetseg::test::sphere(1.0, 48, 25), {0.0}, {-0.45, 0.45}));
  const auto shape = tetseg::BodyShape::from_asset(ball->asset);
  REQUIRE(shape);
  const std::uint32_t n = ball->asset.node_count();
  // Global arrays: ball b's nodes at offset b * n. A 4 x 4 layer of balls 2.1 apart that
  // squeeze together (gaps close and overlap slightly by the last frame) and wobble.
  std::vector<std::vector<double>> x(frames, std::vector<double>(std::size_t(balls) * n * 3));
  for (int f = 0; f < frames; ++f) {
    const double t = double(f) / (frames - 1);
    for (int b = 0; b < balls; ++b) {
      const double cx = 2.1 * (b % 4 - 1.5) * (1 - 0.06 * t);
      const double cy = 2.1 * (b / 4 - 1.5) * (1 - 0.06 * t);
      for (std::uint32_t i = 0; i < n; ++i) {
        const double* p = ball->rest.data() + 3 * i;
        const double w = 1 + 0.03 * t * std::sin(3 * p[0] + 2 * p[1] + b);
        double* q = x[f].data() + (std::size_t(b) * n + i) * 3;
        q[0] = cx + w * p[0];
        q[1] = cy + w * p[1];
        q[2] = w * p[2] - 0.5 * t;
      }
    }
  }
  tetseg::Scene scene;
  for (int b = 0; b < balls; ++b) {
    tetseg::BodyOptions o;
    o.global_offset = std::size_t(b) * n;
    REQUIRE(scene.add_body(shape, o) == ColliderStatus::kOk);
  }
  std::vector<std::uint32_t> merged;
  for (int b = 0; b < balls; ++b)
    for (const auto& tri : ball->asset.data().triangles)
      for (std::uint32_t v : tri) merged.push_back(v + std::uint32_t(b) * n);
  const auto merged_shape =
      tetseg::BodyShape::from_triangles(merged.data(), merged.size() / 3, balls * n);
  REQUIRE(merged_shape);
  tetseg::ColliderOptions bvh_options;
  bvh_options.mode = tetseg::ColliderMode::kBvh;
  tetseg::Collider whole(merged_shape, bvh_options);
  REQUIRE(whole.status() == ColliderStatus::kOk);

  double scene_ms = 0, whole_ms = 0;
  std::size_t scene_contacts = 0, whole_contacts = 0;
  std::uint64_t pairs_tested = 0, pairs_skipped = 0;
  for (int f = 0; f + 1 < frames; ++f) {
    double best_scene = 1e300, best_whole = 1e300;
    tetseg::ContactsResult rs, rw;
    for (int r = 0; r < repeats; ++r) {
      const auto t0 = Clock::now();
      REQUIRE(scene.step(x[f].data(), x[f + 1].data(), x[f].size()) == ColliderStatus::kOk);
      REQUIRE(scene.contacts(nullptr, 0, rs) == ColliderStatus::kOk);
      const auto t1 = Clock::now();
      REQUIRE(whole.step(x[f].data(), x[f + 1].data(), x[f].size()) == ColliderStatus::kOk);
      REQUIRE(whole.contacts(nullptr, 0, rw) == ColliderStatus::kOk);
      const auto t2 = Clock::now();
      best_scene = std::min(best_scene, ms_between(t0, t1));
      best_whole = std::min(best_whole, ms_between(t1, t2));
    }
    CHECK(rs.found == rw.found);  // no self contact in a ball: the same contact set
    scene_ms += best_scene;
    whole_ms += best_whole;
    scene_contacts += rs.found;
    whole_contacts += rw.found;
    pairs_tested += scene.stats().body_pairs_tested;
    pairs_skipped += scene.stats().body_pairs_skipped;
  }
  CHECK(scene_contacts > 0);
  const int steps = frames - 1;
  std::printf(
      "16 balls, %zu triangles each: scene %.3f ms/step, merged bvh %.3f ms/step (%.2fx); "
      "body pairs tested %.1f, skipped %.1f per step; contacts %zu / %zu\n",
      ball->asset.triangle_count(), scene_ms / steps, whole_ms / steps, whole_ms / scene_ms,
      double(pairs_tested) / steps, double(pairs_skipped) / steps, scene_contacts, whole_contacts);
}
