// The supervise stage on hand-made measurements and estimates, with a fake CAN bus: the state
// transitions, the references through the speed ramp, the latching of faults, and commands.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "fakes.hpp"
#include "firmware/protocol/commands.hpp"
#include "firmware/supervisor.hpp"
#include "paper_motor.hpp"

namespace imd::firmware {
namespace {

using protocol::Command;
using protocol::CommandKind;
using Vec2 = control::Vec2<double>;

/// 50 rad/s and 0.2 Wb^2 at every tick.
struct Constant final : ReferenceSource<double> {
  Reference<double> at_tick(uint64_t) const noexcept override { return {50.0, 0.2, 0.0, 1.0}; }
};

/// A reference that differs at every tick (a sine, the flux stepping every 50 ticks), counting
/// how often it is read.
struct Varying final : ReferenceSource<double> {
  Reference<double> at_tick(uint64_t k) const noexcept override {
    ++reads;
    return {30.0 + 20.0 * std::sin(double(k) / 100.0), 0.2 + 0.01 * double((k / 50) % 3),
            5.0 * std::cos(double(k) / 70.0), 0.15};
  }
  mutable int reads = 0;
};

struct Bench {
  DriveConfig config;
  control::VoltageFedCoefficients coefficients;
  test::FakeCan can;
  test::FakeGpio gpio;
  Telemetry telemetry{1, 100'000, 100};
  Constant references;
  LawRegistry<double> laws;
  Magnetizer<double> magnetizer;
  Supervisor<double> supervisor;
  protocol::CommandEncoder host{1};
  Measurement<double> m;
  Estimate<double> e;

  static DriveConfig make_config(bool over_can, ControllerKind controller) {
    DriveConfig c;
    c.controller = controller;
    c.max_accel_rad_s2 = 1000.0;  // 0.1 rad/s per tick
    c.adc_calibration_ticks = 0;  // the offsets are nominal: idle at once
    c.auto_enable = !over_can;
    c.commands_over_can = over_can;
    return c;
  }
  explicit Bench(bool over_can = false, const ReferenceSource<double>* source = nullptr,
                 ControllerKind controller = ControllerKind::dsmc)
      : config(make_config(over_can, controller)),
        coefficients(control::discretize_voltage_fed(test::paper_motor(), 1e-4)),
        laws(LawContext{test::paper_motor(), config, coefficients}),
        magnetizer(test::paper_motor(), coefficients, config),
        supervisor(config, {&can, &gpio, telemetry}, source != nullptr ? source : &references,
                   &laws, &magnetizer, true, true) {
    m.valid = true;
    e.valid = true;
  }
  void flux(double flux_Wb) { e.x.flux_r_AB_Wb = e.x_input.flux_r_AB_Wb = Vec2(flux_Wb, 0.0); }
  void send(const Command& c) { can.inbox.push_back(host.encode(c)); }
};

TEST(Supervisor, MagnetizesUntilTheFluxReachesItsShareThenRuns) {
  Bench b;  // calibrated and auto-enabled: magnetizing from the start
  EXPECT_EQ(b.supervisor.state(), DriveState::magnetizing);
  b.flux(0.3);  // 0.09 Wb^2, below 0.95 x 0.2
  TickPlan<double> p = b.supervisor.plan(1, b.m, b.e);
  EXPECT_EQ(p.mode, Mode::magnetizing);
  EXPECT_TRUE(b.supervisor.supervised(1, p).magnetizing);
  EXPECT_EQ(b.supervisor.supervised(1, p).magnetizing_ticks, 1u);
  b.flux(std::sqrt(0.95 * 0.2) * (1 + 1e-9));  // just past 0.95 x 0.2 Wb^2
  p = b.supervisor.plan(2, b.m, b.e);
  EXPECT_EQ(b.supervisor.state(), DriveState::running);
  EXPECT_EQ(p.mode, Mode::controlling);
}

TEST(Supervisor, TheSpeedReachesTheLawThroughTheRamp) {
  Bench b;
  b.flux(0.3);
  b.e.x.omega_mech_rad_s = 2.0;
  b.supervisor.plan(1, b.m, b.e);  // magnetizing: the limited ramp starts at the estimate
  b.flux(0.45);
  const TickPlan<double> p = b.supervisor.plan(2, b.m, b.e);
  ASSERT_EQ(p.mode, Mode::controlling);
  // Each magnetizing tick restarts the ramp at the estimate; with the PWM latency the input
  // acts from the next step: now is one ramp step on, next two. The step is computed in the
  // design arithmetic (control/real.hpp): the acceleration, the period and their product round
  // by half an epsilon each, relative; the tick's sums add 1e-12 at most.
  const double step_rounding = 1.5 * std::numeric_limits<Real>::epsilon();
  EXPECT_NEAR(p.now.omega_mech_rad_s, 2.0 + 0.1, 0.1 * step_rounding + 1e-12);
  EXPECT_NEAR(p.next.omega_mech_rad_s, 2.0 + 0.2, 0.2 * step_rounding + 1e-12);
  EXPECT_EQ(p.next.flux2_Wb2, 0.2);
}

TEST(Supervisor, ADisableRampsToAStopThenTurnsThePwmOff) {
  Bench b(true);
  b.send({CommandKind::enable});
  b.supervisor.plan(1, b.m, b.e);
  b.flux(0.45);
  b.send({CommandKind::set_speed, 0.0f});
  b.supervisor.plan(2, b.m, b.e);
  ASSERT_EQ(b.supervisor.state(), DriveState::running);
  b.send({CommandKind::disable});
  b.e.x.omega_mech_rad_s = 5.0;  // still turning: the stop goes on
  TickPlan<double> p = b.supervisor.plan(3, b.m, b.e);
  EXPECT_EQ(b.supervisor.state(), DriveState::stopping);
  EXPECT_TRUE(p.stopping);
  b.e.x.omega_mech_rad_s = 0.5;  // below stop_speed_rad_s, and the ramp is at zero
  p = b.supervisor.plan(4, b.m, b.e);
  EXPECT_EQ(b.supervisor.state(), DriveState::idle);
  EXPECT_EQ(p.mode, Mode::off);
}

TEST(Supervisor, TheFirstFaultIsKeptAndEveryBitIsLatched) {
  Bench b;
  Trip first;
  first.add(FaultCode::phase_loss, 2);
  b.supervisor.latch(first, 10);
  Trip second;
  second.add(FaultCode::overcurrent, 1);
  b.supervisor.latch(second, 11);
  EXPECT_EQ(b.supervisor.state(), DriveState::fault);
  EXPECT_EQ(b.supervisor.status().first_fault, FaultCode::phase_loss);
  EXPECT_EQ(b.supervisor.status().fault_detail, 2);
  EXPECT_EQ(b.supervisor.status().first_fault_tick, 10u);
  EXPECT_EQ(b.supervisor.status().fault_bits,
            (1u << unsigned(FaultCode::phase_loss)) | (1u << unsigned(FaultCode::overcurrent)));
  int reports = 0;
  for (const hal::CanFrame& f : b.can.sent) {
    reports += f.id == protocol::can_id(1, protocol::MessageId::fault_report) ? 1 : 0;
  }
  EXPECT_EQ(reports, 1);  // one report, for the first fault
  EXPECT_EQ(b.supervisor.plan(12, b.m, b.e).mode, Mode::off);
}

TEST(Supervisor, AnEmergencyStopLatchesInTheTickItArrives) {
  Bench b(true);
  b.send({CommandKind::enable});
  b.send({CommandKind::emergency_stop});
  const TickPlan<double> p = b.supervisor.plan(1, b.m, b.e);
  EXPECT_EQ(b.supervisor.state(), DriveState::fault);
  EXPECT_EQ(b.supervisor.status().first_fault, FaultCode::emergency_stop);
  EXPECT_EQ(p.mode, Mode::off);
}

TEST(Supervisor, AControllerIsChosenOnlyAtRestAndOnlyIfItFollowsTheCommandedSpeed) {
  Bench b(true);
  b.send({CommandKind::select_controller, 1.0f});  // iol without its speed loop
  b.supervisor.plan(1, b.m, b.e);
  EXPECT_EQ(b.supervisor.status().controller, 0);  // refused: it would ignore set_speed
  b.send({CommandKind::select_controller, 7.0f});  // no such law
  b.supervisor.plan(2, b.m, b.e);
  EXPECT_EQ(b.supervisor.status().controller, 0);
  Bench local(false);  // a profile gives torque references: iol is allowed, once idle
  local.send({CommandKind::select_controller, 1.0f});
  local.supervisor.plan(1, local.m, local.e);
  EXPECT_EQ(local.supervisor.status().controller, 0);  // magnetizing: not at rest
}

TEST(Supervisor, TheSetFluxCommandSetsTheSelectedLawsFlux) {
  Bench b(true);
  b.send({CommandKind::set_flux, 0.3f});
  const TickPlan<double> p = b.supervisor.plan(1, b.m, b.e);  // idle: this tick's reference
  EXPECT_NEAR(p.next.flux2_Wb2, 0.3, 1e-7);
}

/// The same plan, bit for bit, from a supervisor that takes what prepare() made and from one
/// that makes it itself.
void expect_same_plan(const TickPlan<double>& a, const TickPlan<double>& b, uint64_t k) {
  ASSERT_EQ(a.mode, b.mode) << k;
  ASSERT_EQ(a.stopping, b.stopping) << k;
  ASSERT_EQ(a.restarted, b.restarted) << k;
  for (const auto& [x, y] :
       {std::pair{a.now, b.now}, std::pair{a.next, b.next}, std::pair{a.ahead, b.ahead}}) {
    ASSERT_EQ(x.omega_mech_rad_s, y.omega_mech_rad_s) << k;
    ASSERT_EQ(x.flux2_Wb2, y.flux2_Wb2) << k;
    ASSERT_EQ(x.torque_Nm, y.torque_Nm) << k;
    ASSERT_EQ(x.stator_flux2_Wb2, y.stator_flux2_Wb2) << k;
  }
}

class SupervisorReadAhead : public testing::TestWithParam<ControllerKind> {};

// The DSMC looks no further than the next step; the IOL a PWM period ahead (its `ahead`).
TEST_P(SupervisorReadAhead, ThePlanMadeAfterTheWriteIsTheOneThePlanWouldMake) {
  Varying ahead_source, direct_source;
  Bench ahead(false, &ahead_source, GetParam()), direct(false, &direct_source, GetParam());
  int taken = 0, running = 0;
  for (uint64_t k = 1; k <= 3000; ++k) {
    for (Bench* b : {&ahead, &direct}) {
      b->flux(k < 20 ? 0.3 : 0.45);  // magnetizing, then running
      b->e.x.omega_mech_rad_s = 0.01 * double(k);
    }
    const int reads = ahead_source.reads;
    const TickPlan<double> a = ahead.supervisor.plan(k, ahead.m, ahead.e);
    const TickPlan<double> d = direct.supervisor.plan(k, direct.m, direct.e);
    expect_same_plan(a, d, k);
    if (ahead.supervisor.state() == DriveState::running) {
      ++running;
      if (ahead_source.reads == reads) ++taken;
    }
    ahead.supervisor.prepare(k);  // after the write
  }
  // Every running tick after the first took the references read ahead (the first was planned
  // while magnetizing, when the ramp restarts at the estimate).
  EXPECT_EQ(ahead.supervisor.state(), DriveState::running);
  EXPECT_GT(running, 2900);
  EXPECT_EQ(taken, running - 1);
}

INSTANTIATE_TEST_SUITE_P(Laws, SupervisorReadAhead,
                         testing::Values(ControllerKind::dsmc, ControllerKind::iol));

TEST(Supervisor, ACommandOrAFaultAfterTheReadAheadIsNotMissed) {
  Bench ahead(true), direct(true);
  uint64_t k = 1;
  const auto tick = [&](std::initializer_list<Command> commands) {
    for (Bench* b : {&ahead, &direct}) {
      for (const Command& c : commands) b->send(c);
    }
    const TickPlan<double> a = ahead.supervisor.plan(k, ahead.m, ahead.e);
    const TickPlan<double> d = direct.supervisor.plan(k, direct.m, direct.e);
    expect_same_plan(a, d, k);
    ahead.supervisor.prepare(k);
    ++k;
    return a;
  };
  tick({{CommandKind::enable}});
  for (Bench* b : {&ahead, &direct}) b->flux(0.45);
  tick({{CommandKind::set_speed, 20.0f}});
  for (int n = 0; n < 50; ++n) tick({});
  ASSERT_EQ(ahead.supervisor.state(), DriveState::running);
  // A new speed between the read-ahead and the plan: the ramp turns towards it at once.
  const double before = tick({}).next.omega_mech_rad_s;
  const TickPlan<double> turned = tick({{CommandKind::set_speed, -20.0f}});
  EXPECT_LT(turned.next.omega_mech_rad_s, before);
  for (int n = 0; n < 20; ++n) tick({});
  // A fault latched after the read-ahead whose stop is a ramp (SS1): the drive stops on the
  // stop's ramp from the next plan on, not on the speed read ahead.
  Trip trip;
  trip.add(FaultCode::command_timeout);
  for (Bench* b : {&ahead, &direct}) b->supervisor.latch(trip, k - 1);
  ASSERT_EQ(ahead.supervisor.state(), DriveState::stopping);
  ASSERT_EQ(ahead.supervisor.status().stop, StopCategory::ss1);
  const TickPlan<double> stopping = tick({});
  EXPECT_TRUE(stopping.stopping);
  for (int n = 0; n < 20; ++n) tick({});
  EXPECT_EQ(ahead.supervisor.state(), direct.supervisor.state());
}

}  // namespace
}  // namespace imd::firmware
