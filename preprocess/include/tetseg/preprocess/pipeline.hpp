#pragma once
/// \file
/// The whole preprocessing pipeline: tet mesh -> surface -> charge -> segmentation -> detector
/// nodes -> BVH topology -> asset. What `tetseg build` runs.

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "tetseg/format/asset.hpp"
#include "tetseg/preprocess/charge.hpp"
#include "tetseg/preprocess/mesh.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/segmentation.hpp"

namespace tetseg::preprocess {

/// How the surface is cut into clusters.
enum class ClusterMethod {
  kSingle,   ///< one cluster (no charge, no segmentation)
  kCharge,   ///< the paper: charge density, segment boundaries, clusters
  kRefined,  ///< kCharge, then refine_clusters (split by rest visibility, merge)
};

/// How far the asset's surface is from the input surface: the two-sided (approximate)
/// Hausdorff distance, relative to the input's bounding-box diagonal and absolute (input
/// units). 0 for a tet-mesh input, whose boundary is the asset's surface.
struct SurfaceDeviation {
  double input_to_asset = 0.0;  ///< relative to the diagonal
  double asset_to_input = 0.0;  ///< relative to the diagonal
  double input_to_asset_absolute = 0.0;
  double asset_to_input_absolute = 0.0;
  /// A surface input: how far the larger distance is over --max-deviation (relative; 0 within
  /// it) and the Mesh_3 runs repeated to stay within it (TetrahedralizeNotes).
  double excess = 0.0;
  int meshing_retries = 0;
};

struct BuildOptions {
  /// kRefined measured faster per frame than kCharge on every benchmark scene
  /// (docs/benchmarks-history.md, "Cluster refinement").
  ClusterMethod clusters = ClusterMethod::kRefined;
  ChargeOptions charge;
  SegmentationOptions segmentation;
  RefinementOptions refinement;     ///< used by kRefined
  bool keep_rest_positions = true;  ///< store rest positions in the asset (docs/format.md)
  /// kTet: the asset's nodes are a tet mesh's (the input, or the input surface tetrahedralised
  /// first). kSurface: the input surface as it is, no tets (build_surface_asset). Recorded as
  /// provenance key "body" when kSurface.
  format::BodyKind body = format::BodyKind::kTet;
  /// The detector form; unset: the body's own (kTet: kTetPoint, kSurface: kSurfaceWeights).
  /// A kTet body takes only kTetPoint; kBones: the surface body's detectors carried by the
  /// input's skin (the build job, skin.hpp).
  /// Recorded as provenance key "detectors" with a surface body.
  std::optional<format::DetectorForm> detectors;
  /// Set when the tet mesh was made from the source surface by tetrahedralize with these
  /// options; only recorded (provenance keys meshing.*), so that the asset can be rebuilt.
  std::optional<MeshingOptions> meshing;
  /// With `meshing`: the repairs tetrahedralize made (TetrahedralizeNotes::repairs), recorded
  /// as provenance keys "repairs.<kind, spaces as underscores>" = count.
  std::vector<RepairCount> repairs;
  /// Recorded as provenance keys deviation.* (the relative ones and deviation.*_absolute);
  /// only recorded. build_asset records 0 when neither this nor `meshing` is set (a tet mesh
  /// is its own surface); the build jobs set it for a surface input.
  std::optional<SurfaceDeviation> deviation;
  /// With `meshing` and MeshingOptions::Repair::kAuto: the repair used ("fix" or "wrap") and
  /// why the wrap was needed (TetrahedralizeNotes), recorded as provenance keys
  /// meshing.repair_used and meshing.fallback_reason (only recorded).
  std::string repair_used;
  std::string fallback_reason;
};

/// One finished stage: its name, wall time, memory and a short human summary.
struct StageReport {
  std::string name;
  double seconds = 0.0;
  std::string summary;
  /// The process's peak resident set size (Linux VmHWM) at the end of the stage, bytes:
  /// never decreases from stage to stage; 0 where the platform does not say.
  std::uint64_t peak_rss_bytes = 0;
  /// How much the stage raised that peak (end minus start), bytes: 0 when the stage stayed
  /// below an earlier stage's peak.
  std::uint64_t peak_rss_growth_bytes = 0;
};

/// The process's peak resident set size so far, bytes: VmHWM of /proc/self/status, else
/// getrusage's ru_maxrss; 0 when neither is available.
std::uint64_t process_peak_rss_bytes();

/// Counts and times of one build, for `--report`.
struct BuildReport {
  std::vector<StageReport> stages;
  std::uint32_t nodes = 0;
  std::uint32_t tets = 0;
  std::uint32_t surface_triangles = 0;
  std::uint32_t interior_nodes = 0;
  std::uint32_t components = 0;  ///< connected components (bodies), each with its own clusters
  std::uint32_t clusters = 0;
  std::uint32_t boundaries = 0;
  SegmentationCounts segmentation;
  RefinementCounts refinement;                ///< zero unless kRefined
  ChargeResult charge;                        ///< density left empty; solver figures only
  std::vector<float> rest_positive_fraction;  ///< per cluster
};

/// Runs stages, timing each and taking the process peak RSS before and after it (StageReport),
/// appending it to `report.stages` and passing it to `on_stage`.
/// `work(summary)` does the stage, may fill the human summary, and returns its result.
/// Keeps a copy of `on_stage` (a temporary lambda may be passed) and a reference to `report`.
class StageTimer {
 public:
  StageTimer(BuildReport& report, std::function<void(const StageReport&)> on_stage)
      : m_report(report), m_on_stage(std::move(on_stage)) {}

  template <typename Work>
  auto run(const char* name, Work&& work) {
    const std::uint64_t peak_before = process_peak_rss_bytes();
    const auto start = std::chrono::steady_clock::now();
    StageReport stage;
    stage.name = name;
    auto result = work(stage.summary);
    stage.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stage.peak_rss_bytes = process_peak_rss_bytes();
    stage.peak_rss_growth_bytes =
        stage.peak_rss_bytes > peak_before ? stage.peak_rss_bytes - peak_before : 0;
    m_report.stages.push_back(stage);
    if (m_on_stage) m_on_stage(stage);
    return result;
  }

 private:
  BuildReport& m_report;
  std::function<void(const StageReport&)> m_on_stage;
};

/// Options as the key/value pairs recorded in the asset's provenance, sorted by key: every
/// option that changes the asset (charge solver and its parameters, segmentation, refinement
/// when used, rest positions, meshing when set); enum values by their canonical names
/// (names.hpp), numbers as the shortest text that reads back exactly. build_asset records
/// the charge solver it actually used in place of "auto".
std::vector<std::pair<std::string, std::string>> provenance_options(const BuildOptions& options);

/// The inverse of provenance_options: sets `options` from recorded pairs (options not named
/// keep their defaults). Returns false, with the offending key and value in `error`, for an
/// unknown key or a value that does not parse. Building the recorded source with the result
/// (tetrahedralised with `options.meshing` when set) gives the same asset byte for byte.
bool options_from_provenance(const std::vector<std::pair<std::string, std::string>>& recorded,
                             BuildOptions& options, std::string* error = nullptr);

/// Runs every stage on a tet mesh read from `source` (used in messages and provenance: only
/// its file name is stored). Validates the mesh first (InputError on defects). Calls
/// `on_stage` after each stage when given. Deterministic: equal input gives an equal asset.
format::Asset build_asset(const TetMesh& mesh, const std::string& source,
                          const BuildOptions& options, BuildReport& report,
                          const std::function<void(const StageReport&)>& on_stage = {});

/// The detector form a build with `options` makes: options.detectors, else the body's own.
format::DetectorForm detector_form_of(const BuildOptions& options);

/// A surface body (docs/segmentation.md, "Surface bodies"): every stage on `surface` as it is.
/// The asset's nodes are the surface's vertices and its triangles the surface's triangles,
/// both in the input's order (format::BodyKind::kSurface). Validation (InputError naming the
/// first defect): finite coordinates, indices in range, no zero-area triangle, no edge of
/// more than two triangles, consistent orientation; closed components wound outward must
/// also be vertex-manifold, free of self-intersection and not nested. Closed outward
/// components are
/// charged, segmented and refined like a tet mesh's surface, with interior points sampled
/// inside them as detector candidates (used only as candidates); each detector is then written
/// as non-negative weights (sum 1) of at most kSurfaceDetectorTerms surface vertices around it
/// (kSurfaceWeights). Open components and closed ones wound inward (one cluster each), and
/// clusters no candidate sees well at rest, are overlap-only clusters. Deterministic.
format::Asset build_surface_asset(const TriangleMesh& surface, const std::string& source,
                                  const BuildOptions& options, BuildReport& report,
                                  const std::function<void(const StageReport&)>& on_stage = {});

/// Most terms of a surface body's detector (<= format::kMaxDetectorTerms).
inline constexpr std::uint32_t kSurfaceDetectorTerms = 32;

}  // namespace tetseg::preprocess
