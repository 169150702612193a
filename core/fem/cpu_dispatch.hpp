#pragma once

// The hot kernels (K·u: node stencils, element loops) are compiled for three instruction sets
// and chosen once, when the program loads (function multi-versioning: an ifunc per kernel), so a
// binary built for the portable baseline (x86-64-v2, the default build) runs them with AVX2 and
// FMA, or AVX-512, on a CPU that has them, and still runs on one that has not.
// HAPTICSIM_KERNEL_DISPATCH is set by the build (CMakeLists.txt) for the portable build only: a
// native build (-DHAPTICSIM_NATIVE=ON) has one instruction set, the build machine's, and
// sanitized builds keep to one (their runtimes and ifunc resolvers do not mix).
//
// Put HAPTICSIM_KERNEL_CLONES on a kernel's definition, above its first use in the file (clang
// refuses it after); it must not be virtual (GCC cannot clone those); what it calls must be
// inlined (HAPTICSIM_KERNEL_INLINE), so it is compiled for each set with it.

#include <string>

#if defined(HAPTICSIM_KERNEL_DISPATCH) && defined(__x86_64__)
#define HAPTICSIM_KERNEL_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define HAPTICSIM_KERNEL_CLONES
#endif

// What a kernel calls: always inlined, so it is compiled for the kernel's instruction set (a call
// out of a kernel would run the baseline's code).
#define HAPTICSIM_KERNEL_INLINE inline __attribute__((always_inline))

namespace hapticsim {

/**
 * What the kernels run with on this CPU, for logs and benchmarks: "x86-64-v4 (AVX-512)",
 * "x86-64-v3 (AVX2, FMA)" or "x86-64-v2 (baseline)" in the portable build; "native: …" (the
 * build machine's, fixed at build time) otherwise.
 */
std::string KernelInstructionSet();

}  // namespace hapticsim
