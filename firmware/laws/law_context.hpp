#pragma once
/// What every law is built from (construction only).
#include "control/motor_parameters.hpp"
#include "control/voltage_fed_model.hpp"
#include "firmware/drive_config.hpp"

namespace imd::firmware {

struct LawContext {
  const control::MotorParameters& motor;
  const DriveConfig& config;
  /// The voltage-fed motor's exact model at the drive's sample period.
  const control::VoltageFedCoefficients& coefficients;
};

}  // namespace imd::firmware
