#include "tests/support/allocation_counter.hpp"

#include <malloc.h>

#include <cstddef>

// glibc's real allocator entry points, which the interposed functions below forward to.
extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
}

namespace {
thread_local std::size_t allocations = 0;
}

extern "C" {
void* malloc(size_t size) {
  ++allocations;
  return __libc_malloc(size);
}
void* calloc(size_t count, size_t size) {
  ++allocations;
  return __libc_calloc(count, size);
}
void* realloc(void* p, size_t size) {
  ++allocations;
  return __libc_realloc(p, size);
}
void* memalign(size_t alignment, size_t size) {
  ++allocations;
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(size_t alignment, size_t size) {
  ++allocations;
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, size_t alignment, size_t size) {
  ++allocations;
  *out = __libc_memalign(alignment, size);
  return *out == nullptr && size != 0 ? 12 /* ENOMEM */ : 0;
}
}

namespace hapticsim::testing {

ScopedAllocationCount::ScopedAllocationCount() : start_(allocations) {}
ScopedAllocationCount::~ScopedAllocationCount() = default;
std::size_t ScopedAllocationCount::count() const { return allocations - start_; }

}  // namespace hapticsim::testing
