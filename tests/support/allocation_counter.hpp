#pragma once

#include <cstddef>

namespace hapticsim::testing {

/**
 * Counts heap allocations made by the calling thread while a ScopedAllocationCount is alive.
 * Linked into a test executable, allocation_counter.cpp interposes malloc, calloc, realloc and
 * the aligned allocators (and so operator new and Eigen's allocator, which sit on them).
 */
class ScopedAllocationCount {
 public:
  ScopedAllocationCount();
  ~ScopedAllocationCount();
  ScopedAllocationCount(const ScopedAllocationCount&) = delete;
  ScopedAllocationCount& operator=(const ScopedAllocationCount&) = delete;

  /** Allocations by this thread since construction. */
  std::size_t count() const;

 private:
  std::size_t start_;
};

}  // namespace hapticsim::testing
