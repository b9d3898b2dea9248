// libFuzzer harness: arbitrary frames into protocol::CommandDecoder, from a few starting states,
// checking its invariants after every frame.
//
// Input: byte 0 picks the configuration (node id, limits), byte 1 the starting state (no
// counter reference yet, or one accepted command with a given counter). Then records of 12
// bytes: flags, identifier (2 bytes, little-endian), length, 8 data bytes. Flags help the
// fuzzer past the CRC: bit 0 puts the identifier on the node (keeping the message id), bit 1
// sets the table's length for that message, bit 2 writes the correct CRC, bit 3 also reports a
// not_allowed rejection afterwards, as the application does.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iterator>

#include "firmware/protocol/commands.hpp"
#include "firmware/protocol/e2e.hpp"
#include "fuzz_check.hpp"

namespace {

namespace protocol = imd::firmware::protocol;
using protocol::CommandKind;
using protocol::CommandResult;

struct Config {
  uint8_t node_id;
  protocol::CommandLimits limits;
};
constexpr Config kConfigs[] = {
    {1, {400.0f, 0.01f, 4.0f}},
    {0, {100.0f, 0.05f, 1.0f}},
    {63, {1.0f, 0.01f, 0.25f}},
    {17, {0.0f, 0.0f, 1e-6f}},
};

bool value_in_range(const protocol::Command& c, const protocol::CommandLimits& limits) {
  switch (c.kind) {
    case CommandKind::set_speed:
      return c.value >= -limits.max_speed_rad_s && c.value <= limits.max_speed_rad_s;
    case CommandKind::set_flux:
      return c.value >= limits.min_flux2_Wb2 && c.value <= limits.max_flux2_Wb2;
    case CommandKind::select_controller:  // a law of the protocol's table
      return std::any_of(std::begin(protocol::kControllerValues),
                         std::end(protocol::kControllerValues),
                         [&](const protocol::ValueName& v) { return c.value == float(v.raw); });
    case CommandKind::set_telemetry_rate:
      return c.value >= float(protocol::kFastTelemetryMinHz) &&
             c.value <= float(protocol::kFastTelemetryMaxHz);
    case CommandKind::parameter_access:  // any float: the drive judges it and answers why
      return static_cast<int>(c.op) < protocol::kParameterOpCount;
    case CommandKind::identify:  // rotate: 0 standstill only, 1 also the rotating step
      return c.value == 0.0f || c.value == 1.0f;
    default:
      return c.value == 0.0f;
  }
}

uint32_t total_by_reason(const protocol::CommandDecoder& decoder) {
  uint32_t total = 0;
  for (int r = 1; r < protocol::kCommandResultCount; ++r)
    total += decoder.rejected(CommandResult(r));
  return total;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 2) return 0;
  const Config& config = kConfigs[data[0] % std::size(kConfigs)];
  protocol::CommandDecoder decoder(config.node_id, config.limits);
  bool have_reference = false;
  if ((data[1] & 0x10) != 0) {
    protocol::CommandEncoder encoder(config.node_id, data[1] & 0x0F);
    const protocol::Decoded first = decoder.decode(encoder.encode({CommandKind::enable}));
    FUZZ_CHECK(first.result == CommandResult::accepted);  // the first frame sets the reference
    FUZZ_CHECK(decoder.last_counter() == (data[1] & 0x0F));
    have_reference = true;
  }

  for (size_t at = 2; at + 12 <= size; at += 12) {
    const uint8_t flags = data[at];
    imd::hal::CanFrame frame;
    frame.id = static_cast<uint16_t>(data[at + 1] | (data[at + 2] << 8));
    frame.length = data[at + 3];
    for (int i = 0; i < 8; ++i) frame.data[i] = data[at + 4 + i];
    if ((flags & 1) != 0) {
      frame.id = protocol::can_id(config.node_id, protocol::MessageId(frame.id & 0x1F));
    }
    if ((flags & 2) != 0) {
      const protocol::Message* m = protocol::find_message(frame.id & 0x1F);
      if (m != nullptr) frame.length = m->length;
    }
    if ((flags & 4) != 0) frame.data[0] = protocol::e2e_crc(frame.id, frame.data, frame.length);

    const uint32_t rejected_before = decoder.rejected_total();
    const uint8_t counter_before = decoder.last_counter();
    const protocol::Decoded d = decoder.decode(frame);

    FUZZ_CHECK(decoder.rejected_total() == total_by_reason(decoder));
    if (!d.for_this_node) {
      FUZZ_CHECK(decoder.rejected_total() == rejected_before);
      FUZZ_CHECK(decoder.last_counter() == counter_before);
    } else if (d.result == CommandResult::out_of_range) {
      // Past the E2E checks: the counter reference moved on with the host's counter.
      FUZZ_CHECK(decoder.rejected_total() == rejected_before + 1);
      FUZZ_CHECK(decoder.last_counter() == d.counter);
      have_reference = true;
    } else if (d.result != CommandResult::accepted) {
      FUZZ_CHECK(decoder.rejected_total() == rejected_before + 1);
      FUZZ_CHECK(decoder.last_counter() == counter_before);
      FUZZ_CHECK(d.result != CommandResult::not_allowed);  // only the application says that
    } else {
      // An accepted command: well-formed, for this node, in range, and the counter stepped.
      FUZZ_CHECK(decoder.rejected_total() == rejected_before);
      FUZZ_CHECK(frame.id <= 0x7FF && protocol::node_of(frame.id) == config.node_id);
      const protocol::Message* m = protocol::find_message(protocol::message_of(frame.id));
      FUZZ_CHECK(m != nullptr && m->direction == protocol::Direction::host_to_drive);
      FUZZ_CHECK(protocol::message_for(d.command.kind) == m->id);
      FUZZ_CHECK(frame.length == m->length);
      FUZZ_CHECK(frame.data[0] == protocol::e2e_crc(frame.id, frame.data, frame.length));
      // Byte 1's high nibble is reserved (zero), except where parameter_access holds its op.
      if (d.command.kind == CommandKind::parameter_access) {
        FUZZ_CHECK((frame.data[1] >> 4) == static_cast<int>(d.command.op));
      } else {
        FUZZ_CHECK((frame.data[1] & 0xF0) == 0);
      }
      FUZZ_CHECK(d.counter == (frame.data[1] & 0x0F));
      FUZZ_CHECK(decoder.last_counter() == d.counter);
      if (have_reference && d.command.kind != CommandKind::emergency_stop) {
        const int step = (d.counter - counter_before) & 0x0F;
        FUZZ_CHECK(step >= 1 && step <= protocol::kMaxCounterStep);
      }
      FUZZ_CHECK(value_in_range(d.command, config.limits));
      have_reference = true;
    }
    if ((flags & 8) != 0 && d.result == CommandResult::accepted) {
      const uint32_t before = decoder.rejected_total();
      decoder.count_refused(CommandResult::not_allowed);
      FUZZ_CHECK(decoder.rejected_total() == before + 1);
    }
  }
  return 0;
}
