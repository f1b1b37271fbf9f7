// tetseg-sim: drops a soft tet mesh on the ground and writes the frame sequence
// (docs/simulation.md). Exit codes: docs/cli.md (0 ok, 2 usage, 3 bad input, 4 output).

#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "sim.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/runtime/frames.hpp"
#include "tool_support.hpp"

namespace {

using namespace tetseg::tools;
constexpr const char* kTool = "tetseg-sim";

struct Args {
  std::string mesh, asset, output, mode = "rvbc";
  std::uint32_t frames = 100;
  double drop = 0.2, tilt_x = 0.0, tilt_y = 0.0;
  bool json = false;
};

int run(const Args& a, SimOptions opt) {
  if (!tetseg::parse_collider_mode(a.mode.c_str(), opt.collider_mode))
    throw ToolError(kExitUsage, "", "unknown mode '" + a.mode + "'");
  const tetseg::preprocess::TetMesh mesh = tetseg::preprocess::read_tet_mesh(a.mesh);
  tetseg::Asset asset;
  std::string why;
  const tetseg::Status s = tetseg::load_asset_file(a.asset, asset, &why);
  if (s != tetseg::Status::kOk)
    throw ToolError(kExitBadInput, a.asset, std::string(tetseg::to_string(s)) + ": " + why);
  const std::vector<double> start =
      place_above_ground(mesh.nodes, opt.up_axis, opt.ground, a.drop, a.tilt_x, a.tilt_y);
  SoftBody body(mesh, asset, start, opt, a.mesh);

  tetseg::FrameSequence seq;
  seq.node_count = static_cast<std::uint32_t>(mesh.nodes.size());
  seq.frame_count = a.frames;
  seq.positions.reserve(std::size_t(a.frames) * seq.node_count * 3);
  seq.positions.insert(seq.positions.end(), start.begin(), start.end());
  for (std::uint32_t f = 1; f < a.frames; ++f) {
    body.advance_frame();
    seq.positions.insert(seq.positions.end(), body.positions().begin(), body.positions().end());
  }
  write_file_atomic(a.output, tetseg::write_frames(seq));
  const SimCounters& c = body.counters();
  if (a.json) {
    std::cout << "{\"frames\": " << a.frames << ", \"nodes\": " << seq.node_count
              << ", \"substeps\": " << c.substeps
              << ", \"substeps_with_contact\": " << c.substeps_with_contact
              << ", \"contacts_resolved\": " << c.contacts_resolved
              << ", \"query_rounds\": " << c.query_rounds << ", \"max_rounds\": " << c.max_rounds
              << ", \"nodes_frozen\": " << c.nodes_frozen
              << ", \"ground_contacts\": " << c.ground_contacts << "}\n";
  } else {
    std::fprintf(stderr,
                 "tetseg-sim: %u frames, %llu substeps; self-contact: %llu contacts resolved in "
                 "%llu substeps (%llu node freezes, at most %u query rounds per substep)\n",
                 a.frames, static_cast<unsigned long long>(c.substeps),
                 static_cast<unsigned long long>(c.contacts_resolved),
                 static_cast<unsigned long long>(c.substeps_with_contact),
                 static_cast<unsigned long long>(c.nodes_frozen), c.max_rounds);
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tetseg-sim " TETSEG_VERSION
               ": drops a soft tet mesh on the ground; writes a frame sequence whose every "
               "substep is free of self-collision (docs/simulation.md)",
               "tetseg-sim"};
  app.set_version_flag("--version", "tetseg-sim " TETSEG_VERSION);
  Args a;
  SimOptions opt;
  app.add_option("mesh", a.mesh, "Tet mesh (.mesh, .node/.ele, .msh)")->required();
  app.add_option("asset", a.asset, "Asset built from the same mesh (tetseg build)")->required();
  app.add_option("-o,--output", a.output, "Frame-sequence file to write")->required();
  app.add_option("--frames", a.frames, "Frames to write, including the start (default 100)")
      ->check(CLI::Range(1u, 100000u));
  app.add_option("--substeps", opt.substeps, "Substeps per frame (default 4)")
      ->check(CLI::Range(1u, 1000u));
  app.add_option("--iterations", opt.iterations, "Constraint sweeps per substep (default 1)")
      ->check(CLI::Range(1u, 100u));
  app.add_option("--dt", opt.frame_dt, "Seconds per frame (default 1/60)")
      ->check(CLI::PositiveNumber);
  app.add_option("--drop", a.drop, "Start height of the lowest point above the ground")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--tilt-x", a.tilt_x, "Rotation about the x axis in degrees before the drop");
  app.add_option("--tilt-y", a.tilt_y, "Then rotation about the y axis in degrees");
  app.add_option("--up", opt.up_axis, "Up axis: 0 = x, 1 = y, 2 = z (default)")
      ->check(CLI::Range(0, 2));
  app.add_option("--gravity", opt.gravity, "Gravity along -up (default 9.81)");
  app.add_option("--friction", opt.friction, "Ground friction coefficient (default 0.5)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--edge-compliance", opt.edge_compliance,
                 "XPBD compliance of edge lengths (softer when larger; default 1e-4)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--volume-compliance", opt.volume_compliance,
                 "XPBD compliance of tet volumes (default 0)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--damping", opt.damping, "Velocity damping per second (default 0.5)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--mode", a.mode, "Collider mode for self-contact: rvbc (default), bvh, brute")
      ->check(CLI::IsMember({"rvbc", "bvh", "brute"}));
  app.add_flag("--no-self-contact{false}", opt.self_contact,
               "Skip self-contact handling (frames may self-intersect; for comparisons)");
  app.add_flag("--json", a.json, "Print the counters as JSON on stdout");
  try {
    app.parse(argc, argv);
    return run(a, opt);
  } catch (const CLI::ParseError& e) {
    return parse_error_exit(app, e);  // help, version or usage error
  } catch (const ToolError& e) {
    print_error(kTool, e.file(), e.what());
    return e.code();
  } catch (const tetseg::preprocess::InputError& e) {
    print_error(kTool, base_name(e.file()), e.what());
    return kExitBadInput;
  } catch (const tetseg::preprocess::OutputError& e) {
    print_error(kTool, base_name(e.file()), e.what());
    return kExitOutputFailed;
  } catch (const std::bad_alloc&) {
    print_error(kTool, "", "out of memory");
    return kExitProcessingFailed;
  } catch (const std::exception& e) {
    print_error(kTool, "", e.what());
    return kExitProcessingFailed;
  }
}
