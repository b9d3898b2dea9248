// e2e_vectors: command frames written by the firmware's own CommandEncoder
// (firmware/protocol/commands.hpp), one CSV row each, for the Python client's test to reproduce
// bit for bit (tests/python/test_e2e_vectors.py). Values include rounding halves, saturation,
// NaN and every counter, so that the Python port of the single-precision packing and of the
// CRC is checked where it can differ.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

#include "firmware/protocol/commands.hpp"

namespace {

namespace protocol = imd::firmware::protocol;
using protocol::CommandKind;

void row(uint8_t node, uint8_t counter, const protocol::Command& c) {
  protocol::CommandEncoder encoder(node, counter);
  const imd::hal::CanFrame frame = encoder.encode(c);
  const protocol::Message& m = protocol::message(protocol::message_for(c.kind));
  std::printf("%u,%u,%s,%.9g,%u,%u,%03X,", unsigned(node), unsigned(counter), m.name,
              double(c.value), unsigned(c.op), unsigned(c.field), unsigned(frame.id));
  for (int i = 0; i < frame.length; ++i) std::printf("%02X", frame.data[std::size_t(i)]);
  std::printf("\n");
}

}  // namespace

int main() {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::printf("node,counter,message,value,op,field,can_id,data\n");
  const uint8_t nodes[] = {0, 1, 7, 63};
  for (const uint8_t node : nodes) {
    for (uint8_t counter = 0; counter < 16; ++counter) {
      for (const CommandKind kind : {CommandKind::emergency_stop, CommandKind::disable,
                                     CommandKind::enable, CommandKind::clear_faults}) {
        row(node, counter, {kind});
      }
    }
  }
  // Values: plain, negative, halves of the resolution, the range edges, beyond them, NaN.
  const float speeds[] = {0.0f,    30.0f,  -30.0f,    12.3456f, 0.0005f, -0.0005f, 0.0015f,
                          399.99f, 2000.f, -2000.0f,  1e6f,     -1e6f,   1e-7f,    nan,
                          inf,     -inf,   3.14159f};
  const float fluxes[] = {0.01f, 0.2f, 0.0000005f, 4.0f, 1.2345678f, 5000.0f, nan, -1.0f};
  const float rates[] = {10.0f, 100.0f, 1000.0f, 49.5f, 50.5f, 70000.0f, nan};
  for (const uint8_t node : nodes) {
    for (uint8_t counter = 0; counter < 16; counter += 5) {
      for (const float v : speeds) row(node, counter, {CommandKind::set_speed, v});
      for (const float v : fluxes) row(node, counter, {CommandKind::set_flux, v});
      for (const float v : rates) row(node, counter, {CommandKind::set_telemetry_rate, v});
      for (const float v : {0.0f, 1.0f, 2.0f}) row(node, counter, {CommandKind::select_controller, v});
      for (const float v : {0.0f, 1.0f}) row(node, counter, {CommandKind::identify, v});
      for (uint8_t op = 0; op < 3; ++op) {
        for (uint8_t field = 0; field < 11; field += 3) {
          protocol::Command c{CommandKind::parameter_access, 14.0f + float(field) * 0.1f};
          c.op = static_cast<protocol::ParameterOp>(op);
          c.field = field;
          row(node, counter, c);
        }
      }
      protocol::Command odd{CommandKind::parameter_access, nan, protocol::ParameterOp::write, 2};
      row(node, counter, odd);
    }
  }
  return 0;
}
