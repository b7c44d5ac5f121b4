// oocsimp — the mark of the public API. The libraries are compiled with hidden symbols
// by default (CMake's CXX_VISIBILITY_PRESET hidden), so that a shared liboocsimp.so
// exports what include/oocsimp/ declares and nothing of its internals: every function
// and class of the API that the library defines carries OOCSIMP_API. Plain data
// (structs of fields and inline members) needs none.
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define OOCSIMP_API __attribute__((visibility("default")))
#else
#define OOCSIMP_API
#endif
