#pragma once
/// The PWM latency: the duties written at tick k act from k+1, so the law chooses the input for
/// the period after the one already in flight. The exact sampled model predicts the state one
/// period ahead with the voltage in flight (docs/control.md). It also keeps which voltage acts
/// over each period, for the observers. Tick context except construction.
#include "control/encoder_observer.hpp"
#include "control/voltage_fed_model.hpp"
#include "firmware/stages/estimate.hpp"

namespace imd::firmware {

template <typename T>
class LatencyPredictor {
 public:
  /// `latency_ticks` 0 or 1; `compensate` false only to measure what the prediction is worth.
  LatencyPredictor(const control::VoltageFedCoefficients& c, int latency_ticks,
                   bool compensate) noexcept
      : model_(c), latency_(latency_ticks > 0), predict_(latency_ && compensate) {}

  /// Whether the input chosen now acts one tick later than the state it is chosen from.
  bool predicts() const noexcept { return predict_; }

  /// Sets e.x_input, the state the input of this tick will act on.
  void set_input_state(Estimate<T>& e) noexcept {
    if (predict_) {
      // Stored from registers twice: copied from next_, each value would be read back (the
      // estimate's floats may alias the predictor's for the compiler).
      const control::RotorFrameState<T> next = model_.predict(e.x, v_in_flight_V_, e.load_Nm);
      next_ = next;
      e.x_input = next;
    } else {
      e.x_input = e.x;
    }
    e.x_input.theta_mech_rad = control::wrap_pi(e.x_input.theta_mech_rad);
  }

  /// With latency, the state set_input_state() predicted for step k+1, position not wrapped:
  /// the voltage in flight is the one that acts over [k, k+1], so this is also where the
  /// observers advance to (before this tick's write; null without a prediction).
  const control::RotorFrameState<T>* next_state() const noexcept {
    return predict_ ? &next_ : nullptr;
  }

  /// This tick's voltage `v_V` is written (zero if the PWM is off). Returns the voltage acting
  /// over [k, k+1]: the one in flight with latency, this one without.
  control::Vec2<T> written(const control::Vec2<T>& v_V) noexcept {
    const control::Vec2<T> acting = latency_ ? v_in_flight_V_ : v_V;
    v_in_flight_V_ = v_V;
    return acting;
  }
  /// The same for the stator voltage (stationary frame) this tick wrote: returns the one that
  /// acts over [k, k+1].
  control::Vec2<T> written_stator(const control::Vec2<T>& u_V) noexcept {
    const control::Vec2<T> acting = latency_ ? u_in_flight_V_ : u_V;
    u_in_flight_V_ = u_V;
    return acting;
  }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const LatencyPredictor& old) noexcept {
    v_in_flight_V_ = old.v_in_flight_V_;
    u_in_flight_V_ = old.u_in_flight_V_;
  }

 private:
  control::VoltageFedModel<T> model_;
  bool latency_, predict_;
  control::Vec2<T> v_in_flight_V_ = control::Vec2<T>::Zero();  ///< written last tick
  control::Vec2<T> u_in_flight_V_ = control::Vec2<T>::Zero();  ///< its stator voltage
  control::RotorFrameState<T> next_;  ///< the last prediction
};

}  // namespace imd::firmware
