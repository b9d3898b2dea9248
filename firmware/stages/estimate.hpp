#pragma once
/// The estimate stage: from the measurement to the motor's state in the rotor-aligned frame
/// (flux, current, speed, position, load), by the observers; then the prediction over the PWM
/// latency (firmware/stages/latency_predictor.hpp). The observers are the production source; a
/// simulation may substitute its ideal sensors (hal_sim/drive/ideal_sensors.hpp) through the
/// same interface. Tick context except construction.
#include "control/encoder_observer.hpp"
#include "control/flux_observer.hpp"
#include "control/voltage_fed_model.hpp"
#include "firmware/stages/measurement.hpp"

namespace imd::firmware {

template <typename T>
struct Estimate {
  bool valid = false;             ///< a valid measurement was estimated from
  control::RotorFrameState<T> x;  ///< at this tick
  T load_Nm = T(0);               ///< load torque (estimate), held over the period
  /// The state at the start of the period this tick's input acts on (x predicted over the PWM
  /// latency; x itself without latency), position wrapped to (-pi, pi]: what the law acts on.
  control::RotorFrameState<T> x_input;
};

template <typename T>
class StateEstimator {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~StateEstimator() = default;

 public:
  /// The state at this tick from this tick's (valid) measurement; x_input is left to the
  /// caller.
  virtual Estimate<T> estimate(const Measurement<T>& m) noexcept = 0;
  /// Advances the estimators over [k, k+1] with the rotor-frame voltage that acts then. Called
  /// once after each estimate().
  virtual void advance(const control::Vec2<T>& v_acting_AB_V) noexcept = 0;
};

/// The production estimator: the encoder observer (position, speed, load) and the flux
/// observer on the exact sampled model, the measured current rotated into the rotor frame.
template <typename T>
class ObserverEstimator final : public StateEstimator<T> {
 public:
  ObserverEstimator(const control::VoltageFedCoefficients& c, double pole_pairs,
                    double encoder_bandwidth_rad_s)
      : flux_(c), encoder_(c, {encoder_bandwidth_rad_s}), pole_pairs_(T(pole_pairs)) {}

  Estimate<T> estimate(const Measurement<T>& m) noexcept override {
    if (m.encoder_first) encoder_.reset(m.theta_encoder_rad);
    encoder_.correct(m.theta_encoder_rad);
    Estimate<T> e;
    e.valid = true;
    e.x.theta_mech_rad = encoder_.theta_mech_rad();
    e.x.omega_mech_rad_s = encoder_.omega_mech_rad_s();
    e.x.flux_r_AB_Wb = flux_.flux_r_AB_Wb();
    e.load_Nm = encoder_.load_Nm();
    e.x.i_s_AB_A = control::Rotation<T>::from_angle(pole_pairs_ * e.x.theta_mech_rad)
                       .apply_inverse(m.i_alphabeta_A);
    i_s_AB_A_ = e.x.i_s_AB_A;
    return e;
  }

  void advance(const control::Vec2<T>& v_acting_AB_V) noexcept override {
    // The flux observer still holds the estimate of this tick until its update.
    encoder_.predict(i_s_AB_A_, flux_.flux_r_AB_Wb(), v_acting_AB_V);
    flux_.update(i_s_AB_A_, v_acting_AB_V);
  }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const ObserverEstimator& old) noexcept {
    flux_.continue_from(old.flux_);
    encoder_.continue_from(old.encoder_);
    i_s_AB_A_ = old.i_s_AB_A_;
  }

 private:
  control::FluxObserver<T> flux_;
  control::EncoderObserver<T> encoder_;
  T pole_pairs_;
  control::Vec2<T> i_s_AB_A_ = control::Vec2<T>::Zero();  ///< of the last estimate
};

}  // namespace imd::firmware
