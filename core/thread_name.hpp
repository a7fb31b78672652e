#pragma once
// Names for the threads the engine and the CLI own, so that profilers, debuggers and
// `top -H` tell them apart (docs/realtime.md, "Thread budget").

namespace parallax {

/// Names the calling thread (Linux: at most 15 characters are kept; elsewhere a no-op).
/// Failing only leaves the inherited name.
void NameThisThread(const char* name);

}  // namespace parallax
