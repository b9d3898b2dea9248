#pragma once
/// The DBC file and the Markdown reference of the CAN protocol for one node, from the message
/// table (firmware/protocol/messages.hpp). Both are deterministic: same table, same text.
#include <cstdint>
#include <string>

namespace imd::tools::dbc {

std::string dbc_text(uint8_t node_id);
std::string markdown_text(uint8_t node_id);

}  // namespace imd::tools::dbc
