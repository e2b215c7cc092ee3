// collision/assert.h -- CDLAB_ASSERT for programmer errors; on in Debug and RelWithDebInfo.
#pragma once

#include <cstdio>
#include <cstdlib>

#ifdef CDLAB_ENABLE_ASSERTS
#define CDLAB_ASSERT(cond, msg)                                                              \
    do {                                                                                     \
        if (!(cond)) {                                                                       \
            std::fprintf(stderr, "%s:%d: assertion failed: %s: %s\n", __FILE__, __LINE__, \
                         #cond, msg);                                                        \
            std::abort();                                                                    \
        }                                                                                    \
    } while (false)
#else
#define CDLAB_ASSERT(cond, msg) \
    do {                        \
        (void)sizeof(cond);     \
    } while (false)
#endif
