// Preloaded under valgrind (benchmarks/run_callgrind.sh): Highway's run-time dispatch asks the CPU which
// SIMD targets it has, and valgrind emulates no AVX-512, so a process on an AVX-512 machine would pick
// lanes valgrind cannot run. This hides the AVX-512 targets from the process; AVX2 is chosen as on the
// machines the lanes were tuned for (detail/simd_targets.h disables AVX-512 for the lanes anyway).
#include <dlfcn.h>

#include <cstdint>

#include <hwy/detect_targets.h>

namespace hwy {

int64_t SupportedTargets() {
  using Real = int64_t (*)();
  static const Real real = reinterpret_cast<Real>(dlsym(RTLD_NEXT, "_ZN3hwy16SupportedTargetsEv"));
  int64_t hidden = HWY_AVX3 | HWY_AVX3_DL;
#ifdef HWY_AVX3_ZEN4
  hidden |= HWY_AVX3_ZEN4;
#endif
#ifdef HWY_AVX3_SPR
  hidden |= HWY_AVX3_SPR;
#endif
  return real ? real() & ~hidden : 0;
}

}  // namespace hwy
