// Each fault the simulated board can suffer, by its physical effect, and its CAN queues.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "control/svpwm.hpp"
#include "hal_sim/fault_injection.hpp"
#include "hal_sim/sensor_models.hpp"
#include "hal_sim/sim_board.hpp"
#include "hal_sim/sim_can_host.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

const control::MotorParameters& seed000() {
  static const control::MotorParameters motor = test::test_motors()[0].parameters;
  return motor;
}

/// A tick handler that records what the firmware sees each tick (ADC sample, encoder count,
/// execution-clock reads) and, if asked, drives the PWM: fixed duties, or an open-loop rotating
/// voltage amplitude_V at frequency_Hz through SVPWM.
struct Probe final : hal::TickHandler {
  SimBoard& board;
  bool drive_pwm = false;
  hal::PhaseDuties duty{0.5f, 0.5f, 0.5f};
  double amplitude_V = 0.0, frequency_Hz = 0.0;
  int clock_reads = 0;
  std::vector<hal::AdcSample> samples;
  std::vector<uint32_t> counts;
  std::vector<std::vector<uint32_t>> clock_ns;
  explicit Probe(SimBoard& b) : board(b) { board.timer().start(*this); }
  void on_tick() noexcept override {
    std::vector<uint32_t> reads;
    for (int i = 0; i < clock_reads; ++i) reads.push_back(board.timer().execution_counts());
    clock_ns.push_back(reads);
    samples.push_back(board.adc().sample());
    counts.push_back(board.encoder().count());
    if (amplitude_V > 0.0) {
      const double angle = 2.0 * std::numbers::pi * frequency_Hz *
                           static_cast<double>(board.timer().tick_count()) *
                           board.config().period_s;
      const auto pwm = control::svpwm<double>(amplitude_V * Vec2(std::cos(angle), std::sin(angle)),
                                              board.v_bus_V());
      duty = {float(pwm.duty[0]), float(pwm.duty[1]), float(pwm.duty[2])};
    }
    if (drive_pwm || amplitude_V > 0.0) {
      board.pwm().set_duties(duty);
      board.pwm().enable();
    }
  }
};

/// The current the ADC reports on a phase (no offset configured).
double measured_A(const hal::AdcScale& scale, const hal::AdcSample& sample, int phase) {
  return (sample.phase_code[phase] - scale.phase_mid_code) * double(scale.phase_A_per_code);
}

control::PhaseValues<double> phase_currents_A(const SimBoard& board) {
  return control::inverse_clarke(board.plant().state().i_s_alphabeta_A);
}

TEST(FaultKind, NamesRoundTrip) {
  for (int k = 0; k < kFaultKindCount; ++k) {
    const auto kind = static_cast<FaultKind>(k);
    EXPECT_EQ(parse_fault_kind(fault_kind_name(kind)), kind) << fault_kind_name(kind);
  }
  EXPECT_STREQ(fault_kind_name(FaultKind::encoder_loss), "encoder_loss");
  EXPECT_EQ(parse_fault_kind("meltdown"), std::nullopt);
  EXPECT_EQ(parse_fault_kind("Overcurrent"), std::nullopt);
}

TEST(SimBoardFaults, OvercurrentSurgeAppearsInTheNextAdcSample) {
  const double surge_A = 6.0;
  for (int phase = 0; phase < 3; ++phase) {
    SimBoard board(seed000(), {});
    Probe probe(board);
    PlantState s;
    s.i_s_alphabeta_A = {1.0, -0.5};
    board.plant().set_state(s);
    const auto before_A = phase_currents_A(board);
    ASSERT_TRUE(board.inject({.kind = FaultKind::overcurrent, .surge_A = surge_A, .phase = phase}));
    board.run_tick();
    ASSERT_EQ(probe.samples.size(), 1u);
    // Along phase k's axis the surge adds surge_A to phase k and -surge_A/2 to the two others
    // (their sum stays zero). With neither noise nor offset, the reading is off by at most
    // half an LSB of quantization.
    const double half_lsb_A = 0.5 * 20.0 / 4096;
    for (int p = 0; p < 3; ++p) {
      const double expected_A = before_A[p] + (p == phase ? surge_A : -0.5 * surge_A);
      EXPECT_NEAR(measured_A(board.adc().scale(), probe.samples[0], p), expected_A,
                  half_lsb_A + 1e-12)
          << "surge on phase " << phase << ", phase " << p;
    }
  }
}

TEST(SimBoardFaults, BusFaultsChangeTheMeasuredAndAppliedBus) {
  const double volts_per_code = 500.0 / 4096;
  for (const auto& [kind, bus_V] :
       {std::pair{FaultKind::overvoltage, 420.0}, std::pair{FaultKind::undervoltage, 180.0}}) {
    SimBoardConfig config;
    config.pwm_latency_ticks = 0;  // the duties of a tick act in that tick
    SimBoard board(seed000(), config);
    Probe probe(board);
    probe.drive_pwm = true;
    probe.duty = {0.7f, 0.4f, 0.4f};
    board.run_tick();
    EXPECT_EQ(probe.samples[0].bus_code, std::lround(311.0 / volts_per_code));
    ASSERT_TRUE(board.inject({.kind = kind, .bus_V = bus_V}));
    EXPECT_EQ(board.v_bus_V(), bus_V);
    board.run_tick();
    // Same arithmetic as the converter and the inverter model: exact.
    EXPECT_EQ(probe.samples[1].bus_code, std::lround(bus_V / volts_per_code));
    EXPECT_EQ(board.applied_voltage_V(), inverter_output_V(probe.duty, bus_V));
    EXPECT_EQ(board.config().v_bus_V, 311.0);  // the nominal bus is unchanged
  }
}

TEST(SimBoardFaults, EncoderLossFreezesTheCount) {
  SimBoard board(seed000(), {});  // PWM off: no torque, and seed000 has no friction: it coasts
  Probe probe(board);
  PlantState s;
  s.omega_mech_rad_s = 100.0;  // 0.01 rad = 13 counts per tick
  board.plant().set_state(s);
  board.run_tick();
  board.run_tick();
  ASSERT_NE(probe.counts[1], probe.counts[0]);
  ASSERT_TRUE(board.inject({.kind = FaultKind::encoder_loss}));
  for (int k = 0; k < 100; ++k) board.run_tick();
  for (std::size_t k = 2; k < probe.counts.size(); ++k) ASSERT_EQ(probe.counts[k], probe.counts[1]);
  // Meanwhile the rotor turned 1 rad, 1304 counts.
  const uint32_t true_count = encoder_count(board.plant().state().theta_mech_rad, 8192);
  EXPECT_GT(static_cast<int32_t>(true_count - probe.counts[1]), 1000);
}

TEST(SimBoardFaults, StuckAdcRepeatsItsLastConversion) {
  SimBoardConfig config;
  config.adc.noise_A = 0.1;  // 20 LSB: with the seed fixed, every conversion differs
  config.adc.bus_noise_V = 1.0;
  SimBoard board(seed000(), config);
  Probe probe(board);
  const auto same = [](const hal::AdcSample& a, const hal::AdcSample& b) {
    return a.phase_code == b.phase_code && a.bus_code == b.bus_code;
  };
  for (int k = 0; k < 10; ++k) board.run_tick();
  for (int k = 1; k < 10; ++k) ASSERT_FALSE(same(probe.samples[k], probe.samples[k - 1]));
  ASSERT_TRUE(board.inject({.kind = FaultKind::adc_stuck}));
  for (int k = 0; k < 50; ++k) board.run_tick();
  for (std::size_t k = 10; k < probe.samples.size(); ++k) {
    ASSERT_TRUE(same(probe.samples[k], probe.samples[9])) << "tick " << k;
  }
}

TEST(SimBoardFaults, PhaseLossHoldsThatPhaseCurrentAtZero) {
  for (int open = 0; open < 3; ++open) {
    SimBoard board(seed000(), {});
    Probe probe(board);
    probe.amplitude_V = 100.0;  // open-loop 100 V, 25 Hz: a few amperes at standstill
    probe.frequency_Hz = 25.0;
    for (int k = 0; k < 500; ++k) board.run_tick();
    ASSERT_GT(board.plant().state().i_s_alphabeta_A.norm(), 0.5);
    ASSERT_TRUE(board.inject({.kind = FaultKind::phase_loss, .phase = open}));
    const std::size_t first = probe.samples.size();
    double open_max_A = std::abs(phase_currents_A(board)[open]), other_max_A = 0.0;
    for (int k = 0; k < 2000; ++k) {  // 0.2 s, five periods of the supply
      board.run_tick();
      const auto i_A = phase_currents_A(board);
      open_max_A = std::max(open_max_A, std::abs(i_A[open]));
      other_max_A = std::max(other_max_A, std::abs(i_A[(open + 1) % 3]));
      // The two closed phases form one loop, b = -c: the three sum to zero, the open one is ~0.
      ASSERT_NEAR(i_A[(open + 1) % 3], -i_A[(open + 2) % 3], 1e-9);
    }
    // Every stage of dI/dt is projected off the open axis, so the open phase's current only
    // collects rounding: ~eps |I| per RK4 stage, 8e4 stages of a few amperes, < 1e-10 A.
    EXPECT_LT(open_max_A, 1e-9) << "open phase " << open;
    EXPECT_GT(other_max_A, 0.5) << "open phase " << open;
    for (std::size_t k = first; k < probe.samples.size(); ++k) {
      ASSERT_EQ(probe.samples[k].phase_code[open], 2048) << "tick " << k;  // far below LSB/2
    }
  }
}

TEST(PlantOpenPhase, ProjectionOfTheDerivativeAndItsRemoval) {
  InductionMotorPlant plant(seed000(), {});
  InductionMotorPlant::StateVector x;
  x << 0.5, 0.1, 2.0, -1.0, 100.0, 0.3;
  const Vec2 u_V(120.0, -40.0);
  const auto closed = plant.voltage_fed_derivative(x, u_V, 0.5);
  plant.set_open_phase(1);
  const auto open = plant.voltage_fed_derivative(x, u_V, 0.5);
  // Only dI/dt changes, by its component on phase b's axis; what is left has none, to a few
  // ulps of |dI/dt| (the axis has unit norm to an ulp).
  EXPECT_EQ(open.segment<2>(0), closed.segment<2>(0));
  EXPECT_EQ(open.segment<2>(4), closed.segment<2>(4));
  const Vec2 di = open.segment<2>(2);
  EXPECT_LT(std::abs(phase_axis(1).dot(di)), 1e-14 * closed.segment<2>(2).norm());
  const Vec2 removed = closed.segment<2>(2) - di;
  EXPECT_LT(std::abs(removed.x() * phase_axis(1).y() - removed.y() * phase_axis(1).x()),
            1e-14 * closed.segment<2>(2).norm());  // removed along the axis only
  plant.set_open_phase(std::nullopt);
  EXPECT_EQ(plant.voltage_fed_derivative(x, u_V, 0.5), closed);  // the model (1) again, bit for bit
}

TEST(PlantOpenPhase, AnalogFeedbackStepsKeepTheOpenPhaseAtZero) {
  InductionMotorPlant plant(seed000(), {1e-4, 10});
  PlantState s;
  s.flux_r_alphabeta_Wb = {0.5, 0.1};
  s.i_s_alphabeta_A = {2.0, -1.0};
  s.omega_mech_rad_s = 100.0;
  plant.set_state(s);
  plant.set_open_phase(2);  // projects the present current at once
  EXPECT_LT(std::abs(phase_axis(2).dot(plant.state().i_s_alphabeta_A)), 1e-15);
  double open_max_A = 0.0, other_max_A = 0.0;
  for (int k = 0; k < 1000; ++k) {
    plant.step_analog_feedback({40.0, 60.0}, 0.2);
    const auto i_A = control::inverse_clarke(plant.state().i_s_alphabeta_A);
    open_max_A = std::max(open_max_A, std::abs(i_A[2]));
    other_max_A = std::max(other_max_A, std::abs(i_A[0]));
  }
  EXPECT_LT(open_max_A, 1e-9);  // rounding only, as in the board test above
  EXPECT_GT(other_max_A, 0.1);
}

TEST(SimBoardFaults, TwoOpenPhasesLeaveNoCurrentPath) {
  SimBoard board(seed000(), {});
  Probe probe(board);
  probe.amplitude_V = 100.0;
  probe.frequency_Hz = 25.0;
  for (int k = 0; k < 500; ++k) board.run_tick();
  ASSERT_TRUE(board.inject({.kind = FaultKind::phase_loss, .phase = 0}));
  for (int k = 0; k < 100; ++k) board.run_tick();
  ASSERT_GT(board.plant().state().i_s_alphabeta_A.norm(), 0.5);  // b and c still carry current
  ASSERT_TRUE(board.inject({.kind = FaultKind::phase_loss, .phase = 2}));
  EXPECT_EQ(board.plant().open_phases(), 0b101u);
  for (int k = 0; k < 500; ++k) {
    board.run_tick();
    ASSERT_EQ(board.plant().state().i_s_alphabeta_A, Vec2::Zero()) << "tick " << k;  // exactly
  }
}

TEST(SimBoardFaults, OverrunStallsTheExecutionClockInsideEachTick) {
  SimBoard board(seed000(), {});
  Probe probe(board);
  probe.clock_reads = 3;
  // A stall of 0.5 s: the host's own time between two reads is far below it (a descheduling
  // that long would be needed to break the bounds below).
  const uint64_t stall_ns = 500'000'000;
  board.run_tick();
  ASSERT_TRUE(board.inject({.kind = FaultKind::overrun, .stall_us = 5e5}));
  board.run_tick();
  board.run_tick();
  const uint32_t after_ns = board.timer().execution_counts();
  const auto& reads = probe.clock_ns;
  EXPECT_LT(reads[0][1] - reads[0][0], stall_ns);  // before the fault: host time only
  for (int tick = 1; tick <= 2; ++tick) {
    const uint64_t first_to_second = reads[tick][1] - reads[tick][0];
    EXPECT_GE(first_to_second, stall_ns) << "tick " << tick;
    EXPECT_LT(first_to_second - stall_ns, stall_ns) << "tick " << tick;
    EXPECT_LT(reads[tick][2] - reads[tick][1], stall_ns) << "once per tick, not per read";
  }
  // The clock never runs backwards: the stolen time stays passed. It wraps at 2^32 ns (4.3 s),
  // so "later" means a forward difference below 2^31.
  const auto forward = [](uint32_t from, uint32_t to) { return uint32_t(to - from) < (1u << 31); };
  EXPECT_TRUE(forward(reads[0][2], reads[1][0]));
  EXPECT_TRUE(forward(reads[1][2], reads[2][0]));
  EXPECT_TRUE(forward(reads[2][2], after_ns));
  EXPECT_EQ(board.timer().tick_count(), 3u);
}

TEST(SimBoardFaults, CanSilenceDropsFramesForTheFirmwareOnly) {
  SimBoard board(seed000(), {});
  hal::CanFrame frame;
  frame.id = 0x27;
  frame.length = 2;
  ASSERT_TRUE(board.can_side().inject(frame));
  ASSERT_TRUE(board.inject({.kind = FaultKind::can_silence}));
  frame.id = 0x28;
  for (int k = 0; k < 3; ++k) EXPECT_FALSE(board.can_side().inject(frame));
  EXPECT_EQ(board.can_side().dropped_frames(), 3u);
  hal::CanFrame received;
  ASSERT_TRUE(board.can().try_receive(received));  // it arrived before the silence
  EXPECT_EQ(received.id, 0x27);
  EXPECT_FALSE(board.can().try_receive(received));
  EXPECT_TRUE(board.can().try_send(frame));  // the firmware still talks
  hal::CanFrame sent;
  ASSERT_TRUE(board.can_side().take_sent(sent));
  EXPECT_EQ(sent.id, 0x28);
  EXPECT_FALSE(board.can_side().take_sent(sent));
}

TEST(SimBoardCan, QueuesHoldKQueueDepthFramesEachWayInOrder) {
  SimCan can;
  hal::CanFrame frame;
  for (uint16_t id = 0; id < SimCan::kQueueDepth; ++id) {
    frame.id = id;
    ASSERT_TRUE(can.try_send(frame)) << id;
    ASSERT_TRUE(can.inject(frame)) << id;
  }
  EXPECT_FALSE(can.try_send(frame));    // full: the firmware's frame is not queued
  EXPECT_FALSE(can.inject(frame));      // full: the host's frame is lost
  EXPECT_EQ(can.dropped_frames(), 0u);  // counts the silence only
  const std::vector<hal::CanFrame> sent = take_all_sent(can);
  ASSERT_EQ(sent.size(), SimCan::kQueueDepth);
  for (uint16_t id = 0; id < SimCan::kQueueDepth; ++id) {
    EXPECT_EQ(sent[id].id, id);
    ASSERT_TRUE(can.try_receive(frame));
    EXPECT_EQ(frame.id, id);
  }
  EXPECT_FALSE(can.try_receive(frame));
  EXPECT_TRUE(can.try_send(frame));  // room again
}

TEST(SimBoardFaults, InjectRefusesParametersOutOfRangeAndChangesNothing) {
  SimBoard board(seed000(), {});
  struct Case {
    FaultInjection fault;
    const char* message;
  };
  const Case cases[] = {
      {{.kind = FaultKind::overcurrent}, "overcurrent: surge_A must be > 0 and finite"},  // NaN
      {{.kind = FaultKind::overcurrent, .surge_A = std::numeric_limits<double>::infinity()},
       "overcurrent: surge_A must be > 0 and finite"},
      {{.kind = FaultKind::overcurrent, .surge_A = 2.0, .phase = 3},
       "overcurrent: phase must be 0, 1 or 2"},
      {{.kind = FaultKind::phase_loss, .phase = -1}, "phase_loss: phase must be 0, 1 or 2"},
      {{.kind = FaultKind::undervoltage, .bus_V = -1.0},
       "undervoltage: bus_V must be > 0 and finite"},
      {{.kind = FaultKind::overvoltage}, "overvoltage: bus_V must be > 0 and finite"},
      {{.kind = FaultKind::overrun, .stall_us = 0.0},
       "overrun: stall_us must be > 0 and below 1e9"},
      {{.kind = FaultKind::overrun, .stall_us = 1e9},
       "overrun: stall_us must be > 0 and below 1e9"},
  };
  const PlantState before = board.plant().state();
  for (const Case& c : cases) {
    EXPECT_FALSE(board.inject(c.fault)) << c.message;
    const char* message = fault_parameter_error(c.fault);
    ASSERT_NE(message, nullptr) << c.message;
    EXPECT_STREQ(message, c.message);
  }
  EXPECT_EQ(board.injected_count(), 0u);
  EXPECT_EQ(board.plant().state().i_s_alphabeta_A, before.i_s_alphabeta_A);
  EXPECT_EQ(board.plant().open_phases(), 0u);
  EXPECT_EQ(board.v_bus_V(), board.config().v_bus_V);

  EXPECT_EQ(fault_parameter_error({.kind = FaultKind::encoder_loss}), nullptr);
  ASSERT_TRUE(board.inject({.at_s = 0.1, .kind = FaultKind::encoder_loss}));
  ASSERT_TRUE(board.inject({.at_s = 0.2, .kind = FaultKind::adc_stuck}));
  EXPECT_EQ(board.injected_count(), 2u);
  EXPECT_TRUE(board.encoder_frozen());
  EXPECT_TRUE(board.adc_stuck());
}

}  // namespace
}  // namespace imd::sim
