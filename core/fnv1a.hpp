#pragma once

#include <cstddef>
#include <cstdint>

namespace hapticsim {

/**
 * FNV-1a, 64-bit: the one hash behind the map file's checksums, the results checksum and the
 * sweep's fingerprint. Fast and simple, and no defence against anyone choosing the input: it
 * tells a torn or stale file from a good one, not a forged one.
 *
 * Two ways to mix, which give different hashes of the same bytes: Bytes, one byte a step (the
 * classic FNV-1a), and Word, a 64-bit word a step (eight times fewer multiplications; the map
 * file's checksum, over megabytes). Each user keeps the way it always used: changing it would
 * change every checksum already written.
 */
class Fnv1a {
 public:
  void Bytes(const void* data, std::size_t size) noexcept {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) hash_ = (hash_ ^ bytes[i]) * kPrime;
  }
  void Word(std::uint64_t word) noexcept { hash_ = (hash_ ^ word) * kPrime; }
  std::uint64_t value() const noexcept { return hash_; }

 private:
  static constexpr std::uint64_t kOffsetBasis = 0xcbf29ce484222325ull;
  static constexpr std::uint64_t kPrime = 0x100000001b3ull;
  std::uint64_t hash_ = kOffsetBasis;
};

}  // namespace hapticsim
