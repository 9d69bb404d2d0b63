// NIPDEM_TARGET_CLONES: build a hot kernel for AVX-512, AVX2 and generic x86-64 and pick one at
// load time (GCC/clang target_clones: an ifunc whose resolver runs while the program is being
// relocated). Under ThreadSanitizer the resolver would be instrumented and run before the TSan
// runtime exists (a crash at start-up), so a TSan build keeps only the generic version: it checks
// the threading, which is the same for every clone.
#pragma once

#if defined(__SANITIZE_THREAD__)
#define NIPDEM_NO_TARGET_CLONES 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define NIPDEM_NO_TARGET_CLONES 1
#endif
#endif

#if defined(NIPDEM_NO_TARGET_CLONES) || !(defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)))
#define NIPDEM_TARGET_CLONES
#else
#define NIPDEM_TARGET_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#endif
