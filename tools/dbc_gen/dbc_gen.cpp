// dbc_gen: writes the DBC file and the Markdown reference of the drive's CAN protocol for one
// node (or one DBC file for several drives on one bus, --nodes), from the message table in
// firmware/protocol/messages.hpp.
#include <imd_version.hpp>
#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include "firmware/protocol/messages.hpp"
#include "writers.hpp"

namespace {

constexpr int kExitBadInput = 2;

/// A node id must be an integer in 0..kMaxNodeId.
const CLI::Validator kNodeId(
    [](std::string& text) -> std::string {
      const int max_id = imd::firmware::protocol::kMaxNodeId;
      std::size_t end = 0;
      int value = -1;
      try {
        value = std::stoi(text, &end);
      } catch (const std::exception&) {
        end = 0;
      }
      if (end == 0 || end != text.size() || value < 0 || value > max_id) {
        return "must be a node id in 0.." + std::to_string(max_id) + ", got " + text;
      }
      return {};
    },
    "0..63");

/// Writes `text` to `path`; on failure returns why, naming the flag and the path.
std::string write_file(const std::string& flag, const std::string& path, const std::string& text) {
  errno = 0;
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (file) file << text;
  if (file) file.close();
  if (file) return {};
  const std::string why = errno != 0 ? std::strerror(errno) : "write error";
  return flag + " " + path + ": cannot write the file (" + why + ")";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Writes the DBC file (and a Markdown reference) of the drive's CAN protocol."};
  app.set_version_flag("--version", imd::version::kText);
  int node_id = 1;
  std::string dbc_path, markdown_path;
  app.add_option("--node", node_id, "CAN node id of the drive")
      ->check(kNodeId)
      ->capture_default_str();
  std::vector<std::string> node_list;
  app.add_option("--nodes", node_list,
                 "One DBC file for several drives on one bus, e.g. 1,2,5: nodes Drive1, Drive2, "
                 "Drive5, message names suffixed _1, _2, _5")
      ->delimiter(',')
      ->check(kNodeId)
      ->excludes("--node")
      ->type_name("ID,ID,...");
  app.add_option("--output", dbc_path, "Write the DBC file here (default: standard output)")
      ->type_name("PATH");
  app.add_option("--markdown", markdown_path, "Also write the Markdown protocol reference here")
      ->type_name("PATH");
  std::string python_path;
  app.add_option("--python", python_path,
                 "Also write the table as a Python module (tools/python/imdrive/protocol_table.py)")
      ->type_name("PATH");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : kExitBadInput;
  }

  const auto node = static_cast<uint8_t>(node_id);
  std::vector<uint8_t> nodes;
  for (const std::string& id : node_list) nodes.push_back(static_cast<uint8_t>(std::stoi(id)));
  if (!nodes.empty() && std::set<uint8_t>(nodes.begin(), nodes.end()).size() != nodes.size()) {
    std::cerr << "dbc_gen: --nodes: each node id once (two drives cannot share one)\n";
    return kExitBadInput;
  }
  if (!nodes.empty() && !markdown_path.empty()) {
    std::cerr << "dbc_gen: --markdown describes one node: give --node, not --nodes\n";
    return kExitBadInput;
  }
  const std::string dbc =
      nodes.empty() ? imd::tools::dbc::dbc_text(node) : imd::tools::dbc::dbc_text(nodes);
  std::string error;
  if (dbc_path.empty()) {
    std::cout << dbc;
  } else {
    error = write_file("--output", dbc_path, dbc);
  }
  if (error.empty() && !markdown_path.empty()) {
    error = write_file("--markdown", markdown_path, imd::tools::dbc::markdown_text(node));
  }
  if (error.empty() && !python_path.empty()) {
    error = write_file("--python", python_path, imd::tools::dbc::python_text());
  }
  if (!error.empty()) {
    std::cerr << "dbc_gen: " << error << '\n';
    return kExitBadInput;
  }
  return 0;
}
