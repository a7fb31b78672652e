#pragma once
// Transparent huge pages for the `parallax` process's heap (docs/benchmarks.md, "Huge pages
// for the heap"). glibc backs its heap with huge pages only when `glibc.malloc.hugetlb=1`
// is in GLIBC_TUNABLES, which it reads once, when a process starts; so the command sets it
// and executes itself again before doing anything else.

#include <string>

namespace parallax {

/// What `RestartWithHugePageHeap` decides from the environment.
enum class HugePageRestart {
  kNotNeeded,    ///< the tunable is already set (by the user or an earlier start)
  kOptedOut,     ///< PARALLAX_HUGE_PAGES=0
  kUnavailable,  ///< the kernel's transparent huge pages are off ("never")
  kRestart,      ///< set the tunable and execute again
};

/// The decision for a GLIBC_TUNABLES value (nullptr when unset), a PARALLAX_HUGE_PAGES value
/// (nullptr when unset) and the kernel's /sys/kernel/mm/transparent_hugepage/enabled text.
HugePageRestart DecideHugePageRestart(const char* tunables, const char* opt_in,
                                      const char* thp_enabled);

/// GLIBC_TUNABLES with the heap's huge pages added to what the user set (nullptr: unset).
std::string TunablesWithHugePages(const char* tunables);

/// Whether a GLIBC_TUNABLES value (nullptr when unset) asks glibc for a huge-page heap.
bool HeapUsesHugePages(const char* tunables);

/// Executes this program (/proc/self/exe) again with `argv` and the tunable set when
/// `DecideHugePageRestart` says so; returns (the process goes on as it is) otherwise or when that
/// fails. Call it first in main, before any thread or allocation that should use the new heap.
void RestartWithHugePageHeap(char** argv);

}  // namespace parallax
