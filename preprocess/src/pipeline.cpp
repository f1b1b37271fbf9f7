#include "tetseg/preprocess/pipeline.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <numeric>
#include <sstream>
#include <type_traits>

#include <sys/resource.h>

#include "part_stages.hpp"
#include "tetseg/format/asset_io.hpp"
#include "tetseg/preprocess/names.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "validate_internal.hpp"

namespace tetseg::preprocess {
namespace {

// Shortest decimal text that reads back as exactly `value` ("0.1", not "0.10000000000000001").
std::string format_number(double value) {
  char buffer[64];
  if (value == std::floor(value) && std::fabs(value) < 1e15) {
    std::snprintf(buffer, sizeof buffer, "%.0f", value);
    return buffer;
  }
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  return buffer;
}

std::string base_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

namespace {

// One provenance key: when it is recorded, how its value is written and read back. The single
// description of the provenance, used both ways.
struct ProvenanceField {
  const char* key;
  bool (*recorded)(const BuildOptions&);
  std::function<std::string(BuildOptions&)> write;
  std::function<bool(const std::string&, BuildOptions&)> read;
};

bool always(const BuildOptions&) {
  return true;
}
bool refined(const BuildOptions& o) {
  return o.clusters == ClusterMethod::kRefined;
}
bool meshed(const BuildOptions& o) {
  return o.meshing.has_value();
}
bool largest_component_kept(const BuildOptions& o) {
  return o.meshing.has_value() && o.meshing->keep_largest_component;
}
bool wrapped(const BuildOptions& o) {  // the wrap options matter: wrap, or auto's fallback
  return o.meshing.has_value() && (o.meshing->repair == MeshingOptions::Repair::kWrap ||
                                   o.meshing->repair == MeshingOptions::Repair::kAuto);
}
bool auto_repaired(const BuildOptions& o) {
  return o.meshing.has_value() && o.meshing->repair == MeshingOptions::Repair::kAuto;
}
bool fell_back(const BuildOptions& o) {
  return auto_repaired(o) && !o.fallback_reason.empty();
}

bool surface_body(const BuildOptions& o) {
  return o.body == format::BodyKind::kSurface;
}

format::DetectorForm& detectors_of(BuildOptions& o) {
  if (!o.detectors) o.detectors = detector_form_of(o);
  return *o.detectors;
}

bool deviation_known(const BuildOptions& o) {
  return o.deviation.has_value();
}
bool surface_deviation_known(const BuildOptions& o) {  // a surface input, tetrahedralised
  return o.deviation.has_value() && o.meshing.has_value();
}

bool parse_double(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(value);
}

template <typename Int>
bool parse_integer(const std::string& text, Int& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const long long parsed = std::strtoll(text.c_str(), &end, 10);
  if (errno != 0 || end != text.c_str() + text.size()) return false;
  static_assert(sizeof(Int) < sizeof(long long), "the limits must fit a long long");
  if (parsed < static_cast<long long>(std::numeric_limits<Int>::min()) ||
      parsed > static_cast<long long>(std::numeric_limits<Int>::max())) {
    return false;
  }
  value = static_cast<Int>(parsed);
  return true;
}

// A number; `automatic` (0 or -1) is written "auto" when `has_auto`.
template <typename T>
ProvenanceField number(const char* key, bool (*recorded)(const BuildOptions&),
                       T& (*access)(BuildOptions&), bool has_auto = false, T automatic = T{}) {
  return {key, recorded,
          [=](BuildOptions& o) {
            const T value = access(o);
            if (has_auto && value == automatic) return std::string("auto");
            if constexpr (std::is_floating_point_v<T>) {
              return format_number(value);
            } else {
              return std::to_string(value);
            }
          },
          [=](const std::string& text, BuildOptions& o) {
            if (has_auto && text == "auto") {
              access(o) = automatic;
              return true;
            }
            if constexpr (std::is_floating_point_v<T>) {
              return parse_double(text, access(o));
            } else {
              return parse_integer(text, access(o));
            }
          }};
}

// Text recorded as it is.
ProvenanceField text(const char* key, bool (*recorded)(const BuildOptions&),
                     std::string& (*access)(BuildOptions&)) {
  return {key, recorded, [=](BuildOptions& o) { return access(o); },
          [=](const std::string& value, BuildOptions& o) {
            access(o) = value;
            return true;
          }};
}

ProvenanceField flag(const char* key, bool (*recorded)(const BuildOptions&),
                     bool& (*access)(BuildOptions&)) {
  return {key, recorded, [=](BuildOptions& o) { return std::string(access(o) ? "yes" : "no"); },
          [=](const std::string& text, BuildOptions& o) {
            if (text != "yes" && text != "no") return false;
            access(o) = text == "yes";
            return true;
          }};
}

template <typename Enum>
ProvenanceField named(const char* key, bool (*recorded)(const BuildOptions&),
                      Enum& (*access)(BuildOptions&)) {
  return {key, recorded, [=](BuildOptions& o) { return std::string(name_of(access(o))); },
          [=](const std::string& text, BuildOptions& o) { return parse_name(text, access(o)); }};
}

SurfaceDeviation& deviation_of(BuildOptions& o) {
  if (!o.deviation) o.deviation = SurfaceDeviation{};
  return *o.deviation;
}

MeshingOptions& meshing_of(BuildOptions& o) {
  if (!o.meshing) o.meshing.emplace();
  return *o.meshing;
}

const std::vector<ProvenanceField>& provenance_fields() {
  using O = BuildOptions;
  static const std::vector<ProvenanceField> fields = {
      named<ClusterMethod>("clusters", always, [](O& o) -> ClusterMethod& { return o.clusters; }),
      named<ChargeSolver>("charge.solver", always,
                          [](O& o) -> ChargeSolver& { return o.charge.solver; }),
      number<double>(
          "charge.tolerance", always, [](O& o) -> double& { return o.charge.tolerance; }, true,
          0.0),
      number<int>("charge.max_iterations", always,
                  [](O& o) -> int& { return o.charge.max_iterations; }),
      number<int>("charge.restart", always, [](O& o) -> int& { return o.charge.restart; }),
      named<ChargePreconditioner>(
          "charge.preconditioner", always,
          [](O& o) -> ChargePreconditioner& { return o.charge.preconditioner; }),
      number<double>(
          "charge.fast_theta", always, [](O& o) -> double& { return o.charge.fast_theta; }, true,
          0.0),
      number<int>(
          "charge.fast_order", always, [](O& o) -> int& { return o.charge.fast_order; }, true, -1),
      number<int>("charge.leaf_size", always, [](O& o) -> int& { return o.charge.leaf_size; }),
      number<int>(
          "charge.schwarz_set", always, [](O& o) -> int& { return o.charge.schwarz_set; }, true, 0),
      flag("charge.relaxed_products", always,
           [](O& o) -> bool& { return o.charge.relaxed_products; }),
      number<double>("segmentation.alpha", always,
                     [](O& o) -> double& { return o.segmentation.alpha; }),
      number<double>("segmentation.beta_divisor", always,
                     [](O& o) -> double& { return o.segmentation.beta_divisor; }),
      named<Equalization>("segmentation.equalization", always,
                          [](O& o) -> Equalization& { return o.segmentation.equalization; }),
      number<double>("segmentation.growth_bound", always,
                     [](O& o) -> double& { return o.segmentation.growth_bound; }),
      flag("segmentation.grow_through_marked", always,
           [](O& o) -> bool& { return o.segmentation.grow_through_marked; }),
      number<std::uint32_t>(
          "segmentation.min_cluster_triangles", always,
          [](O& o) -> std::uint32_t& { return o.segmentation.min_cluster_triangles; }),
      named<DetectorStrategy>("segmentation.detector", always,
                              [](O& o) -> DetectorStrategy& { return o.segmentation.detector; }),
      number<double>("segmentation.min_visibility", always,
                     [](O& o) -> double& { return o.segmentation.min_visibility; }),
      named<format::BodyKind>("body", surface_body,
                              [](O& o) -> format::BodyKind& { return o.body; }),
      named<format::DetectorForm>("detectors", surface_body, detectors_of),
      flag("rest_positions", always, [](O& o) -> bool& { return o.keep_rest_positions; }),
      number<double>("refine.min_visibility", refined,
                     [](O& o) -> double& { return o.refinement.min_visibility; }),
      number<double>("refine.gain_per_cut_edge", refined,
                     [](O& o) -> double& { return o.refinement.gain_per_cut_edge; }),
      number<double>("refine.invisibility_cost", refined,
                     [](O& o) -> double& { return o.refinement.invisibility_cost; }),
      number<std::uint32_t>("refine.max_clusters", refined,
                            [](O& o) -> std::uint32_t& { return o.refinement.max_clusters; }),
      number<std::uint32_t>(
          "refine.min_cluster_triangles", refined,
          [](O& o) -> std::uint32_t& { return o.refinement.min_cluster_triangles; }),
      flag("refine.merge", refined, [](O& o) -> bool& { return o.refinement.merge; }),
      number<double>("meshing.cell_size", meshed,
                     [](O& o) -> double& { return meshing_of(o).cell_size; }),
      number<double>("meshing.facet_size", meshed,
                     [](O& o) -> double& { return meshing_of(o).facet_size; }),
      number<double>("meshing.facet_distance", meshed,
                     [](O& o) -> double& { return meshing_of(o).facet_distance; }),
      number<double>("meshing.facet_angle", meshed,
                     [](O& o) -> double& { return meshing_of(o).facet_angle; }),
      number<double>("meshing.cell_radius_edge_ratio", meshed,
                     [](O& o) -> double& { return meshing_of(o).cell_radius_edge_ratio; }),
      flag("meshing.optimize", meshed, [](O& o) -> bool& { return meshing_of(o).optimize; }),
      number<double>("meshing.max_deviation", meshed,
                     [](O& o) -> double& { return meshing_of(o).max_deviation; }),
      named<MeshingOptions::Repair>(
          "meshing.repair", meshed,
          [](O& o) -> MeshingOptions::Repair& { return meshing_of(o).repair; }),
      flag("meshing.keep_largest_component", largest_component_kept,
           [](O& o) -> bool& { return meshing_of(o).keep_largest_component; }),
      number<double>("meshing.wrap_alpha", wrapped,
                     [](O& o) -> double& { return meshing_of(o).wrap_alpha; }),
      number<double>("meshing.wrap_offset", wrapped,
                     [](O& o) -> double& { return meshing_of(o).wrap_offset; }),
      number<double>("meshing.wrap_sheet_offset", wrapped,
                     [](O& o) -> double& { return meshing_of(o).wrap_sheet_offset; }),
      text("meshing.repair_used", auto_repaired,
           [](O& o) -> std::string& { return o.repair_used; }),
      text("meshing.fallback_reason", fell_back,
           [](O& o) -> std::string& { return o.fallback_reason; }),
      number<double>("deviation.input_to_asset", deviation_known,
                     [](O& o) -> double& { return deviation_of(o).input_to_asset; }),
      number<double>("deviation.asset_to_input", deviation_known,
                     [](O& o) -> double& { return deviation_of(o).asset_to_input; }),
      number<double>("deviation.input_to_asset_absolute", deviation_known,
                     [](O& o) -> double& { return deviation_of(o).input_to_asset_absolute; }),
      number<double>("deviation.asset_to_input_absolute", deviation_known,
                     [](O& o) -> double& { return deviation_of(o).asset_to_input_absolute; }),
      number<double>("deviation.excess", surface_deviation_known,
                     [](O& o) -> double& { return deviation_of(o).excess; }),
      number<int>("deviation.meshing_retries", surface_deviation_known,
                  [](O& o) -> int& { return deviation_of(o).meshing_retries; }),
  };
  return fields;
}

/// Repairs are recorded as "repairs.<kind>" = count, the kind's spaces as underscores.
constexpr const char* kRepairPrefix = "repairs.";

std::string swap_characters(std::string text, char from, char to) {
  std::replace(text.begin(), text.end(), from, to);
  return text;
}

}  // namespace

format::DetectorForm detector_form_of(const BuildOptions& options) {
  if (options.detectors) return *options.detectors;
  return options.body == format::BodyKind::kSurface ? format::DetectorForm::kSurfaceWeights
                                                    : format::DetectorForm::kTetPoint;
}

std::vector<std::pair<std::string, std::string>> provenance_options(const BuildOptions& options) {
  BuildOptions copy = options;
  std::vector<std::pair<std::string, std::string>> out;
  for (const ProvenanceField& field : provenance_fields()) {
    if (field.recorded(options)) out.emplace_back(field.key, field.write(copy));
  }
  if (options.meshing)
    for (const RepairCount& repair : options.repairs)
      out.emplace_back(kRepairPrefix + swap_characters(repair.kind, ' ', '_'),
                       std::to_string(repair.count));
  std::sort(out.begin(), out.end());
  return out;
}

bool options_from_provenance(const std::vector<std::pair<std::string, std::string>>& recorded,
                             BuildOptions& options, std::string* error) {
  options = BuildOptions{};
  for (const auto& [key, value] : recorded) {
    if (key.rfind(kRepairPrefix, 0) == 0) {
      const std::string kind = swap_characters(key.substr(std::strlen(kRepairPrefix)), '_', ' ');
      std::uint32_t count = 0;  // counts of triangles and vertices, which fit 32 bits
      if (kind.empty() || !parse_integer(value, count)) {
        if (error) *error = "bad repair record " + key + ": '" + value + "'";
        return false;
      }
      options.repairs.push_back({kind, count});
      continue;
    }
    const auto& fields = provenance_fields();
    const auto field = std::find_if(fields.begin(), fields.end(),
                                    [&](const ProvenanceField& f) { return key == f.key; });
    if (field == fields.end() || !field->read(value, options)) {
      if (error)
        *error = (field == fields.end() ? "unknown option " : "bad value for ") + key + ": '" +
                 value + "'";
      return false;
    }
  }
  return true;
}

std::uint64_t process_peak_rss_bytes() {
  // "VmHWM:   123456 kB" (Linux); the whole file is a few hundred bytes.
  if (std::FILE* status = std::fopen("/proc/self/status", "r")) {
    char line[256];
    unsigned long long kib = 0;
    bool found = false;
    while (!found && std::fgets(line, sizeof line, status) != nullptr)
      found = std::sscanf(line, "VmHWM: %llu kB", &kib) == 1;
    std::fclose(status);
    if (found) return static_cast<std::uint64_t>(kib) * 1024;
  }
  struct rusage usage {};
  if (::getrusage(RUSAGE_SELF, &usage) == 0 && usage.ru_maxrss > 0)
    return static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;  // KiB on Linux
  return 0;
}

namespace detail {

void add_clusters(format::Asset& asset, const std::vector<Vec3>& nodes,
                  const std::vector<Tri>& triangles, const Segmentation& segmentation,
                  const std::vector<DetectorChoice>& detectors, StageTimer& timer) {
  asset.triangles = triangles;
  asset.triangle_cluster = segmentation.triangle_cluster;
  timer.run("bvh", [&](std::string& summary) {
    std::vector<std::vector<std::uint32_t>> members(segmentation.cluster_count);
    for (std::uint32_t t = 0; t < segmentation.triangle_cluster.size(); ++t) {
      members[segmentation.triangle_cluster[t]].push_back(t);
    }
    for (std::uint32_t c = 0; c < segmentation.cluster_count; ++c) {
      ClusterBvh bvh = build_cluster_bvh(nodes, triangles, members[c]);
      format::Cluster cluster;
      cluster.detector = detectors[c].point;
      cluster.flags = detectors[c].overlap_only ? format::kClusterOverlapOnly : 0;
      cluster.rest_positive_fraction = detectors[c].rest_positive_fraction;
      cluster.triangle_offset = static_cast<std::uint32_t>(asset.cluster_triangles.size());
      cluster.triangle_count = static_cast<std::uint32_t>(bvh.triangles.size());
      cluster.bvh_offset = static_cast<std::uint32_t>(asset.bvh_nodes.size());
      cluster.bvh_count = static_cast<std::uint32_t>(bvh.nodes.size());
      asset.cluster_triangles.insert(asset.cluster_triangles.end(), bvh.triangles.begin(),
                                     bvh.triangles.end());
      asset.bvh_nodes.insert(asset.bvh_nodes.end(), bvh.nodes.begin(), bvh.nodes.end());
      asset.clusters.push_back(cluster);
    }
    summary = std::to_string(asset.bvh_nodes.size()) + " nodes";
    return 0;
  });
  for (const auto& loop : segmentation.boundary_loops) {
    format::BoundaryLoop boundary;
    boundary.node_offset = static_cast<std::uint32_t>(asset.boundary_nodes.size());
    boundary.node_count = static_cast<std::uint32_t>(loop.size());
    asset.boundary_nodes.insert(asset.boundary_nodes.end(), loop.begin(), loop.end());
    asset.boundaries.push_back(boundary);
  }
}

void set_provenance(format::Asset& asset, const std::string& source, const BuildOptions& options,
                    const BuildReport& report) {
  asset.provenance.tool_version = std::string("tetseg ") + TETSEG_VERSION_STRING;
  asset.provenance.source = base_name(source);
  BuildOptions used = options;  // with the charge solver actually used in place of "auto"
  if (!report.charge.solver.empty()) parse_name(report.charge.solver, used.charge.solver);
  // A tet mesh not made from a surface here (or a surface body: the input surface itself) is
  // the asset's surface: deviation 0.
  if (!used.meshing && !used.deviation) used.deviation = SurfaceDeviation{};
  asset.provenance.options = provenance_options(used);
}

}  // namespace detail

format::Asset build_asset(const TetMesh& mesh, const std::string& source,
                          const BuildOptions& options, BuildReport& report,
                          const std::function<void(const StageReport&)>& on_stage) {
  StageTimer timer(report, on_stage);
  report.nodes = static_cast<std::uint32_t>(mesh.nodes.size());
  report.tets = static_cast<std::uint32_t>(mesh.tets.size());

  std::vector<detail::SurfacePart> parts;  // one per component (docs/segmentation.md)
  const Surface surface = timer.run("surface", [&](std::string& summary) {
    detail::NodeParts node_parts;
    Surface s = detail::extract_valid_surface(mesh, source, node_parts);
    parts = detail::split_surface(mesh, s, node_parts);
    summary = std::to_string(s.triangles.size()) + " triangles, " +
              std::to_string(s.interior_nodes.size()) + " interior nodes, " +
              std::to_string(parts.size()) + (parts.size() == 1 ? " component" : " components");
    return s;
  });
  report.surface_triangles = static_cast<std::uint32_t>(surface.triangles.size());
  report.interior_nodes = static_cast<std::uint32_t>(surface.interior_nodes.size());
  report.components = static_cast<std::uint32_t>(parts.size());

  const Segmentation segmentation =
      detail::segment_parts(mesh.nodes, parts, surface.triangles.size(),
                            !surface.interior_nodes.empty(), options, source, report, timer);
  report.segmentation = segmentation.counts;
  report.clusters = segmentation.cluster_count;
  report.boundaries = static_cast<std::uint32_t>(segmentation.boundary_loops.size());

  const std::vector<DetectorChoice> detectors = timer.run("detectors", [&](std::string& summary) {
    std::vector<DetectorChoice> d;
    try {
      d = detail::detectors_by_part(mesh, parts, segmentation, options.segmentation.detector,
                                    options.segmentation.min_visibility);
    } catch (const InputError& e) {
      throw InputError(source, e.what());
    }
    double worst = 1.0;
    std::size_t in_tets = 0, flagged = 0;
    for (const DetectorChoice& detector : d) {
      worst = std::min<double>(worst, detector.rest_positive_fraction);
      in_tets += detector.point.is_node() ? 0 : 1;
      flagged += detector.overlap_only ? 1 : 0;
    }
    std::ostringstream text;
    text << d.size() << " detectors (" << in_tets << " inside tets), " << flagged
         << " overlap-only, lowest rest visibility " << worst;
    summary = text.str();
    return d;
  });

  format::Asset asset;
  asset.node_count = static_cast<std::uint32_t>(mesh.nodes.size());
  detail::add_clusters(asset, mesh.nodes, surface.triangles, segmentation, detectors, timer);
  if (options.keep_rest_positions) asset.rest_positions = mesh.nodes;
  detail::set_provenance(asset, source, options, report);
  for (const DetectorChoice& detector : detectors) {
    report.rest_positive_fraction.push_back(detector.rest_positive_fraction);
  }

  std::string detail;
  if (format::validate(asset, &detail) != format::Status::kOk) {
    throw std::runtime_error("internal error: built asset does not validate: " + detail);
  }
  return asset;
}

}  // namespace tetseg::preprocess
