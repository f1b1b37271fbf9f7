#pragma once
/// \file
/// The offline jobs, one call each from input to result: building an asset and computing a
/// charge density. `tetseg build`, `tetseg charge` and Python's tetseg.preprocess.build and
/// charge call these and only parse arguments and print; the JSON reports are written here,
/// once, for all of them (docs/cli.md, "Reports").

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tetseg/format/asset.hpp"
#include "tetseg/preprocess/charge.hpp"
#include "tetseg/preprocess/mesh.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/pipeline.hpp"

namespace tetseg::preprocess {

/// Called after each stage of a job (StageReport: name, seconds, summary, memory).
using StageCallback = std::function<void(const StageReport&)>;

/// Options of a build: BuildOptions for every input, MeshingOptions for a surface input.
struct BuildJobOptions {
  /// Segmentation, charge, refinement, rest positions. Its `meshing` and `repairs` are set
  /// by the job for a surface input (recorded in the provenance); what the caller sets there
  /// is ignored.
  BuildOptions build;
  MeshingOptions meshing;  ///< surface input only: repair and tetrahedralisation
  /// Called in the "write" stage with the asset's bytes (the CLI writes its file there); may
  /// throw. The stage summary is "<output_name> (N bytes)", or "N bytes" without a name.
  std::function<void(const std::vector<std::uint8_t>& bytes)> write_output;
  std::string output_name;
  /// Seconds the whole build may take (0: no limit; option_ranges kTimeLimit). Checked after
  /// every stage before "write", and inside tetrahedralize (which gets the time left as its
  /// MeshingOptions::time_limit, so Mesh_3 is stopped there): past it the build throws
  /// TimeLimitExceeded naming the stage, before anything is written.
  double time_limit = kDefaultTimeLimitSeconds;
};

/// A finished build.
struct BuildJobResult {
  format::Asset asset;
  std::vector<std::uint8_t> asset_bytes;  ///< format::write_asset(asset)
  BuildReport report;                     ///< stages (read ... write), counts, charge figures
  bool surface_input = false;             ///< tetrahedralised from a surface
  TetrahedralizeNotes meshing_notes;      ///< surface input: repairs, Hausdorff, retries
  /// How far the asset's surface is from the input's (0 for a tet-mesh input); also in the
  /// provenance (deviation.*) and the report ("hausdorff").
  SurfaceDeviation deviation;
  double total_seconds = 0.0;  ///< wall time of the whole job
};

/// Throws std::invalid_argument naming the first option outside its range
/// (option_ranges.hpp), for the options the build reads.
void validate_options(const BuildJobOptions& options);

/// The whole build: read `path` (a tet mesh by its extension, is_tet_mesh_path, else a
/// surface), tetrahedralise a surface (tetrahedralize with options.meshing: it alone judges
/// the surface, so a build accepts exactly the surfaces `tetseg tetrahedralize` accepts),
/// build_asset, serialise. Stages: read, [tetrahedralize,] surface, [charge, equalize,
/// segmentation, [refinement,]] detectors, bvh, write; `on_stage` is called after each.
/// `source` names the input in messages and the provenance (default: `path`). Throws what the
/// stages throw: InputError naming the file for bad input, TimeLimitExceeded (an InputError)
/// past options.time_limit, std::invalid_argument for bad options (validate_options, first),
/// and whatever on_stage or write_output throw.
BuildJobResult build_asset_from_file(const std::string& path, const BuildJobOptions& options,
                                     const StageCallback& on_stage = {},
                                     const std::string& source = {});
/// build_asset_from_file on a tet mesh in memory (the read stage only counts it).
BuildJobResult build_asset_from_tet_mesh(TetMesh mesh, const std::string& source,
                                         const BuildJobOptions& options,
                                         const StageCallback& on_stage = {});
/// build_asset_from_file on a surface in memory.
BuildJobResult build_asset_from_surface(TriangleMesh surface, const std::string& source,
                                        const BuildJobOptions& options,
                                        const StageCallback& on_stage = {});

/// The build report (`tetseg build --report`, docs/cli.md): input, output (omitted when
/// empty), asset_bytes, seconds per stage and total, peak_rss_bytes, peak_rss_growth_bytes,
/// counts, segmentation, refinement, charge (when computed), hausdorff (every input: the
/// deviation, 0 for a tet mesh), repairs and meshing_retry (surface input), clusters, options.
/// Numbers at 9 digits (detectors at 17).
std::string build_report_json(const BuildJobResult& result, const std::string& input,
                              const std::string& output);

/// Options of a charge density job (`tetseg charge`).
struct ChargeJobOptions {
  ChargeOptions charge;
  Equalization equalization = Equalization::kHistogram;
  int bins = 256;  ///< histogram bins of the equalisation
};

/// A charge density of a closed surface (or a tet mesh's boundary).
struct ChargeJobResult {
  std::vector<Vec3> points;       ///< the surface's points (a tet mesh's nodes)
  std::vector<Tri> triangles;     ///< the surface the values refer to
  ChargeResult charge;            ///< density per triangle and the solver's figures
  std::vector<double> equalized;  ///< per triangle, equalize(density, equalization, bins)
  Equalization equalization = Equalization::kHistogram;
  BuildReport report;  ///< stages: read (and validate), charge (solve and equalise)
};

/// Throws std::invalid_argument naming the first option outside its range.
void validate_options(const ChargeJobOptions& options);

/// Reads `path` (a tet mesh: its validated boundary; a surface: validate_closed_surface as
/// given, no repair, one component) and computes its charge density and its
/// equalisation. Stages: read, charge. Same errors as build_asset_from_file.
ChargeJobResult charge_from_file(const std::string& path, const ChargeJobOptions& options,
                                 const StageCallback& on_stage = {},
                                 const std::string& source = {});
/// charge_from_file on a tet mesh in memory.
ChargeJobResult charge_tet_mesh(TetMesh mesh, const std::string& source,
                                const ChargeJobOptions& options,
                                const StageCallback& on_stage = {});
/// charge_from_file on a surface in memory.
ChargeJobResult charge_surface(TriangleMesh surface, const std::string& source,
                               const ChargeJobOptions& options, const StageCallback& on_stage = {});

/// The charge report (`tetseg charge --report`, docs/cli.md): input, triangles, the solver's
/// figures, equalization, and per stage of result.report peak_rss_bytes and
/// peak_rss_growth_bytes. Numbers at 10 digits.
std::string charge_report_json(const ChargeJobResult& result, const std::string& input);

}  // namespace tetseg::preprocess
