// Counting heap allocations in a test binary (after Drake's LimitMalloc): the tests that
// promise "no allocation after warm-up" (the servo tick, signing, the LDL^T backends, the
// model derivatives) count what the calling thread allocates between two points.
//
// allocation_counter.cc replaces glibc's malloc family (under AddressSanitizer it counts
// in the sanitizer's malloc hook instead) and the global operator new/delete with
// counting versions; it is linked (snapthread::test_allocation_counter) only into the
// test binaries that count, since a program may replace them once. The malloc count sees
// every heap allocation: operator new (the replacements call malloc), Eigen's
// aligned_malloc (std::malloc, which operator new alone would miss) and CHOLMOD's
// SuiteSparse_malloc; operator new has its own count as well, so a test can also say
// "no C++ allocation" independently of the malloc interposition.
#pragma once

#include <cstdlib>  // defines __GLIBC__ on glibc

namespace snapthread::test_support {

// Under AddressSanitizer the sanitizer owns malloc: there its malloc hook counts
// (__sanitizer_install_malloc_and_free_hooks), so the same tests assert the same counts
// in the sanitizer build. Outside glibc there are no __libc_* functions to forward to.
#if defined(__GLIBC__)
inline constexpr bool kCountsAllocations = true;
#else
inline constexpr bool kCountsAllocations = false;
#endif

// Counts the heap allocations of this thread from construction until Stop() (or the
// destructor); other threads are not counted.
class AllocationCounter {
 public:
  AllocationCounter();
  ~AllocationCounter();
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;

  void Stop();
  // Calls of malloc, calloc, realloc, aligned_alloc and posix_memalign (operator new
  // included) so far, or until Stop().
  long mallocs() const;
  // Calls of the global operator new (every form) so far, or until Stop().
  long news() const;

 private:
  long mallocs0_, news0_;
  long mallocs_ = -1, news_ = -1;  // >= 0 once stopped
};

// The heap allocations (malloc calls, operator new included) that f() makes on this
// thread: 0 is the promise of a call that reuses presized outputs.
template <class F>
long MallocsDuring(F&& f) {
  AllocationCounter counter;
  f();
  counter.Stop();
  return counter.mallocs();
}

}  // namespace snapthread::test_support
