// The double an exact conversion maps onto a given value: what a writer puts
// in a file so that the reader's conversion gives back, bit for bit, the
// value that was used (the machine-optimised STEP-NC, lowering's unit
// conversions written back).
#pragma once

#include <cmath>

namespace stepnc {

/// Units in the last place searched either side of a first guess.
inline constexpr int kPreimageUlps = 4;

/// The double near `guess` for which `forward` gives exactly `target`; the
/// guess when none within kPreimageUlps units in the last place does.
template <class Forward> double preimage(double target, double guess, Forward forward) {
  double down = guess, up = guess;
  for (int i = 0; i <= kPreimageUlps; ++i) {
    if (forward(up) == target)
      return up;
    if (forward(down) == target)
      return down;
    up = std::nextafter(up, INFINITY);
    down = std::nextafter(down, -INFINITY);
  }
  return guess;
}

} // namespace stepnc
