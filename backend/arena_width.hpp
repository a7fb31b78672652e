#pragma once
// The TBB concurrency the real-time mode's arenas get (docs/realtime.md, thread budget).

namespace parallax {

#if defined(__SANITIZE_THREAD__)
inline constexpr bool kThreadSanitizer = true;  // g++
#elif defined(__has_feature)
inline constexpr bool kThreadSanitizer = __has_feature(thread_sanitizer);  // clang
#else
inline constexpr bool kThreadSanitizer = false;
#endif

/// The TBB concurrency an arena asked for `threads` gets: `threads`, or 1 in a
/// ThreadSanitizer build (libtbb is not instrumented, so TSan cannot see the synchronisation
/// of TBB's worker threads and reports their parallel loops as races).
constexpr int ArenaWidth(int threads) { return kThreadSanitizer ? 1 : threads; }

}  // namespace parallax
