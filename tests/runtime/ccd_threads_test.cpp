// The elementary CCD tests are reentrant: the same queries on several threads at once give
// the same results as in sequence.

#include <array>
#include <random>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "tetseg/runtime/ccd.hpp"

TEST_CASE("Concurrent elementary tests give the sequential results.", "[ccd]") {
  using tetseg::Vec3d;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<std::array<Vec3d, 8>> queries(4000);
  for (auto& q : queries)
    for (auto& p : q) p = {u(rng), u(rng), u(rng)};
  auto run_all = [&](std::size_t begin, std::size_t step, std::vector<tetseg::CcdResult>& out) {
    for (std::size_t i = begin; i < queries.size(); i += step) {
      const auto& x = queries[i];
      out[i] = i % 2 ? tetseg::vertex_face_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7])
                     : tetseg::edge_edge_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]);
    }
  };
  std::vector<tetseg::CcdResult> serial(queries.size()), parallel(queries.size());
  run_all(0, 1, serial);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < 4; ++t) threads.emplace_back(run_all, t, 4, std::ref(parallel));
  for (auto& t : threads) t.join();
  int hits = 0;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    CAPTURE(i);
    CHECK(serial[i].outcome == parallel[i].outcome);
    CHECK(serial[i].toi == parallel[i].toi);
    hits += serial[i].hit();
  }
  CHECK(hits > 100);  // random segments and triangles in a unit cube often cross
}
