// CHECK for the single-file native tests (test_codec.cpp, probe_checks.cpp): counts results, prints
// the first 50 failures with CONTEXT's text; main() ends with check_summary().
#ifndef ROVERLINK_TESTS_NATIVE_CHECK_H
#define ROVERLINK_TESTS_NATIVE_CHECK_H

#include <stdio.h>

static unsigned g_passed = 0;
static unsigned g_failed = 0;
static char g_ctx[160] = "";  // what the current loop iteration is testing; printed on failure

#define CHECK(cond)                                                                     \
    do {                                                                                \
        if (cond) {                                                                     \
            ++g_passed;                                                                 \
        } else {                                                                        \
            ++g_failed;                                                                 \
            if (g_failed <= 50) {                                                       \
                printf("%s:%d: CHECK(%s) failed [%s]\n", __FILE__, __LINE__, #cond, g_ctx); \
            }                                                                           \
        }                                                                               \
    } while (0)

#define CONTEXT(...) snprintf(g_ctx, sizeof(g_ctx), __VA_ARGS__)

// Prints "N passed, M failed" (the line the Python tests read); the process's exit status.
static inline int check_summary() {
    printf("%u passed, %u failed\n", g_passed, g_failed);
    return g_failed == 0 ? 0 : 1;
}

#endif  // ROVERLINK_TESTS_NATIVE_CHECK_H
