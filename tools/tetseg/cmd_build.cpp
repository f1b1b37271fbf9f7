// `tetseg build`: the whole pipeline from a mesh file to an asset.

#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "mesh_output.hpp"
#include "tetseg/format/asset_io.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/names.hpp"
#include "tetseg/preprocess/pipeline.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "tool_support.hpp"

namespace tetseg::tools {
namespace {

using namespace tetseg::preprocess;

struct BuildArgs {
  std::string input;
  std::string output;
  std::string report_path;
  BuildOptions options;
  MeshingOptions meshing;
  bool no_rest_positions = false;
  bool quiet = false;
};

void print_stage(const StageReport& stage, bool quiet) {
  if (quiet) return;
  std::fprintf(stderr, "tetseg: %-13s %8.3f s  %s\n", stage.name.c_str(), stage.seconds,
               stage.summary.c_str());
}

std::string report_json(const BuildArgs& args, const BuildReport& report,
                        const TetrahedralizeNotes& notes, const format::Asset& asset,
                        std::size_t asset_bytes, double total) {
  std::ostringstream out;
  out.precision(9);
  out << "{\n  \"input\": \"" << json_escape(args.input) << "\",\n";
  out << "  \"output\": \"" << json_escape(args.output) << "\",\n";
  out << "  \"asset_bytes\": " << asset_bytes << ",\n";
  out << "  \"seconds\": {";
  for (std::size_t i = 0; i < report.stages.size(); ++i) {
    out << (i ? ", " : "") << '"' << report.stages[i].name << "\": " << report.stages[i].seconds;
  }
  out << ", \"total\": " << total << "},\n";
  // Process peak RSS at the end of each stage, and how much each stage raised it (docs/cli.md).
  out << "  \"peak_rss_bytes\": {";
  for (std::size_t i = 0; i < report.stages.size(); ++i)
    out << (i ? ", " : "") << '"' << report.stages[i].name
        << "\": " << report.stages[i].peak_rss_bytes;
  out << "},\n  \"peak_rss_growth_bytes\": {";
  for (std::size_t i = 0; i < report.stages.size(); ++i)
    out << (i ? ", " : "") << '"' << report.stages[i].name
        << "\": " << report.stages[i].peak_rss_growth_bytes;
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
  // Surface input: what the repair changed and what it cost (docs/cli.md, "Repair").
  if (!is_tet_mesh_path(args.input)) {
    out << "  \"repairs\": {";
    for (std::size_t i = 0; i < notes.repairs.size(); ++i)
      out << (i ? ", " : "") << '"' << json_escape(notes.repairs[i].kind)
          << "\": " << notes.repairs[i].count;
    out << "},\n";
    if (notes.hausdorff_input_to_mesh >= 0.0)
      out << "  \"hausdorff\": {\"input_to_mesh\": " << notes.hausdorff_input_to_mesh
          << ", \"mesh_to_input\": " << notes.hausdorff_mesh_to_input
          << ", \"relative_to\": \"input bounding-box diagonal\"},\n";
    if (!notes.optimization_used.empty())
      out << "  \"meshing_retry\": \"" << json_escape(notes.optimization_used) << "\",\n";
  }
  out << "  \"clusters\": [";
  for (std::size_t c = 0; c < asset.clusters.size(); ++c) {
    out << (c ? ",\n    " : "\n    ") << "{\"triangles\": " << asset.clusters[c].triangle_count
        << ", " << detector_json(asset, asset.clusters[c])
        << ", \"rest_positive_fraction\": " << asset.clusters[c].rest_positive_fraction << "}";
  }
  out << "\n  ],\n  \"options\": {";
  for (std::size_t i = 0; i < asset.provenance.options.size(); ++i) {
    const auto& [key, value] = asset.provenance.options[i];
    out << (i ? ", " : "") << '"' << json_escape(key) << "\": \"" << json_escape(value) << '"';
  }
  out << "}\n}\n";
  return out.str();
}

/// Rest visibility below which `tetseg build` names the cluster in a note.
constexpr double kPoorVisibility = 0.8;

void run_build(const BuildArgs& args) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  BuildReport report;
  const std::function<void(const StageReport&)> on_stage = [&](const StageReport& stage) {
    print_stage(stage, args.quiet);
  };
  StageTimer timer(report, on_stage);

  BuildOptions options = args.options;
  options.keep_rest_positions = !args.no_rest_positions;
  TetMesh mesh;
  TetrahedralizeNotes notes;
  if (is_tet_mesh_path(args.input)) {
    mesh = timer.run("read", [&](std::string& summary) {
      TetMesh m = read_tet_mesh(args.input);
      summary =
          std::to_string(m.nodes.size()) + " nodes, " + std::to_string(m.tets.size()) + " tets";
      return m;
    });
  } else {
    const TriangleMesh surface = timer.run("read", [&](std::string& summary) {
      TriangleMesh s = read_triangle_mesh(args.input);
      // With --repair fix, tetrahedralize validates after repairing.
      if (args.meshing.repair == MeshingOptions::Repair::kNone)
        validate_closed_surface(s, args.input, /*allow_components=*/true);
      summary = std::to_string(s.vertices.size()) + " vertices, " +
                std::to_string(s.triangles.size()) + " triangles (surface)";
      return s;
    });
    mesh = timer.run("tetrahedralize", [&](std::string& summary) {
      TetMesh m = tetrahedralize(surface, args.meshing, args.input, &notes);
      options.meshing = args.meshing;  // recorded in the provenance, with the repairs
      options.repairs = notes.repairs;
      mesh_cli::print_repairs(args.input, notes);
      if (!notes.optimization_used.empty()) mesh_cli::print_retry_note(args.input, notes);
      summary =
          std::to_string(m.nodes.size()) + " nodes, " + std::to_string(m.tets.size()) + " tets";
      return m;
    });
  }

  const format::Asset asset = build_asset(mesh, args.input, options, report, on_stage);
  const std::vector<std::uint8_t> bytes = timer.run("write", [&](std::string& summary) {
    std::vector<std::uint8_t> b = format::write_asset(asset);
    write_file_atomic(args.output, b);
    summary = args.output + " (" + std::to_string(b.size()) + " bytes)";
    return b;
  });
  const double total = std::chrono::duration<double>(Clock::now() - start).count();
  if (!args.report_path.empty()) {
    write_file_atomic(args.report_path,
                      report_json(args, report, notes, asset, bytes.size(), total));
  }
  if (!args.quiet) {
    // Clusters no detector point sees well cost run time in every frame: say which, and why.
    std::size_t poor = 0, worst = 0, flagged = 0;
    for (std::size_t c = 0; c < asset.clusters.size(); ++c) {
      flagged += (asset.clusters[c].flags & format::kClusterOverlapOnly) ? 1 : 0;
      if (asset.clusters[c].rest_positive_fraction < kPoorVisibility) ++poor;
      if (asset.clusters[c].rest_positive_fraction < asset.clusters[worst].rest_positive_fraction)
        worst = c;
    }
    if (poor > 0) {
      std::fprintf(stderr,
                   "tetseg: note: %zu of %zu clusters are seen less than %.0f%% positive at rest "
                   "from their detector point (lowest: cluster %zu, %.1f%%); %zu flagged "
                   "overlap-only (below --min-visibility %g); thin parts cause this: a finer "
                   "interior (--cell-size) gives more candidates (docs/segmentation.md, step 7)\n",
                   poor, asset.clusters.size(), 100.0 * kPoorVisibility, worst,
                   100.0 * asset.clusters[worst].rest_positive_fraction, flagged,
                   args.options.segmentation.min_visibility);
    }
    std::fprintf(stderr, "tetseg: done in %.3f s\n", total);
  }
}

}  // namespace

void add_build_command(CLI::App& root) {
  auto args = std::make_shared<BuildArgs>();
  CLI::App* cmd = root.add_subcommand(
      "build",
      "Run the whole pipeline on a tet mesh (or a closed surface, tetrahedralised first) "
      "and write the runtime asset");
  cmd->add_option(
         "input", args->input,
         "Tet mesh (.mesh, .node/.ele, .msh) or closed surface (.obj, .ply, .stl, .off, ...)")
      ->required();
  cmd->add_option("-o,--output", args->output, "Asset file to write (.tetseg)")->required();
  cmd->add_option("--report", args->report_path, "Write a JSON report: per-stage seconds, counts");

  cmd->add_option("--clusters", args->options.clusters,
                  "single: one cluster; charge: the paper's charge-based segmentation; "
                  "refined: charge, then split clusters no node sees whole and merge neighbours "
                  "one node sees whole (docs/segmentation.md)")
      ->transform(CLI::CheckedTransformer(name_map<ClusterMethod>(), CLI::ignore_case))
      ->option_text(name_list<ClusterMethod>() + " (refined)");
  RefinementOptions& ref = args->options.refinement;
  cmd->add_option("--refine-visibility", ref.min_visibility,
                  "refined: split clusters seen positive below this share at rest; merge "
                  "neighbours seen at least this well")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--refine-max-clusters", ref.max_clusters,
                  "refined: no split beyond this many clusters")
      ->check(CLI::Range(1u, 100000u))
      ->capture_default_str();
  cmd->add_option("--refine-gain", ref.gain_per_cut_edge,
                  "refined: non-positive triangles a split must remove per cut edge")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--refine-merge", ref.merge, "refined: merge neighbours seen whole from one node")
      ->capture_default_str();

  SegmentationOptions& seg = args->options.segmentation;
  cmd->add_option("--alpha", seg.alpha, "Equalised density below which triangles are marked")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--beta-divisor", seg.beta_divisor,
                  "Segments larger than N/beta-divisor triangles are grown")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--equalization,--equalize", seg.equalization,
                  "histogram (the paper, 256 bins), rank (exact) or log-histogram (alias log)")
      ->transform(CLI::CheckedTransformer(name_map<Equalization>(), CLI::ignore_case))
      ->option_text(name_list<Equalization>() + " (histogram)");
  cmd->add_option("--growth-bound", seg.growth_bound,
                  "A segment never grows beyond this fraction of the surface")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--grow-through-marked", seg.grow_through_marked,
                  "Growing segments take touched marked segments whole (docs/segmentation.md)")
      ->capture_default_str();
  cmd->add_option("--min-cluster-triangles", seg.min_cluster_triangles,
                  "Clusters smaller than this are merged into a neighbour (0: derived)")
      ->capture_default_str();
  cmd->add_option("--detector", seg.detector,
                  "nearest-centroid (the paper) or visibility (most triangles positive at rest)")
      ->transform(CLI::CheckedTransformer(name_map<DetectorStrategy>(), CLI::ignore_case))
      ->option_text(name_list<DetectorStrategy>() + " (visibility)");
  cmd->add_option("--min-visibility", seg.min_visibility,
                  "Clusters whose best detector point sees less than this share of them "
                  "positive at rest are flagged overlap-only: culled by BVH overlap only at run "
                  "time (0: none)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();

  cmd->add_option("--solver", args->options.charge.solver,
                  "Charge solver: auto, direct, gmres, fast")
      ->transform(CLI::CheckedTransformer(name_map<ChargeSolver>(), CLI::ignore_case))
      ->option_text(name_list<ChargeSolver>() + " (auto)");
  cmd->add_option("--tolerance", args->options.charge.tolerance,
                  "Relative residual of the iterative charge solvers (0: 1e-6 below 10k "
                  "triangles, 1e-8 above)")
      ->check(CLI::Range(0.0, 0.5))
      ->capture_default_str();

  cmd->add_option("--cell-size", args->meshing.cell_size,
                  "Surface input only: max tet circumradius (0: derived, docs/cli.md)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--facet-size", args->meshing.facet_size,
                  "Surface input only: max surface Delaunay ball radius (0: derived)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--facet-distance", args->meshing.facet_distance,
                  "Surface input only: max surface approximation error (0: derived)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag(
      "--no-optimize", [args](std::int64_t) { args->meshing.optimize = false; },
      "Surface input only: skip sliver perturbation and exudation (faster meshing)");
  mesh_cli::add_threads_option(*cmd, args->meshing, "Surface input only: ");
  mesh_cli::add_repair_option(*cmd, args->meshing);
  cmd->add_flag("--no-rest-positions", args->no_rest_positions,
                "Do not store rest positions in the asset (smaller; tools cannot draw it)");
  cmd->add_flag("-q,--quiet", args->quiet, "No stage lines");
  cmd->callback([args] { run_naming_file(args->input, [&] { run_build(*args); }); });
}

}  // namespace tetseg::tools
