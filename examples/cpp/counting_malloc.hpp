// A counting interposer on the C allocator for the examples' programs (include it in one source
// file of a program): while `counting` is set, every allocation through malloc, calloc, realloc
// or the aligned allocators (what Rust's standard library calls) is counted, so a program can
// show that the controller's update allocates nothing. glibc only (its __libc_* entry points).
#ifndef TROCAR_EXAMPLES_COUNTING_MALLOC_HPP
#define TROCAR_EXAMPLES_COUNTING_MALLOC_HPP

#include <cstddef>
#include <cstdlib>

namespace {
bool counting = false;
unsigned long allocations = 0;
}  // namespace

extern "C" {
void *__libc_malloc(std::size_t);
void *__libc_calloc(std::size_t, std::size_t);
void *__libc_realloc(void *, std::size_t);
void *__libc_memalign(std::size_t, std::size_t);

void *malloc(std::size_t size) {
    if (counting) ++allocations;
    return __libc_malloc(size);
}
void *calloc(std::size_t n, std::size_t size) {
    if (counting) ++allocations;
    return __libc_calloc(n, size);
}
void *realloc(void *p, std::size_t size) {
    if (counting) ++allocations;
    return __libc_realloc(p, size);
}
void *aligned_alloc(std::size_t alignment, std::size_t size) {
    if (counting) ++allocations;
    return __libc_memalign(alignment, size);
}
void *memalign(std::size_t alignment, std::size_t size) {
    if (counting) ++allocations;
    return __libc_memalign(alignment, size);
}
int posix_memalign(void **out, std::size_t alignment, std::size_t size) {
    if (counting) ++allocations;
    void *p = __libc_memalign(alignment, size);
    if (p == nullptr) return 12;  // ENOMEM
    *out = p;
    return 0;
}
}


// Whether the interposer counts: one allocation made on purpose is seen. Resets the count.
inline bool counting_malloc_counts() {
    counting = true;
    void *probe = std::malloc(16);
    counting = false;
    std::free(probe);
    const bool counts = allocations == 1;
    allocations = 0;
    return counts;
}

#endif  // TROCAR_EXAMPLES_COUNTING_MALLOC_HPP
