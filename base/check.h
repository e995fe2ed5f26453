// Our own broken invariants: abort with a message. Never used for user input
// (that is Diagnostics) or for I/O (that is Result).
#pragma once

#include <cstdio>
#include <cstdlib>

#define SMTCAL_CHECK(cond, msg)                                                   \
  do {                                                                            \
    if (!(cond)) {                                                                \
      std::fprintf(stderr, "smtcal: internal error at %s:%d: %s (%s)\n", __FILE__, \
                   __LINE__, msg, #cond);                                         \
      std::abort();                                                               \
    }                                                                             \
  } while (0)
