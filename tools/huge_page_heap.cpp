#include "tools/huge_page_heap.hpp"

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace parallax {
namespace {

constexpr const char* kTunable = "glibc.malloc.hugetlb";

std::string ReadThpSetting() {
  std::ifstream file("/sys/kernel/mm/transparent_hugepage/enabled");
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

}  // namespace

HugePageRestart DecideHugePageRestart(const char* tunables, const char* opt_in,
                                      const char* thp_enabled) {
  if (tunables != nullptr && std::strstr(tunables, kTunable) != nullptr)
    return HugePageRestart::kNotNeeded;
  if (opt_in != nullptr && std::strcmp(opt_in, "0") == 0) return HugePageRestart::kOptedOut;
  // "always [madvise] never": the bracketed word is the kernel's setting. glibc asks for
  // huge pages with madvise, which both "always" and "madvise" honour.
  if (thp_enabled == nullptr || std::strstr(thp_enabled, "[never]") != nullptr ||
      std::strchr(thp_enabled, '[') == nullptr)
    return HugePageRestart::kUnavailable;
  return HugePageRestart::kRestart;
}

bool HeapUsesHugePages(const char* tunables) {
  if (tunables == nullptr) return false;
  // The last setting of a tunable is the one glibc keeps; "=0" turns it off.
  const std::string text = tunables;
  const std::string key = std::string(kTunable) + "=";
  const std::size_t at = text.rfind(key);
  if (at == std::string::npos || (at > 0 && text[at - 1] != ':')) return false;
  const std::size_t value = at + key.size();
  return value < text.size() && text[value] != '0';
}

std::string TunablesWithHugePages(const char* tunables) {
  std::string value = tunables != nullptr ? tunables : "";
  if (!value.empty()) value += ':';
  return value + kTunable + "=1";
}

void RestartWithHugePageHeap(char** argv) {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  const std::string thp = ReadThpSetting();
  if (DecideHugePageRestart(tunables, std::getenv("PARALLAX_HUGE_PAGES"), thp.c_str()) !=
      HugePageRestart::kRestart)
    return;
  const std::string before = tunables != nullptr ? tunables : "";
  const bool was_set = tunables != nullptr;
  if (setenv("GLIBC_TUNABLES", TunablesWithHugePages(tunables).c_str(), 1) != 0) return;
  // The resolved path, not /proc/self/exe, so that the process keeps its name ("exe"
  // otherwise, in ps, top and perf).
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  execv(error ? "/proc/self/exe" : self.c_str(), argv);
  // Not executed again (no /proc, say): go on with the heap as it is, environment restored.
  if (was_set) {
    setenv("GLIBC_TUNABLES", before.c_str(), 1);
  } else {
    unsetenv("GLIBC_TUNABLES");
  }
}

}  // namespace parallax
