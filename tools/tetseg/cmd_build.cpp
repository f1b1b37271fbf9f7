// `tetseg build`: the whole pipeline from a mesh file to an asset.

#include <cstdio>
#include <map>
#include <memory>

#include "commands.hpp"
#include "tetseg/preprocess/jobs.hpp"
#include "tetseg/preprocess/names.hpp"
#include "tetseg/preprocess/option_ranges.hpp"
#include "tool_support.hpp"

namespace tetseg::tools {
namespace {

using namespace tetseg::preprocess;

struct BuildArgs {
  std::string input;
  std::string output;
  std::string report_path;
  BuildJobOptions job;
  bool no_rest_positions = false;
  bool quiet = false;
};

/// Rest visibility below which `tetseg build` names the cluster in a note.
constexpr double kPoorVisibility = 0.8;

/// Clusters no detector point sees well cost run time in every frame: says which, and why.
void print_visibility_note(const format::Asset& asset, double min_visibility) {
  std::size_t poor = 0, worst = 0, flagged = 0;
  for (std::size_t c = 0; c < asset.clusters.size(); ++c) {
    flagged += (asset.clusters[c].flags & format::kClusterOverlapOnly) ? 1 : 0;
    if (asset.clusters[c].rest_positive_fraction < kPoorVisibility) ++poor;
    if (asset.clusters[c].rest_positive_fraction < asset.clusters[worst].rest_positive_fraction)
      worst = c;
  }
  if (poor == 0) return;
  if (asset.body_kind == format::BodyKind::kSurface) {
    std::fprintf(stderr,
                 "tetseg: note: %zu of %zu clusters are seen less than %.0f%% positive at rest "
                 "from their detector point; %zu are overlap-only (open components, or below "
                 "--min-visibility %g): culled by BVH overlap only\n",
                 poor, asset.clusters.size(), 100.0 * kPoorVisibility, flagged, min_visibility);
    return;
  }
  std::fprintf(stderr,
               "tetseg: note: %zu of %zu clusters are seen less than %.0f%% positive at rest "
               "from their detector point (lowest: cluster %zu, %.1f%%); %zu flagged "
               "overlap-only (below --min-visibility %g); thin parts cause this: a finer "
               "interior (--cell-size) gives more candidates (docs/segmentation.md, step 7)\n",
               poor, asset.clusters.size(), 100.0 * kPoorVisibility, worst,
               100.0 * asset.clusters[worst].rest_positive_fraction, flagged, min_visibility);
}

void run_build(const BuildArgs& args) {
  BuildJobOptions options = args.job;
  options.build.keep_rest_positions = !args.no_rest_positions;
  options.output_name = args.output;
  try {  // option combinations the parser cannot see (--body with --detectors): usage errors
    validate_options(options);
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--detectors", e.what());
  }
  if (!args.quiet) mesh_cli::report_meshing_progress(options.meshing);
  options.write_output = [&](const std::vector<std::uint8_t>& bytes) {
    write_file_atomic(args.output, bytes);
  };
  const BuildJobResult result =
      build_asset_from_file(args.input, options, [&](const StageReport& stage) {
        if (!args.quiet) print_stage(stage);
      });
  if (result.surface_input) {
    mesh_cli::print_repairs(args.input, result.meshing_notes);
    if (!result.meshing_notes.optimization_used.empty())
      mesh_cli::print_retry_note(args.input, result.meshing_notes);
  }
  if (!args.report_path.empty())
    write_file_atomic(args.report_path, build_report_json(result, args.input, args.output));
  if (!args.quiet) {
    print_visibility_note(result.asset, options.build.segmentation.min_visibility);
    std::fprintf(stderr, "tetseg: done in %.3f s\n", result.total_seconds);
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

  cmd->add_option("--body", args->job.build.body,
                  "tet: the asset's nodes are a tet mesh's (the input, or the surface "
                  "tetrahedralised first); surface: the input surface as it is, its vertices "
                  "and triangles in their order, no tets (docs/cli.md, \"Surface bodies\")")
      ->transform(CLI::CheckedTransformer(name_map<format::BodyKind>(), CLI::ignore_case))
      ->option_text(name_list<format::BodyKind>() + " (tet)");
  cmd->add_option_function<format::DetectorForm>(
         "--detectors",
         [args](const format::DetectorForm& form) { args->job.build.detectors = form; },
         "Detector form: weights (surface bodies' default: fixed weights of surface vertices); "
         "skin (bones of the input's skin)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, format::DetectorForm>{
              {"weights", format::DetectorForm::kSurfaceWeights},
              {"skin", format::DetectorForm::kBones}},
          CLI::ignore_case))
      ->option_text("weights|skin (weights with --body surface)");
  cmd->add_option("--clusters", args->job.build.clusters,
                  "single: one cluster; charge: the paper's charge-based segmentation; "
                  "refined: charge, then split clusters no node sees whole and merge neighbours "
                  "one node sees whole (docs/segmentation.md)")
      ->transform(CLI::CheckedTransformer(name_map<ClusterMethod>(), CLI::ignore_case))
      ->option_text(name_list<ClusterMethod>() + " (refined)");
  RefinementOptions& ref = args->job.build.refinement;
  cmd->add_option("--refine-visibility", ref.min_visibility,
                  "refined: split clusters seen positive below this share at rest; merge "
                  "neighbours seen at least this well")
      ->check(range_check(option_ranges::kRefineVisibility))
      ->capture_default_str();
  cmd->add_option("--refine-max-clusters", ref.max_clusters,
                  "refined: no split beyond this many clusters")
      ->check(range_check(option_ranges::kRefineMaxClusters))
      ->capture_default_str();
  cmd->add_option("--refine-gain", ref.gain_per_cut_edge,
                  "refined: non-positive triangles a split must remove per cut edge")
      ->check(range_check(option_ranges::kRefineGain))
      ->capture_default_str();
  cmd->add_option("--refine-merge", ref.merge, "refined: merge neighbours seen whole from one node")
      ->capture_default_str();

  SegmentationOptions& seg = args->job.build.segmentation;
  cmd->add_option("--alpha", seg.alpha, "Equalised density below which triangles are marked")
      ->check(range_check(option_ranges::kAlpha))
      ->capture_default_str();
  cmd->add_option("--beta-divisor", seg.beta_divisor,
                  "Segments larger than N/beta-divisor triangles are grown")
      ->check(range_check(option_ranges::kBetaDivisor))
      ->capture_default_str();
  cmd->add_option("--equalization,--equalize", seg.equalization,
                  "histogram (the paper, 256 bins), rank (exact) or log-histogram (alias log)")
      ->transform(CLI::CheckedTransformer(name_map<Equalization>(), CLI::ignore_case))
      ->option_text(name_list<Equalization>() + " (histogram)");
  cmd->add_option("--growth-bound", seg.growth_bound,
                  "A segment never grows beyond this fraction of the surface")
      ->check(range_check(option_ranges::kGrowthBound))
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
      ->check(range_check(option_ranges::kMinVisibility))
      ->capture_default_str();

  cmd->add_option("--solver", args->job.build.charge.solver,
                  "Charge solver: auto, direct, gmres, fast")
      ->transform(CLI::CheckedTransformer(name_map<ChargeSolver>(), CLI::ignore_case))
      ->option_text(name_list<ChargeSolver>() + " (auto)");
  cmd->add_option("--tolerance", args->job.build.charge.tolerance,
                  "Relative residual of the iterative charge solvers (0: 1e-6 below 10k "
                  "triangles, 1e-8 above)")
      ->check(range_check(option_ranges::kTolerance))
      ->capture_default_str();

  cmd->add_option("--cell-size", args->job.meshing.cell_size,
                  "Surface input only: max tet circumradius (0: derived, docs/cli.md)")
      ->check(range_check(option_ranges::kCellSize))
      ->capture_default_str();
  cmd->add_option("--facet-size", args->job.meshing.facet_size,
                  "Surface input only: max surface Delaunay ball radius (0: derived)")
      ->check(range_check(option_ranges::kFacetSize))
      ->capture_default_str();
  cmd->add_option("--facet-distance", args->job.meshing.facet_distance,
                  "Surface input only: max surface approximation error (0: derived)")
      ->check(range_check(option_ranges::kFacetDistance))
      ->capture_default_str();
  cmd->add_flag(
      "--no-optimize", [args](std::int64_t) { args->job.meshing.optimize = false; },
      "Surface input only: skip sliver perturbation and exudation (faster meshing)");
  mesh_cli::add_threads_option(*cmd, args->job.meshing, "Surface input only: ");
  mesh_cli::add_repair_option(*cmd, args->job.meshing);
  mesh_cli::add_time_limit_option(*cmd, args->job.time_limit, "the whole build");
  cmd->add_flag("--no-rest-positions", args->no_rest_positions,
                "Do not store rest positions in the asset (smaller; tools cannot draw it)");
  cmd->add_flag("-q,--quiet", args->quiet, "No stage lines");
  cmd->callback([args] { run_naming_file(args->input, [&] { run_build(*args); }); });
}

}  // namespace tetseg::tools
