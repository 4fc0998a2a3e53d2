// Uses the installed headers and library: a ZOH discretisation (the
// core's transfer_function.cpp) of 2/(10 s + 1) at 1 s, whose DC gain is 2.
#include <cstdio>

#include "core/transfer_function.hpp"

int main() {
  mpm::ContinuousTf g;
  g.num = {2.0};
  g.den = {10.0, 1.0};
  const mpm::DiscreteTf d = mpm::discretize_zoh(g, 1.0);
  std::printf("dc_gain %.6f pole %.6f\n", d.dc_gain(), -d.den[1]);
  return 0;
}
