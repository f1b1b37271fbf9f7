// tetseg: the offline tool. Reads a tet mesh (or tetrahedralises a surface), computes the
// segmentation and writes the runtime asset. Exit codes: docs/cli.md.

#include "commands.hpp"
#include "tetseg/preprocess/mesh.hpp"
#include "tool_support.hpp"

namespace {

/// The preprocess library's errors as the exit codes of docs/cli.md (run_tool's hook).
void rethrow_preprocess_error_as_tool_error() {
  using namespace tetseg::tools;
  try {
    throw;
  } catch (const tetseg::preprocess::TimeLimitExceeded& e) {
    throw ToolError(kExitTimeLimit, e.file(), e.what());
  } catch (const tetseg::preprocess::InputError& e) {
    throw ToolError(kExitBadInput, e.file(), e.what());
  } catch (const tetseg::preprocess::OutputError& e) {
    throw ToolError(kExitOutputFailed, e.file(), e.what());
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace tetseg::tools;
  CLI::App app{"tetseg " TETSEG_VERSION
               ": builds continuous self-collision assets for deformable tetrahedral objects",
               "tetseg"};
  app.set_version_flag("--version", "tetseg " TETSEG_VERSION);
  app.require_subcommand(1);
  add_generate_command(app);
  add_tetrahedralize_command(app);
  add_charge_command(app);
  add_build_command(app);
  // The subcommands run as parse callbacks.
  return run_tool(
      "tetseg", app, argc, argv, [] { return kExitOk; }, "",
      rethrow_preprocess_error_as_tool_error);
}
