// tetseg: the offline tool. Reads a tet mesh (or tetrahedralises a surface), computes the
// segmentation and writes the runtime asset. Exit codes: docs/cli.md.

#include <exception>
#include <iostream>
#include <new>

#include "commands.hpp"
#include "tetseg/preprocess/mesh.hpp"
#include "tool_support.hpp"

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
  try {
    app.parse(argc, argv);
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    return parse_error_exit(app, e);  // help, version or usage error
  } catch (const ToolError& e) {
    print_error("tetseg", e.file(), e.what());
    return e.code();
  } catch (const tetseg::preprocess::TimeLimitExceeded& e) {
    print_error("tetseg", e.file(), e.what());
    return kExitTimeLimit;
  } catch (const tetseg::preprocess::InputError& e) {
    print_error("tetseg", e.file(), e.what());
    return kExitBadInput;
  } catch (const tetseg::preprocess::OutputError& e) {
    print_error("tetseg", e.file(), e.what());
    return kExitOutputFailed;
  } catch (const std::bad_alloc&) {
    print_error("tetseg", "", "out of memory");
    return kExitProcessingFailed;
  } catch (const std::exception& e) {
    print_error("tetseg", "", e.what());
    return kExitProcessingFailed;
  }
}
