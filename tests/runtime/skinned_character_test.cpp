// The generated skinned character (tetseg/testing/skinned_tube.hpp) as a surface body: every
// step of its bending sequence, up to the step where it first touches itself, matches the
// scene oracle and exact arithmetic (runtime/support/compare.hpp) with detectors carried by
// bones (right and wrong bone motion) and by surface weights (issue 29).

#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "runtime/support/compare.hpp"
#include "tetseg/format/skin.hpp"
#include "tetseg/testing/skinned_tube.hpp"

namespace {

using tetseg::ColliderMode;
using tetseg::ColliderStatus;
using tetseg::format::DetectorForm;
using tetseg::test::Affine;
using tetseg::test::SkinnedTube;

/// The tube as a surface body: one cluster per bone (triangles by centroid x), each watched
/// from the axis at the middle of its bone: carried by that bone alone (kBones), or the mean of
/// the vertex ring there (kSurfaceWeights).
tetseg::test::Scene tube_scene(const SkinnedTube& tube, DetectorForm form) {
  tetseg::test::Surface s;
  for (std::size_t v = 0; v < tube.vertex_count(); ++v)
    s.verts.push_back({tube.rest[3 * v], tube.rest[3 * v + 1], tube.rest[3 * v + 2]});
  s.tris.assign(tube.triangles.begin(), tube.triangles.end());
  tetseg::format::Asset a;
  a.body_kind = tetseg::format::BodyKind::kSurface;
  a.detector_form = form;
  a.node_count = static_cast<std::uint32_t>(s.verts.size());
  a.rest_positions = s.verts;
  a.triangles = s.tris;
  const std::uint32_t bones = tube.options.bones;
  for (std::uint32_t t = 0; t < s.tris.size(); ++t) {
    double x = 0;
    for (std::uint32_t v : s.tris[t]) x += s.verts[v][0] / 3;
    a.triangle_cluster.push_back(std::min<std::uint32_t>(bones - 1, x < 0 ? 0 : std::uint32_t(x)));
  }
  for (std::uint32_t b = 0; b < bones; ++b) {
    std::vector<std::uint32_t> tris, order;
    for (std::uint32_t t = 0; t < s.tris.size(); ++t)
      if (a.triangle_cluster[t] == b) tris.push_back(t);
    std::vector<tetseg::format::BvhNode> nodes;
    tetseg::test::build_bvh(s, tris, 2, order, nodes);
    tetseg::format::Cluster c;
    c.rest_positive_fraction = 1.0f;
    c.triangle_offset = static_cast<std::uint32_t>(a.cluster_triangles.size());
    c.triangle_count = static_cast<std::uint32_t>(order.size());
    c.bvh_offset = static_cast<std::uint32_t>(a.bvh_nodes.size());
    c.bvh_count = static_cast<std::uint32_t>(nodes.size());
    a.cluster_triangles.insert(a.cluster_triangles.end(), order.begin(), order.end());
    a.bvh_nodes.insert(a.bvh_nodes.end(), nodes.begin(), nodes.end());
    c.detector_term_offset = static_cast<std::uint32_t>(a.detector_terms.size());
    const double middle = (b + 0.5) * tube.options.bone_length;
    if (form == DetectorForm::kBones) {
      a.detector_terms.push_back({b, 1.0});
      c.detector_rest = {middle, 0, 0};
    } else {
      std::vector<std::uint32_t> ring;
      for (std::uint32_t v = 0; v < s.verts.size(); ++v)
        if (s.verts[v][0] == middle) ring.push_back(v);
      REQUIRE(ring.size() == tube.options.around);
      for (std::uint32_t v : ring) a.detector_terms.push_back({v, 1.0 / ring.size()});
      c.detector_rest = {0, 0, 0};
      for (std::uint32_t v : ring)
        for (int k = 0; k < 3; ++k) c.detector_rest[k] += s.verts[v][k] / ring.size();
    }
    c.detector_term_count =
        static_cast<std::uint32_t>(a.detector_terms.size()) - c.detector_term_offset;
    a.clusters.push_back(c);
  }
  if (form == DetectorForm::kBones) a.bone_names = tube.bone_names;
  a.provenance.tool_version = "tetseg tests";
  return tetseg::test::load_scene(a, a.node_count);
}

std::vector<double> flat(const std::vector<Affine>& matrices) {
  std::vector<double> out;
  for (const Affine& m : matrices) out.insert(out.end(), m.begin(), m.end());
  return out;
}

/// How the detectors of a kBones asset move in a step.
enum class BoneMotion {
  kRight,     ///< the bones that move the surface
  kReversed,  ///< the bones of the mirrored frame of the sequence, in reversed bone order
  kFarAway,   ///< the right bones, then 3 bone lengths along +z and turned: outside every part
};

struct Run {
  int steps_compared = 0;
  int contact_steps = 0;
  std::uint64_t triangle_pairs = 0;  ///< rvbc's tested triangle pairs over the compared steps
};

/// Steps the sequence with rvbc until the first step with a required contact, each step
/// against the oracle and exact arithmetic (rvbc: every contact at the earliest time).
Run run_sequence(const tetseg::test::Scene& scene, const SkinnedTube& tube,
                 const std::vector<std::vector<Affine>>& poses, BoneMotion motion,
                 ColliderMode mode = ColliderMode::kRvbc) {
  const auto& asset = scene.asset.data();
  std::vector<std::vector<double>> frames, detectors;
  const std::size_t n = poses.size();
  for (std::size_t f = 0; f < n; ++f) {
    frames.push_back(tetseg::test::skin_tube(tube, poses[f]));
    std::vector<Affine> carry = poses[f];
    if (motion == BoneMotion::kReversed) {
      carry.assign(poses[n - 1 - f].rbegin(), poses[n - 1 - f].rend());
    } else if (motion == BoneMotion::kFarAway) {
      const Affine away = tetseg::test::affine_multiply(
          tetseg::test::affine_translation(0, 0, 3 * tube.options.bone_length),
          tetseg::test::affine_rotation_y(0.3 + 0.05 * double(f)));
      for (Affine& m : carry) m = tetseg::test::affine_multiply(away, m);
    }
    detectors.emplace_back(3 * asset.clusters.size());
    tetseg::format::skinned_detector_positions(asset, flat(carry).data(), detectors.back().data());
  }
  tetseg::Collider collider = tetseg::test::collider_for(scene, mode);
  REQUIRE(collider.status() == ColliderStatus::kOk);
  Run run;
  for (std::size_t f = 0; f + 1 < n; ++f) {
    CAPTURE(f);
    if (asset.detector_form == DetectorForm::kBones)
      REQUIRE(collider.set_detector_positions(detectors[f].data(), detectors[f + 1].data(),
                                              detectors[f].size()) == ColliderStatus::kOk);
    const auto truth = tetseg::test::step_truth(scene, frames[f].data(), frames[f + 1].data());
    const auto answer = tetseg::test::answer(collider, frames[f].data(), frames[f + 1].data());
    tetseg::test::require_matches_oracle(answer, truth,
                                         mode == ColliderMode::kRvbc
                                             ? tetseg::test::Expect::kEarliestContacts
                                             : tetseg::test::Expect::kAllContacts);
    ++run.steps_compared;
    run.triangle_pairs += collider.stats().triangle_pairs;
    if (!truth.required.empty()) {
      ++run.contact_steps;
      break;  // later steps may start self-intersecting (the culling's premise)
    }
  }
  return run;
}

}  // namespace

TEST_CASE("skinned character: bone-carried detectors match brute force, also on wrong bones",
          "[skin]") {
  const SkinnedTube tube = tetseg::test::make_skinned_tube({4, 1.0, 0.25, 16, 6, 3, 0.35});
  const auto poses = tetseg::test::tube_bend_sequence(tube, 25, M_PI / 2, 0.15);
  const auto scene = tube_scene(tube, DetectorForm::kBones);
  const Run bvh = run_sequence(scene, tube, poses, BoneMotion::kRight, ColliderMode::kBvh);
  const Run right = run_sequence(scene, tube, poses, BoneMotion::kRight);
  // The sequence reaches a contact, and rvbc culls there (fewer triangle pairs than bvh).
  CHECK(right.contact_steps == 1);
  CHECK(right.steps_compared == bvh.steps_compared);
  CHECK(right.steps_compared > 10);
  CHECK(right.triangle_pairs < bvh.triangle_pairs);
  SECTION("detectors moved by wrong bones: still every contact, only less culling") {
    for (BoneMotion motion : {BoneMotion::kReversed, BoneMotion::kFarAway}) {
      CAPTURE(int(motion));
      const Run wrong = run_sequence(scene, tube, poses, motion);
      CHECK(wrong.contact_steps == 1);
      CHECK(wrong.steps_compared == right.steps_compared);
      CHECK(wrong.triangle_pairs > right.triangle_pairs);
    }
  }
}

TEST_CASE("skinned character: surface-weight detectors match brute force", "[skin]") {
  const SkinnedTube tube = tetseg::test::make_skinned_tube({4, 1.0, 0.25, 16, 6, 3, 0.35});
  const auto poses = tetseg::test::tube_bend_sequence(tube, 25, M_PI / 2, 0.15);
  const auto scene = tube_scene(tube, DetectorForm::kSurfaceWeights);
  const auto bones = tube_scene(tube, DetectorForm::kBones);
  const Run weights = run_sequence(scene, tube, poses, BoneMotion::kRight);
  const Run right = run_sequence(bones, tube, poses, BoneMotion::kRight);
  CHECK(weights.contact_steps == 1);
  CHECK(weights.steps_compared == right.steps_compared);
  const Run bvh = run_sequence(scene, tube, poses, BoneMotion::kRight, ColliderMode::kBvh);
  CHECK(weights.triangle_pairs < bvh.triangle_pairs);
}
