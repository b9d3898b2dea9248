#pragma once
/// drive_monitor send --repeat-hz F --for-s S: when each frame of a repeated command is due,
/// which alive counter it carries, and which command_ack answers which frame. No I/O and no
/// clock of its own: the CLI passes steady_clock times and the frames it received, the tests
/// pass made-up ones.
///
/// Timing: slot k is due at start + k / F (absolute, so rounding never accumulates into drift);
/// there are ceil(S * F) slots. A caller that wakes up after slot k + 1 was already due skips
/// slot k instead of sending a burst: for a keep-alive only the latest frame matters, and a
/// burst after a long stall would only fill the transmit queue.
///
/// Counter: each frame sent carries the previous one's counter + 1, the step the drive expects
/// (it accepts 1..kMaxCounterStep ahead of the last E2E-valid frame). A frame the socket refused
/// never reached the bus, so the next frame reuses its counter; burning it would move the host
/// towards the edge of the drive's window. No resync from the heartbeat after a counter
/// rejection (another host sent in between, or more than two frames were lost): a rejected frame
/// leaves the drive's reference where it was, and counters that keep stepping by one come round
/// mod 16 into its window after at most 13 rejected frames (12 stale, 1 repeated), sooner than
/// the next 10 Hz heartbeat at high rates, and without the race of a heartbeat that predates
/// frames still in flight.
///
/// Acks: no stop-and-wait; each sent frame waits, keyed by its counter, for the command_ack with
/// its message and counter. It counts as unanswered if none came within ack_timeout_s, or by the
/// time its counter comes round again 16 frames later (an ack could no longer be told apart).
///
/// Lead (send set-speed --enable): one other command sent at the start, before slot 0, with the
/// first counter; slot 0 follows at once with the next. One process does both, so the repeated
/// frames feed the command watchdog from the tick the enable arms it. A lead the socket refused
/// or the drive rejected stops the repetition: a drive that was not enabled has nothing to keep
/// alive.
#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "firmware/protocol/commands.hpp"
#include "hal/can_bus.hpp"
#include "tools/drive_monitor/send_command.hpp"

namespace imd::monitor {

using SteadyTime = std::chrono::steady_clock::time_point;

/// Highest --repeat-hz: a set_speed frame and its ack every millisecond already take about a
/// fifth of a 1 Mbit/s bus.
inline constexpr double kMaxRepeatRate_Hz = 1000.0;
/// Longest --for-s (the CLI's limit for every duration).
inline constexpr double kMaxRepeatDuration_s = 1e7;

struct RepeatPlan {
  double rate_Hz = 10.0;       ///< (0, kMaxRepeatRate_Hz]
  double duration_s = 1.0;     ///< (0, kMaxRepeatDuration_s]
  double ack_timeout_s = 0.5;  ///< a sent frame without its command_ack by then is unanswered
};

/// The slots at k / rate_Hz below duration_s: ceil(duration_s * rate_Hz), at least 1, and a
/// product that is a whole number up to rounding (0.3 s at 10 Hz) counts as that number.
uint64_t repeat_slot_count(double rate_Hz, double duration_s);

/// A command sent once before the repeated one (`send set-speed --enable`: the enable), and
/// what became of it. At namespace scope, not nested in RepeatTally: a nested class with
/// default member initializers is not constructible inside its enclosing class for clang 14.
struct RepeatLead {
  firmware::protocol::Command command;
  bool sent = false;                                        ///< the socket took it
  bool send_failed = false;                                 ///< the socket refused it
  std::optional<firmware::protocol::CommandResult> result;  ///< its ack's
  bool unanswered = false;                                  ///< sent, no ack in time
};

/// What happened to the frames of a repeated command.
struct RepeatTally {
  uint64_t planned = 0;        ///< slots in the plan
  uint64_t sent = 0;           ///< frames the socket took
  uint64_t send_failures = 0;  ///< frames the socket refused (queue full, interface down)
  uint64_t skipped = 0;        ///< slots passed over because the caller woke up too late
  uint64_t accepted = 0;
  /// Rejections by the ack's 4-bit result (a CommandResult; all 16 codes, so that a result this
  /// tool does not know is still counted). [0], accepted, stays 0.
  std::array<uint64_t, 16> rejected{};
  uint64_t unanswered = 0;  ///< sent, but no command_ack matched in time
  /// Set when stop() came before the last slot: seconds from the start.
  std::optional<double> stopped_after_s;

  /// The lead command and what became of it (only with a lead).
  std::optional<RepeatLead> lead;

  uint64_t rejected_total() const;
};

/// How the CLI's exit code reads a tally.
enum class RepeatVerdict : uint8_t {
  all_accepted,      ///< every planned-and-sent frame was accepted, none refused by the socket
  rejected,          ///< the drive rejected at least one frame
  not_all_accepted,  ///< none rejected, but some were unanswered or not sent (or none was sent)
};
/// With a lead: rejected if it was, all_accepted only if it was accepted too.
RepeatVerdict verdict(const RepeatTally& tally);

/// One line, e.g. "sent 60 set_speed 30.000 rad/s frames at 20 Hz: 58 accepted, 2 rejected
/// (1 stale_counter, 1 not_allowed), 0 unanswered", then only what is not zero: frames not sent,
/// slots skipped, and an early stop. A lead comes first: "enable: accepted; sent 60 ...".
std::string repeat_summary(const RepeatTally& tally, const firmware::protocol::Command& command,
                           double rate_Hz);

class CommandRepeater {
 public:
  /// The first frame is due at `start` and carries `first_counter`; with a `lead`, that frame
  /// is the lead and slot 0 follows at once.
  CommandRepeater(uint8_t node_id, const firmware::protocol::Command& command,
                  uint8_t first_counter, const RepeatPlan& plan, SteadyTime start,
                  const std::optional<firmware::protocol::Command>& lead = std::nullopt);

  /// The frame to send now if a slot is due (nullopt: not yet, or no slot left). The caller
  /// must report at once whether the socket took it: sent(now, queued).
  std::optional<hal::CanFrame> frame_due(SteadyTime now);
  /// Whether the socket took the frame the last frame_due() returned.
  void sent(SteadyTime now, bool queued);
  /// A frame from the bus; the command_acks of the frames sent count, all else is ignored.
  void receive(SteadyTime now, const hal::CanFrame& frame);
  /// No more frames (a signal, a dead interface); the frames sent still wait for their acks.
  void stop(SteadyTime now);
  /// Nothing left to send and no ack left to wait for.
  bool finished(SteadyTime now);
  /// When frame_due() or an ack timeout next needs the caller; SteadyTime::max() if never.
  /// The caller sleeps until then or until a frame arrives.
  SteadyTime next_event() const;

  /// The time slot `slot` is due.
  SteadyTime slot_time(uint64_t slot) const;
  /// The counter the next frame will carry.
  uint8_t next_counter() const { return encoder_.next_counter(); }
  const RepeatTally& tally() const { return tally_; }

 private:
  struct Waiting {
    bool active = false;
    SteadyTime deadline;
  };

  bool slots_left() const { return !stopped_ && next_slot_ < tally_.planned; }
  bool lead_due() const { return tally_.lead && !stopped_ && !lead_tried_; }
  /// The lead's ack, if `ack` is it: true when consumed.
  bool receive_lead(SteadyTime now, const AckFrame& ack);
  /// Counts the frames whose ack deadline has passed as unanswered.
  void expire(SteadyTime now);
  void give_up(Waiting& w);

  uint8_t node_id_;
  firmware::protocol::Command command_;
  uint8_t message_id_;
  firmware::protocol::CommandEncoder encoder_;
  SteadyTime start_;
  double rate_Hz_;
  std::chrono::nanoseconds ack_timeout_;
  uint64_t next_slot_ = 0;
  bool stopped_ = false;
  std::optional<uint8_t> unreported_counter_;  ///< frame_due() returned it, sent() not yet called
  std::array<Waiting, 16> waiting_{};          ///< by alive counter
  bool lead_tried_ = false;                    ///< frame_due() returned the lead
  uint8_t lead_counter_ = 0;
  Waiting lead_waiting_{};
  RepeatTally tally_;
};

}  // namespace imd::monitor
