#pragma once
// Forces Highway's dispatch to one SIMD target for a scope, and restores the CPU's own targets when the
// scope ends, however it ends (a failed ASSERT included), so that no later test runs on a forced target.
#include <hwy/targets.h>

#include <cstdint>

namespace clearway::test {

struct ForcedTarget {
  explicit ForcedTarget(std::int64_t target) { hwy::SetSupportedTargetsForTest(target); }
  ~ForcedTarget() { hwy::SetSupportedTargetsForTest(0); }
  ForcedTarget(const ForcedTarget&) = delete;
  ForcedTarget& operator=(const ForcedTarget&) = delete;
};

}  // namespace clearway::test
