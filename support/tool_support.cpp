#include "tool_support.hpp"

#include "tetseg/format/asset_json.hpp"

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <new>

#include <unistd.h>

#include <CLI/CLI.hpp>

namespace tetseg::tools {

void print_error(const std::string& tool, const std::string& file, const std::string& message) {
  std::cerr << tool << ": error: ";
  if (!file.empty()) std::cerr << file << ": ";
  std::cerr << message << '\n';
}

void write_files_atomic(const std::vector<std::string>& paths,
                        const std::function<void(const std::vector<std::string>&)>& write) {
  std::vector<std::string> temps;
  for (const std::string& path : paths) {
    const std::string ext = extension_of(path);
    temps.push_back(path.substr(0, path.size() - ext.size()) + ".tmp" + std::to_string(::getpid()) +
                    ext);
  }
  auto remove_temps = [&] {
    for (const std::string& temp : temps) std::remove(temp.c_str());
  };
  try {
    write(temps);
  } catch (...) {
    remove_temps();
    throw;
  }
  for (std::size_t i = 0; i < paths.size(); ++i) {
    if (std::rename(temps[i].c_str(), paths[i].c_str()) != 0) {
      const int saved = errno;
      remove_temps();
      throw ToolError(kExitOutputFailed, paths[i],
                      std::string("cannot rename into place: ") + std::strerror(saved));
    }
  }
}

void write_file_atomic(const std::string& path, const void* bytes, std::size_t size) {
  write_files_atomic({path}, [&](const std::vector<std::string>& temps) {
    std::FILE* file = std::fopen(temps[0].c_str(), "wb");
    if (!file) {
      throw ToolError(kExitOutputFailed, path,
                      std::string("cannot write: ") + std::strerror(errno));
    }
    const bool written = size == 0 || std::fwrite(bytes, 1, size, file) == size;
    const bool flushed = std::fflush(file) == 0;
    const bool closed = std::fclose(file) == 0;
    if (!written || !flushed || !closed) {
      throw ToolError(kExitOutputFailed, path,
                      std::string("write failed: ") + std::strerror(errno));
    }
  });
}

std::string base_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string extension_of(const std::string& path) {
  const std::string name = base_name(path);
  const auto dot = name.find_last_of('.');
  if (dot == std::string::npos || dot == 0) return {};
  std::string ext = name.substr(dot);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::string json_escape(const std::string& text) {
  return format::json_escape(text);
}

int parse_error_exit(const CLI::App& app, const CLI::ParseError& error) {
  return app.exit(error) == 0 ? kExitOk : kExitUsage;
}

int run_tool(const std::string& tool, CLI::App& app, int argc, const char* const* argv,
             const std::function<int()>& body, const std::string& file_of_other_errors,
             const std::function<void()>& rethrow_as_tool_error) {
  try {
    app.parse(argc, argv);
    return body();
  } catch (const CLI::ParseError& e) {
    return parse_error_exit(app, e);  // help, version or usage error
  } catch (...) {
    try {
      if (rethrow_as_tool_error) rethrow_as_tool_error();
      throw;
    } catch (const ToolError& e) {
      print_error(tool, e.file(), e.what());
      return e.code();
    } catch (const std::bad_alloc&) {
      print_error(tool, file_of_other_errors, "out of memory");
      return kExitProcessingFailed;
    } catch (const std::exception& e) {
      print_error(tool, file_of_other_errors, e.what());
      return kExitProcessingFailed;
    }
  }
}

}  // namespace tetseg::tools
