// Built against an installed nlosloc by the ctest `consumer_find_package`.
#include <cstdio>
#include <nlosloc/core/random.hpp>
#include <nlosloc/core/types.hpp>

int main() {
  nlosloc::Rng rng(42);
  const double u = rng.uniform();
  const double a = nlosloc::wrap_angle(3.0 * nlosloc::kPi);
  if (!(u > 0.0 && u < 1.0) || !(a > 0.0 && a <= nlosloc::kPi)) {
    std::printf("nlosloc consumer: unexpected values u=%g a=%g\n", u, a);
    return 1;
  }
  std::printf("nlosloc consumer: ok (u=%.6f, wrap_angle(3 pi)=%.6f)\n", u, a);
  return 0;
}
