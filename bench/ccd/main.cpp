// tetseg-ccd: the elementary continuous collision tests on reference queries and on whole
// frames of a triangle soup. Links the runtime only.

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "fast_cubic.hpp"
#include "soup_ccd.hpp"
#include "tetseg/runtime/ccd.hpp"
#include "tetseg/testing/ccd_io.hpp"
#include "tool_support.hpp"

namespace {

namespace fs = std::filesystem;
using namespace tetseg::tools;
namespace io = tetseg::test::ccd_io;

constexpr const char* kTool = "tetseg-ccd";

using soup::thread_cpu_seconds;

struct Tally {
  long queries = 0;
  long positives = 0;
  long false_negatives = 0;
  long false_positives = 0;
  double seconds = 0;
  std::vector<double> query_us;  ///< each query timed alone (second pass), for the quantiles
  void add(const Tally& o) {
    queries += o.queries;
    positives += o.positives;
    false_negatives += o.false_negatives;
    false_positives += o.false_positives;
    seconds += o.seconds;
    query_us.insert(query_us.end(), o.query_us.begin(), o.query_us.end());
  }
  double mean_us() const { return queries ? seconds * 1e6 / static_cast<double>(queries) : 0.0; }
  /// The q-quantile (0.5: median) of the per-query times: the sorted time at rank
  /// round(q (n - 1)); 0 without queries.
  double quantile_us(double q) const {
    if (query_us.empty()) return 0.0;
    std::vector<double> sorted = query_us;
    const auto rank = static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1) + 0.5);
    std::nth_element(sorted.begin(), sorted.begin() + rank, sorted.end());
    return sorted[rank];
  }
};

std::string tally_json(const Tally& t) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "{\"queries\": %ld, \"positives\": %ld, \"false_negatives\": %ld, "
                "\"false_positives\": %ld, \"mean_us\": %.3f, \"median_us\": %.3f, "
                "\"p90_us\": %.3f}",
                t.queries, t.positives, t.false_negatives, t.false_positives, t.mean_us(),
                t.quantile_us(0.5), t.quantile_us(0.9));
  return buf;
}

bool run_query(const io::Query& q, bool vertex_face, bool fast, const tetseg::CcdOptions& options) {
  const auto& x = q.points;
  if (fast) {
    double toi = 0;
    return vertex_face
               ? fast_cubic::vertex_face(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], toi)
               : fast_cubic::edge_edge(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], toi);
  }
  return vertex_face
             ? tetseg::vertex_face_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], options)
                   .hit()
             : tetseg::edge_edge_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], options).hit();
}

/// Wall time of one steady_clock interval around nothing (the median of many): what timing a
/// query alone adds, subtracted from each per-query time.
double clock_overhead_us() {
  using clock = std::chrono::steady_clock;
  std::vector<double> samples(10001);
  for (double& sample : samples) {
    const auto start = clock::now();
    sample = std::chrono::duration<double, std::micro>(clock::now() - start).count();
  }
  std::nth_element(samples.begin(), samples.begin() + 5000, samples.end());
  return samples[5000];
}

Tally run_folder(const fs::path& folder, bool vertex_face, bool fast,
                 const tetseg::CcdOptions& options) {
  Tally tally;
  if (!fs::is_directory(folder)) return tally;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.path().extension() == ".csv") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const auto& file : files) {
    std::vector<io::Query> queries;
    try {
      queries = io::read_query_csv(file.string());
    } catch (const std::runtime_error& e) {
      throw ToolError(kExitBadInput, file.string(), e.what());
    }
    std::vector<char> results(queries.size());
    // CPU time of this thread: robust to other processes sharing the cores.
    const double start = thread_cpu_seconds();
    for (std::size_t i = 0; i < queries.size(); ++i)
      results[i] = run_query(queries[i], vertex_face, fast, options);
    tally.seconds += thread_cpu_seconds() - start;
    // Second pass for the distribution (medians beside means): each query timed alone by
    // steady_clock (wall time, cheaper to read than the thread CPU clock), less the clock's cost.
    static const double overhead_us = clock_overhead_us();
    for (const auto& query : queries) {
      const auto begin = std::chrono::steady_clock::now();
      const volatile bool hit = run_query(query, vertex_face, fast, options);
      const auto end = std::chrono::steady_clock::now();
      (void)hit;
      const double us = std::chrono::duration<double, std::micro>(end - begin).count();
      tally.query_us.push_back(std::max(0.0, us - overhead_us));
    }
    for (std::size_t i = 0; i < queries.size(); ++i) {
      ++tally.queries;
      tally.positives += queries[i].truth;
      if (queries[i].truth && !results[i]) ++tally.false_negatives;
      if (!queries[i].truth && results[i]) ++tally.false_positives;
    }
  }
  return tally;
}

int command_queries(const std::string& dir, bool json, const std::string& method,
                    const tetseg::CcdOptions& options) {
  if (!fs::is_directory(dir)) throw ToolError(kExitBadInput, dir, "not a directory");
  const bool fast = method == "fast-cubic";
  std::vector<fs::path> scenes;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_directory()) scenes.push_back(entry.path());
  std::sort(scenes.begin(), scenes.end());
  std::map<std::string, std::array<Tally, 2>> per_scene;
  std::array<Tally, 2> total;
  for (const auto& scene : scenes) {
    const Tally vf = run_folder(scene / "vertex-face", true, fast, options);
    const Tally ee = run_folder(scene / "edge-edge", false, fast, options);
    if (vf.queries + ee.queries == 0) continue;
    per_scene[scene.filename().string()] = {vf, ee};
    total[0].add(vf);
    total[1].add(ee);
  }
  if (per_scene.empty())
    throw ToolError(kExitBadInput, dir,
                    "no query CSV found (expected <scene>/{vertex-face,edge-edge}/*.csv)");
  if (json) {
    std::ostringstream out;
    out << "{\n \"vertex_face\": " << tally_json(total[0])
        << ",\n \"edge_edge\": " << tally_json(total[1]) << ",\n \"scenes\": {";
    bool first = true;
    for (const auto& [name, t] : per_scene) {
      out << (first ? "\n" : ",\n") << "  \"" << json_escape(name)
          << "\": {\"vertex_face\": " << tally_json(t[0]) << ", \"edge_edge\": " << tally_json(t[1])
          << "}";
      first = false;
    }
    out << "}}\n";
    std::cout << out.str();
  } else {
    std::printf("%-30s %-3s %8s %9s %4s %4s %10s %10s %10s\n", "scene", "", "queries", "positives",
                "FN", "FP", "mean_us", "median_us", "p90_us");
    auto line = [](const std::string& name, const char* kind, const Tally& t) {
      std::printf("%-30s %-3s %8ld %9ld %4ld %4ld %10.2f %10.3f %10.3f\n", name.c_str(), kind,
                  t.queries, t.positives, t.false_negatives, t.false_positives, t.mean_us(),
                  t.quantile_us(0.5), t.quantile_us(0.9));
    };
    for (const auto& [name, t] : per_scene) {
      line(name, "VF", t[0]);
      line(name, "EE", t[1]);
    }
    line("total (" + method + ")", "VF", total[0]);
    line("total (" + method + ")", "EE", total[1]);
  }
  return kExitOk;
}

io::Mesh load_mesh(const std::string& path) {
  try {
    return io::read_ply(path);
  } catch (const std::runtime_error& e) {
    throw ToolError(kExitBadInput, path, e.what());
  }
}

/// The asset `--asset` names, checked against frame `mesh` (read from `frame`): its nodes must
/// be the frame's vertices and its triangles the frame's faces, in order.
tetseg::Asset load_frame_asset(const std::string& path, const io::Mesh& mesh,
                               const std::string& frame) {
  tetseg::Asset asset;
  std::string detail;
  const tetseg::Status status = tetseg::load_asset_file(path, asset, &detail);
  if (status != tetseg::Status::kOk)
    throw ToolError(kExitBadInput, path,
                    std::string(tetseg::to_string(status)) + (detail.empty() ? "" : ": " + detail));
  const tetseg::format::Asset& a = asset.data();
  if (a.node_count != mesh.vertices.size()) {
    // A frame over the input file's vertices of an asset that merged them (seams, STL corners).
    const std::string merged =
        a.source_vertex_nodes.size() == mesh.vertices.size()
            ? "; they are the input file's vertices, which the asset merged into its nodes: "
              "gather them first (format::gather_node_positions) or write the frame over the "
              "nodes (tetseg-dump --ply)"
            : "";
    throw ToolError(kExitBadInput, frame,
                    std::to_string(mesh.vertices.size()) + " vertices, the asset " + path +
                        " has " + std::to_string(a.node_count) +
                        " nodes (the frame's vertices must be the asset's nodes, in order)" +
                        merged);
  }
  if (a.triangles.size() != mesh.faces.size())
    throw ToolError(kExitBadInput, frame,
                    std::to_string(mesh.faces.size()) + " faces, the asset " + path + " has " +
                        std::to_string(a.triangles.size()) + " triangles");
  for (std::size_t t = 0; t < a.triangles.size(); ++t) {
    if (a.triangles[t] != mesh.faces[t])
      throw ToolError(kExitBadInput, frame,
                      "face " + std::to_string(t) + " differs from triangle " + std::to_string(t) +
                          " of the asset " + path + " (same triangles, same order, needed)");
  }
  return asset;
}

int command_frames(const std::string& path0, const std::string& path1, bool json,
                   const tetseg::CcdOptions& options, soup::BroadPhase broad_phase,
                   soup::StillPairs still_pairs, const std::string& asset_path,
                   std::uint32_t threads) {
  const io::Mesh m0 = load_mesh(path0);
  const io::Mesh m1 = load_mesh(path1);
  if (m0.vertices.size() != m1.vertices.size())
    throw ToolError(kExitBadInput, path1, "vertex count differs from " + path0);
  if (m0.faces != m1.faces) throw ToolError(kExitBadInput, path1, "faces differ from " + path0);
  tetseg::Asset asset;
  if (!asset_path.empty()) asset = load_frame_asset(asset_path, m0, path0);
  soup::FrameStats stats;
  const double cpu_start = thread_cpu_seconds();
  const auto wall_start = std::chrono::steady_clock::now();
  const auto contacts =
      soup::find_contacts(m0.vertices, m1.vertices, m0.faces, options, broad_phase, &stats,
                          still_pairs, asset_path.empty() ? nullptr : &asset, threads);
  const double cpu = thread_cpu_seconds() - cpu_start;
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  std::ostringstream out;
  char buf[160];
  if (json) {
    out << "{\"vertices\": " << m0.vertices.size() << ", \"faces\": " << m0.faces.size()
        << ", \"contacts\": [";
    for (std::size_t i = 0; i < contacts.size(); ++i) {
      const auto& c = contacts[i];
      if (c.vertex_face)
        std::snprintf(buf, sizeof buf,
                      "{\"kind\": \"vf\", \"vertex\": %u, \"face\": [%u, %u, %u], \"toi\": %.17g}",
                      c.ids[0], c.ids[1], c.ids[2], c.ids[3], c.toi);
      else
        std::snprintf(buf, sizeof buf,
                      "{\"kind\": \"ee\", \"edges\": [[%u, %u], [%u, %u]], \"toi\": %.17g}",
                      c.ids[0], c.ids[1], c.ids[2], c.ids[3], c.toi);
      out << (i ? ",\n  " : "\n  ") << buf;
    }
    out << "]}\n";
  } else {
    for (const auto& c : contacts) {
      std::snprintf(buf, sizeof buf, "%s %u %u %u %u %.17g\n", c.vertex_face ? "vf" : "ee",
                    c.ids[0], c.ids[1], c.ids[2], c.ids[3], c.toi);
      out << buf;
    }
  }
  std::cout << out.str();
  std::cerr << kTool << ": " << contacts.size() << " contacts\n";
  if (broad_phase == soup::BroadPhase::kSweep) {
    std::fprintf(stderr,
                 "%s: sort and sweep: %llu VF + %llu EE candidates, %llu elementary tests; CPU "
                 "%.3f s (broad phase %.3f s, tests %.3f s; PLY reading excluded)\n",
                 kTool, static_cast<unsigned long long>(stats.vf_candidates),
                 static_cast<unsigned long long>(stats.ee_candidates),
                 static_cast<unsigned long long>(stats.tests), cpu, stats.broad_seconds,
                 stats.test_seconds);
  } else if (broad_phase == soup::BroadPhase::kFeatures && asset_path.empty() && threads > 1) {
    std::fprintf(stderr,
                 "%s: features mode: %llu feature pairs, %llu elementary tests; wall %.3f s on "
                 "%u threads (PLY reading excluded)\n",
                 kTool, static_cast<unsigned long long>(stats.feature_pairs),
                 static_cast<unsigned long long>(stats.tests), wall, threads);
  } else if (broad_phase == soup::BroadPhase::kFeatures && asset_path.empty()) {
    std::fprintf(stderr,
                 "%s: features mode: %llu feature pairs, %llu elementary tests; CPU %.3f s (PLY "
                 "reading excluded)\n",
                 kTool, static_cast<unsigned long long>(stats.feature_pairs),
                 static_cast<unsigned long long>(stats.tests), cpu);
  } else {
    std::fprintf(stderr,
                 "%s: scene%s: %llu triangle pairs, %llu feature pairs, %llu elementary tests%s; "
                 "CPU %.3f s (PLY reading excluded)\n",
                 kTool, asset_path.empty() ? "" : " (rvbc with the asset's clusters)",
                 static_cast<unsigned long long>(stats.triangle_pairs),
                 static_cast<unsigned long long>(stats.feature_pairs),
                 static_cast<unsigned long long>(stats.tests),
                 asset_path.empty() ? ""
                                    : (", " + std::to_string(stats.orientation_culled) +
                                       " node pairs culled by orientation")
                                          .c_str(),
                 cpu);
  }
  return kExitOk;
}

/// Lists the true pairs of a scalable-CCD frame (boxes + mma_bool) in the text format of
/// `frames` without the time of impact (used by the CLI test).
int command_truth(const std::string& ply, const std::string& boxes_path,
                  const std::string& truth_path, const std::string& kind) {
  const io::Mesh mesh = load_mesh(ply);
  std::vector<std::array<std::int64_t, 2>> boxes;
  std::vector<bool> truth;
  try {
    boxes = io::parse_json_pairs(io::read_text(boxes_path));
  } catch (const std::runtime_error& e) {
    throw ToolError(kExitBadInput, boxes_path, e.what());
  }
  try {
    truth = io::parse_json_bools(io::read_text(truth_path));
  } catch (const std::runtime_error& e) {
    throw ToolError(kExitBadInput, truth_path, e.what());
  }
  if (boxes.size() != truth.size())
    throw ToolError(kExitBadInput, truth_path, "length differs from the boxes file");
  const auto edges = io::unique_edges(mesh.faces);
  const auto n_v = static_cast<std::int64_t>(mesh.vertices.size());
  const auto n_e = static_cast<std::int64_t>(edges.size());
  const auto n_f = static_cast<std::int64_t>(mesh.faces.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    if (!truth[i]) continue;
    const auto [x, y] = boxes[i];
    if (kind == "vf") {
      const std::int64_t f = y - n_v - n_e;
      if (x < 0 || x >= n_v || f < 0 || f >= n_f)
        throw ToolError(kExitBadInput, boxes_path, "bad VF id");
      const auto& face = mesh.faces[static_cast<std::size_t>(f)];
      std::printf("vf %lld %u %u %u\n", static_cast<long long>(x), face[0], face[1], face[2]);
    } else {
      const std::int64_t e0 = x - n_v, e1 = y - n_v;
      if (e0 < 0 || e0 >= n_e || e1 < 0 || e1 >= n_e)
        throw ToolError(kExitBadInput, boxes_path, "bad EE id");
      auto a = edges[static_cast<std::size_t>(e0)];
      auto b = edges[static_cast<std::size_t>(e1)];
      if (b < a) std::swap(a, b);
      std::printf("ee %u %u %u %u\n", a[0], a[1], b[0], b[1]);
    }
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tetseg-ccd " TETSEG_VERSION ": elementary continuous collision tests", kTool};
  app.set_version_flag("--version", std::string(kTool) + " " TETSEG_VERSION);
  app.require_subcommand(1);
  tetseg::CcdOptions options;

  auto* queries = app.add_subcommand(
      "queries", "Run the tests on reference queries (<scene>/{vertex-face,edge-edge}/*.csv)");
  std::string dir;
  bool json = false;
  std::string method = "conservative";
  queries->add_option("dir", dir, "Folder in sample-queries layout")->required();
  queries->add_flag("--json", json, "Print JSON");
  queries
      ->add_option("--method", method,
                   "conservative (runtime) or fast-cubic (non-conservative baseline)")
      ->check(CLI::IsMember({"conservative", "fast-cubic"}));
  queries
      ->add_option("--min-separation", options.min_separation, "Minimum separation (length units)")
      ->check(CLI::NonNegativeNumber);
  queries->add_option("--time-tolerance", options.time_tolerance, "Bisection stop width in t")
      ->check(CLI::PositiveNumber);

  auto* frames = app.add_subcommand(
      "frames",
      "All contacts between two PLY frames of a triangle soup (the runtime's features mode)");
  std::string ply0, ply1;
  frames->add_option("t0", ply0, "Frame at the start of the step (PLY)")->required();
  frames->add_option("t1", ply1, "Frame at the end of the step (PLY, same faces)")->required();
  frames->add_flag("--json", json, "Print JSON");
  bool brute = false;
  bool sweep = false;
  bool bvh = false;
  auto* brute_flag = frames->add_flag("--brute", brute,
                                      "All face pairs instead of the BVH (quadratic; for tests)");
  auto* sweep_flag =
      frames
          ->add_flag("--sweep", sweep,
                     "Sort and sweep over swept boxes, then the same elementary tests (baseline)")
          ->excludes(brute_flag);
  auto* bvh_flag = frames
                       ->add_flag("--bvh", bvh,
                                  "The soup as one surface-only scene body (whole-surface BVH, "
                                  "triangle pairs) instead of the features mode")
                       ->excludes(brute_flag)
                       ->excludes(sweep_flag);
  frames
      ->add_option("--min-separation", options.min_separation, "Minimum separation (length units)")
      ->check(CLI::NonNegativeNumber);
  std::string asset_path;
  auto* asset_option =
      frames
          ->add_option(
              "--asset", asset_path,
              "Cull with this asset's clusters and detectors (rvbc): its nodes are the "
              "frame's vertices and its triangles the frame's faces, in order (a surface "
              "asset built from the first frame). Steps are presumed to start contact-free")
          ->excludes(brute_flag)
          ->excludes(sweep_flag)
          ->excludes(bvh_flag);
  bool skip_still = false;
  std::uint32_t threads = 1;
  frames
      ->add_option("--threads", threads,
                   "Threads of the features mode (OpenMP; default 1). With more than one, the "
                   "time printed is wall time")
      ->check(CLI::Range(1, 256))
      ->excludes(brute_flag)
      ->excludes(sweep_flag)
      ->excludes(bvh_flag)
      ->excludes(asset_option);
  frames->add_flag("--skip-still", skip_still,
                   "Do not test pairs whose four vertices are still (x0 == x1): the runtime's "
                   "default rule for simulator steps that start contact-free. Default: every "
                   "pair touching during the step is reported, still ones included (the "
                   "frame's exact truth)");

  auto* truth =
      app.add_subcommand("truth", "List the true pairs of a scalable-CCD frame (boxes + mma_bool)");
  std::string truth_ply, boxes_path, bools_path, kind;
  truth->add_option("ply", truth_ply, "Frame PLY (for the numbering)")->required();
  truth->add_option("boxes", boxes_path, "boxes/<a>{vf,ee}.json")->required();
  truth->add_option("bools", bools_path, "mma_bool/<a>{vf,ee}_mma_bool.json")->required();
  truth->add_option("--kind", kind, "vf or ee")->required()->check(CLI::IsMember({"vf", "ee"}));

  return run_tool(kTool, app, argc, argv, [&] {
    if (queries->parsed()) return command_queries(dir, json, method, options);
    if (frames->parsed())
      return command_frames(ply0, ply1, json, options,
                            brute                        ? soup::BroadPhase::kBrute
                            : sweep                      ? soup::BroadPhase::kSweep
                            : bvh || !asset_path.empty() ? soup::BroadPhase::kScene
                                                         : soup::BroadPhase::kFeatures,
                            skip_still ? soup::StillPairs::kSkip : soup::StillPairs::kInclude,
                            asset_path, threads);
    return command_truth(truth_ply, boxes_path, bools_path, kind);
  });
}
