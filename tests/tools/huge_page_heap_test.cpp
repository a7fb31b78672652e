#include "tools/huge_page_heap.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>

#include "temp_dir.hpp"

namespace parallax {
namespace {

using test::TempDir;

constexpr const char* kMadvise = "always [madvise] never\n";

TEST(HugePageHeap, RestartsOnlyWhenTheTunableIsMissingAndTheKernelCanHonourIt) {
  EXPECT_EQ(DecideHugePageRestart(nullptr, nullptr, kMadvise), HugePageRestart::kRestart);
  EXPECT_EQ(DecideHugePageRestart("glibc.malloc.arena_max=2", nullptr, kMadvise),
            HugePageRestart::kRestart);
  EXPECT_EQ(DecideHugePageRestart(nullptr, nullptr, "[always] madvise never\n"),
            HugePageRestart::kRestart);
  EXPECT_EQ(DecideHugePageRestart(nullptr, "1", kMadvise), HugePageRestart::kRestart);
  // Set already (by the user, or by this program before it executed itself again): the
  // restart happens at most once and never overrides the user's own choice.
  EXPECT_EQ(DecideHugePageRestart("glibc.malloc.hugetlb=1", nullptr, kMadvise),
            HugePageRestart::kNotNeeded);
  EXPECT_EQ(DecideHugePageRestart("glibc.malloc.hugetlb=0", nullptr, kMadvise),
            HugePageRestart::kNotNeeded);
  EXPECT_EQ(DecideHugePageRestart(nullptr, "0", kMadvise), HugePageRestart::kOptedOut);
  EXPECT_EQ(DecideHugePageRestart(nullptr, nullptr, "always madvise [never]\n"),
            HugePageRestart::kUnavailable);
  EXPECT_EQ(DecideHugePageRestart(nullptr, nullptr, ""), HugePageRestart::kUnavailable);
  EXPECT_EQ(DecideHugePageRestart(nullptr, nullptr, nullptr), HugePageRestart::kUnavailable);
}

TEST(HugePageHeap, TheTunableIsAddedToTheUsersOwn) {
  EXPECT_EQ(TunablesWithHugePages(nullptr), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(TunablesWithHugePages(""), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(TunablesWithHugePages("glibc.malloc.arena_max=2"),
            "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1");
  EXPECT_TRUE(HeapUsesHugePages("glibc.malloc.hugetlb=1"));
  EXPECT_TRUE(HeapUsesHugePages(TunablesWithHugePages("glibc.malloc.arena_max=2").c_str()));
  EXPECT_FALSE(HeapUsesHugePages(nullptr));
  EXPECT_FALSE(HeapUsesHugePages("glibc.malloc.arena_max=2"));
  EXPECT_FALSE(HeapUsesHugePages("glibc.malloc.hugetlb=0"));
  EXPECT_FALSE(HeapUsesHugePages("glibc.malloc.hugetlb=1:glibc.malloc.hugetlb=0"));
  EXPECT_FALSE(HeapUsesHugePages("glibc.malloc.xhugetlb=1"));
}

// The command itself: stats.json says whether the run's heap had huge pages, which it has
// unless the kernel cannot give them or the user opted out.
TEST(HugePageHeap, TheCommandRunsWithTheTunableUnlessOptedOut) {
  const TempDir dir;
  const std::string binary = PARALLAX_BINARY;
  const std::string data = dir.File("room");
  ASSERT_EQ(std::system((binary + " synth room " + data +
                         " --motion shake --frames 6 --width 96 --height 72 > /dev/null")
                            .c_str()),
            0);
  const auto run = [&](const std::string& env, const std::string& out) {
    const std::string command =
        "env -u GLIBC_TUNABLES " + env + " " + binary + " run " + data + " --out " + out;
    EXPECT_EQ(std::system((command + " > /dev/null 2>&1").c_str()), 0) << command;
    return nlohmann::json::parse(test::ReadFile(out + "/stats.json"))["heap_huge_pages"];
  };
  const bool kernel_has_them =
      DecideHugePageRestart(
          nullptr, nullptr,
          test::ReadFile("/sys/kernel/mm/transparent_hugepage/enabled").c_str()) ==
      HugePageRestart::kRestart;
  EXPECT_EQ(run("", dir.File("default")), kernel_has_them);
  EXPECT_EQ(run("PARALLAX_HUGE_PAGES=0", dir.File("opted_out")), false);
  EXPECT_EQ(run("GLIBC_TUNABLES=glibc.malloc.hugetlb=0", dir.File("user_off")), false);
}

}  // namespace
}  // namespace parallax
