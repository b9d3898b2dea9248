#include "tools/drive_monitor/repeat_send.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "tools/drive_monitor/send_command.hpp"

namespace imd::monitor {
namespace {

using firmware::protocol::CommandResult;

std::chrono::steady_clock::duration from_seconds(double seconds) {
  return std::chrono::round<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(seconds));
}

}  // namespace

uint64_t repeat_slot_count(double rate_Hz, double duration_s) {
  const double slots = duration_s * rate_Hz;
  if (!(slots > 1.0)) return 1;  // also NaN: the CLI never passes it, a cast of it is undefined
  // 0.3 s at 10 Hz is 3.0000000000000004 slots: a product that is a whole number but for the
  // rounding of its factors must not gain a slot at exactly duration_s. The inputs carry a
  // relative error of ~1e-16 each, so 1e-12 separates rounding from a real fraction.
  const double nearest = std::round(slots);
  const double count = std::abs(slots - nearest) <= 1e-12 * nearest ? nearest : std::ceil(slots);
  return static_cast<uint64_t>(count);
}

uint64_t RepeatTally::rejected_total() const {
  uint64_t total = 0;
  for (std::size_t i = 1; i < rejected.size(); ++i) total += rejected[i];
  return total;
}

RepeatVerdict verdict(const RepeatTally& tally) {
  const auto& lead = tally.lead;
  if (lead && lead->result && *lead->result != CommandResult::accepted) {
    return RepeatVerdict::rejected;
  }
  if (tally.rejected_total() > 0) return RepeatVerdict::rejected;
  if (lead && lead->result != CommandResult::accepted) return RepeatVerdict::not_all_accepted;
  if (tally.sent > 0 && tally.send_failures == 0 && tally.accepted == tally.sent) {
    return RepeatVerdict::all_accepted;
  }
  return RepeatVerdict::not_all_accepted;
}

std::string repeat_summary(const RepeatTally& tally, const firmware::protocol::Command& command,
                           double rate_Hz) {
  std::ostringstream out;
  if (const auto& lead = tally.lead) {
    out << describe_command(lead->command) << ": "
        << (lead->result       ? result_name(*lead->result)
            : lead->unanswered ? std::string("unanswered")
            : lead->sent       ? std::string("no ack yet")
                               : std::string("not sent (transmit queue full or interface down)"))
        << "; ";
  }
  out << "sent " << tally.sent << ' ' << describe_command(command) << " frames at " << rate_Hz
      << " Hz: " << tally.accepted << " accepted, " << tally.rejected_total() << " rejected";
  if (tally.rejected_total() > 0) {
    const char* separator = " (";
    for (std::size_t i = 1; i < tally.rejected.size(); ++i) {
      if (tally.rejected[i] == 0) continue;
      out << separator << tally.rejected[i] << ' ' << result_name(CommandResult(i));
      separator = ", ";
    }
    out << ')';
  }
  out << ", " << tally.unanswered << " unanswered";
  if (tally.send_failures > 0) {
    out << ", " << tally.send_failures << " not sent (transmit queue full or interface down)";
  }
  if (tally.skipped > 0) out << ", " << tally.skipped << " skipped (the tool woke up late)";
  if (tally.stopped_after_s) {
    out << "; stopped after " << std::fixed << std::setprecision(3) << *tally.stopped_after_s
        << " s";
  }
  return out.str();
}

CommandRepeater::CommandRepeater(uint8_t node_id, const firmware::protocol::Command& command,
                                 uint8_t first_counter, const RepeatPlan& plan, SteadyTime start,
                                 const std::optional<firmware::protocol::Command>& lead)
    : node_id_(node_id),
      command_(command),
      message_id_(static_cast<uint8_t>(firmware::protocol::message_for(command.kind))),
      encoder_(node_id, first_counter),
      start_(start),
      rate_Hz_(plan.rate_Hz),
      ack_timeout_(from_seconds(plan.ack_timeout_s)) {
  tally_.planned = repeat_slot_count(plan.rate_Hz, plan.duration_s);
  if (lead) {
    tally_.lead.emplace();
    tally_.lead->command = *lead;
  }
}

SteadyTime CommandRepeater::slot_time(uint64_t slot) const {
  // From the start every time, never by adding periods: a period rounded to the clock's tick
  // would add its rounding error once per frame.
  return start_ + from_seconds(static_cast<double>(slot) / rate_Hz_);
}

std::optional<hal::CanFrame> CommandRepeater::frame_due(SteadyTime now) {
  expire(now);
  if (lead_due()) {
    if (now < start_) return std::nullopt;
    lead_tried_ = true;
    unreported_counter_ = encoder_.next_counter();
    return encoder_.encode(tally_.lead->command);
  }
  if (!slots_left() || now < slot_time(next_slot_)) return std::nullopt;
  // The latest slot already due. The arithmetic estimate saves stepping through every slot of a
  // long stall; slot_time(), which every other decision uses, settles the boundary.
  const uint64_t last = tally_.planned - 1;
  const double elapsed_slots = std::chrono::duration<double>(now - start_).count() * rate_Hz_;
  uint64_t slot = next_slot_;
  if (elapsed_slots >= static_cast<double>(last)) {
    slot = last;
  } else if (elapsed_slots > static_cast<double>(slot)) {
    slot = static_cast<uint64_t>(elapsed_slots);
  }
  while (slot < last && slot_time(slot + 1) <= now) ++slot;
  while (slot > next_slot_ && slot_time(slot) > now) --slot;
  tally_.skipped += slot - next_slot_;
  next_slot_ = slot + 1;
  unreported_counter_ = encoder_.next_counter();
  return encoder_.encode(command_);
}

void CommandRepeater::sent(SteadyTime now, bool queued) {
  if (!unreported_counter_) return;
  const uint8_t counter = *unreported_counter_;
  unreported_counter_.reset();
  if (tally_.lead && !tally_.lead->sent && !tally_.lead->send_failed) {  // it was the lead
    if (!queued) {
      tally_.lead->send_failed = true;
      stop(now);  // the drive was not enabled: nothing to keep alive
      return;
    }
    tally_.lead->sent = true;
    lead_counter_ = counter;
    lead_waiting_ = Waiting{true, now + ack_timeout_};
    return;
  }
  if (!queued) {
    ++tally_.send_failures;
    encoder_.set_next_counter(counter);  // it never reached the bus: the next frame reuses it
    return;
  }
  ++tally_.sent;
  Waiting& w = waiting_[counter];
  // Sixteen frames later the counter comes round again: an ack for the old frame would now be
  // taken for the new one's, so the old one has had its chance.
  if (w.active) give_up(w);
  w = Waiting{true, now + ack_timeout_};
}

void CommandRepeater::receive(SteadyTime now, const hal::CanFrame& frame) {
  expire(now);
  const std::optional<AckFrame> ack = decode_ack(frame, node_id_);
  if (ack && receive_lead(now, *ack)) return;
  if (!ack || ack->message_id != message_id_) return;
  Waiting& w = waiting_[ack->counter & 0x0F];
  // Not waiting: another host's frame, or an ack that came after its frame was given up.
  if (!w.active) return;
  w.active = false;
  const CommandResult result = ack->ack.result;
  if (result == CommandResult::accepted) {
    ++tally_.accepted;
  } else {
    ++tally_.rejected[static_cast<std::size_t>(result) & 0x0F];
  }
}

bool CommandRepeater::receive_lead(SteadyTime now, const AckFrame& ack) {
  if (!lead_waiting_.active || ack.counter != lead_counter_ ||
      ack.message_id != uint8_t(firmware::protocol::message_for(tally_.lead->command.kind))) {
    return false;
  }
  lead_waiting_.active = false;
  tally_.lead->result = ack.ack.result;
  if (ack.ack.result != CommandResult::accepted) stop(now);  // not enabled: stop feeding it
  return true;
}

void CommandRepeater::stop(SteadyTime now) {
  if (stopped_) return;
  if (next_slot_ < tally_.planned) {
    tally_.stopped_after_s = std::chrono::duration<double>(now - start_).count();
  }
  stopped_ = true;
}

bool CommandRepeater::finished(SteadyTime now) {
  expire(now);
  if (slots_left() || unreported_counter_ || lead_due() || lead_waiting_.active) return false;
  return std::none_of(waiting_.begin(), waiting_.end(), [](const Waiting& w) { return w.active; });
}

SteadyTime CommandRepeater::next_event() const {
  SteadyTime next = lead_due() ? start_ : slots_left() ? slot_time(next_slot_) : SteadyTime::max();
  if (lead_waiting_.active) next = std::min(next, lead_waiting_.deadline);
  for (const Waiting& w : waiting_) {
    if (w.active) next = std::min(next, w.deadline);
  }
  return next;
}

void CommandRepeater::expire(SteadyTime now) {
  if (lead_waiting_.active && now >= lead_waiting_.deadline) {
    lead_waiting_.active = false;  // the repetition goes on: the enable may have been obeyed
    tally_.lead->unanswered = true;
  }
  for (Waiting& w : waiting_) {
    if (w.active && now >= w.deadline) give_up(w);
  }
}

void CommandRepeater::give_up(Waiting& w) {
  w.active = false;
  ++tally_.unanswered;
}

}  // namespace imd::monitor
