#include "hal/cortex_m/stm32g4/fdcan_classic.hpp"

#include "hal/cortex_m/armv7m.hpp"
#include "hal/cortex_m/stm32g4/memory_map.hpp"

namespace imd::hal::cortex_m::stm32g4 {
namespace {

// FDCAN registers (RM0440 §44.4).
constexpr uintptr_t kCccr = kFdcan1 + 0x018;
constexpr uintptr_t kNbtp = kFdcan1 + 0x01C;
constexpr uintptr_t kPsr = kFdcan1 + 0x044;
constexpr uintptr_t kIe = kFdcan1 + 0x054;
constexpr uintptr_t kIle = kFdcan1 + 0x05C;
constexpr uintptr_t kRxgfc = kFdcan1 + 0x080;
constexpr uintptr_t kRxf0s = kFdcan1 + 0x090;
constexpr uintptr_t kRxf0a = kFdcan1 + 0x094;
constexpr uintptr_t kTxbc = kFdcan1 + 0x0C0;
constexpr uintptr_t kTxfqs = kFdcan1 + 0x0C4;
constexpr uintptr_t kTxbar = kFdcan1 + 0x0CC;
constexpr uint32_t kCccrInit = 1u << 0;
constexpr uint32_t kCccrCce = 1u << 1;  // FDOE (8) = BRSE (9) = 0: classic CAN; DAR (6) = 0
constexpr uint32_t kPsrBo = 1u << 7;
// RXGFC: RRFE 0, RRFS 1 (reject remote frames), ANFE [3:2] = 10 (reject non-matching
// extended), ANFS [5:4] = 00 (accept non-matching standard into Rx FIFO 0), LSS = LSE = 0.
constexpr uint32_t kRxgfcRejectRemoteAndExtended = (1u << 0) | (1u << 1) | (0x2u << 2);
constexpr uint32_t kRxf0sFillMask = 0xFu;  // F0FL [3:0]; F0GI [9:8]
constexpr uint32_t kTxfqsFull = 1u << 21;  // TFQF; TFQPI [17:16]

// Message RAM of FDCAN1 (RM0440 §44.3.3): fixed layout, 212 words. Elements of 18 words (room
// for 64-byte FD payloads); a classic frame uses the first four.
constexpr uintptr_t kRam = kFdcanMessageRam;
constexpr uintptr_t kRamRxFifo0 = 0x0B0;    // after 28 standard and 8 extended filter elements
constexpr uintptr_t kRamTxBuffers = 0x278;  // after Rx FIFO 1 (0x188) and Tx events (0x260)
constexpr uintptr_t kRamBytes = 0x350;
constexpr uintptr_t kElementBytes = 18 * 4;
static_assert(kRamRxFifo0 == 28 * 4 + 8 * 8 && kRamTxBuffers == 0x260 + 3 * 8 &&
              kRamBytes == kRamTxBuffers + 3 * kElementBytes);
// Element words 0 and 1: identifier (standard: [28:18]), RTR 29, XTD 30; DLC [19:16].
constexpr uint32_t kIdShift = 18;
constexpr uint32_t kRtr = 1u << 29, kXtd = 1u << 30;
constexpr uint32_t kDlcShift = 16;

constexpr uint32_t kPolls = 100'000;

bool wait_init(uint32_t value) noexcept {
  for (uint32_t n = 0; n < kPolls; ++n) {
    if ((reg32(kCccr) & kCccrInit) == value) return true;
  }
  return false;
}

uint32_t pack(const uint8_t* b) noexcept {
  return uint32_t(b[0]) | (uint32_t(b[1]) << 8) | (uint32_t(b[2]) << 16) | (uint32_t(b[3]) << 24);
}

void unpack(uint32_t word, uint8_t* b) noexcept {
  for (int i = 0; i < 4; ++i) b[i] = static_cast<uint8_t>(word >> (8 * i));
}

}  // namespace

FdcanClassic::FdcanClassic(const FdcanConfig& c) noexcept {
  reg32(kCccr) |= kCccrInit;
  const bool in_init = wait_init(kCccrInit);
  reg32(kCccr) = kCccrInit | kCccrCce;  // configuration writable; classic CAN, retransmission on
  reg32(kNbtp) =
      ((c.sjw - 1) << 25) | ((c.prescaler - 1) << 16) | ((c.tseg1 - 1) << 8) | (c.tseg2 - 1);
  for (uintptr_t offset = 0; offset < kRamBytes; offset += 4) reg32(kRam + offset) = 0;
  reg32(kRxgfc) = kRxgfcRejectRemoteAndExtended;
  reg32(kTxbc) = 0;  // TFQM = 0: Tx FIFO (frames leave in the order queued)
  reg32(kIe) = 0;    // polled: no FDCAN interrupt
  reg32(kIle) = 0;
  reg32(kCccr) &= ~kCccrInit;  // joins the bus after 11 recessive bits; CCE clears itself
  ok_ = in_init && wait_init(0);
}

bool FdcanClassic::try_send(const hal::CanFrame& frame) noexcept {
  return tx_.try_push(frame);
}

bool FdcanClassic::try_receive(hal::CanFrame& frame) noexcept {
  for (int n = 0; n < 3; ++n) {  // skips at most the FIFO's three elements
    const uint32_t status = reg32(kRxf0s);
    if ((status & kRxf0sFillMask) == 0) return false;
    const uint32_t get = (status >> 8) & 0x3u;
    const uintptr_t element = kRam + kRamRxFifo0 + get * kElementBytes;
    const uint32_t r0 = reg32(element);
    const uint32_t r1 = reg32(element + 4);
    const uint32_t d0 = reg32(element + 8);
    const uint32_t d1 = reg32(element + 12);
    reg32(kRxf0a) = get;                      // frees the element
    if ((r0 & (kRtr | kXtd)) != 0) continue;  // rejected by the filter; defensive
    const uint32_t dlc = (r1 >> kDlcShift) & 0xFu;
    frame.id = static_cast<uint16_t>((r0 >> kIdShift) & 0x7FFu);
    frame.length = static_cast<uint8_t>(dlc > 8 ? 8 : dlc);
    unpack(d0, &frame.data[0]);
    unpack(d1, &frame.data[4]);
    return true;
  }
  return false;
}

bool FdcanClassic::bus_off() const noexcept {
  return (reg32(kPsr) & kPsrBo) != 0;
}

void FdcanClassic::pump() noexcept {
  if ((reg32(kCccr) & kCccrInit) != 0 && bus_off()) {
    reg32(kCccr) &= ~kCccrInit;  // bus-off recovery (RM0440 §44.3: INIT is set at bus-off)
    ++recoveries_;
  }
  while (const hal::CanFrame* frame = tx_.front()) {
    const uint32_t status = reg32(kTxfqs);
    if ((status & kTxfqsFull) != 0) return;
    const uint32_t put = (status >> 16) & 0x3u;
    const uintptr_t element = kRam + kRamTxBuffers + put * kElementBytes;
    const uint32_t length = frame->length > 8 ? 8u : frame->length;
    reg32(element) = uint32_t(frame->id & 0x7FFu) << kIdShift;
    reg32(element + 4) = length << kDlcShift;  // FDF = BRS = 0, no Tx event
    reg32(element + 8) = pack(&frame->data[0]);
    reg32(element + 12) = pack(&frame->data[4]);
    reg32(kTxbar) = 1u << put;
    tx_.pop();
  }
}

}  // namespace imd::hal::cortex_m::stm32g4
