#pragma once
/// The papers' power stages, which only the simulated board has, as substitutes for the drive's
/// SVPWM stage (firmware::PowerStage):
///   * AnalogInnerLoopStage: paper 000's hybrid scheme, the law's v~ written to the analog
///     inner-loop circuit that evaluates (2) continuously (no voltage limit);
///   * CurrentSourceStage: paper 001's current-fed plant, the law's rotor-frame current
///     command imposed by the ideal current source.
/// The board's PWM enable still gates both. Tick context.
#include <cmath>

#include "firmware/stages/power_stage.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::sim {

template <typename T>
bool finite_vec(const control::Vec2<T>& v) noexcept {
  return std::isfinite(v.x()) && std::isfinite(v.y());
}

template <typename T>
class AnalogInnerLoopStage final : public firmware::PowerStage<T> {
 public:
  explicit AnalogInnerLoopStage(SimBoard& board) noexcept : board_(board) {}

  firmware::Modulation<T> modulate(const firmware::LawOutput<T>& law,
                                   const control::RotorFrameState<T>&, T) noexcept override {
    firmware::Modulation<T> m;
    m.v_acting_AB_V = law.v_AB_V;  // the circuit applies it whole
    m.finite = finite_vec(law.v_AB_V);
    return m;
  }
  void write(const firmware::Modulation<T>& m) noexcept override {
    board_.analog_inner_loop().set_input_AB_V(double(m.v_acting_AB_V.x()),
                                              double(m.v_acting_AB_V.y()));
    board_.pwm().enable();
  }

 private:
  SimBoard& board_;
};

template <typename T>
class CurrentSourceStage final : public firmware::PowerStage<T> {
 public:
  explicit CurrentSourceStage(SimBoard& board) noexcept : board_(board) {}

  firmware::Modulation<T> modulate(const firmware::LawOutput<T>& law,
                                   const control::RotorFrameState<T>&, T) noexcept override {
    firmware::Modulation<T> m;
    m.v_acting_AB_V = law.v_AB_V;  // what the law's current loop would apply: the observers'
    m.finite = finite_vec(law.i_cmd_AB_A);
    i_cmd_AB_A_ = law.i_cmd_AB_A;
    return m;
  }
  void write(const firmware::Modulation<T>&) noexcept override {
    board_.current_source().set_current_AB_A(double(i_cmd_AB_A_.x()), double(i_cmd_AB_A_.y()));
    board_.pwm().enable();
  }

 private:
  SimBoard& board_;
  control::Vec2<T> i_cmd_AB_A_ = control::Vec2<T>::Zero();  ///< of the last modulate()
};

}  // namespace imd::sim
