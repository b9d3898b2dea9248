#pragma once
/// The squaring step shared by the structured exponentials (block_exponential.hpp in double,
/// metzler_exponential.hpp in the control arithmetic): with B = [X I 0; 0 g I; 0 0 0],
/// exp(B) = (exp(B/2^s))^(2^s), and one squaring of [E Y Z; 0 e w; 0 0 I] is
/// [E^2, EY + eY, EZ + wY + Z; 0, e^2, (e + 1) w; 0 0 I]: three block products, no 9x9.
#include <type_traits>

namespace imd::control {

/// Squares `blocks` (members e_x, y, z: matrices; e_g, w: scalars) `squarings` times.
template <typename Blocks>
void square_blocks(Blocks& r, int squarings) noexcept {
  using Matrix = std::decay_t<decltype(r.e_x)>;
  using Scalar = std::decay_t<decltype(r.e_g)>;
  for (int k = 0; k < squarings; ++k) {
    const Matrix e_x = r.e_x * r.e_x;
    const Matrix y = r.e_x * r.y + r.e_g * r.y;
    const Matrix z = r.e_x * r.z + r.w * r.y + r.z;
    r.w = (r.e_g + Scalar(1)) * r.w;
    r.e_g = r.e_g * r.e_g;
    r.e_x = e_x;
    r.y = y;
    r.z = z;
  }
}

}  // namespace imd::control
