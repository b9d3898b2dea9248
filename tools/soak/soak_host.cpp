#include "tools/soak/soak_host.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "control/motor_parameters.hpp"
#include "firmware/drive_state.hpp"
#include "firmware/protocol/commands.hpp"
#include "firmware/protocol/e2e.hpp"
#include "firmware/protocol/frame_codec.hpp"

namespace imd::soak {
namespace {

using firmware::DriveState;
using firmware::protocol::MessageId;

/// The code each injected kind must be detected as.
const char* expected_code(sim::FaultKind kind) noexcept {
  switch (kind) {
    case sim::FaultKind::overcurrent: return "overcurrent";
    case sim::FaultKind::overvoltage: return "bus_overvoltage";
    case sim::FaultKind::undervoltage: return "bus_undervoltage";
    case sim::FaultKind::encoder_loss: return "encoder";
    case sim::FaultKind::adc_stuck: return "adc_stuck";
    case sim::FaultKind::phase_loss: return "phase_loss";
    case sim::FaultKind::overrun: return "overrun";
    case sim::FaultKind::can_silence: return "command_timeout";
  }
  return "";
}

}  // namespace

SoakHost::SoakHost(const sim::Scenario& s, uint64_t seed) : s_(s), rng_(seed) {
  const control::MotorParameters& m = s.motor;
  flux2_Wb2_ = s.controller == "iol" ? s.stator_flux2_Wb2 : s.flux2_Wb2;
  const double rotor_flux2 =
      s.controller == "iol" ? std::pow(m.Lm_H / m.Ls_H, 2) * s.stator_flux2_Wb2 : s.flux2_Wb2;
  // Base speed: the no-load voltage at the flux reaches 0.95 v_bus / sqrt(3).
  const double v_max = 0.95 * s.v_bus_V / std::sqrt(3.0), i_d = std::sqrt(rotor_flux2) / m.Lm_H;
  base_speed_rad_s_ =
      std::sqrt(std::pow(v_max / i_d, 2) - m.Rs_Ohm * m.Rs_Ohm) / m.Ls_H / m.pole_pairs;
  const double i_lim = 0.95 * s.i_max_A;
  torque_limit_Nm_ = 1.5 * m.pole_pairs * m.Lm_H / m.Lr_H * std::sqrt(rotor_flux2) *
                     std::sqrt(std::max(i_lim * i_lim - i_d * i_d, 0.0));
  overspeed_rad_s_ = s.protection.overspeed_rad_s.value_or(400.0);
  // The trip, plus what one tick of the whole bus across the leakage inductance adds before
  // the PWM goes off.
  overcurrent_A_ = s.protection.overcurrent_A.value_or(1.5 * s.i_max_A) +
                   s.sample_period_s * s.v_bus_V / control::derive_voltage_fed(m).sigma_H;
}

bool SoakHost::modulating(const firmware::DriveStatus& status) noexcept {
  return status.state == DriveState::magnetizing || status.state == DriveState::running ||
         status.state == DriveState::stopping;
}

void SoakHost::send(sim::SimBoard& board, MessageId id, float value, bool valid) {
  hal::CanFrame frame = firmware::protocol::encode_frame(uint8_t(s_.can_node_id), id,
                                                         {0.0f, 0.0f, value});
  firmware::protocol::e2e_protect(frame.id, frame.data, frame.length, counter_);
  if (valid) counter_ = uint8_t((counter_ + 1) & 0x0F);
  board.can_side().inject(frame);
}

void SoakHost::send_invalid(sim::SimBoard& board) {
  hal::CanFrame frame = firmware::protocol::encode_frame(uint8_t(s_.can_node_id),
                                                         MessageId::set_speed,
                                                         {0.0f, 0.0f, float(speed_ref_rad_s_)});
  firmware::protocol::e2e_protect(frame.id, frame.data, frame.length, counter_);
  switch (std::uniform_int_distribution<int>(0, 4)(rng_)) {
    case 0: frame.data[0] ^= 0x5A; break;  // bad CRC
    case 1: frame.length = 3; break;        // wrong length
    case 2:  // the last counter again
      firmware::protocol::e2e_protect(frame.id, frame.data, frame.length,
                                      uint8_t((counter_ + 15) & 0x0F));
      break;
    case 3:  // beyond the overspeed limit, properly protected
      firmware::protocol::set_physical(
          frame.data, firmware::protocol::message(MessageId::set_speed).signals[2],
          float(3.0 * overspeed_rad_s_));
      firmware::protocol::e2e_protect(frame.id, frame.data, frame.length, counter_);
      counter_ = uint8_t((counter_ + 1) & 0x0F);
      break;
    default:  // a message id the drive does not know
      frame.id = firmware::protocol::can_id(uint8_t(s_.can_node_id), MessageId(0x1E));
      break;
  }
  board.can_side().inject(frame);
  ++counts_.invalid_frames;
}

void SoakHost::violation(double t_s, const std::string& what) {
  ++counts_.violations;
  if (violations_.size() < 20) violations_.push_back(fmt::format("{:.4f} s: {}", t_s, what));
}

void SoakHost::before_tick(uint64_t, double t_s, sim::SimBoard& board,
                           const firmware::DriveStatus& status) {
  t_s_ = t_s;
  // As a host does from the heartbeat's command_counter: frames lost in a silence moved the
  // host's counter beyond the step the drive accepts; take up from the drive's.
  if (((counter_ - status.command_counter) & 0x0F) > firmware::protocol::kMaxCounterStep) {
    counter_ = uint8_t((status.command_counter + 1) & 0x0F);
  }
  if (!repaired_ && t_s >= repair_at_s_) {
    board.repair(fault_);
    repaired_ = true;
  }
  const bool faulted = status.fault_bits != 0;
  if (faulted && phase_ == Phase::running) {
    violation(t_s, fmt::format("{} latched with no cause", firmware::fault_name(status.first_fault)));
    phase_ = Phase::waiting_clear;
    phase_until_s_ = t_s + 0.3;
  }
  if (phase_ == Phase::waiting_fault) {
    if (faulted) {
      const char* code = firmware::fault_name(status.first_fault);
      if (std::string(code) != expected_code_) {
        violation(t_s, fmt::format("{} injected, {} latched", expected_code_, code));
      } else {
        ++counts_.detected;
      }
      phase_ = Phase::waiting_clear;
      phase_until_s_ = t_s + 0.2;
    } else if (t_s > phase_until_s_) {
      violation(t_s, fmt::format("{} not detected within 1 s", expected_code_));
      phase_ = Phase::waiting_clear;
      phase_until_s_ = t_s;
    }
  }
  if (phase_ == Phase::waiting_clear && t_s >= phase_until_s_ && repaired_ &&
      status.state != DriveState::stopping) {  // a fault's controlled stop runs to its end
    if (faulted) send(board, MessageId::clear_faults, 0.0f);
    phase_ = Phase::running;
    expecting_ = false;
    enable_at_s_ = t_s + 0.1;
    next_segment_s_ = t_s + 0.5;
  }
  // The watchdog fed in every phase: a slow detection must not turn into a command_timeout.
  if (modulating(status) && t_s >= next_keepalive_s_) {
    send(board, MessageId::set_speed, float(speed_ref_rad_s_));
    next_keepalive_s_ = t_s + 0.05;
  }
  if (phase_ != Phase::running) return;
  if (status.state == DriveState::idle && t_s >= enable_at_s_) {  // (again, if refused)
    send(board, MessageId::enable, 0.0f);
    enable_at_s_ = t_s + 0.5;
    next_keepalive_s_ = t_s + 0.01;
  }
  if (t_s >= next_segment_s_) start_segment(t_s, board, status);
}

void SoakHost::start_segment(double t_s, sim::SimBoard& board,
                             const firmware::DriveStatus& status) {
  ++counts_.segments;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  next_segment_s_ = t_s + 0.5 + 3.5 * unit(rng_);
  const double action = unit(rng_);
  const bool running = status.state == DriveState::running;
  const bool fast = std::abs(board.plant().state().omega_mech_rad_s) > 10.0;
  if (action < 0.3 || (action >= 0.78 && !(running && fast))) {
    speed_ref_rad_s_ = (2.0 * unit(rng_) - 1.0) * 0.8 * base_speed_rad_s_;
    send(board, MessageId::set_speed, float(speed_ref_rad_s_));
    ++counts_.speed;
  } else if (action < 0.4) {
    send(board, MessageId::set_flux, float((0.6 + 0.4 * unit(rng_)) * flux2_Wb2_));
    ++counts_.flux;
  } else if (action < 0.6) {
    sim::LoadProfile load;
    load.value_Nm = (2.0 * unit(rng_) - 1.0) * 0.5 * torque_limit_Nm_;
    board.set_load_profile(load);
    ++counts_.load;
  } else if (action < 0.7) {
    for (int i = 0; i < 5; ++i) send_invalid(board);
  } else if (action < 0.76) {
    send(board, MessageId::disable, 0.0f);
    enable_at_s_ = t_s + 0.5 + unit(rng_);
    ++counts_.disables;
  } else if (action < 0.78) {
    send(board, MessageId::emergency_stop, 0.0f);
    expecting_ = true;
    surge_ = false;
    expected_code_ = "emergency_stop";
    phase_ = Phase::waiting_fault;
    phase_until_s_ = t_s + 1.0;
    ++counts_.emergency_stops;
  } else {  // a fault of the board, while every check can see it
    sim::FaultInjection f;
    f.at_s = t_s;
    f.kind = sim::FaultKind(std::uniform_int_distribution<int>(0, sim::kFaultKindCount - 1)(rng_));
    f.surge_A = 3.0 * s_.i_max_A;  // past the 1.5 i_max trip whatever the phase carries
    f.phase = std::uniform_int_distribution<int>(0, 2)(rng_);
    f.bus_V = f.kind == sim::FaultKind::overvoltage ? 1.45 * s_.v_bus_V : 0.5 * s_.v_bus_V;
    f.stall_us = 2.5e6;  // 2.5 x the soak's tick budget (soak.cpp), within the 32-bit ns clock
    f.until_s = t_s + 0.3;
    if (!board.inject(f)) {
      violation(t_s, "the board refused a fault");
      return;
    }
    fault_ = f;
    repaired_ = false;
    repair_at_s_ = f.until_s;
    expecting_ = true;
    surge_ = f.kind == sim::FaultKind::overcurrent;
    expected_code_ = expected_code(f.kind);
    phase_ = Phase::waiting_fault;
    phase_until_s_ = t_s + 1.0;
    ++counts_.faults;
    ++counts_.faults_by_kind[int(f.kind)];
  }
}

void SoakHost::after_tick(const sim::SimRow& row) {
  const double values[] = {row.omega_mech_rad_s, row.omega_est_rad_s, row.flux2_Wb2,
                           row.flux2_est_Wb2,   row.i_alpha_A,       row.i_beta_A,
                           row.v_alpha_V,       row.v_beta_V,        row.load_est_Nm};
  for (const double v : values) {
    if (!std::isfinite(v)) {
      violation(row.t_s, "a value of the plant or the drive is not finite");
      return;
    }
  }
  if (std::abs(row.omega_mech_rad_s) > 1.5 * overspeed_rad_s_) {
    violation(row.t_s, fmt::format("speed {:.1f} rad/s", row.omega_mech_rad_s));
  }
  const bool surge = expecting_ && surge_;
  const double i_A = std::hypot(row.i_alpha_A, row.i_beta_A);
  if (!surge && i_A > overcurrent_A_) violation(row.t_s, fmt::format("current {:.2f} A", i_A));
}

}  // namespace imd::soak
