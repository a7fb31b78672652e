#include "backend/orb_matching.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <opencv2/features2d.hpp>
#include <random>
#include <vector>

namespace parallax {
namespace {

/// Descriptors with few bits set, so that many pairs share a distance and the ties decide.
std::vector<OrbDescriptor> SparseDescriptors(std::size_t n, std::mt19937* rng) {
  std::uniform_int_distribution<int> bit(0, 255);
  std::vector<OrbDescriptor> d(n);
  for (OrbDescriptor& x : d) {
    x = {};
    for (int k = 0; k < 4; ++k) {
      const int b = bit(*rng);
      x[static_cast<std::size_t>(b / 64)] |= std::uint64_t{1} << (b % 64);
    }
  }
  return d;
}

std::vector<OrbDescriptor> DenseDescriptors(std::size_t n, std::mt19937_64* rng) {
  std::vector<OrbDescriptor> d(n);
  for (OrbDescriptor& x : d) x = {(*rng)(), (*rng)(), (*rng)(), (*rng)()};
  return d;
}

cv::Mat ToRows(const std::vector<OrbDescriptor>& d) {
  cv::Mat rows(static_cast<int>(d.size()), 32, CV_8U);
  for (std::size_t i = 0; i < d.size(); ++i)
    std::memcpy(rows.ptr(static_cast<int>(i)), d[i].data(), sizeof(OrbDescriptor));
  return rows;
}

/// OpenCV's brute-force k = 2 matcher, the reference the two-view start used before.
void ExpectSameAsOpenCv(const std::vector<OrbDescriptor>& query,
                        const std::vector<OrbDescriptor>& train) {
  std::vector<std::vector<cv::DMatch>> knn;
  cv::BFMatcher(cv::NORM_HAMMING).knnMatch(ToRows(query), ToRows(train), knn, 2);
  const std::vector<NearestTwo> ours = NearestTwoByHamming(query, train);
  ASSERT_EQ(ours.size(), query.size());
  ASSERT_EQ(knn.size(), query.size());
  for (std::size_t i = 0; i < query.size(); ++i) {
    ASSERT_EQ(knn[i].size(), train.size() >= 2 ? 2u : train.size()) << i;
    ASSERT_FALSE(knn[i].empty());
    EXPECT_EQ(ours[i].nearest, knn[i][0].trainIdx) << i;
    EXPECT_EQ(static_cast<float>(ours[i].nearest_distance), knn[i][0].distance) << i;
    if (knn[i].size() == 2) {
      EXPECT_EQ(ours[i].second, knn[i][1].trainIdx) << i;
      EXPECT_EQ(static_cast<float>(ours[i].second_distance), knn[i][1].distance) << i;
    } else {
      EXPECT_EQ(ours[i].second, -1) << i;
    }
  }
}

TEST(OrbMatching, NearestTwoAreOpenCvsIncludingTies) {
  std::mt19937 rng(3);
  std::mt19937_64 rng64(5);
  // Sparse: distances 0-8, so ties between the nearest and the second are the rule.
  ExpectSameAsOpenCv(SparseDescriptors(700, &rng), SparseDescriptors(900, &rng));
  ExpectSameAsOpenCv(DenseDescriptors(300, &rng64), DenseDescriptors(1200, &rng64));
  // Exact duplicates in the train set: the lower index first, its twin second.
  std::vector<OrbDescriptor> train = SparseDescriptors(50, &rng);
  train.push_back(train[7]);
  train.push_back(train[7]);
  ExpectSameAsOpenCv({train[7], train[3]}, train);
  const std::vector<NearestTwo> dup = NearestTwoByHamming({{train[7]}}, train);
  EXPECT_EQ(dup[0].nearest, 7);
  EXPECT_EQ(dup[0].second, 50);
  EXPECT_EQ(dup[0].second_distance, 0);
  // One train descriptor: no second.
  ExpectSameAsOpenCv(SparseDescriptors(20, &rng), SparseDescriptors(1, &rng));
}

TEST(OrbMatching, TheFastPathEqualsItsScalarTwin) {
  std::mt19937 rng(11);
  std::mt19937_64 rng64(13);
  for (const auto& [query, train] :
       {std::pair{SparseDescriptors(513, &rng), SparseDescriptors(777, &rng)},
        std::pair{DenseDescriptors(1000, &rng64), DenseDescriptors(1500, &rng64)}}) {
    const std::vector<NearestTwo> fast = NearestTwoByHamming(query, train);
    const std::vector<NearestTwo> scalar = NearestTwoByHammingScalar(query, train);
    ASSERT_EQ(fast.size(), scalar.size());
    for (std::size_t i = 0; i < fast.size(); ++i) {
      EXPECT_EQ(fast[i].nearest, scalar[i].nearest) << i;
      EXPECT_EQ(fast[i].nearest_distance, scalar[i].nearest_distance) << i;
      EXPECT_EQ(fast[i].second, scalar[i].second) << i;
      EXPECT_EQ(fast[i].second_distance, scalar[i].second_distance) << i;
      // The pair really is the nearest two: nothing else is closer than the second.
      for (std::size_t j = 0; j < train.size(); ++j) {
        if (static_cast<int>(j) == fast[i].nearest || static_cast<int>(j) == fast[i].second)
          continue;
        ASSERT_GE(Hamming(query[i], train[j]), fast[i].second_distance) << i << " " << j;
      }
    }
  }
  EXPECT_TRUE(NearestTwoByHamming({}, DenseDescriptors(3, &rng64)).empty());
  const std::vector<NearestTwo> none = NearestTwoByHamming(DenseDescriptors(2, &rng64), {});
  ASSERT_EQ(none.size(), 2u);
  EXPECT_EQ(none[0].nearest, -1);
  EXPECT_EQ(none[0].second, -1);
}

}  // namespace
}  // namespace parallax
