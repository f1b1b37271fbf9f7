// The offline jobs (jobs.hpp): build and charge, from a file or arrays, and their reports.

#include "tetseg/preprocess/jobs.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <sstream>
#include <utility>

#include "tetseg/format/asset_io.hpp"
#include "tetseg/format/asset_json.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/preprocess/names.hpp"
#include "tetseg/preprocess/option_ranges.hpp"
#include "tetseg/preprocess/skin.hpp"
#include "tetseg/preprocess/surface.hpp"

namespace tetseg::preprocess {
namespace {

using Clock = std::chrono::steady_clock;
namespace range = option_ranges;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string count_text(std::size_t count, const char* what) {
  return std::to_string(count) + " " + what;
}

std::string tet_mesh_summary(const TetMesh& mesh) {
  return count_text(mesh.nodes.size(), "nodes") + ", " + count_text(mesh.tets.size(), "tets");
}

/// What a build starts from: a tet mesh, or a surface to tetrahedralise.
struct BuildInput {
  bool is_surface = false;
  TetMesh tet_mesh;
  TriangleMesh surface;
  std::optional<Skin> skin;  ///< --detectors skin: the input's skin
  /// --body surface from a reader that merges vertices (STL, glTF, FBX, ...): each file
  /// vertex's vertex (read_triangle_mesh_keeping_vertices); else empty.
  std::vector<std::uint32_t> source_vertex_nodes;
};

/// Records in a surface asset which node each vertex of the input file became, unless the
/// reader kept the file's vertices as they are (no map, or the identity).
void set_source_vertex_nodes(format::Asset& asset, std::vector<std::uint32_t> map) {
  if (map.empty()) return;
  bool identity = map.size() == asset.node_count;
  for (std::size_t i = 0; identity && i < map.size(); ++i) identity = map[i] == i;
  if (identity) return;
  asset.source_vertex_nodes = std::move(map);
  std::string detail;
  if (format::validate(asset, &detail) != format::Status::kOk)
    throw std::runtime_error("internal error: the source vertex map does not validate: " + detail);
}

/// The stages after read: [tetrahedralize,] build_asset's, write.
BuildJobResult run_build(const std::function<BuildInput(std::string& summary)>& read,
                         const std::string& source, const BuildJobOptions& options,
                         const StageCallback& on_stage) {
  validate_options(options);
  const auto start = Clock::now();
  // The time limit, checked after every stage but the last ("write": the output exists then).
  const auto seconds_left = [&] { return options.time_limit - seconds_since(start); };
  const StageCallback checked_on_stage = [&](const StageReport& stage) {
    if (on_stage) on_stage(stage);
    if (options.time_limit > 0.0 && stage.name != "write" && seconds_left() <= 0.0) {
      char text[160];
      std::snprintf(text, sizeof text,
                    "time limit of %g s reached in stage %s (%.1f s in all); nothing was "
                    "written (raise --time-limit)",
                    options.time_limit, stage.name.c_str(), seconds_since(start));
      throw TimeLimitExceeded(source, text);
    }
  };
  BuildJobResult result;
  StageTimer timer(result.report, checked_on_stage);
  BuildInput input = timer.run("read", read);
  result.surface_input = input.is_surface;
  BuildOptions build = options.build;
  build.meshing.reset();
  build.repairs.clear();
  if (build.body == format::BodyKind::kSurface) {
    if (!input.is_surface)
      throw InputError(source,
                       "--body surface builds from a surface file (.obj, .ply, .off, ...), not "
                       "a tet mesh");
    if (detector_form_of(build) == format::DetectorForm::kBones) {
      // The surface pipeline chooses the clusters and detector points; the skin then carries
      // them (skin.hpp).
      if (!input.skin)
        throw std::invalid_argument("--detectors skin reads the skin from the input file");
      BuildOptions weights = build;
      weights.detectors = format::DetectorForm::kSurfaceWeights;
      result.asset =
          build_surface_asset(input.surface, source, weights, result.report, checked_on_stage);
      timer.run("skin", [&](std::string& summary) {
        carry_detectors_by_bones(result.asset, input.surface.vertices, *input.skin, source);
        for (auto& [key, value] : result.asset.provenance.options)
          if (key == "detectors") value = name_of(format::DetectorForm::kBones);
        summary = count_text(input.skin->bone_names.size(), "bones") + ", " +
                  count_text(result.asset.detector_terms.size(), "detector terms");
        return 0;
      });
    } else {
      result.asset =
          build_surface_asset(input.surface, source, build, result.report, checked_on_stage);
    }
    set_source_vertex_nodes(result.asset, std::move(input.source_vertex_nodes));
  } else if (input.is_surface) {
    // tetrahedralize alone judges the surface (with its own rules: pinch points accepted), so
    // that a build accepts exactly the surfaces `tetseg tetrahedralize` accepts.
    input.tet_mesh = timer.run("tetrahedralize", [&](std::string& summary) {
      MeshingOptions meshing = options.meshing;
      // The time left, at least a millisecond (0 would mean no limit).
      meshing.time_limit = options.time_limit > 0.0 ? std::max(seconds_left(), 1e-3) : 0.0;
      TetMesh mesh;
      try {
        mesh = tetrahedralize(input.surface, meshing, source, &result.meshing_notes);
      } catch (const TimeLimitExceeded& e) {
        // Named with the build's limit (tetrahedralize had the time left) and its step.
        const std::string inner = e.what();
        const auto from = inner.find("reached in ");
        const std::string step =
            from == std::string::npos ? "" : inner.substr(from + 11, inner.find(';') - from - 11);
        char text[96];
        std::snprintf(text, sizeof text, "time limit of %g s reached in stage tetrahedralize",
                      options.time_limit);
        throw TimeLimitExceeded(source, text + (step.empty() ? "" : ", in " + step) +
                                            "; nothing was written (raise --time-limit, give "
                                            "larger meshing sizes, or try --repair wrap)");
      }
      summary = tet_mesh_summary(mesh) + ", " + deviation_summary(result.meshing_notes);
      return mesh;
    });
    input.surface = TriangleMesh{};
    build.meshing = options.meshing;  // recorded in the provenance, with the repairs
    build.repairs = result.meshing_notes.repairs;
    const TetrahedralizeNotes& notes = result.meshing_notes;
    if (options.meshing.repair == MeshingOptions::Repair::kAuto) {
      build.repair_used = name_of(notes.repair_used);
      build.fallback_reason = notes.fallback_reason;
    }
    if (notes.hausdorff_input_to_mesh >= 0.0)
      result.deviation = {notes.hausdorff_input_to_mesh,
                          notes.hausdorff_mesh_to_input,
                          notes.hausdorff_input_to_mesh * notes.diagonal,
                          notes.hausdorff_mesh_to_input * notes.diagonal,
                          notes.deviation_excess,
                          static_cast<int>(notes.deviation_retries)};
  }
  build.deviation = result.deviation;  // a tet-mesh input: 0, its boundary is the surface
  if (build.body == format::BodyKind::kTet)
    result.asset = build_asset(input.tet_mesh, source, build, result.report, checked_on_stage);
  result.asset_bytes = timer.run("write", [&](std::string& summary) {
    std::vector<std::uint8_t> bytes = format::write_asset(result.asset);
    if (options.write_output) options.write_output(bytes);
    summary = (options.output_name.empty() ? "" : options.output_name + " (") +
              count_text(bytes.size(), "bytes") + (options.output_name.empty() ? "" : ")");
    return bytes;
  });
  result.total_seconds = seconds_since(start);
  return result;
}

BuildInput read_tet_mesh_input(TetMesh mesh, std::string& summary) {
  summary = tet_mesh_summary(mesh);
  BuildInput input;
  input.tet_mesh = std::move(mesh);
  return input;
}

BuildInput read_surface_input(TriangleMesh surface, std::string& summary) {
  summary = count_text(surface.vertices.size(), "vertices") + ", " +
            count_text(surface.triangles.size(), "triangles (surface)");
  BuildInput input;
  input.is_surface = true;
  input.surface = std::move(surface);
  return input;
}

/// The surface a charge job solves on: a tet mesh's validated boundary, or a closed surface
/// validated as given.
struct ChargeSurface {
  std::vector<Vec3> points;
  std::vector<Tri> triangles;
};

ChargeSurface tet_mesh_boundary(TetMesh mesh, const std::string& source) {
  const Surface surface = extract_valid_surface(mesh, source);
  return {std::move(mesh.nodes), surface.triangles};
}

ChargeSurface validated_surface(TriangleMesh mesh, const std::string& source) {
  validate_closed_surface(mesh, source);
  return {std::move(mesh.vertices), std::move(mesh.triangles)};
}

ChargeJobResult run_charge(const std::function<ChargeSurface()>& read,
                           const ChargeJobOptions& options, const std::string& source,
                           const StageCallback& on_stage) {
  validate_options(options);
  ChargeJobResult result;
  result.equalization = options.equalization;
  StageTimer timer(result.report, on_stage);
  timer.run("read", [&](std::string& summary) {
    ChargeSurface surface = read();
    result.points = std::move(surface.points);
    result.triangles = std::move(surface.triangles);
    summary = count_text(result.triangles.size(), "surface triangles");
    return 0;
  });
  timer.run("charge", [&](std::string& summary) {
    result.charge = compute_charge(result.points, result.triangles, options.charge, source);
    result.equalized = equalize(result.charge.density, options.equalization, options.bins);
    const ChargeResult& r = result.charge;
    std::ostringstream text;
    text.precision(3);
    text << r.solver << ", " << r.iterations << " iterations (" << r.relaxed_products
         << " relaxed), residual " << r.residual << ", capacitance " << r.capacitance
         << " (assembly " << r.assembly_seconds << " s, solve " << r.solve_seconds << " s)";
    summary = text.str();
    return 0;
  });
  return result;
}

/// `"name": value` per stage of `stages`, comma-separated, of the member `field`.
template <typename Field>
void stage_members(std::ostream& out, const std::vector<StageReport>& stages, Field field) {
  for (std::size_t i = 0; i < stages.size(); ++i)
    out << (i ? ", " : "") << '"' << stages[i].name << "\": " << field(stages[i]);
}

}  // namespace

void validate_options(const BuildJobOptions& options) {
  const BuildOptions& b = options.build;
  check_option(range::kTolerance, b.charge.tolerance);
  check_option(range::kMaxIterations, b.charge.max_iterations);
  check_option(range::kTheta, b.charge.fast_theta);
  check_option(range::kOrder, b.charge.fast_order);
  check_option(range::kAlpha, b.segmentation.alpha);
  check_option(range::kBetaDivisor, b.segmentation.beta_divisor);
  check_option(range::kGrowthBound, b.segmentation.growth_bound);
  check_option(range::kMinVisibility, b.segmentation.min_visibility);
  check_option(range::kRefineVisibility, b.refinement.min_visibility);
  check_option(range::kRefineMaxClusters, b.refinement.max_clusters);
  check_option(range::kRefineGain, b.refinement.gain_per_cut_edge);
  const MeshingOptions& m = options.meshing;
  check_option(range::kCellSize, m.cell_size);
  check_option(range::kFacetSize, m.facet_size);
  check_option(range::kFacetDistance, m.facet_distance);
  check_option(range::kThreads, m.threads);
  check_option(range::kWrapAlpha, m.wrap_alpha);
  check_option(range::kWrapOffset, m.wrap_offset);
  check_option(range::kWrapSheetOffset, m.wrap_sheet_offset);
  check_option(range::kMaxDeviation, m.max_deviation);
  check_option(range::kTimeLimit, options.time_limit);
  const format::DetectorForm form = detector_form_of(b);
  if (b.body == format::BodyKind::kTet && form != format::DetectorForm::kTetPoint)
    throw std::invalid_argument(std::string("--detectors ") + name_of(form) +
                                " needs --body surface");
  if (b.body == format::BodyKind::kSurface && form == format::DetectorForm::kTetPoint)
    throw std::invalid_argument("--body surface takes --detectors weights or skin");
}

void validate_options(const ChargeJobOptions& options) {
  check_option(range::kTolerance, options.charge.tolerance);
  check_option(range::kMaxIterations, options.charge.max_iterations);
  check_option(range::kTheta, options.charge.fast_theta);
  check_option(range::kOrder, options.charge.fast_order);
  check_option(range::kBins, options.bins);
}

BuildJobResult build_asset_from_file(const std::string& path, const BuildJobOptions& options,
                                     const StageCallback& on_stage, const std::string& source) {
  const std::string& name = source.empty() ? path : source;
  return run_build(
      [&](std::string& summary) {
        if (is_tet_mesh_path(path)) return read_tet_mesh_input(read_tet_mesh(path), summary);
        std::vector<std::uint32_t> source_vertex_nodes;
        BuildInput input =
            read_surface_input(options.build.body == format::BodyKind::kSurface
                                   ? read_triangle_mesh_keeping_vertices(path, &source_vertex_nodes)
                                   : read_triangle_mesh(path),
                               summary);
        input.source_vertex_nodes = std::move(source_vertex_nodes);
        if (detector_form_of(options.build) == format::DetectorForm::kBones) {
          input.skin = read_skin(path);
          summary += ", skin of " + count_text(input.skin->bone_names.size(), "bones");
        }
        return input;
      },
      name, options, on_stage);
}

BuildJobResult build_asset_from_tet_mesh(TetMesh mesh, const std::string& source,
                                         const BuildJobOptions& options,
                                         const StageCallback& on_stage) {
  return run_build(
      [&](std::string& summary) { return read_tet_mesh_input(std::move(mesh), summary); }, source,
      options, on_stage);
}

BuildJobResult build_asset_from_surface(TriangleMesh surface, const std::string& source,
                                        const BuildJobOptions& options,
                                        const StageCallback& on_stage) {
  return run_build(
      [&](std::string& summary) { return read_surface_input(std::move(surface), summary); }, source,
      options, on_stage);
}

ChargeJobResult charge_from_file(const std::string& path, const ChargeJobOptions& options,
                                 const StageCallback& on_stage, const std::string& source) {
  const std::string& name = source.empty() ? path : source;
  return run_charge(
      [&] {
        return is_tet_mesh_path(path) ? tet_mesh_boundary(read_tet_mesh(path), name)
                                      : validated_surface(read_triangle_mesh(path), name);
      },
      options, name, on_stage);
}

ChargeJobResult charge_tet_mesh(TetMesh mesh, const std::string& source,
                                const ChargeJobOptions& options, const StageCallback& on_stage) {
  return run_charge([&] { return tet_mesh_boundary(std::move(mesh), source); }, options, source,
                    on_stage);
}

ChargeJobResult charge_surface(TriangleMesh surface, const std::string& source,
                               const ChargeJobOptions& options, const StageCallback& on_stage) {
  return run_charge([&] { return validated_surface(std::move(surface), source); }, options, source,
                    on_stage);
}

std::string build_report_json(const BuildJobResult& result, const std::string& input,
                              const std::string& output) {
  using format::json_escape;
  const BuildReport& report = result.report;
  const format::Asset& asset = result.asset;
  std::ostringstream out;
  out.precision(9);
  out << "{\n  \"input\": \"" << json_escape(input) << "\",\n";
  if (!output.empty()) out << "  \"output\": \"" << json_escape(output) << "\",\n";
  out << "  \"asset_bytes\": " << result.asset_bytes.size() << ",\n";
  out << "  \"body\": \"" << name_of(asset.body_kind) << "\", \"detectors\": \""
      << name_of(asset.detector_form) << "\",\n";
  out << "  \"seconds\": {";
  stage_members(out, report.stages, [](const StageReport& s) { return s.seconds; });
  out << ", \"total\": " << result.total_seconds << "},\n";
  // Process peak RSS at the end of each stage, and how much each stage raised it (docs/cli.md).
  out << "  \"peak_rss_bytes\": {";
  stage_members(out, report.stages, [](const StageReport& s) { return s.peak_rss_bytes; });
  out << "},\n  \"peak_rss_growth_bytes\": {";
  stage_members(out, report.stages, [](const StageReport& s) { return s.peak_rss_growth_bytes; });
  out << "},\n";
  out << "  \"counts\": {\"nodes\": " << report.nodes << ", \"tets\": " << report.tets
      << ", \"surface_triangles\": " << report.surface_triangles
      << ", \"interior_nodes\": " << report.interior_nodes
      << ", \"components\": " << report.components << ", \"clusters\": " << report.clusters
      << ", \"boundaries\": " << report.boundaries << "},\n";
  const SegmentationCounts& seg = report.segmentation;
  out << "  \"segmentation\": {\"segments_found\": " << seg.segments_found
      << ", \"segments_grown\": " << seg.segments_grown
      << ", \"segments_shrunk\": " << seg.segments_shrunk << ", \"boundaries\": " << seg.boundaries
      << ", \"clusters\": " << seg.clusters << ", \"clusters_merged\": " << seg.clusters_merged
      << "},\n";
  out << "  \"refinement\": {\"clusters_before\": " << report.refinement.clusters_before
      << ", \"splits\": " << report.refinement.splits
      << ", \"merges\": " << report.refinement.merges << "},\n";
  if (!report.charge.solver.empty()) {
    const ChargeResult& c = report.charge;
    out << "  \"charge\": {\"solver\": \"" << c.solver << "\", \"tolerance\": " << c.tolerance
        << ", \"converged\": " << (c.converged ? "true" : "false")
        << ", \"iterations\": " << c.iterations << ", \"relaxed_products\": " << c.relaxed_products
        << ", \"residual\": " << c.residual << ", \"capacitance\": " << c.capacitance
        << ", \"assembly_seconds\": " << c.assembly_seconds
        << ", \"solve_seconds\": " << c.solve_seconds << "},\n";
  }
  // How far the asset's surface is from the input's, always (docs/cli.md, "Deviation").
  const SurfaceDeviation& d = result.deviation;
  out << "  \"hausdorff\": {\"input_to_mesh\": " << d.input_to_asset
      << ", \"mesh_to_input\": " << d.asset_to_input
      << ", \"relative_to\": \"input bounding-box diagonal\", \"input_to_mesh_absolute\": "
      << d.input_to_asset_absolute << ", \"mesh_to_input_absolute\": " << d.asset_to_input_absolute
      << "},\n";
  // Surface input: what the repair changed (docs/cli.md, "Repair").
  if (result.surface_input) {
    const TetrahedralizeNotes& notes = result.meshing_notes;
    out << "  \"repairs\": {";
    for (std::size_t i = 0; i < notes.repairs.size(); ++i)
      out << (i ? ", " : "") << '"' << json_escape(notes.repairs[i].kind)
          << "\": " << notes.repairs[i].count;
    out << "},\n";
    out << "  \"repair_used\": \"" << name_of(notes.repair_used) << "\",\n";
    // Over --max-deviation (options: meshing.max_deviation) by this much; 0 within it.
    out << "  \"deviation_excess\": " << notes.deviation_excess << ",\n";
    // Mesh_3 runs repeated at smaller sizes to stay within it, and the sizes kept.
    out << "  \"deviation_retries\": " << notes.deviation_retries << ",\n";
    if (!notes.deviation_retry_sizes.empty())
      out << "  \"deviation_retry_sizes\": \"" << json_escape(notes.deviation_retry_sizes)
          << "\",\n";
    if (!notes.fallback_reason.empty())
      out << "  \"fallback_reason\": \"" << json_escape(notes.fallback_reason) << "\",\n";
    if (!notes.optimization_used.empty())
      out << "  \"meshing_retry\": \"" << json_escape(notes.optimization_used) << "\",\n";
  }
  out << "  \"clusters\": [";
  for (std::size_t c = 0; c < asset.clusters.size(); ++c) {
    out << (c ? ",\n    " : "\n    ") << "{\"triangles\": " << asset.clusters[c].triangle_count
        << ", " << format::detector_json(asset, asset.clusters[c])
        << ", \"rest_positive_fraction\": " << asset.clusters[c].rest_positive_fraction << "}";
  }
  out << "\n  ],\n  \"options\": " << format::provenance_options_json(asset) << "\n}\n";
  return out.str();
}

std::string charge_report_json(const ChargeJobResult& result, const std::string& input) {
  const ChargeResult& r = result.charge;
  std::ostringstream j;
  j.precision(10);
  j << "{\n  \"input\": \"" << format::json_escape(input)
    << "\",\n  \"triangles\": " << result.triangles.size() << ",\n  \"solver\": \"" << r.solver
    << "\",\n  \"iterations\": " << r.iterations
    << ",\n  \"relaxed_products\": " << r.relaxed_products << ",\n  \"residual\": " << r.residual
    << ",\n  \"converged\": " << (r.converged ? "true" : "false")
    << ",\n  \"tolerance\": " << r.tolerance << ",\n  \"capacitance\": " << r.capacitance
    << ",\n  \"total_area\": " << r.total_area << ",\n  \"equalization\": \""
    << name_of(result.equalization) << "\",\n  \"assembly_seconds\": " << r.assembly_seconds
    << ",\n  \"solve_seconds\": " << r.solve_seconds;
  j << ",\n  \"peak_rss_bytes\": {";
  stage_members(j, result.report.stages, [](const StageReport& s) { return s.peak_rss_bytes; });
  j << "},\n  \"peak_rss_growth_bytes\": {";
  stage_members(j, result.report.stages,
                [](const StageReport& s) { return s.peak_rss_growth_bytes; });
  j << "}\n}\n";
  return j.str();
}

}  // namespace tetseg::preprocess
