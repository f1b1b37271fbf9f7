// Hidden benchmark (run with "[.bench]"): tet mesh write/read per format, boundary extraction
// and validation on a large generated mesh. Prints figures; asserts only correctness.

#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <numeric>
#include <random>

#include "preprocess/support/grid_mesh.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "tetseg/testing/charge_shapes.hpp"

using namespace tetseg::preprocess;

namespace {

template <class F>
double best_of(int runs, F&& f) {
  double best = 1e300;
  for (int r = 0; r < runs; ++r) {
    const auto start = std::chrono::steady_clock::now();
    f();
    best = std::min(
        best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

}  // namespace

TEST_CASE("Benchmark: closed-surface validation at 131k triangles", "[.bench][io-bench]") {
  const TriangleMesh s = tetseg::test::icosphere(81);
  const double t = best_of(3, [&] { validate_closed_surface(s, "sphere"); });
  std::printf("validate_closed_surface: %zu triangles, %.3f s\n", s.triangles.size(), t);
}

TEST_CASE("Benchmark: tet mesh I/O, extraction and validation", "[.bench][io-bench]") {
  ShapeOptions o;
  o.size = 2.5;
  TetMesh mesh;
  MeshingOptions fast;
  fast.optimize = false;
  const double t_mesh = best_of(1, [&] { mesh = generate_shape(Shape::kPawn, o, fast); });
  std::printf("generate pawn --size 2.5 --no-optimize: %.2f s, %zu nodes, %zu tets\n", t_mesh,
              mesh.nodes.size(), mesh.tets.size());
  const auto dir =
      std::filesystem::temp_directory_path() / ("tetseg_io_bench_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const char* name : {"b.mesh", "b.node", "b.msh", "b22.msh", "bbin.msh"}) {
    const std::string path = (dir / name).string();
    const bool v22 = std::string(name) == "b22.msh";
    const bool binary = std::string(name) == "bbin.msh";
    const double t_write = best_of(3, [&] {
      if (v22) {
        write_gmsh22(path, mesh);
      } else if (binary) {
        write_gmsh41_binary(path, mesh);
      } else {
        write_tet_mesh(path, mesh);
      }
    });
    TetMesh back;
    const double t_read = best_of(3, [&] { back = read_tet_mesh(path); });
    CHECK(back.tets == mesh.tets);
    double bytes = static_cast<double>(std::filesystem::file_size(path));
    if (std::string(name) == "b.node")
      bytes += static_cast<double>(std::filesystem::file_size(dir / "b.ele"));
    const double mb = bytes / 1e6;
    std::printf("%-8s %6.1f MB  write %.3f s (%.0f MB/s)  read %.3f s (%.0f MB/s)\n", name, mb,
                t_write, mb / t_write, t_read, mb / t_read);
  }
  std::filesystem::remove_all(dir);
  Surface surface;
  const double t_extract = best_of(3, [&] { surface = extract_surface(mesh); });
  const double t_validate = best_of(3, [&] { validate_tet_mesh(mesh, surface, "bench"); });
  std::printf("extract_surface %.3f s (%zu triangles), validate_tet_mesh %.3f s\n", t_extract,
              surface.triangles.size(), t_validate);
}

// Issue 17 (docs/benchmarks-history.md, "Scale"): a 93^3 Kuhn grid (830,584 nodes, 4,826,142 tets,
// close to the 4.87 M-tet dumbbell), interior nodes jittered and nodes and tets shuffled as in
// a Mesh_3 output; wall and process CPU time of each step, one run each.
TEST_CASE("Benchmark: read, extract and validate 4.8 M tets", "[.bench][scale-bench]") {
  std::mt19937_64 random(17);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  constexpr int kCells = 93;
  TetMesh grid = tetseg::test::kuhn_grid(kCells, kCells, kCells, [&](int i, int j, int k) {
    Vec3 p;
    const int c[3] = {i, j, k};
    for (int a = 0; a < 3; ++a)
      p[a] = (c[a] + (c[a] == 0 || c[a] == kCells ? 0.0 : jitter(random))) / kCells;
    return p;
  });
  std::vector<std::uint32_t> new_id(grid.nodes.size());
  std::iota(new_id.begin(), new_id.end(), 0u);
  std::shuffle(new_id.begin(), new_id.end(), random);
  TetMesh mesh;
  mesh.nodes.resize(grid.nodes.size());
  for (std::size_t v = 0; v < grid.nodes.size(); ++v) mesh.nodes[new_id[v]] = grid.nodes[v];
  mesh.tets = grid.tets;
  for (Tet& t : mesh.tets)
    for (std::uint32_t& v : t) v = new_id[v];
  std::shuffle(mesh.tets.begin(), mesh.tets.end(), random);

  auto timed = [](const char* what, auto&& work) {
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    work();
    const double cpu = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%-22s wall %.3f s  cpu %.3f s\n", what, wall, cpu);
  };
  const auto dir =
      std::filesystem::temp_directory_path() / ("tetseg_scale_bench_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  // TETSEG_SCALE_MESH=<path>: also leave the mesh there, for timing `tetseg build` on it.
  const char* keep = std::getenv("TETSEG_SCALE_MESH");
  const std::string path = keep != nullptr ? std::string(keep) : (dir / "grid.mesh").string();
  write_tet_mesh(path, mesh);
  std::printf("%zu nodes, %zu tets, %.1f MB MEDIT\n", mesh.nodes.size(), mesh.tets.size(),
              static_cast<double>(std::filesystem::file_size(path)) / 1e6);
  TetMesh back;
  timed("read_tet_mesh (.mesh)", [&] { back = read_tet_mesh(path); });
  std::filesystem::remove_all(dir);
  CHECK(back.tets == mesh.tets);
  Surface surface;
  timed("extract_surface", [&] { surface = extract_surface(mesh); });
  timed("validate_tet_mesh", [&] { validate_tet_mesh(mesh, surface, "bench"); });
  Surface valid;
  timed("extract_valid_surface", [&] { valid = extract_valid_surface(mesh, "bench"); });
  CHECK(surface.triangles.size() == 6u * kCells * kCells * 2);
  CHECK(valid.triangles == surface.triangles);

  // Nodes numbered in order of first use by the tets, as Mesh_3's output is
  // (c3t3_to_tet_mesh): a tet's nodes are then mostly near in memory.
  TetMesh first_use;
  std::vector<std::uint32_t> renumbered(mesh.nodes.size(), UINT32_MAX);
  first_use.tets = mesh.tets;
  for (Tet& t : first_use.tets)
    for (std::uint32_t& v : t) {
      if (renumbered[v] == UINT32_MAX) {
        renumbered[v] = static_cast<std::uint32_t>(first_use.nodes.size());
        first_use.nodes.push_back(mesh.nodes[v]);
      }
      v = renumbered[v];
    }
  Surface first_use_surface;
  timed("extract_valid_surface, first-use node order",
        [&] { first_use_surface = extract_valid_surface(first_use, "bench"); });
  CHECK(first_use_surface.triangles.size() == surface.triangles.size());
}
