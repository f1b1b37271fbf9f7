#pragma once
/// \file
/// What every tetseg command-line tool shares: exit codes, error reporting, atomic output.

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace CLI {
class App;
class ParseError;
}  // namespace CLI

namespace tetseg::tools {

/// Exit codes of every tetseg tool (docs/cli.md).
enum ExitCode : int {
  kExitOk = 0,
  kExitProcessingFailed = 1,
  kExitUsage = 2,
  kExitBadInput = 3,
  kExitOutputFailed = 4,
  kExitTimeLimit = 5,  ///< a stage ran past --time-limit; nothing was written
};

/// An error that ends the tool with `code` after printing `<tool>: error: <file>: <message>`.
class ToolError : public std::runtime_error {
 public:
  ToolError(int code, std::string file, const std::string& message)
      : std::runtime_error(message), m_code(code), m_file(std::move(file)) {}
  int code() const noexcept { return m_code; }
  const std::string& file() const noexcept { return m_file; }

 private:
  int m_code;
  std::string m_file;
};

/// Prints `<tool>: error: <file>: <message>` (or without the file when empty) to stderr.
void print_error(const std::string& tool, const std::string& file, const std::string& message);

/// Writes files all or nothing, so readers never see a partial file: `write(temporaries)`
/// writes each file to the temporary path given for it (beside its final path, same
/// extension: `x.tmp<pid>.ext`), then every file is renamed into place. When `write` throws
/// or a rename fails, no temporary file is left behind; a failed rename throws
/// ToolError(kExitOutputFailed) naming the file. The tools' one atomic writer.
void write_files_atomic(const std::vector<std::string>& paths,
                        const std::function<void(const std::vector<std::string>&)>& write);

/// write_files_atomic of one file holding `bytes`. Throws ToolError(kExitOutputFailed).
void write_file_atomic(const std::string& path, const void* bytes, std::size_t size);
inline void write_file_atomic(const std::string& path, const std::string& text) {
  write_file_atomic(path, text.data(), text.size());
}
inline void write_file_atomic(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  write_file_atomic(path, bytes.data(), bytes.size());
}

/// After a CLI11 parse error: prints help, the version or the usage error through `app`, and
/// returns the tool's exit code (kExitOk for --help / --version, else kExitUsage).
int parse_error_exit(const CLI::App& app, const CLI::ParseError& error);

/// A tool's whole `main`, the tools' one mapping of errors to messages and exit codes
/// (docs/cli.md): parses `argv` with `app` (running any subcommand callbacks), then returns
/// `body()`. Help, --version and usage errors end as parse_error_exit says; a ToolError prints
/// `<tool>: error: <file>: <message>` and returns its code; std::bad_alloc prints "out of
/// memory" and any other std::exception its message, both kExitProcessingFailed and naming
/// `file_of_other_errors` (read when the error is reported, so it may be an option's variable;
/// "" names none). `rethrow_as_tool_error`, when given, is called in the handler of any
/// exception but a parse error: it rethrows it (`throw;`) and turns the tool's own exception
/// types into ToolErrors.
int run_tool(const std::string& tool, CLI::App& app, int argc, const char* const* argv,
             const std::function<int()>& body, const std::string& file_of_other_errors = "",
             const std::function<void()>& rethrow_as_tool_error = nullptr);

/// File name without directories ("a/b/c.mesh" -> "c.mesh").
std::string base_name(const std::string& path);

/// Lower-case extension with the dot (".mesh"), or "" when there is none.
std::string extension_of(const std::string& path);

/// format::json_escape (tetseg/format/asset_json.hpp), for tools that link no asset code.
std::string json_escape(const std::string& text);

}  // namespace tetseg::tools
