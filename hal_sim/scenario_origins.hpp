#pragma once
/// Where each key of a scenario's document came from (internal to hal_sim/scenario*.cpp): the
/// scenario file, a motor file it names, the --motor-file, or a --set override. The document
/// is assembled from all of them before it is read, so an error message asks this map which
/// file or flag to name: the place the user must fix. Host only.
#include <map>
#include <string>
#include <string_view>
#include <utility>

namespace imd::sim::detail {

class KeyOrigins {
 public:
  /// `fallback`: the origin of every key no entry covers (the scenario file).
  explicit KeyOrigins(std::string fallback) : fallback_(std::move(fallback)) {}

  /// The key or table at dotted `path`, and everything below it that has no entry of its own,
  /// comes from `origin`.
  void set(const std::string& path, std::string origin) { origins_[path] = std::move(origin); }

  /// Forgets the entries at `path` and below: the table there was replaced as a whole.
  void clear_below(const std::string& path) {
    for (auto it = origins_.begin(); it != origins_.end();) {
      it = below(it->first, path) ? origins_.erase(it) : std::next(it);
    }
  }

  /// The origin of `path`: its own entry, else that of the nearest table above it ("a.b[2].c"
  /// looks up "a.b[2].c", "a.b[2]", "a.b", "a"), else the fallback.
  const std::string& of(std::string_view path) const {
    for (std::string_view p = path; !p.empty();) {
      if (const auto it = origins_.find(std::string(p)); it != origins_.end()) return it->second;
      const std::size_t cut = p.find_last_of(".[");
      p = cut == std::string_view::npos ? std::string_view() : p.substr(0, cut);
    }
    return fallback_;
  }

 private:
  static bool below(std::string_view key, std::string_view path) {
    return key.substr(0, path.size()) == path &&
           (key.size() == path.size() || key[path.size()] == '.' || key[path.size()] == '[');
  }

  std::string fallback_;
  std::map<std::string, std::string> origins_;
};

}  // namespace imd::sim::detail
