#pragma once
/// \file
/// Detectors carried by bones (DetectorForm::kBones): their positions for a pose of the
/// skeleton, by linear blend skinning, as an application computes them before each step
/// (`Collider::set_detector_positions`).

#include "tetseg/format/asset.hpp"

namespace tetseg::format {

/// Every cluster's detector position for one pose. `bone_matrices`: bone_names.size() x 12
/// doubles, per bone a row-major 3x4 skinning matrix (the bone's world transform times its
/// inverse bind matrix, so identity matrices leave the rest pose). `out`: clusters.size() x 3
/// doubles: per cluster `sum weight * (M_bone * detector_rest)` over its terms in term order;
/// a cluster without terms (overlap-only) gets `detector_rest` unchanged. For a kBones asset
/// that passed validation (term indices below bone_names.size()); other forms: every cluster
/// gets `detector_rest`. Non-finite matrices give non-finite positions (the collider then
/// rejects the step). Never throws, never allocates.
void skinned_detector_positions(const Asset& asset, const double* bone_matrices,
                                double* out) noexcept;

}  // namespace tetseg::format
