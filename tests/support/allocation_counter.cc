// The counting replacements of glibc's malloc family and of the global operator
// new/delete behind AllocationCounter (allocation_counter.h). glibc lets a program
// replace malloc; the replacements forward to __libc_* and count while the calling
// thread has counting switched on. Under AddressSanitizer, which owns malloc, the
// sanitizer's malloc hook counts instead, and operator new forwards to its malloc.
#include "allocation_counter.h"

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <new>

namespace {
std::atomic<long> g_mallocs{0};
std::atomic<long> g_news{0};
thread_local bool t_counting = false;
}  // namespace

#if defined(__GLIBC__)
namespace {
void Note(std::atomic<long>* count) {
  if (t_counting) count->fetch_add(1, std::memory_order_relaxed);
}
}  // namespace
#endif

#if defined(__GLIBC__) && defined(__SANITIZE_ADDRESS__)
// The sanitizer calls the malloc hook once for every heap allocation it serves (malloc,
// calloc, realloc, aligned_alloc, posix_memalign; operator new below calls malloc),
// uninstrumented libraries included, which is what the __libc_* forwarding counts in the
// other builds. Declared here as in compiler-rt's sanitizer/allocator_interface.h, which
// GCC does not ship.
extern "C" int __sanitizer_install_malloc_and_free_hooks(
    void (*malloc_hook)(const volatile void* ptr, std::size_t size),
    void (*free_hook)(const volatile void* ptr));

namespace {
void* ForwardMalloc(std::size_t size) { return std::malloc(size); }
void* ForwardAlignedAlloc(std::size_t alignment, std::size_t size) {
  return std::aligned_alloc(alignment, size);
}
void ForwardFree(void* ptr) { std::free(ptr); }
void OnMalloc(const volatile void* /*ptr*/, std::size_t /*size*/) { Note(&g_mallocs); }
void OnFree(const volatile void* /*ptr*/) {}
[[maybe_unused]] const int g_hooks_installed =
    __sanitizer_install_malloc_and_free_hooks(&OnMalloc, &OnFree);
}  // namespace
#elif defined(__GLIBC__)
extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* ptr, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
void __libc_free(void* ptr);

void* malloc(std::size_t size) {
  Note(&g_mallocs);
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) {
  Note(&g_mallocs);
  return __libc_calloc(count, size);
}
void* realloc(void* ptr, std::size_t size) {
  Note(&g_mallocs);
  return __libc_realloc(ptr, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  Note(&g_mallocs);
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  Note(&g_mallocs);
  *out = __libc_memalign(alignment, size);
  return *out == nullptr ? ENOMEM : 0;
}
void free(void* ptr) { __libc_free(ptr); }
}  // extern "C"

namespace {
void* ForwardMalloc(std::size_t size) { return malloc(size); }
void* ForwardAlignedAlloc(std::size_t alignment, std::size_t size) {
  return aligned_alloc(alignment, size);
}
void ForwardFree(void* ptr) { __libc_free(ptr); }
}  // namespace
#endif

#if defined(__GLIBC__)
namespace {
void* CountedNew(std::size_t size) {
  Note(&g_news);
  return ForwardMalloc(size == 0 ? 1 : size);  // counted by malloc too
}
void* CountedAlignedNew(std::size_t size, std::align_val_t alignment) {
  Note(&g_news);
  const auto a = static_cast<std::size_t>(alignment);
  return ForwardAlignedAlloc(a, ((size + a - 1) / a) * a);  // counted by malloc too
}
void* OrThrow(void* p) {
  if (p == nullptr) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t size) { return OrThrow(CountedNew(size)); }
void* operator new[](std::size_t size) { return OrThrow(CountedNew(size)); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return CountedNew(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return CountedNew(size);
}
void* operator new(std::size_t size, std::align_val_t al) {
  return OrThrow(CountedAlignedNew(size, al));
}
void* operator new[](std::size_t size, std::align_val_t al) {
  return OrThrow(CountedAlignedNew(size, al));
}
void operator delete(void* p) noexcept { ForwardFree(p); }
void operator delete[](void* p) noexcept { ForwardFree(p); }
void operator delete(void* p, std::size_t) noexcept { ForwardFree(p); }
void operator delete[](void* p, std::size_t) noexcept { ForwardFree(p); }
void operator delete(void* p, std::align_val_t) noexcept { ForwardFree(p); }
void operator delete[](void* p, std::align_val_t) noexcept { ForwardFree(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { ForwardFree(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { ForwardFree(p); }
#endif  // glibc

namespace snapthread::test_support {

AllocationCounter::AllocationCounter() : mallocs0_(g_mallocs.load()), news0_(g_news.load()) {
  t_counting = true;
}

AllocationCounter::~AllocationCounter() { t_counting = false; }

void AllocationCounter::Stop() {
  if (mallocs_ >= 0) return;
  t_counting = false;
  mallocs_ = g_mallocs.load() - mallocs0_;
  news_ = g_news.load() - news0_;
}

long AllocationCounter::mallocs() const {
  return mallocs_ >= 0 ? mallocs_ : g_mallocs.load() - mallocs0_;
}

long AllocationCounter::news() const { return news_ >= 0 ? news_ : g_news.load() - news0_; }

}  // namespace snapthread::test_support
