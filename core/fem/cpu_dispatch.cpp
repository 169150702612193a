#include "core/fem/cpu_dispatch.hpp"

namespace hapticsim {

std::string KernelInstructionSet() {
#if defined(HAPTICSIM_KERNEL_DISPATCH) && defined(__x86_64__)
  __builtin_cpu_init();
  // The same tests the clones' resolvers make (GCC's arch levels; feature by feature for clang).
#if defined(__clang__)
  const bool v4 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                  __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512dq") &&
                  __builtin_cpu_supports("avx512vl");
  const bool v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                  __builtin_cpu_supports("bmi2");
#else
  const bool v4 = __builtin_cpu_supports("x86-64-v4");
  const bool v3 = __builtin_cpu_supports("x86-64-v3");
#endif
  if (v4) return "x86-64-v4 (AVX-512)";
  if (v3) return "x86-64-v3 (AVX2, FMA)";
  return "x86-64-v2 (baseline)";
#else
  std::string native = "native: one instruction set, fixed at build time (";
#if defined(__AVX512F__)
  native += "AVX-512";
#elif defined(__AVX2__) && defined(__FMA__)
  native += "AVX2, FMA";
#elif defined(__AVX__)
  native += "AVX";
#else
  native += "SSE";
#endif
  return native + ")";
#endif
}

}  // namespace hapticsim
