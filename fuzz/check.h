#pragma once
/// @file FUZZ_CHECK: an invariant of a fuzz target. On failure it prints the condition and
/// aborts, which libFuzzer (and the replay driver) reports as a crash with the input saved.

#include <cstdio>
#include <cstdlib>

#define FUZZ_CHECK(cond, what)                                                             \
    do {                                                                                   \
        if (!(cond)) {                                                                     \
            std::fprintf(stderr, "fuzz invariant failed: %s (%s) at %s:%d\n", what, #cond, \
                         __FILE__, __LINE__);                                              \
            std::abort();                                                                  \
        }                                                                                  \
    } while (false)
