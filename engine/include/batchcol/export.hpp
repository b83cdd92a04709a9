// BATCHCOL_API marks the public API. The library is compiled with -fvisibility=hidden and
// -fvisibility-inlines-hidden, so only what is marked here (and what the marked classes contain) is visible to
// users when batchcol is built as a shared library; the kernels, the broad phase and engine/src stay internal.
// Exception types must be marked: their type information has to be the same object across library boundaries for a
// user's catch (InputError&) to match. For a static library the marks change nothing.
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define BATCHCOL_API __attribute__((visibility("default")))
#else
#define BATCHCOL_API
#endif
