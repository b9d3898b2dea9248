#pragma once
/// The estimate stage: from the measurement to the motor's state in the rotor-aligned frame
/// (flux, current, speed, position, load), by the observers; then the prediction over the PWM
/// latency (firmware/stages/latency_predictor.hpp). The observers are the production source; a
/// simulation may substitute its ideal sensors (hal_sim/drive/ideal_sensors.hpp) through the
/// same interface. Tick context except construction.
#include "control/encoder_observer.hpp"
#include "control/flux_observer.hpp"
#include "control/real.hpp"
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
  /// The stator current the exact model predicted for this tick at the last one, from the
  /// current measured then, the flux estimate and the input that acted, in the stator frame
  /// (the phase-loss check compares it with the measured current); false at the first tick.
  bool current_predicted = false;
  control::Vec2<T> i_predicted_alphabeta_A = control::Vec2<T>::Zero();
};

/// The exact model's current row, I~_{k+1} = a21 Phi~_k + a22 I~_k + b2 v~_k (rotor frame):
/// the current one period ahead. Tick context.
template <typename T>
struct CurrentPredictor {
  explicit CurrentPredictor(const control::VoltageFedCoefficients& c) noexcept
      : a21(T(c.a21)), a22(T(c.a22)), b2(T(c.b2)) {}
  control::Vec2<T> next_AB_A(const control::Vec2<T>& flux_AB_Wb, const control::Vec2<T>& i_AB_A,
                             const control::Vec2<T>& v_AB_V) const noexcept {
    return a21 * flux_AB_Wb + a22 * i_AB_A + b2 * v_AB_V;
  }
  T a21, a22, b2;
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
  ObserverEstimator(const control::VoltageFedCoefficients& c, Real pole_pairs,
                    Real encoder_bandwidth_rad_s)
      : flux_(c), encoder_(c, {encoder_bandwidth_rad_s}), current_(c), pole_pairs_(T(pole_pairs)) {}

  Estimate<T> estimate(const Measurement<T>& m) noexcept override {
    if (m.encoder_first) encoder_.reset(m.theta_encoder_rad);
    encoder_.correct(m.theta_encoder_rad);
    Estimate<T> e;
    e.valid = true;
    e.x.theta_mech_rad = encoder_.theta_mech_rad();
    e.x.omega_mech_rad_s = encoder_.omega_mech_rad_s();
    e.x.flux_r_AB_Wb = flux_.flux_r_AB_Wb();
    e.load_Nm = encoder_.load_Nm();
    const auto rotor = control::Rotation<T>::from_angle(pole_pairs_ * e.x.theta_mech_rad);
    e.x.i_s_AB_A = rotor.apply_inverse(m.i_alphabeta_A);
    e.current_predicted = predicted_;
    e.i_predicted_alphabeta_A = rotor.apply(i_next_AB_A_);
    i_s_AB_A_ = e.x.i_s_AB_A;
    return e;
  }

  void advance(const control::Vec2<T>& v_acting_AB_V) noexcept override {
    // The flux observer still holds the estimate of this tick until its update.
    encoder_.predict(i_s_AB_A_, flux_.flux_r_AB_Wb(), v_acting_AB_V);
    i_next_AB_A_ = current_.next_AB_A(flux_.flux_r_AB_Wb(), i_s_AB_A_, v_acting_AB_V);
    predicted_ = true;
    flux_.update(i_s_AB_A_, v_acting_AB_V);
  }

  /// advance() when the exact model has already predicted step k+1 from this tick's estimate
  /// (its flux, current, speed, position and load) with the voltage that acts over [k, k+1]:
  /// the latency predictor's `next` (position not wrapped). The same rows, not computed twice.
  void advance_to(const control::RotorFrameState<T>& next) noexcept {
    // The encoder observer's predict() keeps its load and wraps the position as reset() does.
    encoder_.reset(next.theta_mech_rad, next.omega_mech_rad_s, encoder_.load_Nm());
    i_next_AB_A_ = next.i_s_AB_A;
    predicted_ = true;
    flux_.reset(next.flux_r_AB_Wb);
  }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const ObserverEstimator& old) noexcept {
    flux_.continue_from(old.flux_);
    encoder_.continue_from(old.encoder_);
    i_s_AB_A_ = old.i_s_AB_A_;
    i_next_AB_A_ = old.i_next_AB_A_;
    predicted_ = old.predicted_;
  }

 private:
  control::FluxObserver<T> flux_;
  control::EncoderObserver<T> encoder_;
  CurrentPredictor<T> current_;
  T pole_pairs_;
  control::Vec2<T> i_s_AB_A_ = control::Vec2<T>::Zero();     ///< of the last estimate
  control::Vec2<T> i_next_AB_A_ = control::Vec2<T>::Zero();  ///< predicted for the next
  bool predicted_ = false;
};

}  // namespace imd::firmware
