// The sense stage on a fake ADC and encoder: offset calibration, scaling, rails, unwrapping.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "fakes.hpp"
#include "firmware/stages/sense.hpp"

namespace imd::firmware {
namespace {

constexpr double kAPerCode = 10.0 / 2048.0;

TEST(SenseStage, CalibratesTheOffsetsThenMeasuresAgainstThem) {
  test::FakeAdc adc;
  test::FakeEncoder encoder;
  BoardSensing<double> sensing(adc, encoder, {4, 0.5});
  EXPECT_FALSE(sensing.calibrated());
  adc.next.phase_code = {2058, 2040, 2048};  // +10, -8, 0 codes of offset
  for (int k = 0; k < 3; ++k) EXPECT_EQ(sensing.measure(true).calibration, Calibration::running);
  const Measurement<double> last = sensing.measure(true);
  EXPECT_EQ(last.calibration, Calibration::done);
  EXPECT_FALSE(last.valid);  // the tick that ends the calibration measures nothing yet
  EXPECT_TRUE(sensing.calibrated());

  adc.next.phase_code = {2058 + 100, 2040 - 50, 2048 - 50};
  const Measurement<double> m = sensing.measure(false);
  ASSERT_TRUE(m.valid);
  // Exact: the offsets are whole codes and the scale a power of two.
  EXPECT_EQ(m.i_abc_A[0], 100 * kAPerCode);
  EXPECT_EQ(m.i_abc_A[1], -50 * kAPerCode);
  EXPECT_EQ(m.i_abc_A[2], -50 * kAPerCode);
  EXPECT_EQ(m.i_peak_A, 100 * kAPerCode);
  EXPECT_FALSE(m.adc_saturated);
  // Amplitude-invariant Clarke: alpha is phase a for a balanced set.
  EXPECT_NEAR(m.i_alphabeta_A.x(), 100 * kAPerCode, 1e-12);
  EXPECT_NEAR(m.i_alphabeta_A.y(), 0.0, 1e-12);
  EXPECT_EQ(m.v_bus_V, 2000 * double(400.0f / 4095.0f));  // code times the float scale
}

TEST(SenseStage, AnOffsetBeyondItsLimitNamesThePhase) {
  test::FakeAdc adc;
  test::FakeEncoder encoder;
  BoardSensing<double> sensing(adc, encoder, {2, 0.5});
  adc.next.phase_code = {2048, 2048, 2048 + 120};  // 0.59 A on phase c
  sensing.measure(true);
  const Measurement<double> m = sensing.measure(true);
  EXPECT_EQ(m.calibration, Calibration::offset_fault);
  EXPECT_EQ(m.offset_fault_phase, 2);
  EXPECT_FALSE(sensing.calibrated());
  EXPECT_FALSE(sensing.measure(false).valid);  // nothing is measured without offsets
}

TEST(SenseStage, ACalibrationStartsAfreshWhenItIsAskedForAgain) {
  test::FakeAdc adc;
  test::FakeEncoder encoder;
  BoardSensing<double> sensing(adc, encoder, {2, 0.5});
  adc.next.phase_code = {2048, 2048, 2048 + 120};
  sensing.measure(true);
  sensing.measure(true);  // offset fault
  sensing.measure(false);
  adc.next.phase_code = {2050, 2048, 2046};  // a healthy converter now
  sensing.measure(true);
  EXPECT_EQ(sensing.measure(true).calibration, Calibration::done);  // the old sums are gone
}

TEST(SenseStage, ACodeOnARailIsSaturation) {
  test::FakeAdc adc;
  test::FakeEncoder encoder;
  BoardSensing<float> sensing(adc, encoder, {0, 0.5});  // nominal offsets
  adc.next.phase_code = {4095, 0, 2048};
  const Measurement<float> m = sensing.measure(false);
  ASSERT_TRUE(m.valid);
  EXPECT_TRUE(m.adc_saturated);
}

TEST(SenseStage, TheEncoderUnwrapsAcrossTheCounterWrap) {
  test::FakeAdc adc;
  test::FakeEncoder encoder;
  encoder.counter = 0xFFFF'FFF0u;  // 16 counts before the 32-bit wrap
  BoardSensing<double> sensing(adc, encoder, {0, 0.5});
  const Measurement<double> first = sensing.measure(false);
  EXPECT_TRUE(first.encoder_first);
  EXPECT_EQ(first.encoder_delta_counts, 0);
  EXPECT_EQ(first.theta_encoder_rad, 0.0);  // the first reading is the origin
  encoder.counter += 40;                    // wraps to 24
  const Measurement<double> m = sensing.measure(false);
  EXPECT_FALSE(m.encoder_first);
  EXPECT_EQ(m.encoder_delta_counts, 40);
  EXPECT_NEAR(m.theta_encoder_rad, 2 * std::numbers::pi * 40 / 8192, 1e-15);
  encoder.counter -= 80;  // backwards past the origin: the angle stays in [0, 2 pi)
  const Measurement<double> back = sensing.measure(false);
  EXPECT_EQ(back.encoder_delta_counts, -80);
  EXPECT_NEAR(back.theta_encoder_rad, 2 * std::numbers::pi * (8192 - 40) / 8192, 1e-12);
}

}  // namespace
}  // namespace imd::firmware
