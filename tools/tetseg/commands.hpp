#pragma once
/// \file
/// Subcommands of the `tetseg` tool. Each `add_*_command` registers one subcommand on `root`;
/// its callback runs the command and throws ToolError / InputError / OutputError on failure
/// (main maps them to exit codes). One file per subcommand: cmd_<name>.cpp.

#include <CLI/CLI.hpp>
#include <exception>
#include <new>
#include <string>
#include <utility>

#include "tetseg/preprocess/mesh.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/option_ranges.hpp"
#include "tetseg/preprocess/pipeline.hpp"
#include "tool_support.hpp"

namespace tetseg::tools {

void add_generate_command(CLI::App& root);
void add_tetrahedralize_command(CLI::App& root);
void add_charge_command(CLI::App& root);
void add_build_command(CLI::App& root);

/// Runs `command`. An exception that names no file (a CGAL, Eigen or assimp failure, out of
/// memory) becomes ToolError(kExitProcessingFailed) naming `file`, so a failure of any stage
/// names the input it failed on; ToolError, InputError, OutputError and CLI errors pass as is.
template <typename Command>
void run_naming_file(const std::string& file, Command&& command) {
  try {
    command();
  } catch (const ToolError&) {
    throw;
  } catch (const preprocess::InputError&) {
    throw;
  } catch (const preprocess::OutputError&) {
    throw;
  } catch (const CLI::Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw ToolError(kExitProcessingFailed, file, "out of memory");
  } catch (const std::exception& e) {
    throw ToolError(kExitProcessingFailed, file, std::string("processing failed: ") + e.what());
  }
}

/// The CLI11 check of an option's declared range (tetseg/preprocess/option_ranges.hpp). A range
/// open at its minimum is (0, inf] (CLI::PositiveNumber).
inline CLI::Validator range_check(const preprocess::OptionRange& range) {
  if (range.min_exclusive) return CLI::PositiveNumber;
  return CLI::Range(range.min, range.max);
}

/// The one stage printer of the `tetseg` commands: `tetseg: <stage> <seconds> s  <summary>` on
/// stderr, for each finished stage of a job (defined in cmd_generate.cpp).
void print_stage(const preprocess::StageReport& stage);

/// Helpers shared by the commands that write tet meshes (defined in cmd_generate.cpp).
namespace mesh_cli {

/// How a `.msh` output is written: Gmsh 4.1 ASCII by default.
struct MshOutput {
  bool gmsh22 = false;  ///< Gmsh 2.2 ASCII
  bool binary = false;  ///< Gmsh 4.1 binary
};

/// Runs `work(summary)` (returning its result) as one stage named `name`, timed and printed
/// by print_stage. Defined here: a template.
template <typename Work>
auto run_stage(const char* name, Work&& work) {
  preprocess::BuildReport stages;
  preprocess::StageTimer timer(stages, print_stage);
  return timer.run(name, std::forward<Work>(work));
}

/// "N nodes, M tets".
std::string tet_mesh_summary(const preprocess::TetMesh& mesh);

/// Adds the Mesh_3 options (--cell-size, ...) and the .msh flags (--gmsh22, --binary).
void add_meshing_options(CLI::App& cmd, preprocess::MeshingOptions& m, MshOutput& msh);
/// Throws a usage error unless `path` names a tet mesh format.
void check_output_path(const std::string& path);
/// Validates `mesh` (exit 1 when invalid) and writes it atomically to `output` (stages
/// validate and write).
void finish_tet_mesh(const preprocess::TetMesh& mesh, const std::string& output,
                     const MshOutput& msh);

/// Says on stderr that tetrahedralize meshed `file` again with less optimisation because the
/// optimised mesh's boundary was invalid (`notes`).
void print_retry_note(const std::string& file, const preprocess::TetrahedralizeNotes& notes);

/// Adds `--threads N` (MeshingOptions::threads); `prefix` starts its help text.
void add_threads_option(CLI::App& cmd, preprocess::MeshingOptions& m, const std::string& prefix);
/// Adds `--repair none|fix` (MeshingOptions::repair).
void add_repair_option(CLI::App& cmd, preprocess::MeshingOptions& m);
/// Adds `--time-limit SECONDS` (option_ranges kTimeLimit; default kDefaultTimeLimitSeconds):
/// `what` says what it bounds.
void add_time_limit_option(CLI::App& cmd, double& seconds, const std::string& what);
/// Sets `m.progress` to print "tetseg: tetrahedralize: still in <step> after N s" on stderr.
void report_meshing_progress(preprocess::MeshingOptions& m);
/// Prints why --repair auto wrapped `file` (when it did) and the repairs tetrahedralize made
/// ("tetseg: repaired x.off: 2 duplicate triangles removed, ..."), nothing when none.
void print_repairs(const std::string& file, const preprocess::TetrahedralizeNotes& notes);

}  // namespace mesh_cli

}  // namespace tetseg::tools
