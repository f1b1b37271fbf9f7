#include "tetseg/preprocess/pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <sstream>

#include "tetseg/format/asset_io.hpp"
#include "tetseg/preprocess/surface.hpp"

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

const char* solver_name(ChargeSolver solver) {
  switch (solver) {
    case ChargeSolver::kAuto: return "auto";
    case ChargeSolver::kDirect: return "direct";
    case ChargeSolver::kGmres: return "gmres";
    case ChargeSolver::kFast: return "fast";
  }
  return "auto";
}

const char* equalization_name(Equalization method) {
  switch (method) {
    case Equalization::kHistogram: return "histogram";
    case Equalization::kRank: return "rank";
    case Equalization::kLogHistogram: return "log-histogram";
  }
  return "histogram";
}

const char* detector_name(DetectorStrategy strategy) {
  return strategy == DetectorStrategy::kNearestCentroid ? "nearest-centroid" : "visibility";
}

const char* cluster_method_name(ClusterMethod method) {
  switch (method) {
    case ClusterMethod::kSingle: return "single";
    case ClusterMethod::kCharge: return "charge";
    case ClusterMethod::kRefined: return "refined";
  }
  return "charge";
}

std::string base_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

std::vector<std::pair<std::string, std::string>> provenance_options(const BuildOptions& options) {
  const SegmentationOptions& seg = options.segmentation;
  std::vector<std::pair<std::string, std::string>> out = {
      {"clusters", cluster_method_name(options.clusters)},
      {"charge.solver", solver_name(options.charge.solver)},
      {"charge.tolerance",
       options.charge.tolerance == 0.0 ? "auto" : format_number(options.charge.tolerance)},
      {"segmentation.alpha", format_number(seg.alpha)},
      {"segmentation.beta_divisor", format_number(seg.beta_divisor)},
      {"segmentation.equalization", equalization_name(seg.equalization)},
      {"segmentation.growth_bound", format_number(seg.growth_bound)},
      {"segmentation.grow_through_marked", seg.grow_through_marked ? "yes" : "no"},
      {"segmentation.min_cluster_triangles", std::to_string(seg.min_cluster_triangles)},
      {"segmentation.detector", detector_name(seg.detector)},
      {"rest_positions", options.keep_rest_positions ? "yes" : "no"},
  };
  if (options.clusters == ClusterMethod::kRefined) {
    const RefinementOptions& ref = options.refinement;
    out.insert(out.end(), {{"refine.min_visibility", format_number(ref.min_visibility)},
                           {"refine.gain_per_cut_edge", format_number(ref.gain_per_cut_edge)},
                           {"refine.invisibility_cost", format_number(ref.invisibility_cost)},
                           {"refine.max_clusters", std::to_string(ref.max_clusters)},
                           {"refine.min_cluster_triangles",
                            std::to_string(ref.min_cluster_triangles)},
                           {"refine.merge", ref.merge ? "yes" : "no"}});
  }
  std::sort(out.begin(), out.end());
  return out;
}

format::Asset build_asset(const TetMesh& mesh, const std::string& source,
                          const BuildOptions& options, BuildReport& report,
                          const std::function<void(const StageReport&)>& on_stage) {
  StageTimer timer(report, on_stage);
  report.nodes = static_cast<std::uint32_t>(mesh.nodes.size());
  report.tets = static_cast<std::uint32_t>(mesh.tets.size());

  const Surface surface = timer.run("surface", [&](std::string& summary) {
    Surface s = extract_surface(mesh);
    validate_tet_mesh(mesh, s, source);
    summary = std::to_string(s.triangles.size()) + " triangles, " +
              std::to_string(s.interior_nodes.size()) + " interior nodes";
    return s;
  });
  report.surface_triangles = static_cast<std::uint32_t>(surface.triangles.size());
  report.interior_nodes = static_cast<std::uint32_t>(surface.interior_nodes.size());
  if (surface.interior_nodes.empty()) {
    throw InputError(source, "tet mesh has no interior node to serve as a detector point "
                             "(refine the mesh or tetrahedralise with a smaller cell size)");
  }

  Segmentation segmentation;
  if (options.clusters == ClusterMethod::kSingle) {
    segmentation.triangle_cluster.assign(surface.triangles.size(), 0);
    segmentation.cluster_count = 1;
    segmentation.counts.clusters = 1;
  } else {
    ChargeResult charge = timer.run("charge", [&](std::string& summary) {
      ChargeResult r = compute_charge(mesh.nodes, surface.triangles, options.charge, source);
      std::ostringstream text;
      text << r.solver << ", " << r.iterations << " iterations, residual " << r.residual
           << " (tolerance " << r.tolerance << ")"
           << ", capacitance " << r.capacitance;
      summary = text.str();
      return r;
    });
    const std::vector<double> equalized = timer.run("equalize", [&](std::string& summary) {
      summary = equalization_name(options.segmentation.equalization);
      return equalize(charge.density, options.segmentation.equalization);
    });
    charge.density.clear();
    report.charge = std::move(charge);
    segmentation = timer.run("segmentation", [&](std::string& summary) {
      Segmentation s = segment_surface(mesh.nodes, surface, equalized, options.segmentation);
      summary = std::to_string(s.counts.segments_found) + " segments, " +
                std::to_string(s.boundary_loops.size()) + " boundaries, " +
                std::to_string(s.cluster_count) + " clusters";
      return s;
    });
    if (options.clusters == ClusterMethod::kRefined) {
      segmentation = timer.run("refinement", [&](std::string& summary) {
        Segmentation s = refine_clusters(mesh.nodes, surface, equalized, segmentation,
                                         options.refinement, &report.refinement);
        summary = std::to_string(report.refinement.splits) + " splits, " +
                  std::to_string(report.refinement.merges) + " merges, " +
                  std::to_string(s.cluster_count) + " clusters";
        return s;
      });
    }
  }
  report.segmentation = segmentation.counts;
  report.clusters = segmentation.cluster_count;
  report.boundaries = static_cast<std::uint32_t>(segmentation.boundary_loops.size());

  const std::vector<Detector> detectors = timer.run("detectors", [&](std::string& summary) {
    std::vector<Detector> d =
        choose_detectors(mesh.nodes, surface, segmentation.triangle_cluster,
                         segmentation.cluster_count, options.segmentation.detector);
    double worst = 1.0;
    for (const Detector& detector : d) worst = std::min<double>(worst, detector.rest_positive_fraction);
    std::ostringstream text;
    text << d.size() << " detector nodes, lowest rest visibility " << worst;
    summary = text.str();
    return d;
  });

  format::Asset asset;
  asset.node_count = static_cast<std::uint32_t>(mesh.nodes.size());
  asset.triangles = surface.triangles;
  asset.triangle_cluster = segmentation.triangle_cluster;
  timer.run("bvh", [&](std::string& summary) {
    std::vector<std::vector<std::uint32_t>> members(segmentation.cluster_count);
    for (std::uint32_t t = 0; t < segmentation.triangle_cluster.size(); ++t) {
      members[segmentation.triangle_cluster[t]].push_back(t);
    }
    for (std::uint32_t c = 0; c < segmentation.cluster_count; ++c) {
      ClusterBvh bvh = build_cluster_bvh(mesh.nodes, surface.triangles, members[c]);
      format::Cluster cluster;
      cluster.detector_node = detectors[c].node;
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
  if (options.keep_rest_positions) asset.rest_positions = mesh.nodes;
  asset.provenance.tool_version = std::string("tetseg ") + TETSEG_VERSION_STRING;
  asset.provenance.source = base_name(source);
  asset.provenance.options = provenance_options(options);
  for (const Detector& detector : detectors) {
    report.rest_positive_fraction.push_back(detector.rest_positive_fraction);
  }

  std::string detail;
  if (format::validate(asset, &detail) != format::Status::kOk) {
    throw std::runtime_error("internal error: built asset does not validate: " + detail);
  }
  return asset;
}

}  // namespace tetseg::preprocess
