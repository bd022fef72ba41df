#pragma once
// The SIMD targets the lanes kernels are compiled for (kinematics/kinematic_lanes.cpp,
// body/enclosing_lanes.cpp), named before Highway's headers as HWY_DISABLED_TARGETS:
// - fixed-width vectors only: the kernels keep vectors in arrays, which sizeless ones (SVE, RVV) forbid;
// - no AVX-512: on Intel's server parts its arithmetic lowers the core's clock for a while after, so the
//   scalar checks that follow each pass ran slower than the lanes saved (measured on a Xeon: a batch of
//   box_panda states 3–9% slower than one at a time with AVX-512 lanes, 4–5% faster with AVX2's).
// The kernels load and store what lies side by side: gathers (AVX2's made each state slower on a Xeon than
// SSE4's plain loads did) are avoided by laying the data out for the lanes.
#define CLEARWAY_LANES_DISABLED (HWY_AVX3 | HWY_AVX3_DL | HWY_SVE | HWY_SVE2 | HWY_SVE_256 | HWY_SVE2_128 | HWY_RVV)
