// Symbol visibility of the pullout client library. The library is built with hidden visibility;
// only what is marked PULLOUT_CLIENT_EXPORT is part of its ABI.
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define PULLOUT_CLIENT_EXPORT __attribute__((visibility("default")))
#else
#define PULLOUT_CLIENT_EXPORT
#endif
