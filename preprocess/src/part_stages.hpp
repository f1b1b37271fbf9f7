#pragma once
// Private: the pipeline stages of build_asset run per component of a tet mesh (each component
// is its own conductor, segmentation and detector set; docs/segmentation.md, "Several
// components"). The component topology itself is in components.hpp.

#include <cstdint>
#include <string>
#include <vector>

#include "components.hpp"
#include "tetseg/format/asset.hpp"
#include "tetseg/preprocess/charge.hpp"
#include "tetseg/preprocess/mesh.hpp"
#include "tetseg/preprocess/pipeline.hpp"
#include "tetseg/preprocess/segmentation.hpp"

namespace tetseg::preprocess::detail {

/// The values of `whole` (one per surface triangle) at the part's triangles, in order.
std::vector<double> part_values(const std::vector<double>& whole, const SurfacePart& part);

/// compute_charge on each part's surface alone (each component is its own conductor, so it
/// gets the charge, and hence the clusters, it would get in an asset of its own). Densities
/// are gathered into one value per surface triangle; capacitance, area and iterations add up,
/// the residual is the largest, converged only when every part converged.
ChargeResult charge_by_part(const std::vector<Vec3>& nodes, const std::vector<SurfacePart>& parts,
                            std::size_t triangle_count, const ChargeOptions& options,
                            const std::string& file);

/// One segmentation of the whole surface from one per part (in part order, local triangle
/// ids): cluster ids renumbered by their smallest triangle id, loops and counts concatenated.
Segmentation join_segmentations(const std::vector<SurfacePart>& parts,
                                const std::vector<Segmentation>& pieces,
                                std::size_t triangle_count);

/// One cluster per part (--clusters single on a mesh with several components).
Segmentation one_cluster_per_part(const std::vector<SurfacePart>& parts,
                                  std::size_t triangle_count);

/// choose_detector_points for each part on its own (only its interior nodes and tets are
/// candidates), for a segmentation whose clusters never span two parts; one detector per
/// cluster, tet ids those of `mesh`. Copies the node array once when there are several parts.
std::vector<DetectorChoice> detectors_by_part(const TetMesh& mesh,
                                              const std::vector<SurfacePart>& parts,
                                              const Segmentation& segmentation,
                                              DetectorStrategy strategy, double min_visibility);

/// The clustering stages of a build on `parts` (their triangle ids < triangle_count), timed by
/// `timer`: kSingle: one cluster per part, no stage; else charge, equalize, segmentation and,
/// for kRefined when `any_interior` (some part has interior nodes), refinement of the parts
/// with interior nodes (the others keep their charge segmentation). Fills report.charge
/// (density dropped) and report.refinement.
Segmentation segment_parts(const std::vector<Vec3>& nodes, const std::vector<SurfacePart>& parts,
                           std::size_t triangle_count, bool any_interior,
                           const BuildOptions& options, const std::string& source,
                           BuildReport& report, StageTimer& timer);

/// The "bvh" stage and the rest of the asset's cluster sections: `triangles` and
/// triangle_cluster, per cluster its BVH, detector (detectors[c]: point, overlap-only flag,
/// rest fraction) and offsets, and the boundary loops of `segmentation`.
void add_clusters(format::Asset& asset, const std::vector<Vec3>& nodes,
                  const std::vector<Tri>& triangles, const Segmentation& segmentation,
                  const std::vector<DetectorChoice>& detectors, StageTimer& timer);

/// The asset's provenance: tool version, the source's file name, provenance_options of
/// `options` with the charge solver report.charge used and deviation 0 when not set.
void set_provenance(format::Asset& asset, const std::string& source, const BuildOptions& options,
                    const BuildReport& report);

}  // namespace tetseg::preprocess::detail
