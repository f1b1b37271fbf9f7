// Format 1.2: surface bodies and detectors carried by surface weights or bones. The golden
// assets, the layout of the new fields, every new validation rule broken once, and the
// variations the rules allow.
#include <catch2/catch.hpp>

#include <limits>

#include "format/support/broken_rule.hpp"
#include "format/support/test_assets.hpp"
#include "tetseg/format/skin.hpp"

using namespace tetseg::format;
using namespace tetseg::test;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Asset weights_asset() {
  return make_surface_octahedron_v12(DetectorForm::kSurfaceWeights);
}
Asset bones_asset() {
  return make_surface_octahedron_v12(DetectorForm::kBones);
}

// The golden surface assets (test_assets.hpp): weights: cluster 0 has terms 0..4 (nodes 0, 2,
// 1, 3, 4), cluster 1 terms 5..7 (nodes 5, 0, 1); bones: cluster 0 terms 0..1 (bones 1, 2),
// cluster 1 overlap-only without terms. Each rule ends with the valid asset it breaks.
const std::vector<BrokenRule>& rules() {
  static const std::vector<BrokenRule> table = {
      {"an unknown body kind", "body_kind 2 is unknown",
       [](Asset& a) { a.body_kind = static_cast<BodyKind>(2); }, weights_asset},
      {"an unknown detector form", "detector_form 3 is unknown",
       [](Asset& a) { a.detector_form = static_cast<DetectorForm>(3); }, weights_asset},
      {"a surface body with tet-point detectors", "needs body_kind kTet",
       [](Asset& a) { a.body_kind = BodyKind::kSurface; }, make_octahedron_asset},
      {"a tet-point asset with detector terms", "detector form is kTetPoint",
       [](Asset& a) {
         a.detector_terms = {{0, 1.0}};
       },
       make_octahedron_asset},
      {"a tet-point asset with a term range", "(kTetPoint: all 0)",
       [](Asset& a) { a.clusters[1].detector_term_count = 1; }, make_octahedron_asset},
      {"a tet-point asset with a rest detector", "(kTetPoint: all 0)",
       [](Asset& a) { a.clusters[0].detector_rest[2] = 0.5; }, make_octahedron_asset},
      {"a weights asset with bone names", "not kBones", [](Asset& a) { a.bone_names = {"root"}; },
       weights_asset},
      {"a weights asset with a used tet-point detector", "unused node form at node 0",
       [](Asset& a) { a.clusters[1].detector = DetectorPoint::at_node(5); }, weights_asset},
      {"a weights asset with a tet id", "unused node form at node 0",
       [](Asset& a) { a.clusters[0].detector.tet = 0; }, weights_asset},
      {"a term range that does not start where the previous ended", "contiguous",
       [](Asset& a) { a.clusters[1].detector_term_offset = 4; }, weights_asset},
      {"a term range past the end", "exceeds detector_terms",
       [](Asset& a) { a.clusters[1].detector_term_count = 4; }, weights_asset},
      {"terms no cluster uses", "clusters use 8 of 9 detector_terms",
       [](Asset& a) {
         a.detector_terms.push_back({6, 1.0});
       },
       weights_asset},
      {"a classified cluster without terms", "no detector terms and is not overlap-only",
       [](Asset& a) {
         a.clusters[1].detector_term_count = 0;
         a.detector_terms.resize(5);
       },
       weights_asset},
      {"more terms than the limit", "the limit is 256",
       [](Asset& a) {
         a.clusters[1].detector_term_count = kMaxDetectorTerms + 1;
         a.detector_terms.resize(5);
         for (std::uint32_t i = 0; i <= kMaxDetectorTerms; ++i)
           a.detector_terms.push_back({0, 1.0 / (kMaxDetectorTerms + 1)});
       },
       weights_asset},
      {"a node index equal to node_count", ">= node_count 7",
       [](Asset& a) { a.detector_terms[2].index = 7; }, weights_asset},
      {"a huge node index", ">= node_count",
       [](Asset& a) { a.detector_terms[7].index = 0xFFFFFFFFu; }, weights_asset},
      {"a bone index equal to the bone count", ">= bone_names.size() 3",
       [](Asset& a) { a.detector_terms[1].index = 3; }, bones_asset},
      {"a repeated node in one cluster", "repeat index 1",
       [](Asset& a) { a.detector_terms[3].index = 1; }, weights_asset},
      {"a repeated bone in one cluster", "repeat index 2",
       [](Asset& a) { a.detector_terms[0].index = 2; }, bones_asset},
      {"a negative weight", "not a finite non-negative value",
       [](Asset& a) {
         a.detector_terms[0].weight = -0.125;
         a.detector_terms[4].weight = 0.75;
       },
       weights_asset},
      {"a NaN weight", "not a finite non-negative value",
       [](Asset& a) { a.detector_terms[1].weight = std::nan(""); }, bones_asset},
      {"an infinite weight", "not a finite non-negative value",
       [](Asset& a) { a.detector_terms[6].weight = kInf; }, weights_asset},
      {"weights summing to 1 + 2e-9", "sum to",
       [](Asset& a) { a.detector_terms[4].weight += 2e-9; }, weights_asset},
      {"weights summing to 0.5", "sum to", [](Asset& a) { a.detector_terms[0].weight = 0.25; },
       bones_asset},
      {"an overlap-only cluster's terms not summing to 1", "sum to",
       [](Asset& a) {
         a.clusters[1].flags = kClusterOverlapOnly;
         a.detector_terms[5].weight = 0.25;
       },
       weights_asset},
      {"a NaN rest detector", "detector_rest is not finite",
       [](Asset& a) { a.clusters[1].detector_rest[0] = std::nan(""); }, weights_asset},
      {"an infinite rest detector of an overlap-only cluster", "detector_rest is not finite",
       [](Asset& a) { a.clusters[1].detector_rest[2] = -kInf; }, bones_asset},
      {"a bone name over the string limit", "the limit is",
       [](Asset& a) { a.bone_names[1].assign(kMaxStringBytes + 1, 'b'); }, bones_asset},
      {"more bones than the limit", "bone_names has 65537 entries, the limit is",
       [](Asset& a) { a.bone_names.resize(kMaxBones + 1); }, bones_asset},
      // source_vertex_nodes (the weights golden maps 9 file vertices onto the 7 nodes).
      {"a source vertex map on a tet body", "the body kind is not kSurface",
       [](Asset& a) { a.source_vertex_nodes = {0, 1, 2, 3, 4, 5, 6, 7}; }, make_octahedron_asset},
      {"a source vertex on node_count", "source_vertex_nodes[8] is 7 >= node_count 7",
       [](Asset& a) { a.source_vertex_nodes[8] = 7; }, weights_asset},
      {"a huge source vertex node", "source_vertex_nodes[0] is 4294967295 >= node_count",
       [](Asset& a) { a.source_vertex_nodes[0] = 0xFFFFFFFFu; }, weights_asset},
      {"a node no source vertex reaches", "node 6 is no source vertex's node",
       [](Asset& a) { a.source_vertex_nodes[7] = 5; }, weights_asset},
      {"fewer source vertices than nodes", "fewer than the 7 nodes",
       [](Asset& a) { a.source_vertex_nodes = {0, 1, 2, 3, 4, 5}; }, weights_asset},
      {"a source vertex map that cannot reach a huge node_count", "fewer than the",
       [](Asset& a) {
         a.rest_positions.clear();  // else their count fails first
         a.node_count = kMaxNodes;  // the hit table must not be sized by this
       },
       weights_asset},
  };
  return table;
}

}  // namespace

TEST_CASE("Format 1.2: each new validation rule rejects an asset that breaks it",
          "[format][validate][v12]") {
  const std::size_t index = GENERATE(range(std::size_t(0), rules().size()));
  const BrokenRule& rule = rules()[index];
  CAPTURE(rule.name);
  // Whatever 1.2 field is broken is written as 1.2 (and refused by the reader).
  CHECK(get_le(check_refused(rule), kMinorAt, 2) == 2);
}

TEST_CASE("Format 1.2: validation accepts the legitimate variations", "[format][validate][v12]") {
  Asset a = weights_asset();
  SECTION("Vertices no triangle uses (an input surface may have them), even as detector terms.") {
    a.detector_terms[5].index = 6;  // cluster 1: nodes 6, 0, 1
  }
  SECTION("Rest positions may be stripped; detector_rest is not checked against them.") {
    a.rest_positions.clear();
    a.clusters[0].detector_rest = {7, 8, 9};
  }
  SECTION("A single term of weight 1: the detector is a vertex.") {
    a.clusters[1].detector_term_count = 1;
    a.detector_terms.resize(6);
    a.detector_terms[5] = {5, 1.0};
  }
  SECTION("Zero weights are allowed, and sums may miss 1 by up to the documented bound.") {
    a.detector_terms[0].weight = 0.0;
    a.detector_terms[4].weight = 0.625 - 5e-10;
  }
  SECTION("The same node may serve several clusters' detectors.") {
    a.detector_terms[6].index = 4;
  }
  SECTION("An overlap-only cluster may keep its terms, or have none.") {
    a.clusters[1].flags = kClusterOverlapOnly;
    SECTION("none") {
      a.clusters[1].detector_term_count = 0;
      a.detector_terms.resize(5);
    }
  }
  SECTION("Every cluster overlap-only without terms.") {
    for (Cluster& c : a.clusters) {
      c.flags = kClusterOverlapOnly;
      c.detector_term_offset = 0;
      c.detector_term_count = 0;
    }
    a.detector_terms.clear();
  }
  SECTION("A tet body may carry weighted detectors (any nodes, interior ones too).") {
    a = make_octahedron_asset();
    a.detector_form = DetectorForm::kSurfaceWeights;
    for (Cluster& c : a.clusters) c.detector = DetectorPoint::at_node(0);
    set_detector_terms(a, 0, {{6, 0.5}, {4, 0.5}}, {0, 0, 0.625});
    set_detector_terms(a, 1, {{7, 1.0}}, {0, 0, -0.25});
  }
  SECTION("A tet body may carry bone detectors.") {
    a = bones_asset();
    a.body_kind = BodyKind::kTet;
  }
  SECTION("Bone names may be empty strings and repeat (unnamed joints); extra bones are fine.") {
    a = bones_asset();
    a.bone_names = {"", "", "head", "tail"};
  }
  SECTION("No source vertex map (node i is file vertex i), or one that only renumbers.") {
    SECTION("none") {
      a.source_vertex_nodes.clear();
    }
    SECTION("a permutation") {
      a.source_vertex_nodes = {6, 5, 4, 3, 2, 1, 0};
    }
  }
  SECTION("A bone asset may map source vertices too.") {
    a = bones_asset();
    a.source_vertex_nodes = {0, 0, 1, 2, 3, 4, 5, 6, 6};
  }
  std::string why;
  CHECK(validate(a, &why) == Status::kOk);
  INFO(why);
  const auto bytes = write_asset(a);
  CHECK(get_le(bytes, kMinorAt, 2) == 2);
  Asset out;
  CHECK(read_asset(bytes.data(), bytes.size(), out, &why) == Status::kOk);
  CHECK(assets_equal(a, out));
  CHECK(write_asset(out) == bytes);
}

TEST_CASE("Format 1.2: the new fields sit where docs/format.md puts them", "[format][v12]") {
  const Asset a = GENERATE(weights_asset(), bones_asset());
  const auto bytes = write_asset(a);
  CHECK(get_le(bytes, kMinorAt, 2) == 2);
  const std::size_t p = kHeaderBytes;
  CHECK(bytes[p] == 1);
  CHECK(get_le(bytes, p + 1, 4) == a.node_count);
  CHECK(get_le(bytes, p + 5, 4) == 1);  // body_kind kSurface
  CHECK(get_le(bytes, p + 9, 4) == static_cast<std::uint32_t>(a.detector_form));
  const auto tags = payload_size_tags(a);
  auto tag_at = [&](const std::string& name) {
    for (const auto& [n, at] : tags)
      if (n == name) return p + at;
    FAIL("no tag " << name);
    return std::size_t(0);
  };
  CHECK(get_le(bytes, tag_at("rest_positions"), 8) == a.rest_positions.size());
  // Cluster records: 108 bytes; the 1.2 part (term offset, count, rest xyz) ends each record.
  const std::size_t clusters = tag_at("clusters");
  REQUIRE(get_le(bytes, clusters, 8) == a.clusters.size());
  for (std::size_t c = 0; c < a.clusters.size(); ++c) {
    const std::size_t rec = clusters + 8 + 108 * c;
    CHECK(get_le(bytes, rec + 76, 4) == a.clusters[c].detector_term_offset);
    CHECK(get_le(bytes, rec + 80, 4) == a.clusters[c].detector_term_count);
    for (int k = 0; k < 3; ++k) {
      double x = 0;
      const std::uint64_t raw = get_le(bytes, rec + 84 + 8 * k, 8);
      std::memcpy(&x, &raw, 8);
      CHECK(same_bits(x, a.clusters[c].detector_rest[k]));
    }
  }
  CHECK(tag_at("cluster_triangles") == clusters + 8 + 108 * a.clusters.size());
  // Terms: (u32 index, f64 weight) after boundary_nodes; then the bone names.
  const std::size_t terms = tag_at("detector_terms");
  REQUIRE(get_le(bytes, terms, 8) == a.detector_terms.size());
  for (std::size_t i = 0; i < a.detector_terms.size(); ++i) {
    CHECK(get_le(bytes, terms + 8 + 12 * i, 4) == a.detector_terms[i].index);
    double w = 0;
    const std::uint64_t raw = get_le(bytes, terms + 8 + 12 * i + 4, 8);
    std::memcpy(&w, &raw, 8);
    CHECK(same_bits(w, a.detector_terms[i].weight));
  }
  CHECK(get_le(bytes, tag_at("bone_names"), 8) == a.bone_names.size());
  // The source vertex map (u32 per file vertex) right after the bone names.
  const std::size_t map = tag_at("source_vertex_nodes");
  CHECK(map == tag_at("bone_names") + 8 + 8 * a.bone_names.size() + [&] {
    std::size_t n = 0;
    for (const auto& s : a.bone_names) n += s.size();
    return n;
  }());
  REQUIRE(get_le(bytes, map, 8) == a.source_vertex_nodes.size());
  for (std::size_t i = 0; i < a.source_vertex_nodes.size(); ++i)
    CHECK(get_le(bytes, map + 8 + 4 * i, 4) == a.source_vertex_nodes[i]);
  CHECK(tag_at("provenance.tool_version") == map + 8 + 4 * a.source_vertex_nodes.size());
  CHECK(tags.back().second == bytes.size() - kHeaderBytes);
}

TEST_CASE("Format 1.2: the golden surface assets load with their original content",
          "[format][golden][v12]") {
  const auto [variant, form] =
      GENERATE(std::make_pair(std::string(""), DetectorForm::kSurfaceWeights),
               std::make_pair(std::string("-bones"), DetectorForm::kBones));
  const std::string path = golden_path(2, variant);
  CAPTURE(path);
  Asset loaded;
  std::string why;
  REQUIRE(read_asset_file(path, loaded, &why) == Status::kOk);
  INFO(why);
  const auto bytes = read_file(path);
  std::uint16_t major = 0, minor = 0;
  REQUIRE(peek_version(bytes.data(), bytes.size(), major, minor));
  CHECK(major == 1);
  CHECK(minor == 2);
  CHECK(assets_equal(loaded, make_surface_octahedron_v12(form)));
  CHECK(write_asset(loaded) == bytes);
  CHECK(loaded.body_kind == BodyKind::kSurface);
  CHECK(loaded.detector_form == form);
  // Independent truth: each classified detector, evaluated from the rest positions (weights) or
  // skinned with identity matrices (bones), is its stored rest position, strictly inside the
  // octahedron and on its cluster's side.
  std::vector<double> skinned(3 * loaded.clusters.size());
  std::vector<double> identity(12 * loaded.bone_names.size(), 0.0);
  for (std::size_t b = 0; b < loaded.bone_names.size(); ++b)
    identity[12 * b + 0] = identity[12 * b + 5] = identity[12 * b + 10] = 1.0;
  skinned_detector_positions(loaded, identity.data(), skinned.data());
  for (std::size_t c = 0; c < loaded.clusters.size(); ++c) {
    const Cluster& cl = loaded.clusters[c];
    const Vec3 d = form == DetectorForm::kSurfaceWeights
                       ? weighted_detector_position(
                             loaded.detector_terms.data() + cl.detector_term_offset,
                             cl.detector_term_count, loaded.rest_positions.front().data())
                       : Vec3{skinned[3 * c], skinned[3 * c + 1], skinned[3 * c + 2]};
    CHECK(d == cl.detector_rest);
    CHECK(std::abs(d[0]) + std::abs(d[1]) + std::abs(d[2]) < 1.0);
    CHECK(d[2] * (c == 0 ? 1.0 : -1.0) > 0.0);
    CHECK(cl.rest_positive_fraction == 1.0f);
  }
}

TEST_CASE("Format 1.2: tet assets are still written as 1.0 and 1.1, byte for byte",
          "[format][v12]") {
  CHECK(minor_version_needed(make_octahedron_asset()) == 0);
  CHECK(minor_version_needed(make_octahedron_asset_v11()) == 1);
  CHECK(minor_version_needed(weights_asset()) == 2);
  CHECK(minor_version_needed(bones_asset()) == 2);
  CHECK(write_asset(make_octahedron_asset()) == read_file(golden_path(0)));
  CHECK(write_asset(make_octahedron_asset_v11()) == read_file(golden_path(1)));
  SECTION("Any one 1.2 field set needs 1.2.") {
    Asset a = make_octahedron_asset();
    const int which = GENERATE(range(0, 7));
    CAPTURE(which);
    if (which == 0) a.body_kind = BodyKind::kSurface;
    if (which == 1) a.detector_form = DetectorForm::kBones;
    if (which == 2) a.detector_terms.push_back({0, 1.0});
    if (which == 3) a.bone_names.push_back("b");
    if (which == 4) a.clusters[1].detector_term_offset = 1;
    if (which == 5) a.clusters[0].detector_rest[1] = 1.0;
    if (which == 6) a.source_vertex_nodes.push_back(0);
    CHECK(minor_version_needed(a) == 2);
  }
}

TEST_CASE("Skinned detector positions follow linear blend skinning", "[format][v12]") {
  const Asset a = bones_asset();
  // Bone 1 translates by (1, 2, 3); bone 2 rotates 90 degrees about z and scales by 2; bone 0
  // (unused) is garbage.
  std::vector<double> m(36, 0.0);
  for (int i = 0; i < 12; ++i) m[i] = std::nan("");
  const double translate[12] = {1, 0, 0, 1, 0, 1, 0, 2, 0, 0, 1, 3};
  const double rotate[12] = {0, -2, 0, 0, 2, 0, 0, 0, 0, 0, 2, 0};
  std::copy(translate, translate + 12, m.begin() + 12);
  std::copy(rotate, rotate + 12, m.begin() + 24);
  std::vector<double> out(6, -1.0);
  skinned_detector_positions(a, m.data(), out.data());
  // Cluster 0: rest (0, 0, 0.5); 0.75 * (1, 2, 3.5) + 0.25 * (0, 0, 1) = (0.75, 1.5, 2.875).
  CHECK(out[0] == 0.75);
  CHECK(out[1] == 1.5);
  CHECK(out[2] == 2.875);
  // Cluster 1: overlap-only without terms: its rest position.
  CHECK(out[3] == 0.0);
  CHECK(out[4] == 0.0);
  CHECK(out[5] == -0.5);
  SECTION("Other forms: every detector at its rest position.") {
    const Asset w = weights_asset();
    skinned_detector_positions(w, nullptr, out.data());
    CHECK(out == std::vector<double>{0, 0, 0.5, 0, 0, -0.5});
  }
}
