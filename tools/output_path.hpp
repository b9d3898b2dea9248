#pragma once
/// Whether a host tool can write an output file, checked before a run that may be long, so
/// that a wrong path is bad input (exit 2) reported at once, not an output lost at the end.
/// Host only.
#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

#include <unistd.h>

namespace imd::tools {

/// Why `path`, given by `flag` ("--csv"), cannot be written: its directory is missing or not
/// writable, or the path is a directory or a read-only file. Empty: it can. Creates nothing.
inline std::string output_path_problem(std::string_view flag, const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code status;
  const fs::path file(path);
  const fs::path directory = file.parent_path().empty() ? fs::path(".") : file.parent_path();
  if (fs::is_directory(file, status)) {
    return fmt::format("{} {}: is a directory, not a file", flag, path);
  }
  if (!fs::exists(directory, status)) {
    return fmt::format("{} {}: no directory {}", flag, path, directory.string());
  }
  if (!fs::is_directory(directory, status)) {
    return fmt::format("{} {}: {} is not a directory", flag, path, directory.string());
  }
  const bool exists = fs::exists(file, status);
  if (::access(exists ? file.c_str() : directory.c_str(), W_OK) != 0) {
    return fmt::format("{} {}: cannot write {} ({})", flag, path,
                       exists ? "the file" : "in directory " + directory.string(),
                       std::strerror(errno));
  }
  return "";
}

}  // namespace imd::tools
