// Skins through assimp (read_skin), skin weights mapped onto surface vertices, bone-carried
// detector terms, and the generated skinned character they are tested on
// (tetseg/testing/skinned_tube.hpp).

#include <unistd.h>

#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "tetseg/preprocess/io.hpp"
#include "tetseg/preprocess/skin.hpp"
#include "tetseg/testing/skinned_tube.hpp"

namespace fs = std::filesystem;
using namespace tetseg::preprocess;
using tetseg::test::SkinnedTube;

namespace {

struct TempDir {
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() /
             ("tetseg_skin_test_" + std::to_string(::getpid()) + "_" + name)) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string write(const std::string& name, const std::string& text) const {
    const std::string file = (path / name).string();
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }
  fs::path path;
};

/// The message of the InputError `read` throws ("" when it does not throw).
template <class F>
std::string input_error(F&& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

double signed_volume(const std::vector<double>& x,
                     const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  double volume = 0;
  for (const auto& t : triangles) {
    const double* a = &x[3 * t[0]];
    const double* b = &x[3 * t[1]];
    const double* c = &x[3 * t[2]];
    volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
               a[2] * (b[0] * c[1] - b[1] * c[0])) /
              6;
  }
  return volume;
}

double max_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double out = a.size() == b.size() ? 0.0 : INFINITY;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    out = std::max(out, std::fabs(a[i] - b[i]));
  return out;
}

}  // namespace

TEST_CASE("skinned tube: a closed outward surface, weights summing to 1, rest = identity pose",
          "[skin]") {
  tetseg::test::SkinnedTubeOptions capsule_options;
  capsule_options.joint_pinch = 0;
  const SkinnedTube capsule_tube = tetseg::test::make_skinned_tube(capsule_options);
  const SkinnedTube tube = tetseg::test::make_skinned_tube();
  CHECK(signed_volume(tube.rest, tube.triangles) <
        0.97 * signed_volume(capsule_tube.rest, capsule_tube.triangles));  // the necks
  // Closed: every undirected edge in exactly two triangles, once in each direction.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : tube.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    REQUIRE(count == 1);
    REQUIRE(directed.count({edge.second, edge.first}) == 1);
  }
  // Outward, and close to the capsule's volume pi r^2 (L + 4/3 r).
  const double r = tube.options.radius, length = tube.options.bones * tube.options.bone_length;
  const double capsule = M_PI * r * r * (length + 4.0 / 3.0 * r);
  CHECK(signed_volume(capsule_tube.rest, capsule_tube.triangles) > 0.97 * capsule);
  CHECK(signed_volume(capsule_tube.rest, capsule_tube.triangles) < capsule);
  std::size_t blended = 0;
  for (const auto& vw : tube.weights) {
    double sum = 0;
    for (const auto& bw : vw) {
      sum += bw.weight;
      REQUIRE(double(float(bw.weight)) == bw.weight);  // what glTF stores
    }
    REQUIRE(sum == 1.0);
    blended += vw.size() == 2;
  }
  CHECK(blended > tube.vertex_count() / 4);  // smooth weights near every joint
  const std::vector<double> angles(tube.options.bones, 0.0);
  CHECK(max_difference(
            tetseg::test::skin_tube(tube, tetseg::test::tube_skinning_matrices(tube, angles)),
            tube.rest) < 1e-15);
}

TEST_CASE("skinned tube: the bending sequence ends with the tip inside the root", "[skin]") {
  const SkinnedTube tube = tetseg::test::make_skinned_tube();
  const auto poses = tetseg::test::tube_bend_sequence(tube, 31, M_PI / 2, 0.1);
  const auto first = tetseg::test::skin_tube(tube, poses.front());
  CHECK(max_difference(first, tube.rest) < 1e-15);
  const auto last = tetseg::test::skin_tube(tube, poses.back());
  // Some vertex of the tip's cap (rest x > L) ends inside the root bone's cylinder (x in
  // (0, 1), closer than r to the x axis): the tube went through itself.
  const double length = tube.options.bones * tube.options.bone_length;
  std::size_t tip_inside_root = 0;
  for (std::size_t v = 0; v < tube.vertex_count(); ++v) {
    const double* p = &last[3 * v];
    if (tube.rest[3 * v] > length && p[0] > 0 && p[0] < tube.options.bone_length &&
        std::hypot(p[1], p[2]) < 0.95 * tube.options.radius)
      ++tip_inside_root;
  }
  CHECK(tip_inside_root > 0);
  // Vertices carried by bone 0 alone do not move.
  for (std::size_t v = 0; v < tube.vertex_count(); ++v) {
    if (tube.weights[v].size() == 1 && tube.weights[v][0].bone == 0)
      REQUIRE(std::equal(&last[3 * v], &last[3 * v] + 3, &tube.rest[3 * v]));
  }
}

TEST_CASE("read_skin: the generated glTF reads back with its vertices, triangles and weights",
          "[skin]") {
  const SkinnedTube tube = tetseg::test::make_skinned_tube();
  TempDir dir("roundtrip");
  const std::string path = dir.write("tube.gltf", tetseg::test::tube_gltf(tube));
  const Skin skin = read_skin(path);
  REQUIRE(skin.vertices.size() == tube.vertex_count());
  for (std::size_t v = 0; v < tube.vertex_count(); ++v)
    REQUIRE(std::equal(skin.vertices[v].begin(), skin.vertices[v].end(), &tube.rest[3 * v]));
  REQUIRE(skin.triangles.size() == tube.triangles.size());
  for (std::size_t t = 0; t < tube.triangles.size(); ++t)
    REQUIRE(skin.triangles[t] == tube.triangles[t]);
  REQUIRE(skin.bone_names == tube.bone_names);
  for (std::uint32_t b = 0; b < tube.options.bones; ++b) {
    const auto expected = tube.inverse_bind(b);
    for (int k = 0; k < 12; ++k) REQUIRE(skin.inverse_bind[b][k] == expected[k]);
  }
  for (std::size_t v = 0; v < tube.vertex_count(); ++v) {
    REQUIRE(skin.influences[v].size() == tube.weights[v].size());
    for (std::size_t k = 0; k < tube.weights[v].size(); ++k) {
      REQUIRE(skin.influences[v][k].bone == tube.weights[v][k].bone);
      REQUIRE(skin.influences[v][k].weight == Approx(tube.weights[v][k].weight).margin(1e-7));
    }
  }
  // tetseg's surface reader numbers the same vertices the same way, so the skin maps 1:1.
  const TriangleMesh surface = read_triangle_mesh(path);
  REQUIRE(surface.vertices == skin.vertices);
  const auto weights = skin_weights_at(skin, surface.vertices, path);
  for (std::size_t v = 0; v < weights.size(); ++v)
    REQUIRE(weights[v].front().bone == skin.influences[v].front().bone);
}

TEST_CASE("read_skin: hostile skins are refused naming the file and the problem", "[skin]") {
  TempDir dir("hostile");
  SkinnedTube tube = tetseg::test::make_skinned_tube({2, 1.0, 0.25, 8, 2, 2, 0.35});
  std::size_t blended = 0;  // the first vertex with two bones
  while (tube.weights[blended].size() < 2) ++blended;
  const std::string blended_sum = "vertex " + std::to_string(blended) + " sum to";
  SECTION("a negative weight") {
    tube.weights[blended][0].weight = -0.5;
    const std::string path = dir.write("negative.gltf", tetseg::test::tube_gltf(tube));
    CHECK_THAT(input_error([&] { read_skin(path); }), Catch::Contains(blended_sum));
  }
  SECTION("a NaN weight") {
    tube.weights[blended][1].weight = std::nan("");
    const std::string path = dir.write("nan.gltf", tetseg::test::tube_gltf(tube));
    CHECK_THAT(input_error([&] { read_skin(path); }), Catch::Contains(blended_sum));
  }
  SECTION("weights that do not sum to 1") {
    tube.weights[blended][0].weight = 7;
    const std::string path = dir.write("sum.gltf", tetseg::test::tube_gltf(tube));
    CHECK_THAT(input_error([&] { read_skin(path); }), Catch::Contains(blended_sum));
  }
  SECTION("a vertex without weights") {
    for (auto& bw : tube.weights[7]) bw.weight = 0;
    const std::string path = dir.write("unweighted.gltf", tetseg::test::tube_gltf(tube));
    CHECK_THAT(input_error([&] { read_skin(path); }),
               Catch::Contains("vertex 7 has no bone weights"));
  }
  SECTION("a joint index past the skin's joints") {
    tube.weights[blended][1].bone = 9;
    const std::string path = dir.write("joint.gltf", tetseg::test::tube_gltf(tube));
    CHECK_THAT(input_error([&] { read_skin(path); }), Catch::Contains(blended_sum));
    tube.weights[3][0].bone = 9;  // the only bone of vertex 3
    const std::string path3 = dir.write("joint3.gltf", tetseg::test::tube_gltf(tube));
    CHECK_THAT(input_error([&] { read_skin(path3); }),
               Catch::Contains("vertex 3 has no bone weights"));
  }
  SECTION("no skin at all") {
    std::string text = tetseg::test::tube_gltf(tube);
    const std::string skin_ref = ",\"skin\":0";
    text.erase(text.find(skin_ref), skin_ref.size());
    const std::string path = dir.write("noskin.gltf", text);
    CHECK_THAT(input_error([&] { read_skin(path); }), Catch::Contains("has no bones"));
  }
  SECTION("not a model") {
    const std::string path = dir.write("garbage.gltf", "{\"asset\": 17");
    CHECK_THAT(input_error([&] { read_skin(path); }), Catch::Contains("cannot read"));
  }
}

TEST_CASE("skin_weights_at: surfaces that the skin does not cover are refused", "[skin]") {
  const SkinnedTube tube = tetseg::test::make_skinned_tube({2, 1.0, 0.25, 8, 2, 2, 0.35});
  TempDir dir("match");
  const std::string path = dir.write("tube.gltf", tetseg::test::tube_gltf(tube));
  Skin skin = read_skin(path);
  std::vector<Vec3> vertices = skin.vertices;
  // Any order of the same vertices maps (by position).
  std::reverse(vertices.begin(), vertices.end());
  const auto reversed = skin_weights_at(skin, vertices, path);
  CHECK(reversed.front().front().bone == skin.influences.back().front().bone);
  SECTION("a vertex the skin does not have") {
    vertices.push_back({9, 9, 9});
    CHECK_THAT(input_error([&] { skin_weights_at(skin, vertices, path); }),
               Catch::Contains("has no skinned vertex"));
  }
  SECTION("a seam whose two copies disagree") {
    skin.vertices.push_back(skin.vertices[0]);
    skin.influences.push_back({{1, 1.0}});
    skin.influences[0] = {{0, 1.0}};
    CHECK_THAT(input_error([&] { skin_weights_at(skin, vertices, path); }),
               Catch::Contains("not their bone weights"));
  }
}

TEST_CASE("bone_detector_terms: the cluster's averaged weights, heaviest bones, sum 1", "[skin]") {
  const SkinnedTube tube = tetseg::test::make_skinned_tube();
  std::vector<std::vector<BoneInfluence>> influences;
  for (const auto& vw : tube.weights) {
    influences.emplace_back();
    for (const auto& bw : vw) influences.back().push_back({bw.bone, bw.weight});
  }
  std::vector<Tri> triangles(tube.triangles.begin(), tube.triangles.end());
  // Clusters by the x of the triangle's centroid: the root cap and first half bone; around
  // joint 1; the whole tube.
  std::vector<std::uint32_t> root, joint1, all;
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    double x = 0;
    for (std::uint32_t v : triangles[t]) x += tube.rest[3 * v] / 3;
    if (x < 0.5) root.push_back(t);
    if (x > 0.8 && x < 1.2) joint1.push_back(t);
    all.push_back(t);
  }
  const auto root_terms = bone_detector_terms(influences, triangles, root);
  REQUIRE(root_terms.size() == 1);
  CHECK(root_terms[0].index == 0);
  CHECK(root_terms[0].weight == 1.0);
  const auto joint_terms = bone_detector_terms(influences, triangles, joint1);
  REQUIRE(joint_terms.size() == 2);
  CHECK(joint_terms[0].index == 0);
  CHECK(joint_terms[1].index == 1);
  CHECK(joint_terms[0].weight == Approx(0.5).margin(0.05));  // symmetric about the joint
  CHECK(std::fabs(joint_terms[0].weight + joint_terms[1].weight - 1) <= 1e-12);
  // Four bones, at most two terms kept: the heaviest (the end bones carry caps: more vertices).
  const auto two = bone_detector_terms(influences, triangles, all, 2);
  REQUIRE(two.size() == 2);
  CHECK(two[0].index == 0);
  CHECK(two[1].index == 3);
  CHECK(std::fabs(two[0].weight + two[1].weight - 1) <= 1e-12);
}

TEST_CASE("carry_detectors_by_bones: every classified cluster carried by its own bones", "[skin]") {
  const SkinnedTube tube = tetseg::test::make_skinned_tube();
  TempDir dir("carry");
  const std::string path = dir.write("tube.gltf", tetseg::test::tube_gltf(tube));
  const Skin skin = read_skin(path);
  // A surface body by hand: one cluster per bone by triangle-centroid x (the last one
  // overlap-only), detectors on the axis at the bones' middles.
  tetseg::format::Asset asset;
  asset.body_kind = tetseg::format::BodyKind::kSurface;
  asset.detector_form = tetseg::format::DetectorForm::kSurfaceWeights;
  asset.node_count = static_cast<std::uint32_t>(tube.vertex_count());
  for (std::size_t v = 0; v < tube.vertex_count(); ++v)
    asset.rest_positions.push_back({tube.rest[3 * v], tube.rest[3 * v + 1], tube.rest[3 * v + 2]});
  asset.triangles.assign(tube.triangles.begin(), tube.triangles.end());
  const std::uint32_t bones = tube.options.bones;
  std::vector<std::vector<std::uint32_t>> by_bone(bones);
  for (std::uint32_t t = 0; t < asset.triangles.size(); ++t) {
    double x = 0;
    for (std::uint32_t v : asset.triangles[t]) x += tube.rest[3 * v] / 3;
    by_bone[std::min<std::uint32_t>(bones - 1, x < 0 ? 0 : std::uint32_t(x))].push_back(t);
  }
  asset.triangle_cluster.resize(asset.triangles.size());
  for (std::uint32_t b = 0; b < bones; ++b) {
    tetseg::format::Cluster c;
    c.triangle_offset = static_cast<std::uint32_t>(asset.cluster_triangles.size());
    c.triangle_count = static_cast<std::uint32_t>(by_bone[b].size());
    c.detector_rest = {b + 0.5, 0, 0};
    if (b + 1 == bones) c.flags = tetseg::format::kClusterOverlapOnly;
    for (std::uint32_t t : by_bone[b]) {
      asset.cluster_triangles.push_back(t);
      asset.triangle_cluster[t] = b;
    }
    asset.clusters.push_back(c);
  }
  SECTION("carried") {
    carry_detectors_by_bones(asset, skin.vertices, skin, path, 2);
    CHECK(asset.detector_form == tetseg::format::DetectorForm::kBones);
    CHECK(asset.bone_names == tube.bone_names);
    std::uint32_t offset = 0;
    for (std::uint32_t b = 0; b < bones; ++b) {
      const auto& c = asset.clusters[b];
      CHECK(c.detector_rest == std::array<double, 3>{b + 0.5, 0, 0});
      REQUIRE(c.detector_term_offset == offset);
      offset += c.detector_term_count;
      if (b + 1 == bones) {
        CHECK(c.detector_term_count == 0);
        continue;
      }
      REQUIRE(c.detector_term_count >= 1);
      REQUIRE(c.detector_term_count <= 2);
      double sum = 0, own = 0;
      for (std::uint32_t k = 0; k < c.detector_term_count; ++k) {
        const auto& term = asset.detector_terms[c.detector_term_offset + k];
        sum += term.weight;
        if (term.index == b) own = term.weight;
      }
      CHECK(std::fabs(sum - 1) <= 1e-12);
      CHECK(own > 0.5);  // the bone the cluster sits on carries most of it
    }
    CHECK(offset == asset.detector_terms.size());
  }
  SECTION("refused when the skin is of another surface; the asset unchanged") {
    std::vector<Vec3> moved = skin.vertices;
    moved[17][1] += 1e-3;
    const tetseg::format::Asset before = asset;
    CHECK_THROWS_AS(carry_detectors_by_bones(asset, moved, skin, path), InputError);
    CHECK(asset.detector_form == before.detector_form);
    CHECK(asset.detector_terms.empty());
    CHECK(asset.bone_names.empty());
  }
}

TEST_CASE("read_skin: FBX bones, with the per-corner vertices mapped back onto the surface",
          "[skin]") {
  // 4 vertices per ring and one cap ring: every coordinate prints exactly in ASCII FBX's six
  // decimals. assimp's ASCII FBX exporter writes the file; its FBX importer gives every
  // triangle corner its own vertex, which skin_weights_at maps back by position.
  const SkinnedTube tube = tetseg::test::make_skinned_tube({3, 1.0, 0.25, 4, 2, 1, 0.35, 0.0});
  TempDir dir("fbx");
  const std::string gltf = dir.write("tube.gltf", tetseg::test::tube_gltf(tube));
  const std::string fbx = (dir.path / "tube.fbx").string();
  {
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(gltf, 0);
    REQUIRE(scene != nullptr);
    Assimp::Exporter exporter;
    REQUIRE(exporter.Export(scene, "fbxa", fbx) == aiReturn_SUCCESS);
  }
  const Skin skin = read_skin(fbx);
  CHECK(skin.vertices.size() == 3 * tube.triangles.size());  // split per corner
  REQUIRE(skin.bone_names == tube.bone_names);
  for (std::uint32_t b = 0; b < tube.options.bones; ++b) {
    const auto expected = tube.inverse_bind(b);
    for (int k = 0; k < 12; ++k) CHECK(skin.inverse_bind[b][k] == Approx(expected[k]).margin(1e-6));
  }
  std::vector<Vec3> rest;
  for (std::size_t v = 0; v < tube.vertex_count(); ++v)
    rest.push_back({tube.rest[3 * v], tube.rest[3 * v + 1], tube.rest[3 * v + 2]});
  const auto weights = skin_weights_at(skin, rest, fbx);
  for (std::size_t v = 0; v < tube.vertex_count(); ++v) {
    REQUIRE(weights[v].size() == tube.weights[v].size());
    for (std::size_t k = 0; k < weights[v].size(); ++k) {
      REQUIRE(weights[v][k].bone == tube.weights[v][k].bone);
      REQUIRE(weights[v][k].weight == Approx(tube.weights[v][k].weight).margin(1e-5));
    }
  }
}
