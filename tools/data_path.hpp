#pragma once
/// Where a host tool finds the project's data files (plot scripts, scenarios, motors): beside
/// its installed location first (PREFIX/bin/tool finds PREFIX/share/imdrive/..., where
/// cmake/Install.cmake puts them), else in the source tree it was built from (a tool of a build
/// tree). Host only.
#include <filesystem>
#include <string_view>
#include <system_error>

namespace imd::tools {

/// The data file at `installed` under the installed data directory when that exists, else at
/// `source` under the source tree. IMD_DATA_DIR_FROM_BIN (the data directory relative to the
/// executable's directory) and IMD_SOURCE_DIR come from the build.
inline std::filesystem::path data_file(std::string_view installed, std::string_view source) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) {
    const std::filesystem::path beside =
        self.parent_path() / IMD_DATA_DIR_FROM_BIN / std::filesystem::path(installed);
    if (std::filesystem::exists(beside, error)) return beside.lexically_normal();
  }
  return std::filesystem::path(IMD_SOURCE_DIR) / std::filesystem::path(source);
}

}  // namespace imd::tools
