// Tet meshes with several components: splitting the surface by component, the per-component
// checks, and running charge, segmentation and detector choice per component.

#include "components.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "segment_topology.hpp"
#include "vec3_math.hpp"

namespace tetseg::preprocess::detail {
namespace {

constexpr std::uint32_t kUnset = NodeParts::kNoPart;

/// Node sets joined through every triangle (or tet) of `elements`.
template <typename Elements>
UnionFind joined_nodes(std::size_t node_count, const Elements& elements) {
  UnionFind sets(static_cast<std::uint32_t>(node_count));
  for (const auto& element : elements)
    for (std::size_t k = 1; k < element.size(); ++k) sets.unite(element[0], element[k]);
  return sets;
}

/// Each node's component from the roots of tet_node_roots, numbered in order of the first
/// surface triangle.
NodeParts node_parts(const std::vector<std::uint32_t>& roots, const Surface& surface) {
  NodeParts parts;
  std::vector<std::uint32_t> part_of_root(roots.size(), kUnset);
  for (const Tri& t : surface.triangles)
    if (part_of_root[roots[t[0]]] == kUnset) part_of_root[roots[t[0]]] = parts.count++;
  parts.part.resize(roots.size());
  for (std::uint32_t v = 0; v < parts.part.size(); ++v) parts.part[v] = part_of_root[roots[v]];
  return parts;
}

}  // namespace

std::vector<std::uint32_t> tet_node_roots(const TetMesh& mesh) {
  UnionFind sets(static_cast<std::uint32_t>(mesh.nodes.size()));
  const std::size_t tet_count = mesh.tets.size();
  for (std::size_t t = 0; t < tet_count; ++t) {
    // The parent array is prefetched a few tets ahead: node order rarely follows the tets.
    constexpr std::size_t kAhead = 8;
    if (t + kAhead < tet_count)
      for (std::uint32_t v : mesh.tets[t + kAhead]) sets.prefetch(v);
    const Tet& tet = mesh.tets[t];
    for (std::size_t k = 1; k < 4; ++k) sets.unite(tet[0], tet[k]);
  }
  std::vector<std::uint32_t> roots(mesh.nodes.size());
  for (std::uint32_t v = 0; v < roots.size(); ++v) roots[v] = sets.find(v);
  return roots;
}

std::vector<SurfacePart> split_surface(const TetMesh& mesh, const Surface& surface,
                                       const NodeParts& node_parts) {
  const std::uint32_t count = node_parts.count;
  const std::vector<std::uint32_t>& part = node_parts.part;
  if (count <= 1) {
    SurfacePart whole;
    whole.triangles.resize(surface.triangles.size());
    std::iota(whole.triangles.begin(), whole.triangles.end(), 0u);
    whole.surface = surface;
    return {whole};
  }
  std::vector<SurfacePart> parts(count);
  for (std::uint32_t t = 0; t < surface.triangles.size(); ++t) {
    SurfacePart& p = parts[part[surface.triangles[t][0]]];
    p.triangles.push_back(t);
    p.surface.triangles.push_back(surface.triangles[t]);
  }
  for (std::uint32_t t = 0; t < mesh.tets.size(); ++t)
    if (part[mesh.tets[t][0]] != kUnset) parts[part[mesh.tets[t][0]]].tets.push_back(t);
  for (std::uint32_t v : surface.surface_nodes)
    if (part[v] != kUnset) parts[part[v]].surface.surface_nodes.push_back(v);
  for (std::uint32_t v : surface.interior_nodes)
    if (part[v] != kUnset) parts[part[v]].surface.interior_nodes.push_back(v);
  return parts;
}

NodeParts check_components(const TetMesh& mesh, const Surface& surface,
                           const std::vector<std::uint32_t>& roots, const std::string& file) {
  NodeParts parts = node_parts(roots, surface);
  const std::uint32_t count = parts.count;
  const std::vector<std::uint32_t>& part = parts.part;
  // Closed surfaces per component: triangles joined through shared nodes (the surface is
  // vertex-manifold here, so this is edge-connectivity).
  UnionFind shell_sets = joined_nodes(mesh.nodes.size(), surface.triangles);
  std::vector<std::uint32_t> shells(count, 0);
  std::vector<std::uint32_t> first_node(count, kUnset);
  for (std::uint32_t v : surface.surface_nodes) {
    if (shell_sets.find(v) == v) ++shells[part[v]];
    if (first_node[part[v]] == kUnset) first_node[part[v]] = v;
  }
  for (std::uint32_t c = 0; c < count; ++c)
    if (shells[c] > 1)
      throw InputError(file, "component " + std::to_string(c + 1) + " of " + std::to_string(count) +
                                 " (node " + std::to_string(first_node[c]) + ") is bounded by " +
                                 std::to_string(shells[c]) +
                                 " closed surfaces: bodies with a cavity are not supported");
  if (count <= 1) return parts;
  std::vector<std::uint32_t> triangle_component;
  triangle_component.reserve(surface.triangles.size());
  for (const Tri& t : surface.triangles) triangle_component.push_back(part[t[0]]);
  check_not_nested(mesh.nodes, surface.triangles, triangle_component, count, file);
  return parts;
}

void check_not_nested(const std::vector<Vec3>& points, const std::vector<Tri>& triangles,
                      const std::vector<std::uint32_t>& triangle_component, std::uint32_t count,
                      const std::string& file) {
  if (count <= 1) return;
  std::vector<std::array<Vec3, 2>> box(count);
  for (auto& b : box) {
    b[0] = {INFINITY, INFINITY, INFINITY};
    b[1] = {-INFINITY, -INFINITY, -INFINITY};
  }
  std::vector<std::uint32_t> first_node(count, kUnset);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const std::uint32_t c = triangle_component[t];
    if (first_node[c] == kUnset) first_node[c] = triangles[t][0];
    for (std::uint32_t v : triangles[t])
      for (int k = 0; k < 3; ++k) {
        box[c][0][k] = std::min(box[c][0][k], points[v][k]);
        box[c][1][k] = std::max(box[c][1][k], points[v][k]);
      }
  }
  for (std::uint32_t c = 0; c < count; ++c) {
    const Vec3& p = points[first_node[c]];
    for (std::uint32_t d = 0; d < count; ++d) {
      if (d == c) continue;
      bool inside_box = true;
      for (int k = 0; k < 3; ++k)
        inside_box = inside_box && p[k] >= box[d][0][k] && p[k] <= box[d][1][k];
      if (!inside_box) continue;
      double angle = 0.0;
      for (std::size_t t = 0; t < triangles.size(); ++t)
        if (triangle_component[t] == d)
          angle += solid_angle(p, points[triangles[t][0]], points[triangles[t][1]],
                               points[triangles[t][2]]);
      const double four_pi = 16.0 * std::atan(1.0);
      if (std::fabs(angle) > 0.5 * four_pi)
        throw InputError(file, "component " + std::to_string(c + 1) + " (node " +
                                   std::to_string(first_node[c]) + ") lies inside component " +
                                   std::to_string(d + 1) + " of " + std::to_string(count) +
                                   ": their volumes overlap at rest (a body inside another, or a "
                                   "cavity, is not supported)");
    }
  }
}

void check_surface_not_nested(const TriangleMesh& mesh, const std::string& file) {
  UnionFind sets = joined_nodes(mesh.vertices.size(), mesh.triangles);
  std::vector<std::uint32_t> component_of_root(mesh.vertices.size(), kUnset);
  std::vector<std::uint32_t> triangle_component;
  std::uint32_t count = 0;
  for (const Tri& t : mesh.triangles) {
    std::uint32_t& c = component_of_root[sets.find(t[0])];
    if (c == kUnset) c = count++;
    triangle_component.push_back(c);
  }
  check_not_nested(mesh.vertices, mesh.triangles, triangle_component, count, file);
}

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

}  // namespace tetseg::preprocess::detail
