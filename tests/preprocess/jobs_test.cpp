// The offline jobs (tetseg/preprocess/jobs.hpp) and the option ranges they validate
// (tetseg/preprocess/option_ranges.hpp).

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "tetseg/format/asset_io.hpp"
#include "tetseg/preprocess/jobs.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/option_ranges.hpp"
#include "tetseg/preprocess/pipeline.hpp"
#include "tetseg/preprocess/surface.hpp"

using namespace tetseg::preprocess;

namespace {

const TetMesh& small_sphere() {
  static const TetMesh mesh = [] {
    ShapeOptions shape;
    shape.size = 0.4;
    return generate_shape(Shape::kSphere, shape);
  }();
  return mesh;
}

}  // namespace

TEST_CASE("A range admits its ends and refuses what lies beyond them, and NaN", "[jobs]") {
  const OptionRange& tolerance = option_ranges::kTolerance;
  CHECK(in_range(tolerance, 0.0));
  CHECK(in_range(tolerance, 0.5));
  CHECK_FALSE(in_range(tolerance, 0.5000001));
  CHECK_FALSE(in_range(tolerance, -1e-300));
  CHECK_FALSE(in_range(tolerance, std::nan("")));
  const OptionRange& beta = option_ranges::kBetaDivisor;  // (0, inf]
  CHECK_FALSE(in_range(beta, 0.0));
  CHECK(in_range(beta, 1e-9));
  CHECK_THROWS_WITH(check_option(beta, 0.0), "beta_divisor must be positive, got 0");
  CHECK_THROWS_WITH(check_option(option_ranges::kAlpha, 7.0), "alpha must be in [0, 1], got 7");
  CHECK_NOTHROW(check_option(option_ranges::kCellSize, std::numeric_limits<double>::infinity()));
}

TEST_CASE("The library refuses the option values the front ends refuse", "[jobs]") {
  // Before issue 27, compute_charge accepted a tolerance and a theta up to 1 that both front
  // ends refused above 0.5 and 0.95.
  ChargeOptions charge;
  charge.tolerance = 0.7;
  CHECK_THROWS_AS(
      compute_charge(small_sphere().nodes, extract_surface(small_sphere()).triangles, charge),
      std::invalid_argument);
  charge.tolerance = 0.0;
  charge.fast_theta = 0.96;
  CHECK_THROWS_AS(
      compute_charge(small_sphere().nodes, extract_surface(small_sphere()).triangles, charge),
      std::invalid_argument);

  BuildJobOptions build;
  CHECK_NOTHROW(validate_options(build));  // the defaults lie in their ranges
  build.build.segmentation.growth_bound = 1.5;
  CHECK_THROWS_WITH(validate_options(build), "growth_bound must be in [0, 1], got 1.5");
  build = BuildJobOptions{};
  build.meshing.wrap_alpha = 0.0;
  CHECK_THROWS_WITH(build_asset_from_tet_mesh(small_sphere(), "sphere.mesh", build),
                    "wrap_alpha must be in [0.0001, 1], got 0");
  ChargeJobOptions charge_job;
  CHECK_NOTHROW(validate_options(charge_job));
  charge_job.bins = 0;
  CHECK_THROWS_WITH(validate_options(charge_job), "bins must be in [1, 1048576], got 0");
}

TEST_CASE("A build job gives the asset build_asset gives, with every stage reported", "[jobs]") {
  BuildJobOptions options;
  options.build.clusters = ClusterMethod::kCharge;
  std::vector<std::string> seen;
  std::vector<std::uint8_t> written;
  options.write_output = [&](const std::vector<std::uint8_t>& bytes) { written = bytes; };
  options.output_name = "out.tetseg";
  const BuildJobResult result =
      build_asset_from_tet_mesh(small_sphere(), "sphere.mesh", options,
                                [&](const StageReport& stage) { seen.push_back(stage.name); });

  BuildReport report;
  const auto expected = tetseg::format::write_asset(
      build_asset(small_sphere(), "sphere.mesh", options.build, report));
  CHECK(result.asset_bytes == expected);
  CHECK(written == expected);
  CHECK_FALSE(result.surface_input);
  const std::vector<std::string> stages = {"read",         "surface",   "charge", "equalize",
                                           "segmentation", "detectors", "bvh",    "write"};
  CHECK(seen == stages);
  REQUIRE(result.report.stages.size() == stages.size());
  CHECK(result.report.stages.back().summary ==
        "out.tetseg (" + std::to_string(expected.size()) + " bytes)");
  const std::string json = build_report_json(result, "in.mesh", "");
  CHECK(json.find("\"output\"") == std::string::npos);
  CHECK(json.find("\"repairs\"") == std::string::npos);  // a tet mesh: nothing repaired
  CHECK(json.find("\"input\": \"in.mesh\"") != std::string::npos);
}

TEST_CASE("A surface build job reports its repairs, and charge jobs agree on arrays and files",
          "[jobs]") {
  // The boundary of the sphere's tets, with one triangle given twice: fix removes it.
  const TetMesh& sphere = small_sphere();
  TriangleMesh surface{sphere.nodes, extract_surface(sphere).triangles};
  surface.triangles.push_back(surface.triangles.front());
  BuildJobOptions options;
  options.build.clusters = ClusterMethod::kSingle;
  options.meshing.optimize = false;
  options.meshing.facet_size = 0.3;  // a coarse mesh: the test is about the report
  const BuildJobResult result = build_asset_from_surface(surface, "sphere.off", options);
  CHECK(result.surface_input);
  REQUIRE_FALSE(result.meshing_notes.repairs.empty());
  CHECK(result.report.stages[1].name == "tetrahedralize");
  const std::string json = build_report_json(result, "sphere.off", "sphere.tetseg");
  CHECK(json.find("\"repairs\": {\"duplicate triangles removed\": ") != std::string::npos);
  CHECK(json.find("\"hausdorff\": {\"input_to_mesh\": ") != std::string::npos);

  ChargeJobOptions charge;
  charge.charge.solver = ChargeSolver::kDirect;
  const ChargeJobResult from_tets = charge_tet_mesh(sphere, "sphere.mesh", charge);
  const ChargeJobResult from_surface =
      charge_surface(TriangleMesh{sphere.nodes, extract_surface(sphere).triangles}, "s", charge);
  CHECK(from_tets.charge.density == from_surface.charge.density);
  CHECK(from_tets.equalized.size() == from_tets.triangles.size());
  REQUIRE(from_tets.report.stages.size() == 2);
  CHECK(charge_report_json(from_tets, "sphere.mesh").find("\"peak_rss_bytes\": {\"read\": ") !=
        std::string::npos);
}
