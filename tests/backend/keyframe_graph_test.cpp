// The keyframe graph: points follow pose corrections, compaction is lossless, and the
// System built on it is deterministic over many keyframes and atomic on bad input.

#include "backend/keyframe_graph.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "backend/system.hpp"
#include "core/undistorter.hpp"
#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/dataset_reader.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/run_pipeline.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

using test::ReadFile;

class KeyframeGraphTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDirAt>("parallax_keyframe_graph_test");
    synth::SynthOptions options;
    options.scene = "room";
    options.motion = "orbit";  // ~25 keyframes in 90 frames, neighbour edges
    options.frames = 90;
    synth::WriteSyntheticSequence(options, dir_->File("orbit"));
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static inline std::unique_ptr<test::TempDirAt> dir_;

  /// The first `count` frames of the orbit, undistorted, and their camera.
  static std::vector<DatasetFrame> Frames(int count, std::optional<PinholeCamera>* camera) {
    const auto reader = OpenDataset(dir_->File("orbit"), {});
    const Undistorter undistorter(reader->GetCamera(), reader->SuggestedRectification());
    camera->emplace(undistorter.OutputCamera());
    std::vector<DatasetFrame> frames;
    while (static_cast<int>(frames.size()) < count) {
      auto f = reader->Next();
      if (!f) break;
      f->image = undistorter.Apply(f->image);
      frames.push_back(std::move(*f));
    }
    return frames;
  }
};

std::shared_ptr<Keyframe> SmallKeyframe(std::int64_t id) {
  auto kf = std::make_shared<Keyframe>();
  kf->id = id;
  kf->image = ImageU8(8, 6, 100);
  kf->depth.width = 8;
  kf->depth.height = 6;
  kf->depth.pixel = {9, 20, 30};
  kf->depth.idepth = {0.5f, 1.0f, 2.0f};
  kf->depth.variance = {0.01f, 0.01f, 0.01f};
  kf->depth.confirmed = {1, 0, 1};
  return kf;
}

TEST(KeyframeGraph, PointsFollowACorrectionOfTheirKeyframe) {
  const PinholeCamera camera(8, 6, 10.0, 10.0, 4.0, 3.0);
  KeyframeGraph graph;
  graph.Upsert(SmallKeyframe(0), Sim3d());
  graph.Upsert(SmallKeyframe(5), Sim3d(SE3d(SO3d(), Eigen::Vector3d(1, 0, 0))));
  EXPECT_TRUE(graph.Poses().IsFixed(0));  // the first keyframe is the gauge
  EXPECT_FALSE(graph.Poses().IsFixed(5));
  const auto before = graph.MapPoints(camera);
  ASSERT_EQ(before.size(), 4u);  // unconfirmed hypotheses are not map points
  // Pixel 9 = (1, 1) at inverse depth 0.5: 2 units deep.
  EXPECT_NEAR(before[0].z(), 2.0f, 1e-6f);
  EXPECT_NEAR(before[0].x(), 2.0f * (1.0f - 4.0f) / 10.0f, 1e-6f);
  const Sim3d correction(2.0, SO3d::Exp(Eigen::Vector3d(0, 0.3, 0)), Eigen::Vector3d(0, 1, 0));
  graph.Poses().SetPose(5, correction);
  const auto after = graph.MapPoints(camera);
  for (std::size_t k = 0; k < 2; ++k) EXPECT_EQ(after[k], before[k]);  // keyframe 0 stayed
  const Sim3d S_w_5_before(SE3d(SO3d(), Eigen::Vector3d(1, 0, 0)));
  for (std::size_t k = 2; k < 4; ++k) {
    const Eigen::Vector3d p_kf = S_w_5_before.Inverse() * before[k].cast<double>();
    EXPECT_LT((after[k].cast<double>() - correction * p_kf).norm(), 1e-5);
  }
}

/// True when two similarities agree to 1e-9 (rotation, translation, scale).
bool SameSim3(const Sim3d& a, const Sim3d& b) {
  const Sim3d d = a.Inverse() * b;
  return d.Translation().norm() < 1e-9 && d.Rotation().Log().norm() < 1e-9 &&
         std::abs(d.Scale() - 1.0) < 1e-9;
}

// The real-time backend optimises a copy while mapping goes on: its result is taken back
// with the keyframes made meanwhile moved along, and a merge made in the copy carried over.
TEST(KeyframeGraph, AnOptimisedCopyIsAdoptedAndLaterKeyframesMoveWithTheirMap) {
  const auto at = [](double x, double s = 1.0) {
    return Sim3d(s, SO3d::Exp(Eigen::Vector3d(0, 0.1 * x, 0)), Eigen::Vector3d(x, 0, 0));
  };
  KeyframeGraph graph;
  graph.Upsert(SmallKeyframe(0), at(0));
  graph.Upsert(SmallKeyframe(1), at(1));
  graph.Upsert(SmallKeyframe(2), at(0.5), 1);  // a second map, its own gauge
  graph.AddEdge(PoseGraphEdge{0, 1, at(1), Matrix7d::Identity(), EdgeKind::kOdometry});
  KeyframeGraph copy = graph;  // the backend's
  const std::size_t edges_before = copy.Poses().Edges().size();
  // Meanwhile mapping adds a keyframe to each map and replaces keyframe 1's data.
  graph.Upsert(SmallKeyframe(3), at(2));
  graph.Upsert(SmallKeyframe(4), at(1.5), 1);
  auto replaced = SmallKeyframe(1);
  replaced->timestamp = 7.0;
  graph.Upsert(replaced, at(9));  // data replaced, pose kept
  // The backend moves keyframe 1, adds a loop edge and merges map 1 into map 0.
  const Sim3d moved = Sim3d(1.2, SO3d::Exp(Eigen::Vector3d(0.05, 0, 0)), Eigen::Vector3d(1, 1, 0));
  copy.Poses().SetPose(1, moved);
  const Sim3d S_0_1(0.5, SO3d::Exp(Eigen::Vector3d(0, 0, 0.2)), Eigen::Vector3d(0, 2, 0));
  copy.MergeMaps(1, 0, S_0_1);
  copy.AddEdge(PoseGraphEdge{1, 2, at(1), Matrix7d::Identity(), EdgeKind::kLoop});
  graph.AdoptOptimised(copy, edges_before);

  EXPECT_TRUE(SameSim3(graph.Pose(1), moved));
  EXPECT_EQ(graph.Get(1).timestamp, 7.0);  // the graph's data, the copy's pose
  // Keyframe 3 keeps its pose relative to keyframe 1, the newest of its map in the copy.
  EXPECT_TRUE(SameSim3(graph.Pose(3), moved * at(1).Inverse() * at(2)));
  // Map 1 was merged: keyframe 2 as the copy has it, keyframe 4 moved with it.
  EXPECT_EQ(graph.MapOf(2), 0);
  EXPECT_EQ(graph.MapOf(4), 0);
  EXPECT_EQ(graph.NumMaps(), 1);
  EXPECT_TRUE(SameSim3(graph.Pose(2), S_0_1 * at(0.5)));
  EXPECT_TRUE(SameSim3(graph.Pose(4), S_0_1 * at(1.5)));
  EXPECT_FALSE(graph.Poses().IsFixed(2));
  EXPECT_FALSE(graph.Poses().IsFixed(4));
  EXPECT_TRUE(graph.Poses().IsFixed(0));
  ASSERT_EQ(graph.Poses().Edges().size(), 2u);
  EXPECT_EQ(graph.Poses().Edges()[1].kind, EdgeKind::kLoop);
}

TEST_F(KeyframeGraphTest, CompactedKeyframesRebuildTheSameReference) {
  std::optional<PinholeCamera> K;
  const DatasetFrame first = Frames(1, &K).front();
  const PinholeCamera camera = *K;
  auto kf = std::make_shared<Keyframe>();
  kf->id = 3;
  kf->image = first.image;
  kf->frame = std::make_shared<const Frame>(3, 0.0, camera, first.image);
  kf->depth.width = first.image.Width();
  kf->depth.height = first.image.Height();
  for (int p = 0; p < first.image.Width() * first.image.Height(); p += 7) {
    kf->depth.pixel.push_back(p);
    kf->depth.idepth.push_back(0.5f + 0.001f * static_cast<float>(p % 500));
    kf->depth.variance.push_back(0.01f);
    kf->depth.confirmed.push_back(1);
  }
  ImageF idepth, variance;
  kf->depth.ToImages(&idepth, &variance);
  kf->reference = std::make_shared<const TrackingReference>(kf->frame, idepth, variance);
  KeyframeGraph graph;
  graph.Upsert(kf, Sim3d());
  const std::size_t full_bytes = graph.Bytes();
  graph.Compact({});
  EXPECT_TRUE(graph.Get(3).IsCompact());
  EXPECT_LT(graph.Bytes() * 3, full_bytes);
  const auto rebuilt = Materialize(graph.GetPtr(3), camera, {}, {});
  ASSERT_EQ(rebuilt->reference->NumLevels(), kf->reference->NumLevels());
  for (int l = 0; l < kf->reference->NumLevels(); ++l) {
    EXPECT_EQ(rebuilt->reference->Level(l).idepth, kf->reference->Level(l).idepth);
    EXPECT_EQ(rebuilt->reference->Level(l).intensity, kf->reference->Level(l).intensity);
  }
}

TEST_F(KeyframeGraphTest, RunsAreBitIdenticalOverManyKeyframesAndOutputsTheOptimisedGraph) {
  RunOptions a, b;
  a.dataset = b.dataset = dir_->File("orbit");
  a.out_dir = dir_->File("a");
  b.out_dir = dir_->File("b");
  const RunSummary s = RunDataset(a);
  RunDataset(b);
  EXPECT_GE(s.keyframes, 20);
  EXPECT_GE(s.optimisations, 10);
  EXPECT_GT(s.edges.neighbour, 0);
  for (const char* file : {"trajectory.txt", "trajectory_online.txt", "keyframes.txt", "map.ply"}) {
    EXPECT_EQ(ReadFile(a.out_dir + "/" + file), ReadFile(b.out_dir + "/" + file)) << file;
  }
  // Each keyframe's own frame is anchored at it: trajectory.txt holds the optimised keyframe
  // poses, which differ from what was reported live once the graph has moved them.
  const Trajectory keyframes = ReadTumTrajectory(a.out_dir + "/keyframes.txt");
  const Trajectory final_poses = ReadTumTrajectory(a.out_dir + "/trajectory.txt");
  const Trajectory online = ReadTumTrajectory(a.out_dir + "/trajectory_online.txt");
  ASSERT_EQ(final_poses.size(), online.size());
  int moved = 0;
  for (const StampedPose& kf : keyframes) {
    for (std::size_t k = 0; k < final_poses.size(); ++k) {
      if (final_poses[k].timestamp != kf.timestamp) continue;
      EXPECT_LT((final_poses[k].T_w_c.Translation() - kf.T_w_c.Translation()).norm(), 1e-6);
      moved += (online[k].T_w_c.Translation() - kf.T_w_c.Translation()).norm() > 1e-4;
    }
  }
  EXPECT_GT(moved, 0);
}

TEST_F(KeyframeGraphTest, AThrowingFrameLeavesTheSystemUnchanged) {
  std::optional<PinholeCamera> K;
  const std::vector<DatasetFrame> frames = Frames(40, &K);
  const PinholeCamera camera = *K;
  System plain(camera), interrupted(camera);
  const ImageU8 wrong_size(camera.Width() / 2, camera.Height());
  for (int i = 0; i < static_cast<int>(frames.size()); ++i) {
    const DatasetFrame& f = frames[static_cast<std::size_t>(i)];
    const FrameResult expected = plain.ProcessFrame(f.image, f.timestamp);
    if (i % 9 == 4) {
      EXPECT_THROW(interrupted.ProcessFrame(wrong_size, f.timestamp), std::invalid_argument);
      EXPECT_THROW(interrupted.ProcessFrame(f.image, std::nan("")), std::invalid_argument);
    }
    const FrameResult got = interrupted.ProcessFrame(f.image, f.timestamp);
    ASSERT_EQ(got.T_w_c.has_value(), expected.T_w_c.has_value()) << "frame " << i;
    if (got.T_w_c) {
      EXPECT_EQ(got.T_w_c->Translation(), expected.T_w_c->Translation()) << "frame " << i;
    }
  }
  EXPECT_EQ(interrupted.FramesProcessed(), plain.FramesProcessed());
  EXPECT_EQ(interrupted.Keyframes().size(), plain.Keyframes().size());
}

}  // namespace
}  // namespace parallax
