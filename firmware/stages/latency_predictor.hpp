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
  void set_input_state(Estimate<T>& e) const noexcept {
    e.x_input = predict_ ? model_.predict(e.x, v_in_flight_V_, e.load_Nm) : e.x;
    e.x_input.theta_mech_rad = control::wrap_pi(e.x_input.theta_mech_rad);
  }

  /// This tick's voltage `v_V` is written (zero if the PWM is off). Returns the voltage acting
  /// over [k, k+1]: the one in flight with latency, this one without.
  control::Vec2<T> written(const control::Vec2<T>& v_V) noexcept {
    const control::Vec2<T> acting = latency_ ? v_in_flight_V_ : v_V;
    v_in_flight_V_ = v_V;
    return acting;
  }
  /// The tick's voltage will never act (an overrun turned the PWM off after it was written).
  void cancel_in_flight() noexcept { v_in_flight_V_ = control::Vec2<T>::Zero(); }

 private:
  control::VoltageFedModel<T> model_;
  bool latency_, predict_;
  control::Vec2<T> v_in_flight_V_ = control::Vec2<T>::Zero();  ///< written last tick
};

}  // namespace imd::firmware
