// FUZZ_CHECK(cond): a broken invariant is a finding. It prints where and aborts, which libFuzzer
// reports as a crash and saves the input that caused it (build/fuzz/findings/).
#ifndef ROVERLINK_TESTS_FUZZ_CHECK_H
#define ROVERLINK_TESTS_FUZZ_CHECK_H

#include <stdio.h>
#include <stdlib.h>

#define FUZZ_CHECK(cond)                                                                      \
    do {                                                                                      \
        if (!(cond)) {                                                                        \
            fprintf(stderr, "%s:%d: invariant broken: %s\n", __FILE__, __LINE__, #cond);      \
            abort();                                                                          \
        }                                                                                     \
    } while (0)

#endif  // ROVERLINK_TESTS_FUZZ_CHECK_H
