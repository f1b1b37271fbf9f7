// tetseg-bench table: the paper's Table I on frame sequences. For each scene and collider
// mode: mean per-step milliseconds of BVH update, orientation check, traversal, elementary
// tests and total, the work counts, and the contacts missed against the scene oracle
// (tetseg/testing/scene_oracle.hpp: its own feature enumeration and the elementary tests alone,
// sharing nothing with the collider's narrow phase); every mode, brute included, is compared:
// every contact of every step, the any-collision answer and the earliest time of impact.
// Comparisons cover the steps whose start frame passes the static intersection check: the
// collider's culling assumes an intersection-free start (docs/runtime.md); the table shows
// how many steps were compared.
// Links the runtime only. Timings: each step is run `--repeat` times and the fastest run of
// the step is kept (robust to the shared cores of a CI machine); the mean is over steps (the
// JSON also has the medians over steps of the total and CPU times).
// tetseg-bench scene: scene_table.hpp.

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "scene_table.hpp"
#include "surface_frames.hpp"
#include "tetseg/format/skin.hpp"
#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/runtime/frames.hpp"
#include "tetseg/testing/scene_oracle.hpp"
#include "tool_support.hpp"

namespace {

using Clock = std::chrono::steady_clock;

/// Process CPU time in milliseconds, all threads (robust to other processes on the shared
/// cores; with OpenMP it sums the threads' time).
double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

using tetseg::tools::kExitBadInput;
using tetseg::tools::kExitProcessingFailed;
using tetseg::tools::kExitUsage;
using tetseg::tools::ToolError;

using Key = std::array<std::uint32_t, 5>;  // kind, nodes

Key key_of(const tetseg::Contact& c) {
  return {static_cast<std::uint32_t>(c.kind), c.nodes[0], c.nodes[1], c.nodes[2], c.nodes[3]};
}

struct StepTruth {
  bool clean_start = true;  ///< start frame passes the static intersection check
  bool any = false;
  double earliest = 1.0;
  std::vector<Key> contacts;           // sorted
  std::vector<Key> earliest_contacts;  // sorted: contacts with toi == earliest
};

struct Row {
  std::string scene, mode;
  bool openmp = false;
  bool timed_tests = false;  ///< elementary tests timed apart (else counted as traversal)
  std::size_t steps = 0;
  double refit = 0, classify = 0, cone = 0, traversal = 0, tests = 0, total = 0, cpu = 0;
  /// Medians over steps of the kept run's wall and CPU milliseconds (means: total, cpu).
  double total_median = 0, cpu_median = 0;
  double tri_pairs = 0, feature_tests = 0, contacts = 0, neg_unc = 0;
  std::size_t clusters = 0;
  /// missed: oracle contacts at the step's earliest toi that the mode did not report (must be
  /// 0); later_missed: oracle contacts after the earliest toi not reported (informative: once
  /// the surface touches, the culling premise no longer holds for the rest of the step).
  std::uint64_t missed = 0, later_missed = 0, extra = 0, any_mismatch = 0, toi_mismatch = 0;
  std::size_t compared = 0;  ///< steps whose start is intersection-free (the collider's premise)
  bool truncated = false;
};

struct Scene {
  std::string name;
  tetseg::Asset asset;
  tetseg::FrameSequence frames;
  /// Bone-carried detectors (DetectorForm::kBones): per frame, every cluster's detector
  /// position (cluster_count * 3), from the --bones file's matrices. Empty for other forms.
  std::vector<double> detectors;
  const double* detectors_at(std::size_t frame) const {
    return detectors.data() + frame * 3 * asset.cluster_count();
  }
};

/// Reads the per-frame bone matrices of `bones_path` (tetseg-character's PREFIX.bones.tsf: per
/// frame, each bone's row-major 3x4 skinning matrix as 4 points) and poses the detectors of
/// every frame (format::skinned_detector_positions).
void pose_detectors(Scene& s, const std::string& bones_path) {
  tetseg::FrameSequence bones;
  std::string why;
  const tetseg::FramesStatus fs = tetseg::read_frames_file(bones_path, bones, &why);
  if (fs != tetseg::FramesStatus::kOk)
    throw ToolError(kExitBadInput, "", bones_path + ": " + tetseg::to_string(fs) + ": " + why);
  const tetseg::format::Asset& a = s.asset.data();
  if (bones.node_count != 4 * a.bone_names.size() || bones.frame_count != s.frames.frame_count)
    throw ToolError(kExitBadInput, "",
                    bones_path + ": expected " + std::to_string(a.bone_names.size()) +
                        " bones (4 points each) in " + std::to_string(s.frames.frame_count) +
                        " frames");
  const std::size_t per_frame = 3 * a.clusters.size();
  s.detectors.resize(per_frame * bones.frame_count);
  for (std::size_t f = 0; f < bones.frame_count; ++f)
    tetseg::format::skinned_detector_positions(a, bones.frame(f),
                                               s.detectors.data() + f * per_frame);
}

void load_scene(Scene& s, const std::string& asset_path, const std::string& frames_path) {
  std::string why;
  const tetseg::Status st = tetseg::load_asset_file(asset_path, s.asset, &why);
  if (st != tetseg::Status::kOk)
    throw ToolError(kExitBadInput, "", asset_path + ": " + tetseg::to_string(st) + ": " + why);
  const tetseg::FramesStatus fs = tetseg::read_frames_file(frames_path, s.frames, &why);
  if (fs != tetseg::FramesStatus::kOk)
    throw ToolError(kExitBadInput, "", frames_path + ": " + tetseg::to_string(fs) + ": " + why);
  if (s.frames.node_count != s.asset.node_count())
    throw ToolError(kExitBadInput, "", frames_path + ": node count differs from the asset's");
}

/// Median of `v` (mean of the two middle values for an even count; 0 when empty).
double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

/// Which steps are run and what is timed.
struct Plan {
  std::size_t stride = 1;  ///< step f -> f + stride
  bool pairs = false;      ///< frame-pair file: step i is frame 2i -> 2i + 1
  std::size_t max_steps = 1000000;
  int repeat = 3;           ///< runs per step, the fastest kept
  bool time_tests = false;  ///< ColliderOptions::time_tests
  bool earliest = false;    ///< time step + earliest_toi (else step + contacts)
};

/// Steps of `frames` under `plan`, and the frames of step i.
std::size_t step_count(const tetseg::FrameSequence& frames, const Plan& plan) {
  const std::size_t n = frames.frame_count;
  const std::size_t steps = plan.pairs ? n / 2 : n > plan.stride ? (n - 1) / plan.stride : 0;
  return std::min(steps, plan.max_steps);
}
std::size_t step_start(std::size_t i, const Plan& plan) {
  return plan.pairs ? 2 * i : i * plan.stride;
}
std::size_t step_end(std::size_t i, const Plan& plan) {
  return plan.pairs ? 2 * i + 1 : i * plan.stride + plan.stride;
}

/// The scene oracle's truth for every step of `plan`; a step is compared when its start frame
/// passes the static intersection check (the collider's premise).
std::vector<StepTruth> oracle_truth(const Scene& s, const Plan& plan) {
  tetseg::Collider collider(s.asset);
  if (collider.status() != tetseg::ColliderStatus::kOk)
    throw ToolError(kExitProcessingFailed, "", "cannot create the collider");
  const auto& triangles = s.asset.data().triangles;
  std::vector<StepTruth> truth(step_count(s.frames, plan));
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const double* x0 = s.frames.frame(step_start(i, plan));
    const double* x1 = s.frames.frame(step_end(i, plan));
    const tetseg::RestCheck rc =
        collider.check_rest_intersection(x0, std::size_t(s.frames.node_count) * 3);
    truth[i].clean_start = rc.status == tetseg::ColliderStatus::kOk && !rc.intersecting;
    const std::vector<tetseg::Contact> contacts = tetseg::test::scene_brute_contacts(
        {tetseg::test::OracleBody{triangles.data(), triangles.size(), x0, x1, true}});
    truth[i].any = !contacts.empty();
    truth[i].earliest = contacts.empty() ? 1.0 : contacts.front().toi;
    for (const tetseg::Contact& c : contacts) {
      truth[i].contacts.push_back(key_of(c));
      if (c.toi == truth[i].earliest) truth[i].earliest_contacts.push_back(key_of(c));
    }
    std::sort(truth[i].contacts.begin(), truth[i].contacts.end());
    std::sort(truth[i].earliest_contacts.begin(), truth[i].earliest_contacts.end());
  }
  return truth;
}

/// Runs `mode` over the steps of `plan`; fills timing and counts; compares with `truth` when
/// it is not empty.
Row run_mode(const Scene& s, tetseg::ColliderMode mode, bool openmp, const Plan& plan,
             const std::vector<StepTruth>& truth, std::vector<tetseg::Contact>& buffer) {
  tetseg::ColliderOptions opt;
  opt.mode = mode;
  opt.use_openmp = openmp;
  opt.time_tests = plan.time_tests;
  tetseg::Collider collider(s.asset, opt);
  if (collider.status() != tetseg::ColliderStatus::kOk)
    throw ToolError(kExitProcessingFailed, "", "cannot create the collider");
  Row row;
  row.scene = s.name;
  row.mode = tetseg::to_string(mode);
  row.openmp = openmp;
  row.timed_tests = plan.time_tests;
  row.clusters = s.asset.cluster_count();
  const std::size_t steps = step_count(s.frames, plan);
  row.steps = steps;
  std::vector<double> step_total, step_cpu;
  for (std::size_t i = 0; i < steps; ++i) {
    const double* x0 = s.frames.frame(step_start(i, plan));
    const double* x1 = s.frames.frame(step_end(i, plan));
    if (!s.detectors.empty() &&
        collider.set_detector_positions(s.detectors_at(step_start(i, plan)),
                                        s.detectors_at(step_end(i, plan)),
                                        3 * s.asset.cluster_count()) != tetseg::ColliderStatus::kOk)
      throw ToolError(kExitBadInput, "",
                      s.name + ": detector positions of step " + std::to_string(i) + " rejected");
    double best_total = 1e300, best_cpu = 1e300;
    tetseg::ColliderStats best_stats;
    tetseg::ContactsResult result;
    tetseg::EarliestContact e;
    for (int r = 0; r < plan.repeat; ++r) {
      const double c0 = process_cpu_ms();
      const auto t0 = Clock::now();
      if (collider.step(x0, x1) != tetseg::ColliderStatus::kOk)
        throw ToolError(kExitBadInput, "", s.name + ": step " + std::to_string(i) + " rejected");
      const tetseg::ColliderStatus st =
          plan.earliest ? collider.earliest_toi(e)
                        : collider.contacts(buffer.data(), buffer.size(), result);
      const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
      best_cpu = std::min(best_cpu, process_cpu_ms() - c0);
      if (st != tetseg::ColliderStatus::kOk)
        throw ToolError(kExitProcessingFailed, "", s.name + ": query failed");
      if (ms < best_total) {
        best_total = ms;
        best_stats = collider.stats();
      }
    }
    // Untimed: the other query, for the counts and the comparison.
    if ((plan.earliest ? collider.contacts(buffer.data(), buffer.size(), result)
                       : collider.earliest_toi(e)) != tetseg::ColliderStatus::kOk)
      throw ToolError(kExitProcessingFailed, "", s.name + ": query failed");
    row.total += best_total;
    row.cpu += best_cpu;
    step_total.push_back(best_total);
    step_cpu.push_back(best_cpu);
    row.refit += best_stats.refit_ms;
    row.classify += best_stats.classify_ms;
    row.cone += best_stats.cone_ms;
    row.traversal += best_stats.traversal_ms;
    row.tests += best_stats.tests_ms;
    row.tri_pairs += double(best_stats.triangle_pairs);
    row.neg_unc += double(best_stats.triangles_negative + best_stats.triangles_uncertain);
    row.feature_tests += double(best_stats.feature_tests);
    row.contacts += double(result.found);
    row.truncated = row.truncated || result.truncated();
    std::vector<Key> keys;
    keys.reserve(result.written);
    for (std::size_t k = 0; k < result.written; ++k) keys.push_back(key_of(buffer[k]));
    std::sort(keys.begin(), keys.end());
    std::vector<Key> first_keys;
    for (std::size_t k = 0; k < result.written; ++k)
      if (e.found && buffer[k].toi == e.contact.toi) first_keys.push_back(key_of(buffer[k]));
    std::sort(first_keys.begin(), first_keys.end());
    if (truth.empty()) continue;  // --no-truth
    const StepTruth& t = truth[i];
    if (!t.clean_start) continue;
    ++row.compared;
    if (t.any != (result.found > 0)) ++row.any_mismatch;
    if (t.any && e.found && e.contact.toi != t.earliest) ++row.toi_mismatch;
    std::vector<Key> diff;
    std::set_difference(t.earliest_contacts.begin(), t.earliest_contacts.end(), keys.begin(),
                        keys.end(), std::back_inserter(diff));
    const std::size_t missed_first = diff.size();
    row.missed += missed_first;
    diff.clear();
    std::set_difference(t.contacts.begin(), t.contacts.end(), keys.begin(), keys.end(),
                        std::back_inserter(diff));
    row.later_missed += diff.size() - std::min(diff.size(), missed_first);
    diff.clear();
    std::set_difference(keys.begin(), keys.end(), t.contacts.begin(), t.contacts.end(),
                        std::back_inserter(diff));
    row.extra += diff.size();
  }
  const double n = steps ? double(steps) : 1.0;
  for (double* v : {&row.refit, &row.classify, &row.cone, &row.traversal, &row.tests, &row.total,
                    &row.cpu, &row.tri_pairs, &row.feature_tests, &row.contacts, &row.neg_unc})
    *v /= n;
  row.total_median = median(step_total);
  row.cpu_median = median(step_cpu);
  return row;
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

int table(const std::vector<std::string>& scene_args, const std::vector<std::string>& bones_files,
          const std::string& mode_list, const Plan& plan, bool openmp, bool json, bool with_truth) {
  if (scene_args.empty() || scene_args.size() % 3 != 0)
    throw ToolError(kExitUsage, "", "scenes are given as NAME ASSET FRAMES triples");
  std::vector<tetseg::ColliderMode> modes;
  {
    std::size_t p = 0;
    while (p <= mode_list.size()) {
      const std::size_t q = std::min(mode_list.find(',', p), mode_list.size());
      const std::string name = mode_list.substr(p, q - p);
      tetseg::ColliderMode m;
      if (!tetseg::parse_collider_mode(name.c_str(), m))
        throw ToolError(kExitUsage, "", "unknown mode '" + name + "'");
      modes.push_back(m);
      p = q + 1;
    }
  }
  std::vector<Row> rows;
  std::vector<tetseg::Contact> buffer(1 << 20);
  std::map<std::string, std::vector<StepTruth>> truths;  // by frames path
  std::size_t bones_used = 0;                            // --bones files given to scenes
  for (std::size_t i = 0; i < scene_args.size(); i += 3) {
    Scene s;
    s.name = scene_args[i];
    load_scene(s, scene_args[i + 1], scene_args[i + 2]);
    if (s.asset.data().detector_form == tetseg::format::DetectorForm::kBones) {
      if (bones_used == bones_files.size())
        throw ToolError(kExitUsage, "",
                        s.name + ": its detectors are carried by bones: give --bones");
      pose_detectors(s, bones_files[bones_used++]);
    }
    if (plan.pairs && s.frames.frame_count % 2 != 0)
      throw ToolError(kExitBadInput, "", scene_args[i + 2] + ": --pairs needs an even frame count");
    // A scene on the same frames as an earlier one (another asset of the same mesh, e.g.
    // another cluster method) reuses that scene's oracle truth.
    std::vector<StepTruth>& truth = truths[scene_args[i + 2]];
    if (with_truth && truth.empty()) {
      truth = oracle_truth(s, plan);
      std::fprintf(stderr, "tetseg-bench: %s: oracle done\n", s.name.c_str());
    }
    for (tetseg::ColliderMode m : modes) {
      for (int omp = 0; omp <= (openmp ? 1 : 0); ++omp) {
        rows.push_back(run_mode(s, m, omp == 1, plan, truth, buffer));
        std::fprintf(stderr, "tetseg-bench: %s: %s%s done\n", s.name.c_str(), to_string(m),
                     omp ? " (OpenMP)" : "");
      }
    }
  }
  if (bones_used != bones_files.size())
    throw ToolError(kExitUsage, "", "more --bones files than scenes with bone-carried detectors");
  bool all_found = true;
  for (const Row& r : rows)
    all_found = all_found && r.missed == 0 && r.extra == 0 && r.any_mismatch == 0 &&
                r.toi_mismatch == 0 && !r.truncated;
  if (json) {
    std::cout << "{\"rows\": [";
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      std::cout << (i ? ", " : "") << "{\"scene\": \"" << r.scene << "\", \"mode\": \"" << r.mode
                << "\", \"openmp\": " << (r.openmp ? "true" : "false") << ", \"steps\": " << r.steps
                << ", \"compared\": " << r.compared << ", \"clusters\": " << r.clusters
                << ", \"uncertain_negative\": " << r.neg_unc << ", \"bvh_update_ms\": " << r.refit
                << ", \"orientation_ms\": " << r.classify << ", \"cone_ms\": " << r.cone
                << ", \"traversal_ms\": " << r.traversal
                << ", \"tests_ms\": " << (r.timed_tests ? fmt("%.17g", r.tests) : "null")
                << ", \"total_ms\": " << r.total << ", \"total_cpu_ms\": " << r.cpu
                << ", \"median_total_ms\": " << r.total_median
                << ", \"median_cpu_ms\": " << r.cpu_median
                << ", \"triangle_pairs\": " << r.tri_pairs
                << ", \"feature_tests\": " << r.feature_tests << ", \"contacts\": " << r.contacts
                << ", \"missed\": " << r.missed << ", \"later_missed\": " << r.later_missed
                << ", \"extra\": " << r.extra << ", \"any_mismatch\": " << r.any_mismatch
                << ", \"toi_later\": " << r.toi_mismatch
                << ", \"truncated\": " << (r.truncated ? "true" : "false") << "}";
    }
    std::cout << "], \"all_contacts_found\": "
              << (!with_truth ? "null"
                  : all_found ? "true"
                              : "false")
              << "}\n";
  } else {
    std::cout
        << "| scene | mode | steps (compared) | BVH update | orientation | cone+contour | "
           "traversal | "
           "elem. tests | total | total CPU | tri pairs | feature tests | contacts | missed | "
           "later missed | extra "
           "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Row& r : rows) {
      std::cout << "| " << r.scene << " | " << r.mode << (r.openmp ? " (OpenMP)" : "") << " | "
                << r.steps << " (" << r.compared << ") | " << fmt("%.4f", r.refit) << " | "
                << (r.mode == "rvbc" ? fmt("%.4f", r.classify) : "-") << " | "
                << (r.mode == "cone" ? fmt("%.4f", r.cone) : "-") << " | "
                << fmt("%.4f", r.traversal) << " | " << (r.timed_tests ? fmt("%.4f", r.tests) : "-")
                << " | " << fmt("%.4f", r.total) << " | " << fmt("%.4f", r.cpu) << " | "
                << fmt("%.0f", r.tri_pairs) << " | " << fmt("%.0f", r.feature_tests) << " | "
                << fmt("%.2f", r.contacts) << " | "
                << std::to_string(r.missed + r.any_mismatch + r.toi_mismatch) << " | "
                << std::to_string(r.later_missed) << " | " << std::to_string(r.extra) << " |\n";
    }
    // Per scene: speed-up of rvbc over the other modes (targets are per scene, in
    // docs/benchmarks.md; the tool does not judge them).
    for (const Row& r : rows) {
      if (r.mode != "rvbc" || r.openmp) continue;
      for (const Row& o : rows) {
        if (o.scene != r.scene || o.openmp || o.mode == "rvbc" || o.mode == "brute") continue;
        std::cout << "\n"
                  << r.scene << ": rvbc is " << fmt("%.2f", o.cpu / r.cpu) << "x faster than "
                  << o.mode << " per step";
      }
      std::cout << "\n" << r.scene << ": rvbc total CPU " << fmt("%.4f", r.cpu) << " ms per step\n";
    }
    std::cout << "\ncontacts at the earliest toi found by every mode, none outside the oracle's: "
              << (!with_truth ? "not compared (--no-truth)"
                  : all_found ? "yes"
                              : "NO")
              << "\n";
  }
  return all_found ? 0 : kExitProcessingFailed;
}

/// `check`: every frame free of static self-intersection, every step free of contacts (the
/// scene oracle). Exit 0 when clean, 1 otherwise.
int check(const std::string& asset_path, const std::string& frames_path) {
  Scene s;
  s.name = frames_path;
  load_scene(s, asset_path, frames_path);
  tetseg::Collider collider(s.asset);
  if (collider.status() != tetseg::ColliderStatus::kOk)
    throw ToolError(kExitProcessingFailed, "", "cannot create the collider");
  const auto& triangles = s.asset.data().triangles;
  const std::size_t values = std::size_t(s.frames.node_count) * 3;
  std::size_t bad_frames = 0, bad_steps = 0, contacts = 0;
  for (std::size_t f = 0; f < s.frames.frame_count; ++f) {
    const tetseg::RestCheck r = collider.check_rest_intersection(s.frames.frame(f), values);
    if (r.status != tetseg::ColliderStatus::kOk || r.intersecting) {
      ++bad_frames;
      std::printf("frame %zu: self-intersecting (triangles %u, %u)\n", f, r.triangle_a,
                  r.triangle_b);
    }
  }
  for (std::size_t f = 0; f + 1 < s.frames.frame_count; ++f) {
    const std::size_t found =
        tetseg::test::scene_brute_contacts(
            {tetseg::test::OracleBody{triangles.data(), triangles.size(), s.frames.frame(f),
                                      s.frames.frame(f + 1), true}})
            .size();
    if (found > 0) {
      ++bad_steps;
      contacts += found;
      std::printf("step %zu: %zu contacts\n", f, found);
    }
  }
  std::printf("frames %u, self-intersecting frames %zu, steps with contacts %zu (%zu contacts)\n",
              s.frames.frame_count, bad_frames, bad_steps, contacts);
  return bad_frames == 0 && bad_steps == 0 ? 0 : kExitProcessingFailed;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tetseg-bench " TETSEG_VERSION
               ": benchmarks of the runtime collider (docs/benchmarks.md)",
               "tetseg-bench"};
  app.set_version_flag("--version", "tetseg-bench " TETSEG_VERSION);
  app.require_subcommand(1);
  CLI::App* t = app.add_subcommand(
      "table", "Table I: per-step stage times, work counts and missed contacts per mode");
  std::vector<std::string> scenes, bones_files;
  std::string modes = "rvbc,bvh,cone,brute";
  Plan plan;
  std::string query = "all";
  bool openmp = false, json = false, no_truth = false;
  t->add_option("scenes", scenes,
                "NAME ASSET FRAMES, repeated per scene (scenes on the same FRAMES file share "
                "one oracle truth)")
      ->required();
  t->add_option("--bones", bones_files,
                "Per-frame bone matrices (tetseg-character's PREFIX.bones.tsf) for each scene "
                "whose detectors are carried by bones, in scene order")
      ->allow_extra_args(false);
  t->add_option("--modes", modes, "Comma-separated modes, each compared with the scene oracle");
  t->add_option("--stride", plan.stride, "Step from frame f to f + stride (default 1)")
      ->check(CLI::Range(std::size_t(1), std::size_t(1000)));
  t->add_flag("--pairs", plan.pairs,
              "FRAMES are frame pairs (tetseg-sim --record-queries): step i is frame 2i -> 2i + 1")
      ->excludes("--stride");
  t->add_option("--max-steps", plan.max_steps, "Use at most this many steps per scene")
      ->check(CLI::PositiveNumber);
  t->add_option("--repeat", plan.repeat, "Runs per step; the fastest is kept (default 3)")
      ->check(CLI::Range(1, 100));
  t->add_option("--query", query,
                "Timed query after each step: all (contacts into a buffer, default) or earliest "
                "(earliest_toi); the other runs untimed for the comparison")
      ->check(CLI::IsMember({"all", "earliest"}));
  t->add_flag("--openmp", openmp,
              "Also run each mode with use_openmp (refit, classification and the traversal "
              "of every query; threads: OMP_NUM_THREADS)");
  t->add_flag("--no-truth", no_truth,
              "Skip the oracle and the comparison (timings only; missed reads 0)");
  t->add_flag("--json", json, "JSON on stdout instead of the Markdown table");
  t->add_flag("--time-tests", plan.time_tests,
              "Time the elementary tests apart (two clock reads per test, in every total); "
              "without it their time counts as traversal and the column reads '-'");
  CLI::App* c = app.add_subcommand(
      "check", "No frame self-intersects and no step has a contact (scene oracle; exit 1 if any)");
  std::string check_asset, check_frames;
  c->add_option("asset", check_asset, "Asset file")->required();
  c->add_option("frames", check_frames, "Frame-sequence file")->required();
  CLI::App* sc = app.add_subcommand(
      "scene",
      "Scene table: stage times, body pairs, contacts and missed contacts over scenes "
      "written by tetseg-sim --scene");
  tetseg::bench::SceneTableOptions scene_options;
  sc->add_option("scenes", scene_options.scenes, "NAME DESCRIPTION, repeated per scene")
      ->required();
  sc->add_option("--stride", scene_options.stride, "Step from frame f to f + stride (default 1)")
      ->check(CLI::Range(std::size_t(1), std::size_t(1000)));
  sc->add_option("--max-steps", scene_options.max_steps, "Use at most this many steps per scene")
      ->check(CLI::PositiveNumber);
  sc->add_option("--repeat", scene_options.repeat, "Runs per step; the fastest is kept (default 3)")
      ->check(CLI::Range(1, 100));
  sc->add_flag("--merged", scene_options.merged,
               "Also time all surfaces merged into one body in bvh mode");
  sc->add_flag("--no-truth{false}", scene_options.truth,
               "Skip brute force and the comparison (timings only)");
  sc->add_flag("--expect-clean", scene_options.expect_clean,
               "Exit 1 when a frame intersects or brute force finds a contact in a step");
  CLI::App* sf = app.add_subcommand(
      "surface",
      "A tet scene as a surface body: its rest surface as OFF (surface nodes in ascending id) "
      "and frame files restricted to those nodes");
  std::string surface_asset, surface_off;
  std::vector<std::string> surface_frame_pairs;
  sf->add_option("asset", surface_asset, "Tet asset (with rest positions)")->required();
  sf->add_option("surface", surface_off, "OFF file to write")->required();
  sf->add_option("frames", surface_frame_pairs, "FRAMES OUT_FRAMES, repeated")->expected(0, -1);
  return tetseg::tools::run_tool("tetseg-bench", app, argc, argv, [&] {
    if (c->parsed()) return check(check_asset, check_frames);
    if (sf->parsed()) {
      if (surface_frame_pairs.size() % 2 != 0)
        throw ToolError(kExitUsage, "", "surface: frame files come in pairs (FRAMES OUT_FRAMES)");
      return tetseg::bench::surface_frames(surface_asset, surface_off, surface_frame_pairs);
    }
    if (sc->parsed()) return tetseg::bench::scene_table(scene_options);
    plan.earliest = query == "earliest";
    return table(scenes, bones_files, modes, plan, openmp, json, !no_truth);
  });
}
