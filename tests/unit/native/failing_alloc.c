/* An LD_PRELOAD shim whose malloc and realloc fail for one size (tests/unit/native/failing_alloc.py).
 *
 * The process sets `failing_alloc_size` through ctypes (0, at start: nothing fails); from then
 * on every malloc or realloc of exactly that many bytes returns NULL with ENOMEM, except the
 * first `failing_alloc_spared` of them, and `failing_alloc_failures` counts the failures, so
 * that a test can check that the failure it meant happened, and only it. Every other call
 * goes to glibc's own allocator (free needs no wrapper). */
#include <errno.h>
#include <stddef.h>

extern void *__libc_malloc(size_t size);
extern void *__libc_realloc(void *pointer, size_t size);

size_t failing_alloc_size;
unsigned long failing_alloc_spared;
unsigned long failing_alloc_failures;

static int fails(size_t size) {
    size_t failing = __atomic_load_n(&failing_alloc_size, __ATOMIC_RELAXED);
    if (failing == 0 || size != failing) return 0;
    unsigned long spared = __atomic_load_n(&failing_alloc_spared, __ATOMIC_RELAXED);
    while (spared > 0)
        if (__atomic_compare_exchange_n(&failing_alloc_spared, &spared, spared - 1, 0,
                                        __ATOMIC_RELAXED, __ATOMIC_RELAXED))
            return 0;
    __atomic_add_fetch(&failing_alloc_failures, 1, __ATOMIC_RELAXED);
    errno = ENOMEM;
    return 1;
}

void *malloc(size_t size) { return fails(size) ? NULL : __libc_malloc(size); }

void *realloc(void *pointer, size_t size) {
    return fails(size) ? NULL : __libc_realloc(pointer, size);
}
