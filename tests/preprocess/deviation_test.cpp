// Issue 28: how far the asset's surface is from the input (the deviation, always measured)
// and every input ending (the time limit), through the build job as the CLI and Python run it.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "tetseg/preprocess/jobs.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/testing/charge_shapes.hpp"

using namespace tetseg::preprocess;

namespace {

std::string provenance_value(const tetseg::format::Asset& asset, const std::string& key) {
  for (const auto& [k, v] : asset.provenance.options)
    if (k == key) return v;
  return "(absent)";
}

BuildJobOptions single_cluster() {
  BuildJobOptions options;
  options.build.clusters = ClusterMethod::kSingle;
  return options;
}

}  // namespace

TEST_CASE("A tet-mesh input deviates by 0, recorded in the report and the provenance",
          "[deviation]") {
  ShapeOptions shape;
  shape.size = 0.5;
  const TetMesh mesh = generate_shape(Shape::kSphere, shape);
  const BuildJobResult result = build_asset_from_tet_mesh(mesh, "ball.mesh", single_cluster());
  CHECK(result.deviation.input_to_asset == 0.0);
  CHECK(result.deviation.asset_to_input == 0.0);
  CHECK(provenance_value(result.asset, "deviation.input_to_asset") == "0");
  CHECK(provenance_value(result.asset, "deviation.asset_to_input_absolute") == "0");
  const std::string report = build_report_json(result, "ball.mesh", "");
  CHECK(report.find("\"hausdorff\": {\"input_to_mesh\": 0, \"mesh_to_input\": 0") !=
        std::string::npos);
}

TEST_CASE(
    "A clean sphere's deviation is measured without any repair and lies within the "
    "documented default",
    "[deviation]") {
  // A unit sphere, 5120 triangles (chord error 1 - cos(edge / 2) ~ 1e-3 of the radius), meshed
  // at the default sizes (facet distance 1/400 of the diagonal): Mesh_3 puts its surface
  // vertices on the input, so both distances are about the facet distance, 0.0025 of the
  // diagonal, and never 0 (the boundary is re-meshed). docs/cli.md documents 0.001-0.003 and
  // the check is < 0.01, the median the issue asks of real meshes.
  const TriangleMesh sphere = tetseg::test::icosphere(16);
  BuildJobOptions options = single_cluster();
  const BuildJobResult result = build_asset_from_surface(sphere, "ball.off", options);
  REQUIRE(result.meshing_notes.repairs.empty());
  const SurfaceDeviation& d = result.deviation;
  CHECK(d.input_to_asset > 1e-5);
  CHECK(d.asset_to_input > 1e-5);
  CHECK(d.input_to_asset < 0.01);
  CHECK(d.asset_to_input < 0.01);
  // Absolute = relative x the diagonal (2 sqrt 3 for the unit sphere's box).
  CHECK(d.input_to_asset_absolute == Approx(d.input_to_asset * 2.0 * std::sqrt(3.0)).epsilon(1e-3));
  CHECK(std::stod(provenance_value(result.asset, "deviation.input_to_asset")) == d.input_to_asset);
  CHECK(std::stod(provenance_value(result.asset, "deviation.asset_to_input_absolute")) ==
        d.asset_to_input_absolute);
  // Provenance read back gives the same figures (an asset rebuilt from it is identical).
  BuildOptions recovered;
  std::string error;
  REQUIRE(options_from_provenance(result.asset.provenance.options, recovered, &error));
  REQUIRE(recovered.deviation.has_value());
  CHECK(recovered.deviation->asset_to_input == d.asset_to_input);
}

TEST_CASE("The deviation of a wrap is its offset (analytic)", "[deviation]") {
  // The alpha wrap of a sphere lies `offset` outside it; Mesh_3 re-meshes the wrap within its
  // facet distance. With offset 0.02 of the diagonal and a fine facet size (facet distance
  // 1/1000 of the diagonal), both distances are 0.02 within 0.004. --max-deviation caps the
  // offset at a quarter of it: 0.1 lets 0.02 through; the default 0.01 makes it 0.0025.
  const TriangleMesh sphere = tetseg::test::icosphere(16);
  BuildJobOptions options = single_cluster();
  options.meshing.repair = MeshingOptions::Repair::kWrap;
  options.meshing.wrap_offset = 0.02;
  options.meshing.max_deviation = 0.1;
  options.meshing.facet_size = 2.0 * std::sqrt(3.0) / 100.0;
  options.meshing.optimize = false;
  const BuildJobResult result = build_asset_from_surface(sphere, "ball.off", options);
  CHECK(result.deviation.input_to_asset == Approx(0.02).margin(0.004));
  CHECK(result.deviation.asset_to_input == Approx(0.02).margin(0.004));
  options.meshing.max_deviation = 0.01;
  const BuildJobResult capped = build_asset_from_surface(sphere, "ball.off", options);
  CHECK(capped.deviation.asset_to_input == Approx(0.0025).margin(0.0015));
}

TEST_CASE("A build past its time limit is refused with the stage named", "[time-limit]") {
  const TriangleMesh sphere = tetseg::test::icosphere(3);
  SECTION("Inside tetrahedralize: Mesh_3 is stopped") {
    MeshingOptions meshing;
    meshing.time_limit = 1e-3;
    try {
      tetrahedralize(sphere, meshing, "ball.off");
      FAIL("no TimeLimitExceeded");
    } catch (const TimeLimitExceeded& e) {
      CHECK(e.file() == "ball.off");
      CHECK(std::string(e.what()).find("tetrahedralize: time limit of 0.001 s reached in ") == 0);
    }
  }
  SECTION("Between the stages of a tet-mesh build, before anything is written") {
    ShapeOptions shape;
    shape.size = 0.5;
    BuildJobOptions options;
    options.time_limit = 1e-9;
    bool written = false;
    options.write_output = [&](const std::vector<std::uint8_t>&) { written = true; };
    try {
      build_asset_from_tet_mesh(generate_shape(Shape::kSphere, shape), "ball.mesh", options);
      FAIL("no TimeLimitExceeded");
    } catch (const TimeLimitExceeded& e) {
      CHECK(std::string(e.what()).find("time limit of 1e-09 s reached in stage read") == 0);
    }
    CHECK_FALSE(written);
  }
  SECTION("Range-checked, like every numeric option") {
    BuildJobOptions options;
    options.time_limit = -1.0;
    CHECK_THROWS_AS(validate_options(options), std::invalid_argument);
    options.time_limit = 0.0;  // no limit
    CHECK_NOTHROW(validate_options(options));
  }
}

TEST_CASE("The maximum deviation bounds the re-meshing, and says by how much an input exceeds it",
          "[deviation][max-deviation]") {
  const TriangleMesh sphere = tetseg::test::icosphere(16);
  SECTION("A tighter bound halves the facet distance it derives: the sphere stays within it") {
    MeshingOptions loose, tight;
    loose.optimize = tight.optimize = false;
    tight.max_deviation = 0.0015;  // facet distance 0.00075 of the diagonal instead of 0.0025
    TetrahedralizeNotes at_default, at_tight;
    tetrahedralize(sphere, loose, "ball.off", &at_default);
    tetrahedralize(sphere, tight, "ball.off", &at_tight);
    const auto larger = [](const TetrahedralizeNotes& n) {
      return std::max(n.hausdorff_input_to_mesh, n.hausdorff_mesh_to_input);
    };
    CHECK(larger(at_tight) < larger(at_default));
    CHECK(larger(at_tight) <= 0.0015);
    CHECK(at_tight.deviation_excess == 0.0);
    CHECK(at_default.deviation_excess == 0.0);  // within the default 0.01
  }
  SECTION("A sheet wrapped as a slab cannot stay within 0.005: the excess is reported") {
    TriangleMesh square;
    square.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    square.triangles = {{0, 1, 2}, {0, 2, 3}};
    MeshingOptions m;
    m.repair = MeshingOptions::Repair::kWrap;
    m.max_deviation = 0.005;
    m.optimize = false;
    TetrahedralizeNotes notes;
    tetrahedralize(square, m, "sheet.off", &notes);
    // The slab's faces lie wrap_sheet_offset (0.01 of the diagonal) from the sheet.
    const double larger = std::max(notes.hausdorff_input_to_mesh, notes.hausdorff_mesh_to_input);
    CHECK(larger == Approx(0.01).margin(0.004));
    CHECK(notes.deviation_excess == Approx(larger - 0.005).margin(1e-12));
  }
  SECTION("Range-checked") {
    BuildJobOptions options;
    options.meshing.max_deviation = 0.0;
    CHECK_THROWS_AS(validate_options(options), std::invalid_argument);
  }
}
