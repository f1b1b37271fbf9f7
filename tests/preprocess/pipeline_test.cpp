#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdint>
#include <cstdio>
#include <set>

#include "preprocess/support/grid_mesh.hpp"
#include "tetseg/format/asset_io.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/pipeline.hpp"
#include "tetseg/preprocess/segmentation.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "tetseg/testing/charge_shapes.hpp"

using namespace tetseg::preprocess;

namespace {

/// A cluster's detector lies inside the body: an interior node, or the centroid of a tet of
/// the mesh with non-zero volume (strictly inside that tet), weights summing to 1.
void require_detector_inside(const TetMesh& mesh, const Surface& surface,
                             const tetseg::format::Cluster& cluster) {
  const auto& d = cluster.detector;
  if (d.is_node()) {
    REQUIRE(std::binary_search(surface.interior_nodes.begin(), surface.interior_nodes.end(),
                               d.nodes[0]));
    return;
  }
  REQUIRE(d.tet < mesh.tets.size());
  REQUIRE(mesh.tets[d.tet] == d.nodes);
  double sum = 0;
  for (double w : d.weights) {
    REQUIRE(w > 0.0);
    sum += w;
  }
  REQUIRE(sum == Approx(1.0).margin(1e-12));
  const auto& n = mesh.nodes;
  REQUIRE(tetseg::test::orient(n[d.nodes[0]], n[d.nodes[1]], n[d.nodes[2]], n[d.nodes[3]]) != 0.0);
}

const TetMesh& coarse_dumbbell() {
  static const TetMesh mesh = [] {
    ShapeOptions shape;
    shape.size = 0.6;
    return generate_shape(Shape::kDumbbell, shape);
  }();
  return mesh;
}

}  // namespace

TEST_CASE("The pipeline turns a dumbbell into a valid, loadable asset", "[pipeline]") {
  const TetMesh& mesh = coarse_dumbbell();
  BuildOptions options;
  BuildReport report;
  std::vector<std::string> stages;
  const tetseg::format::Asset asset =
      build_asset(mesh, "dir/dumbbell.mesh", options, report,
                  [&](const StageReport& stage) { stages.push_back(stage.name); });

  REQUIRE(stages == std::vector<std::string>{"surface", "charge", "equalize", "segmentation",
                                             "refinement", "detectors", "bvh"});
  const Surface surface = extract_surface(mesh);
  REQUIRE(asset.node_count == mesh.nodes.size());
  REQUIRE(asset.triangles == surface.triangles);
  REQUIRE(asset.rest_positions == mesh.nodes);
  REQUIRE(report.surface_triangles == surface.triangles.size());
  REQUIRE(report.clusters == asset.clusters.size());
  REQUIRE(report.rest_positive_fraction.size() == asset.clusters.size());
  // Memory per stage: the process peak never decreases, and a stage raises it by at most
  // the difference to the previous stage's peak.
  std::uint64_t previous_peak = 0;
  for (const StageReport& stage : report.stages) {
    CHECK(stage.peak_rss_bytes > 0);
    CHECK(stage.peak_rss_bytes >= previous_peak);
    CHECK(stage.peak_rss_growth_bytes <= stage.peak_rss_bytes - previous_peak);
    previous_peak = stage.peak_rss_bytes;
  }

  // Detectors are interior nodes or tet centroids, and every triangle is in exactly one
  // cluster.
  std::vector<int> seen(asset.triangles.size(), 0);
  for (std::size_t c = 0; c < asset.clusters.size(); ++c) {
    const auto& cluster = asset.clusters[c];
    require_detector_inside(mesh, surface, cluster);
    for (std::uint32_t i = 0; i < cluster.triangle_count; ++i) {
      const std::uint32_t t = asset.cluster_triangles[cluster.triangle_offset + i];
      ++seen[t];
      REQUIRE(asset.triangle_cluster[t] == c);
    }
  }
  REQUIRE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));

  // The provenance records every option (the defaults, written out here), the solver actually
  // used in place of "auto", the tool and the file name without directories.
  REQUIRE(asset.provenance.source == "dumbbell.mesh");
  REQUIRE(asset.provenance.tool_version.rfind("tetseg ", 0) == 0);
  REQUIRE((report.charge.solver == "direct" || report.charge.solver == "gmres" ||
           report.charge.solver == "fast"));
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"charge.fast_order", "auto"},
      {"charge.fast_theta", "auto"},
      {"charge.leaf_size", "32"},
      {"charge.max_iterations", "500"},
      {"charge.preconditioner", "two-level"},
      {"charge.relaxed_products", "yes"},
      {"charge.restart", "80"},
      {"charge.schwarz_set", "auto"},
      {"charge.solver", report.charge.solver},
      {"charge.tolerance", "auto"},
      {"clusters", "refined"},
      {"deviation.asset_to_input", "0"},  // a tet mesh is its own surface
      {"deviation.asset_to_input_absolute", "0"},
      {"deviation.input_to_asset", "0"},
      {"deviation.input_to_asset_absolute", "0"},
      {"refine.gain_per_cut_edge", "0.5"},
      {"refine.invisibility_cost", "1"},
      {"refine.max_clusters", "32"},
      {"refine.merge", "yes"},
      {"refine.min_cluster_triangles", "0"},
      {"refine.min_visibility", "0.98"},
      {"rest_positions", "yes"},
      {"segmentation.alpha", "0.1"},
      {"segmentation.beta_divisor", "400"},
      {"segmentation.detector", "visibility"},
      {"segmentation.equalization", "histogram"},
      {"segmentation.grow_through_marked", "yes"},
      {"segmentation.growth_bound", "0.25"},
      {"segmentation.min_cluster_triangles", "0"},
      {"segmentation.min_visibility", "0.5"},
  };
  REQUIRE(asset.provenance.options == expected);

  // The bytes load back into the same asset.
  const auto bytes = tetseg::format::write_asset(asset);
  tetseg::format::Asset loaded;
  std::string detail;
  REQUIRE(tetseg::format::read_asset(bytes.data(), bytes.size(), loaded, &detail) ==
          tetseg::format::Status::kOk);
  REQUIRE(tetseg::format::write_asset(loaded) == bytes);
}

TEST_CASE("Two builds with the same input and options give byte-identical assets", "[pipeline]") {
  const TetMesh& mesh = coarse_dumbbell();
  BuildOptions options;
  BuildReport first_report;
  BuildReport second_report;
  const auto first =
      tetseg::format::write_asset(build_asset(mesh, "a.mesh", options, first_report));
  const auto second =
      tetseg::format::write_asset(build_asset(mesh, "a.mesh", options, second_report));
  REQUIRE(first == second);

  options.segmentation.alpha = 0.05;
  BuildReport third_report;
  const auto third =
      tetseg::format::write_asset(build_asset(mesh, "a.mesh", options, third_report));
  REQUIRE(third != first);  // at least the provenance differs
}

namespace {

// Builds `mesh` with `options`, reads the options back from the asset's provenance, builds
// again with them and returns both assets' bytes.
std::pair<std::vector<std::uint8_t>, std::vector<std::uint8_t>> build_and_rebuild(
    const TetMesh& mesh, const BuildOptions& options, BuildOptions& recovered) {
  BuildReport first_report, second_report;
  const tetseg::format::Asset first = build_asset(mesh, "a.mesh", options, first_report);
  std::string error;
  REQUIRE(options_from_provenance(first.provenance.options, recovered, &error));
  INFO(error);
  const tetseg::format::Asset second = build_asset(mesh, "a.mesh", recovered, second_report);
  return {tetseg::format::write_asset(first), tetseg::format::write_asset(second)};
}

}  // namespace

TEST_CASE("An asset rebuilt from its provenance is byte-identical", "[pipeline][provenance]") {
  SECTION("Non-default charge, segmentation and refinement options.") {
    BuildOptions options;
    options.charge.solver = ChargeSolver::kGmres;
    options.charge.tolerance = 1e-7;
    options.charge.preconditioner = ChargePreconditioner::kBlock;
    options.segmentation.alpha = 0.05;
    options.segmentation.equalization = Equalization::kRank;
    options.segmentation.detector = DetectorStrategy::kNearestCentroid;
    options.refinement.min_visibility = 0.9;
    options.refinement.max_clusters = 7;
    options.keep_rest_positions = false;
    BuildOptions recovered;
    const auto [first, second] = build_and_rebuild(coarse_dumbbell(), options, recovered);
    CHECK(first == second);
    CHECK(recovered.charge.tolerance == 1e-7);
    CHECK(recovered.segmentation.detector == DetectorStrategy::kNearestCentroid);
    CHECK(recovered.refinement.max_clusters == 7);
    CHECK_FALSE(recovered.keep_rest_positions);
  }
  SECTION("Defaults: \"auto\" comes back as the solver that was used.") {
    BuildOptions recovered;
    const auto [first, second] = build_and_rebuild(coarse_dumbbell(), BuildOptions{}, recovered);
    CHECK(first == second);
    CHECK(recovered.charge.solver != ChargeSolver::kAuto);
  }
  SECTION("A tet mesh made from a surface: the meshing options are recorded and reused.") {
    const TriangleMesh surface = tetseg::test::icosphere(4);
    MeshingOptions meshing;
    meshing.facet_size = 0.3;
    meshing.optimize = false;
    BuildOptions options;
    options.clusters = ClusterMethod::kCharge;
    options.meshing = meshing;
    BuildReport report;
    const auto first =
        build_asset(tetrahedralize(surface, meshing, "ball.off"), "ball.off", options, report);
    BuildOptions recovered;
    std::string error;
    REQUIRE(options_from_provenance(first.provenance.options, recovered, &error));
    REQUIRE(recovered.meshing.has_value());
    CHECK(recovered.meshing->facet_size == 0.3);
    CHECK_FALSE(recovered.meshing->optimize);
    const auto second = build_asset(tetrahedralize(surface, *recovered.meshing, "ball.off"),
                                    "ball.off", recovered, report);
    CHECK(tetseg::format::write_asset(first) == tetseg::format::write_asset(second));
  }
  SECTION("A wrapped surface: the wrap options and the repairs are recorded and read back.") {
    tetseg::preprocess::TriangleMesh surface = tetseg::test::icosphere(3);
    surface.triangles.pop_back();  // a hole, which only the wrap closes
    MeshingOptions meshing;
    meshing.facet_size = 0.3;
    meshing.optimize = false;
    meshing.repair = MeshingOptions::Repair::kWrap;
    meshing.wrap_alpha = 0.25;
    TetrahedralizeNotes notes;
    const TetMesh mesh = tetrahedralize(surface, meshing, "holed.off", &notes);
    REQUIRE(notes.repairs.size() == 1);
    BuildOptions options;
    options.clusters = ClusterMethod::kSingle;
    options.meshing = meshing;
    options.repairs = notes.repairs;
    BuildReport report;
    const auto asset = build_asset(mesh, "holed.off", options, report);
    const auto& recorded = asset.provenance.options;
    auto value_of = [&](const std::string& key) {
      for (const auto& [k, v] : recorded)
        if (k == key) return v;
      return std::string("(absent)");
    };
    CHECK(value_of("meshing.repair") == "wrap");
    CHECK(value_of("meshing.wrap_alpha") == "0.25");
    CHECK(value_of("meshing.wrap_offset") == "0.002");
    CHECK(value_of("repairs.surface_replaced_by_an_alpha_wrap_of_this_many_triangles") ==
          std::to_string(notes.repairs[0].count));
    BuildOptions recovered;
    std::string error;
    REQUIRE(options_from_provenance(recorded, recovered, &error));
    REQUIRE(recovered.meshing.has_value());
    CHECK(recovered.meshing->repair == MeshingOptions::Repair::kWrap);
    CHECK(recovered.meshing->wrap_alpha == 0.25);
    REQUIRE(recovered.repairs.size() == 1);
    CHECK(recovered.repairs[0].kind == notes.repairs[0].kind);
    CHECK(recovered.repairs[0].count == notes.repairs[0].count);
  }
}

TEST_CASE("Provenance options that cannot be read back are refused", "[pipeline][provenance]") {
  BuildOptions options;
  std::string error;
  CHECK_FALSE(options_from_provenance({{"clusters", "many"}}, options, &error));
  CHECK(error == "bad value for clusters: 'many'");
  CHECK_FALSE(options_from_provenance({{"segmentation.alpha", "0.1x"}}, options, &error));
  CHECK_FALSE(options_from_provenance({{"refine.max_clusters", "-1"}}, options, &error));
  CHECK_FALSE(options_from_provenance({{"refine.max_clusters", "4294967296"}}, options, &error));
  REQUIRE(options_from_provenance({{"charge.fast_order", "-2"}}, options, &error));
  CHECK(options.charge.fast_order == -2);  // read as written; compute_charge judges it
  CHECK_FALSE(options_from_provenance({{"colour", "blue"}}, options, &error));
  CHECK(error == "unknown option colour: 'blue'");
  CHECK_FALSE(options_from_provenance({{"repairs.holes_filled", "some"}}, options, &error));
  REQUIRE(options_from_provenance({{"segmentation.alpha", "0.05"}}, options, &error));
  CHECK(options.segmentation.alpha == 0.05);
  CHECK(options.segmentation.beta_divisor == 400.0);  // not named: the default
}

TEST_CASE("StageTimer keeps its own copy of a temporary callback", "[pipeline]") {
  BuildReport report;
  std::vector<std::string> seen;
  StageTimer timer(report, [&](const StageReport& stage) { seen.push_back(stage.name); });
  // The lambda above was a temporary: calling it after the constructor must still work.
  const int value = timer.run("first", [](std::string& summary) {
    summary = "done";
    return 42;
  });
  CHECK(value == 42);
  timer.run("second", [](std::string&) { return 0; });
  CHECK(seen == std::vector<std::string>{"first", "second"});
  REQUIRE(report.stages.size() == 2);
  CHECK(report.stages[0].summary == "done");
}

TEST_CASE("StageTimer reports the peak RSS a stage reached and how much it raised it",
          "[pipeline]") {
  // Independent truth: the resident size now (/proc/self/statm) and a buffer of known size
  // touched in a stage, large enough to lift the process above its earlier peak.
  auto resident_bytes = [] {
    std::FILE* statm = std::fopen("/proc/self/statm", "r");
    REQUIRE(statm != nullptr);
    unsigned long long size = 0, resident = 0;
    REQUIRE(std::fscanf(statm, "%llu %llu", &size, &resident) == 2);
    std::fclose(statm);
    return static_cast<std::uint64_t>(resident) *
           static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
  };
  BuildReport report;
  StageTimer timer(report, nullptr);
  timer.run("idle", [](std::string&) { return 0; });
  const std::uint64_t peak_before = report.stages[0].peak_rss_bytes;
  const std::uint64_t resident = resident_bytes();
  REQUIRE(peak_before >= resident / 2);  // same quantity, up to pages freed since
  constexpr std::uint64_t kRaise = 48u << 20;
  const std::uint64_t size = (peak_before > resident ? peak_before - resident : 0) + kRaise;
  timer.run("allocate", [&](std::string&) {
    std::vector<char> buffer(size, 1);  // every page touched
    return static_cast<int>(buffer[size / 2]);
  });
  timer.run("after", [](std::string&) { return 0; });
  REQUIRE(report.stages.size() == 3);
  const StageReport& allocate = report.stages[1];
  CHECK(allocate.peak_rss_bytes >= resident + size - (4u << 20));
  CHECK(allocate.peak_rss_growth_bytes >= kRaise - (4u << 20));
  // Growth counts from the peak when the stage started, which the test's own code between
  // the two stages may have raised a little.
  CHECK(allocate.peak_rss_growth_bytes <= allocate.peak_rss_bytes - peak_before);
  CHECK(allocate.peak_rss_growth_bytes + (1u << 20) >= allocate.peak_rss_bytes - peak_before);
  // The buffer is gone: the next stage keeps the peak and does not raise it.
  CHECK(report.stages[2].peak_rss_bytes == allocate.peak_rss_bytes);
  CHECK(report.stages[2].peak_rss_growth_bytes == 0);
}

TEST_CASE(
    "Refined clusters are seen at least as well as the paper's, with fewer non-positive "
    "triangles in all",
    "[pipeline]") {
  BuildOptions options;
  options.clusters = ClusterMethod::kCharge;
  BuildReport charge_report, refined_report;
  const auto charge = build_asset(coarse_dumbbell(), "d.mesh", options, charge_report);
  options.clusters = ClusterMethod::kRefined;
  const auto refined = build_asset(coarse_dumbbell(), "d.mesh", options, refined_report);
  auto non_positive = [](const tetseg::format::Asset& asset) {
    double sum = 0.0;
    for (const auto& c : asset.clusters)
      sum += static_cast<double>(c.triangle_count) * (1.0 - c.rest_positive_fraction);
    return sum;
  };
  CHECK(non_positive(refined) <= non_positive(charge) + 1e-3);
  CHECK(refined_report.refinement.clusters_before == charge.clusters.size());
  CHECK(refined.clusters.size() == charge.clusters.size() + refined_report.refinement.splits -
                                       refined_report.refinement.merges);
  REQUIRE(tetseg::format::validate(refined) == tetseg::format::Status::kOk);
}

TEST_CASE("A single-cluster build skips charge and segmentation", "[pipeline]") {
  BuildOptions options;
  options.clusters = ClusterMethod::kSingle;
  options.keep_rest_positions = false;
  BuildReport report;
  const auto asset = build_asset(coarse_dumbbell(), "d.mesh", options, report);
  REQUIRE(asset.clusters.size() == 1);
  REQUIRE(asset.boundaries.empty());
  REQUIRE(asset.rest_positions.empty());
  REQUIRE(report.charge.solver.empty());
  for (const auto& stage : report.stages) REQUIRE(stage.name != "charge");
}

TEST_CASE("A tet mesh without interior nodes gets detector points inside tets", "[pipeline]") {
  SECTION("One tet: its centroid sees all four faces.") {
    TetMesh mesh;
    mesh.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    mesh.tets = {{0, 1, 2, 3}};
    BuildReport report;
    const auto asset = build_asset(mesh, "tet.mesh", BuildOptions{}, report);
    REQUIRE(asset.clusters.size() == 1);
    const auto& d = asset.clusters[0].detector;
    CHECK(d.tet == 0);
    CHECK(d.nodes == std::array<std::uint32_t, 4>{0, 1, 2, 3});
    CHECK(d.weights == std::array<double, 4>{0.25, 0.25, 0.25, 0.25});
    CHECK(asset.clusters[0].rest_positive_fraction == 1.0f);
    CHECK(asset.clusters[0].flags == 0);
  }
  SECTION("A mat one tet layer thick (no interior node) builds; every detector is inside.") {
    const TetMesh mesh = tetseg::test::kuhn_grid(12, 12, 1, [](int i, int j, int k) {
      return Vec3{0.1 * i, 0.1 * j, 0.02 * k};
    });
    const Surface surface = extract_surface(mesh);
    REQUIRE(surface.interior_nodes.empty());
    BuildReport report;
    const auto asset = build_asset(mesh, "mat.mesh", BuildOptions{}, report);
    REQUIRE(asset.clusters.size() >= 1);
    for (const auto& cluster : asset.clusters) require_detector_inside(mesh, surface, cluster);
    std::string why;
    REQUIRE(tetseg::format::validate(asset, &why) == tetseg::format::Status::kOk);
  }
  SECTION("With --min-visibility 1 every cluster not seen whole is flagged overlap-only.") {
    const TetMesh mesh = tetseg::test::kuhn_grid(12, 12, 1, [](int i, int j, int k) {
      return Vec3{0.1 * i, 0.1 * j, 0.02 * k};
    });
    BuildOptions options;
    options.segmentation.min_visibility = 1.0;
    BuildReport report;
    const auto asset = build_asset(mesh, "mat.mesh", options, report);
    for (const auto& cluster : asset.clusters) {
      CHECK(((cluster.flags & tetseg::format::kClusterOverlapOnly) != 0) ==
            (cluster.rest_positive_fraction < 1.0f));
    }
  }
}

TEST_CASE("A mesh with no interior node and no tet of non-zero volume is refused", "[pipeline]") {
  TetMesh mesh;
  mesh.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.tets = {{0, 1, 2, 3}};
  Surface surface = extract_surface(mesh);
  mesh.nodes[3] = {1, 1, 0};  // flat
  REQUIRE_THROWS_AS(
      choose_detector_points(mesh, surface, {0, 0, 0, 0}, 1, DetectorStrategy::kVisibility, 0.5),
      InputError);
}
