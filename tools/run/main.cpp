// tetseg-run: steps a collider through a frame sequence and reports, per step, the query
// result and, overall, the mean time per stage. Links the runtime only. Exit codes:
// docs/cli.md (0 ok, 2 usage, 3 bad input).

#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/runtime/frames.hpp"
#include "tool_support.hpp"

namespace {

using namespace tetseg::tools;
constexpr const char* kTool = "tetseg-run";

struct FrameResult {
  bool any = false;
  bool has_earliest = false;
  double earliest = 0;
  bool has_contacts = false;
  std::size_t contacts = 0;
};

std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

int run(const std::string& asset_path, const std::string& frames_path, const std::string& mode_name,
        const std::string& query, bool json, bool stop_at_contact, bool openmp) {
  tetseg::ColliderOptions options;
  options.use_openmp = openmp;
  options.time_tests = true;  // the JSON reports elementary-test time separately
  if (!tetseg::parse_collider_mode(mode_name.c_str(), options.mode))
    throw ToolError(kExitUsage, "",
                    "unknown mode '" + mode_name + "' (rvbc, bvh, brute, cone, features)");
  tetseg::Asset asset;
  std::string why;
  const tetseg::Status s = tetseg::load_asset_file(asset_path, asset, &why);
  if (s != tetseg::Status::kOk)
    throw ToolError(kExitBadInput, asset_path, std::string(tetseg::to_string(s)) + ": " + why);
  tetseg::FrameSequence frames;
  const tetseg::FramesStatus fs = tetseg::read_frames_file(frames_path, frames, &why);
  if (fs != tetseg::FramesStatus::kOk)
    throw ToolError(kExitBadInput, frames_path, std::string(tetseg::to_string(fs)) + ": " + why);
  if (frames.node_count != asset.node_count())
    throw ToolError(kExitBadInput, frames_path,
                    "has " + std::to_string(frames.node_count) + " nodes, the asset has " +
                        std::to_string(asset.node_count()));
  tetseg::Collider collider(asset, options);
  if (collider.status() != tetseg::ColliderStatus::kOk)
    throw ToolError(kExitProcessingFailed, "", "cannot create the collider (out of memory)");
  // Bone-carried detectors: the frames carry no pose, so they stay at rest (exact, culls less).
  const std::vector<double> rest_detectors = tetseg::format::rest_detector_positions(asset.data());
  if (asset.data().detector_form == tetseg::format::DetectorForm::kBones) {
    if (collider.set_detector_positions(rest_detectors.data(), rest_detectors.data(),
                                        rest_detectors.size()) != tetseg::ColliderStatus::kOk)
      throw ToolError(kExitProcessingFailed, asset_path, "cannot set the detector positions");
    std::fprintf(stderr,
                 "tetseg-run: %s: detectors carried by bones stay at their rest positions (the "
                 "frames carry no pose)\n",
                 asset_path.c_str());
  }

  std::vector<tetseg::Contact> buffer;  // contacts are counted, not stored
  std::vector<FrameResult> results;
  double refit = 0, classify = 0, traversal = 0, tests = 0, total = 0;
  double uncertain = 0, feature_tests = 0, skipped = 0;
  using Clock = std::chrono::steady_clock;
  const std::size_t steps = frames.frame_count > 0 ? frames.frame_count - 1 : 0;
  for (std::size_t f = 0; f < steps; ++f) {
    FrameResult r;
    const auto t0 = Clock::now();
    const tetseg::ColliderStatus st = collider.step(frames.frame(f), frames.frame(f + 1));
    if (st != tetseg::ColliderStatus::kOk)
      throw ToolError(kExitBadInput, frames_path,
                      "frame " + std::to_string(f) + ": " + tetseg::to_string(st));
    tetseg::ColliderStatus qs = tetseg::ColliderStatus::kOk;
    if (query == "any") {
      qs = collider.any_collision(r.any);
    } else if (query == "earliest") {
      tetseg::EarliestContact e;
      qs = collider.earliest_toi(e);
      r.any = e.found;
      r.has_earliest = e.found;
      r.earliest = e.contact.toi;
    } else {
      tetseg::ContactsResult c;
      tetseg::EarliestContact e;
      qs = collider.contacts(nullptr, 0, c);
      if (qs == tetseg::ColliderStatus::kOk) qs = collider.earliest_toi(e);  // reuses the traversal
      r.any = c.found > 0;
      r.has_contacts = true;
      r.contacts = c.found;
      r.has_earliest = e.found;
      r.earliest = e.contact.toi;
    }
    if (qs != tetseg::ColliderStatus::kOk)
      throw ToolError(kExitProcessingFailed, frames_path,
                      "frame " + std::to_string(f) + ": query failed: " + tetseg::to_string(qs));
    total += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    const tetseg::ColliderStats& stats = collider.stats();
    refit += stats.refit_ms;
    classify += stats.classify_ms;
    traversal += stats.traversal_ms;
    tests += stats.tests_ms;
    uncertain += double(stats.triangles_uncertain);
    feature_tests += double(stats.feature_tests);
    skipped += double(stats.clusters_skipped);
    results.push_back(r);
    if (!json) {
      std::cout << "frame " << f << ": any " << (r.any ? "yes" : "no");
      if (query != "any")
        std::cout << ", earliest toi "
                  << (r.has_earliest ? number(r.earliest) : std::string("none"));
      if (r.has_contacts) std::cout << ", contacts " << r.contacts;
      std::cout << '\n';
    }
    if (stop_at_contact && r.any) break;
  }
  const double n = results.empty() ? 1.0 : double(results.size());
  if (json) {
    std::cout << "{\"mode\": \"" << mode_name << "\", \"query\": \"" << query
              << "\", \"frames\": [";
    for (std::size_t f = 0; f < results.size(); ++f) {
      const FrameResult& r = results[f];
      std::cout << (f ? ", " : "") << "{\"frame\": " << f
                << ", \"any\": " << (r.any ? "true" : "false")
                << ", \"earliest_toi\": " << (r.has_earliest ? number(r.earliest) : "null")
                << ", \"contacts\": " << (r.has_contacts ? std::to_string(r.contacts) : "null")
                << "}";
    }
    std::cout << "], \"mean_ms\": {\"refit\": " << number(refit / n)
              << ", \"classify\": " << number(classify / n)
              << ", \"traversal\": " << number(traversal / n)
              << ", \"tests\": " << number(tests / n) << ", \"total\": " << number(total / n)
              << "}}\n";
  } else {
    std::cout << "mode " << mode_name << ", query " << query << ", " << results.size()
              << " steps; mean ms: refit " << refit / n << ", classify " << classify / n
              << ", traversal " << traversal / n << ", tests " << tests / n << ", total "
              << total / n << "; mean per step: " << uncertain / n << " uncertain triangles of "
              << asset.triangle_count() << ", " << skipped / n << " clusters skipped, "
              << feature_tests / n << " elementary tests\n";
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tetseg-run " TETSEG_VERSION
               ": continuous self-collision queries over a frame sequence (docs/runtime.md)",
               "tetseg-run"};
  app.set_version_flag("--version", "tetseg-run " TETSEG_VERSION);
  std::string asset_path, frames_path, mode = "rvbc", query = "all";
  bool json = false;
  app.add_option("asset", asset_path, "Asset file (.tetseg)")->required();
  app.add_option("frames", frames_path, "Frame-sequence file (docs/format.md)")->required();
  app.add_option("--mode", mode,
                 "Candidate search: rvbc (default), bvh, brute, cone (normal cones, ICCD-style) or "
                 "features (per-feature trees)")
      ->check(CLI::IsMember({"rvbc", "bvh", "brute", "cone", "features"}));
  app.add_option("--query", query, "any, earliest or all (default)")
      ->check(CLI::IsMember({"any", "earliest", "all"}));
  app.add_flag("--json", json, "Machine-readable output on stdout");
  bool stop_at_contact = false;
  app.add_flag("--stop-at-contact", stop_at_contact,
               "Stop after the first step with a contact (as a simulator would respond)");
  bool openmp = false;
  app.add_flag("--openmp", openmp,
               "Use OpenMP threads inside each step (ColliderOptions::use_openmp)");
  return run_tool(kTool, app, argc, argv, [&] {
    return run(asset_path, frames_path, mode, query, json, stop_at_contact, openmp);
  });
}
