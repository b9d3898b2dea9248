#pragma once
/// The DBC file and the Markdown reference of the CAN protocol for one node, from the message
/// table (firmware/protocol/messages.hpp). Both are deterministic: same table, same text.
#include <cstdint>
#include <string>
#include <vector>

namespace imd::tools::dbc {

std::string dbc_text(uint8_t node_id);
/// One DBC file for several drives on one bus: node names Drive<id>, message names <name>_<id>.
std::string dbc_text(const std::vector<uint8_t>& node_ids);
std::string markdown_text(uint8_t node_id);
/// The table as a Python module of plain data (imdrive/protocol_table.py): node independent.
std::string python_text();

}  // namespace imd::tools::dbc
