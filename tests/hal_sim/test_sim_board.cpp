// The simulated board's realism, each switch on its own: PWM latency, the quantized encoder,
// the ADC (quantization, offset, seeded noise), the inverter's average output. Its faults and
// its CAN queues: test_sim_board_faults.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "control/svpwm.hpp"
#include "hal_sim/sensor_models.hpp"
#include "hal_sim/sim_board.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

/// A tick handler that writes a given duty set on each tick.
struct Writer final : hal::TickHandler {
  SimBoard& board;
  hal::PhaseDuties duty{0.5f, 0.5f, 0.5f};
  explicit Writer(SimBoard& b) : board(b) {}
  void on_tick() noexcept override {
    board.pwm().set_duties(duty);
    board.pwm().enable();
  }
};

TEST(SimBoard, DutyWrittenAtTickKActsFromTickKPlusOne) {
  for (const int latency : {0, 1}) {
    SimBoardConfig config;
    config.pwm_latency_ticks = latency;
    SimBoard board(test::test_motors()[0].parameters, config);
    Writer writer(board);
    board.timer().start(writer);
    const hal::PhaseDuties first{0.7f, 0.4f, 0.4f}, second{0.4f, 0.7f, 0.4f};
    writer.duty = first;
    board.run_tick();  // tick 0 writes `first`
    writer.duty = second;
    board.run_tick();  // tick 1 writes `second`
    const Vec2 expected = inverter_output_V(latency == 1 ? first : second, config.v_bus_V);
    EXPECT_NEAR((board.applied_voltage_V() - expected).norm(), 0.0, 1e-9) << "latency " << latency;
  }
}

TEST(SimBoard, DisabledPwmForcesZeroCurrent) {
  SimBoard board(test::test_motors()[0].parameters, {});
  PlantState s;
  s.i_s_alphabeta_A = {3.0, 1.0};
  s.flux_r_alphabeta_Wb = {0.4, 0.0};
  board.plant().set_state(s);
  board.run_tick();  // nobody enabled the PWM
  EXPECT_EQ(board.plant().state().i_s_alphabeta_A, Vec2::Zero());
  EXPECT_EQ(board.applied_voltage_V(), Vec2::Zero());
}

TEST(EncoderModel, QuantizesAndWraps) {
  const uint32_t cpr = 8192;
  const double lsb = 2 * std::numbers::pi / cpr;
  EXPECT_EQ(encoder_count(0.0, cpr), 0u);
  EXPECT_EQ(encoder_count(0.999 * lsb, cpr), 0u);
  EXPECT_EQ(encoder_count(1.001 * lsb, cpr), 1u);
  EXPECT_EQ(encoder_count(-0.5 * lsb, cpr), UINT32_MAX);  // one count below zero wraps
  // Differences of the wrapped counter recover the travel across the 32-bit wrap.
  const uint32_t before = encoder_count(-3.0, cpr), after = encoder_count(3.0, cpr);
  EXPECT_NEAR(static_cast<int32_t>(after - before) * lsb, 6.0, 2 * lsb);
}

TEST(AdcModel, QuantizationOffsetAndSeededNoise) {
  AdcModelConfig config;
  config.bits = 12;
  config.full_scale_A = 10.0;
  config.offset_A = {0.05, 0.0, -0.1};
  AdcModel quiet(config, 1);
  const hal::AdcScale scale = quiet.scale();
  EXPECT_FLOAT_EQ(scale.phase_A_per_code, 20.0f / 4096);
  EXPECT_EQ(scale.phase_mid_code, 2048);
  const hal::AdcSample sample = quiet.convert({1.0, 0.0, -20.0}, 311.0);
  // Code = round((i + offset) / LSB) + mid, clamped to the rails.
  EXPECT_EQ(sample.phase_code[0], 2048 + std::lround(1.05 / (20.0 / 4096)));
  EXPECT_EQ(sample.phase_code[1], 2048);
  EXPECT_EQ(sample.phase_code[2], 0);  // beyond full scale: on the rail
  EXPECT_EQ(sample.bus_code, std::lround(311.0 / (500.0 / 4096)));

  config.noise_A = 0.1;
  AdcModel a(config, 42), b(config, 42), c(config, 43);
  double sum = 0, sum_sq = 0;
  const int n = 20000;
  bool differs = false;
  for (int i = 0; i < n; ++i) {
    const auto sa = a.convert({0.0, 0.0, 0.0}, 311.0);
    const auto sb = b.convert({0.0, 0.0, 0.0}, 311.0);
    const auto sc = c.convert({0.0, 0.0, 0.0}, 311.0);
    ASSERT_EQ(sa.phase_code, sb.phase_code);  // same seed, same noise
    differs = differs || sa.phase_code != sc.phase_code;
    const double amps = (sa.phase_code[1] - 2048) * (20.0 / 4096);
    sum += amps;
    sum_sq += amps * amps;
  }
  EXPECT_TRUE(differs);
  // Standard deviation of noise plus quantization: sqrt(0.1^2 + LSB^2/12) = 0.1001 A. With
  // 20000 samples the estimate's relative standard error is 1/sqrt(2n) = 0.5 %: allow 3 %.
  const double mean = sum / n, sd = std::sqrt(sum_sq / n - mean * mean);
  EXPECT_NEAR(sd, 0.1001, 0.003);
  EXPECT_NEAR(mean, 0.0, 5 * 0.1 / std::sqrt(n));
}

TEST(InverterModel, AverageOutputIsTheSvpwmRequest) {
  const double v_bus = 311.0;
  const control::Vec2<double> u(100.0, -50.0);
  const auto pwm = control::svpwm(u, v_bus);
  const hal::PhaseDuties duty{float(pwm.duty[0]), float(pwm.duty[1]), float(pwm.duty[2])};
  // Duties pass through float (the HAL type): 6e-8 relative of 311 V.
  EXPECT_NEAR((inverter_output_V(duty, v_bus) - u).norm(), 0.0, 1e-4);
}

}  // namespace
}  // namespace imd::sim
