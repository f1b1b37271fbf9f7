#pragma once
/// \file
/// Subcommands of the `tetseg` tool. Each `add_*_command` registers one subcommand on `root`;
/// its callback runs the command and throws ToolError / InputError / OutputError on failure
/// (main maps them to exit codes). One file per subcommand: cmd_<name>.cpp.

#include <CLI/CLI.hpp>

namespace tetseg::tools {

void add_generate_command(CLI::App& root);
void add_tetrahedralize_command(CLI::App& root);
void add_charge_command(CLI::App& root);
void add_build_command(CLI::App& root);

}  // namespace tetseg::tools
