#pragma once
// Whether this test binary runs under a sanitizer. Under one, every step is several times slower
// than its period: tests of real-time behaviour check what the sanitizer is for (the protocol,
// the memory) and leave out their timing and force bounds.
//
// g++ defines __SANITIZE_ADDRESS__ / __SANITIZE_THREAD__; clang 14 (the AddressSanitizer stage's
// compiler) defines neither and answers __has_feature instead, so both are asked.

namespace hapticsim {

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define HAPTICSIM_TEST_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define HAPTICSIM_TEST_SANITIZED 1
#endif

#if defined(HAPTICSIM_TEST_SANITIZED)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

}  // namespace hapticsim
