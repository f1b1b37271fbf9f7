#pragma once
/// \file
/// Skinned characters: a skeleton's bones and per-vertex skin weights read through assimp
/// (glTF `JOINTS_0`/`WEIGHTS_0`, FBX bones), and detectors carried by bones for
/// `tetseg build --body surface --detectors skin` (format::DetectorForm::kBones).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "tetseg/format/asset.hpp"
#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess {

/// A row-major 3x4 affine matrix (R | t): p -> R p + t.
using Affine3x4 = std::array<double, 12>;

/// One bone's share of a vertex.
struct BoneInfluence {
  std::uint32_t bone = 0;  ///< into Skin::bone_names
  double weight = 0.0;     ///< > 0
};

/// A skinned mesh as the file holds it.
struct Skin {
  std::vector<std::string> bone_names;  ///< distinct, in order of first appearance
  /// Per bone: its inverse bind matrix (mesh space at bind time -> bone space), affine.
  std::vector<Affine3x4> inverse_bind;
  /// The file's vertices (bind pose, mesh space), every mesh of the file in order, each mesh's
  /// vertices in the file's order (assimp told to keep them: no joining, no splitting).
  std::vector<Vec3> vertices;
  std::vector<Tri> triangles;  ///< into `vertices`, the file's order
  /// Per vertex: 1 or more influences, distinct bones in increasing order, weights > 0
  /// normalised to sum 1 (the file's weights, which sum to 1 within
  /// kSkinWeightSumTolerance, divided by their sum).
  std::vector<std::vector<BoneInfluence>> influences;
};

/// Largest |sum of a vertex's bone weights in the file - 1| that read_skin accepts.
inline constexpr double kSkinWeightSumTolerance = 0.01;

/// Reads the skin of every mesh in a file assimp reads (glTF 2.0 with a skin, FBX with
/// bones, ...). Throws InputError naming the file and the problem when it cannot be read,
/// holds no triangles, a mesh has no bones, a weight is negative or not finite, a vertex's
/// weights do not sum to 1 (within kSkinWeightSumTolerance; assimp's glTF importer silently
/// drops weights <= 0 and joints past the skin, which this catches), a weight
/// names a vertex that does not exist, a vertex has no positive weight, an inverse bind
/// matrix is not a finite affine matrix, or one bone name has two different inverse bind
/// matrices. Safe on untrusted input as far as assimp is.
Skin read_skin(const std::string& path);

/// The skin weights of each of `vertices` (a surface read from the same file, in whatever order
/// its reader numbered them), found by exact position among the skin's vertices. Vertices that
/// the file stores several times at one position (seams, FBX's per-corner vertices) must carry
/// the same weights within 1e-6. Throws InputError(path) naming the first vertex with no skin
/// vertex at its position, or with different weights at one position.
std::vector<std::vector<BoneInfluence>> skin_weights_at(const Skin& skin,
                                                        const std::vector<Vec3>& vertices,
                                                        const std::string& path);

/// The bones carrying one cluster's detector: the skin weights of the cluster's vertices (the
/// corners of `cluster_triangles`, each vertex once) averaged, the `max_terms` heaviest bones
/// kept (ties: lower bone id), renormalised to sum 1. Terms sorted by bone id. The detector's
/// rest position is left to the caller (`Cluster::detector_rest`): the terms move whatever
/// point the pipeline chose rigidly with the cluster's dominant bones.
/// `vertex_influences`: per surface vertex (skin_weights_at); `cluster_triangles`: non-empty.
std::vector<format::DetectorTerm> bone_detector_terms(
    const std::vector<std::vector<BoneInfluence>>& vertex_influences,
    const std::vector<Tri>& triangles, const std::vector<std::uint32_t>& cluster_triangles,
    std::uint32_t max_terms = 4);

/// Turns a surface body's detectors into bone-carried ones (`--detectors skin`): for every
/// classified cluster, bone_detector_terms over its triangles; overlap-only clusters get no
/// terms. Keeps each cluster's `detector_rest` (the point the pipeline chose), sets
/// `detector_form` = kBones, `detector_terms` and `bone_names` = the skin's. `asset`: a
/// kSurface body whose node i is at `vertices[i]` at rest (matched to the skin's vertices by
/// position, skin_weights_at). Throws InputError(path) when the skin does not cover the
/// vertices or has more than format::kMaxBones bones; `asset` is unchanged then.
void carry_detectors_by_bones(format::Asset& asset, const std::vector<Vec3>& vertices,
                              const Skin& skin, const std::string& path,
                              std::uint32_t max_terms = 4);

}  // namespace tetseg::preprocess
