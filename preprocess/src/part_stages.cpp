// The pipeline stages run per component (part_stages.hpp): charge, segmentation joining and
// detector choice on each part of a tet mesh with several components.

#include "part_stages.hpp"

#include <algorithm>
#include <sstream>
#include <utility>

#include "tetseg/preprocess/names.hpp"

namespace tetseg::preprocess::detail {
namespace {

constexpr std::uint32_t kUnset = NodeParts::kNoPart;

}  // namespace

std::vector<double> part_values(const std::vector<double>& whole, const SurfacePart& part) {
  std::vector<double> out;
  out.reserve(part.triangles.size());
  for (std::uint32_t t : part.triangles) out.push_back(whole[t]);
  return out;
}

ChargeResult charge_by_part(const std::vector<Vec3>& nodes, const std::vector<SurfacePart>& parts,
                            std::size_t triangle_count, const ChargeOptions& options,
                            const std::string& file) {
  if (parts.size() == 1) return compute_charge(nodes, parts[0].surface.triangles, options, file);
  ChargeResult total;
  total.density.assign(triangle_count, 0.0);
  total.converged = true;
  for (const SurfacePart& part : parts) {
    ChargeResult r = compute_charge(nodes, part.surface.triangles, options, file);
    for (std::size_t i = 0; i < part.triangles.size(); ++i)
      total.density[part.triangles[i]] = r.density[i];
    total.capacitance += r.capacitance;
    total.total_area += r.total_area;
    if (total.solver.empty()) {
      total.solver = r.solver;
    } else if (total.solver != r.solver) {
      total.solver += "+" + r.solver;
    }
    total.iterations += r.iterations;
    total.relaxed_products += r.relaxed_products;
    total.residual = std::max(total.residual, r.residual);
    total.tolerance = std::max(total.tolerance, r.tolerance);
    total.converged = total.converged && r.converged;
    total.near_entries += r.near_entries;
    total.assembly_seconds += r.assembly_seconds;
    total.solve_seconds += r.solve_seconds;
  }
  return total;
}

Segmentation join_segmentations(const std::vector<SurfacePart>& parts,
                                const std::vector<Segmentation>& pieces,
                                std::size_t triangle_count) {
  if (parts.size() == 1) return pieces.front();
  // Global cluster ids in order of each cluster's smallest triangle id.
  std::vector<std::uint32_t> offset(parts.size() + 1, 0);
  for (std::size_t p = 0; p < parts.size(); ++p)
    offset[p + 1] = offset[p] + pieces[p].cluster_count;
  std::vector<std::uint32_t> key(triangle_count, kUnset);  // offset[p] + local cluster
  for (std::size_t p = 0; p < parts.size(); ++p)
    for (std::size_t i = 0; i < parts[p].triangles.size(); ++i)
      key[parts[p].triangles[i]] = offset[p] + pieces[p].triangle_cluster[i];
  std::vector<std::uint32_t> renumber(offset.back(), kUnset);
  Segmentation out;
  out.triangle_cluster.resize(triangle_count);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    if (renumber[key[t]] == kUnset) renumber[key[t]] = out.cluster_count++;
    out.triangle_cluster[t] = renumber[key[t]];
  }
  out.min_cluster_triangles = pieces.front().min_cluster_triangles;
  for (const Segmentation& s : pieces) {
    out.boundary_loops.insert(out.boundary_loops.end(), s.boundary_loops.begin(),
                              s.boundary_loops.end());
    out.boundary_lengths.insert(out.boundary_lengths.end(), s.boundary_lengths.begin(),
                                s.boundary_lengths.end());
    out.min_cluster_triangles = std::min(out.min_cluster_triangles, s.min_cluster_triangles);
    out.counts.segments_found += s.counts.segments_found;
    out.counts.segments_grown += s.counts.segments_grown;
    out.counts.segments_shrunk += s.counts.segments_shrunk;
    out.counts.boundaries += s.counts.boundaries;
    out.counts.clusters_merged += s.counts.clusters_merged;
  }
  out.counts.clusters = out.cluster_count;
  return out;
}

Segmentation one_cluster_per_part(const std::vector<SurfacePart>& parts,
                                  std::size_t triangle_count) {
  Segmentation out;
  out.triangle_cluster.assign(triangle_count, 0);
  for (std::uint32_t p = 0; p < parts.size(); ++p)
    for (std::uint32_t t : parts[p].triangles) out.triangle_cluster[t] = p;
  out.cluster_count = static_cast<std::uint32_t>(parts.size());
  out.counts.clusters = out.cluster_count;
  return out;
}

std::vector<DetectorChoice> detectors_by_part(const TetMesh& mesh,
                                              const std::vector<SurfacePart>& parts,
                                              const Segmentation& segmentation,
                                              DetectorStrategy strategy, double min_visibility) {
  if (parts.size() == 1)
    return choose_detector_points(mesh, parts[0].surface, segmentation.triangle_cluster,
                                  segmentation.cluster_count, strategy, min_visibility);
  std::vector<DetectorChoice> out(segmentation.cluster_count);
  std::vector<std::uint32_t> local_of(segmentation.cluster_count, kUnset);
  TetMesh component;  // all nodes (ids kept), the part's tets
  component.nodes = mesh.nodes;
  for (const SurfacePart& part : parts) {
    std::vector<std::uint32_t> global_of;  // local cluster -> global cluster
    std::vector<std::uint32_t> local(part.triangles.size());
    for (std::size_t i = 0; i < part.triangles.size(); ++i) {
      const std::uint32_t c = segmentation.triangle_cluster[part.triangles[i]];
      if (local_of[c] == kUnset) {
        local_of[c] = static_cast<std::uint32_t>(global_of.size());
        global_of.push_back(c);
      }
      local[i] = local_of[c];
    }
    component.tets.clear();
    for (std::uint32_t t : part.tets) component.tets.push_back(mesh.tets[t]);
    std::vector<DetectorChoice> chosen = choose_detector_points(
        component, part.surface, local, static_cast<std::uint32_t>(global_of.size()), strategy,
        min_visibility);
    for (std::size_t k = 0; k < chosen.size(); ++k) {
      if (chosen[k].point.tet != format::kNoTet)
        chosen[k].point.tet = part.tets[chosen[k].point.tet];
      out[global_of[k]] = chosen[k];
    }
  }
  return out;
}

Segmentation segment_parts(const std::vector<Vec3>& nodes, const std::vector<SurfacePart>& parts,
                           std::size_t triangle_count, bool any_interior,
                           const BuildOptions& options, const std::string& source,
                           BuildReport& report, StageTimer& timer) {
  Segmentation segmentation;
  if (options.clusters == ClusterMethod::kSingle) {
    segmentation = one_cluster_per_part(parts, triangle_count);
  } else {
    ChargeResult charge = timer.run("charge", [&](std::string& summary) {
      ChargeResult r = charge_by_part(nodes, parts, triangle_count, options.charge, source);
      std::ostringstream text;
      text << r.solver << ", " << r.iterations << " iterations, residual " << r.residual
           << " (tolerance " << r.tolerance << ")"
           << ", capacitance " << r.capacitance;
      summary = text.str();
      return r;
    });
    std::vector<std::vector<double>> equalized;  // per part
    timer.run("equalize", [&](std::string& summary) {
      summary = name_of(options.segmentation.equalization);
      for (const SurfacePart& part : parts)
        equalized.push_back(
            equalize(part_values(charge.density, part), options.segmentation.equalization));
      return 0;
    });
    charge.density.clear();
    report.charge = std::move(charge);
    std::vector<Segmentation> pieces;  // per part
    segmentation = timer.run("segmentation", [&](std::string& summary) {
      for (std::size_t p = 0; p < parts.size(); ++p)
        pieces.push_back(
            segment_surface(nodes, parts[p].surface, equalized[p], options.segmentation));
      Segmentation s = join_segmentations(parts, pieces, triangle_count);
      summary = std::to_string(s.counts.segments_found) + " segments, " +
                std::to_string(s.boundary_loops.size()) + " boundaries, " +
                std::to_string(s.cluster_count) + " clusters";
      return s;
    });
    // Refinement searches interior nodes; a mesh without one (a mat one tet thick) keeps the
    // charge segmentation, and its detectors are points inside tets.
    if (options.clusters == ClusterMethod::kRefined && any_interior) {
      segmentation = timer.run("refinement", [&](std::string& summary) {
        for (std::size_t p = 0; p < parts.size(); ++p) {
          if (parts[p].surface.interior_nodes.empty()) {  // kept as segmented
            report.refinement.clusters_before += pieces[p].cluster_count;
            continue;
          }
          RefinementCounts counts;
          pieces[p] = refine_clusters(nodes, parts[p].surface, equalized[p], pieces[p],
                                      options.refinement, &counts);
          report.refinement.clusters_before += counts.clusters_before;
          report.refinement.splits += counts.splits;
          report.refinement.merges += counts.merges;
        }
        Segmentation s = join_segmentations(parts, pieces, triangle_count);
        summary = std::to_string(report.refinement.splits) + " splits, " +
                  std::to_string(report.refinement.merges) + " merges, " +
                  std::to_string(s.cluster_count) + " clusters";
        return s;
      });
    }
  }
  return segmentation;
}

}  // namespace tetseg::preprocess::detail
