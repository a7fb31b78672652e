// LoopCloser on its own: a revisit of a rendered room, with drift injected along the keyframe
// chain, is verified (ORB matches lifted with depth, Sim(3) RANSAC, direct alignment both
// ways) and closed, and the optimised graph takes the drift out.

#include "backend/loop_closer.hpp"

#include <gtest/gtest.h>

#include "tests/backend/revisit_fixture.hpp"

namespace parallax {
namespace {

double RotationDeg(const Sim3d& S) { return S.Rotation().Log().norm() * 180.0 / 3.14159265358979; }

TEST(LoopCloser, ARevisitWithDriftIsClosedByItsTrueRelativePoseAndTheDriftRemoved) {
  SystemOptions options;
  test::Revisit r = test::MakeRevisit(options);
  GraphBackend backend(options.backend, r.build);
  const Sim3d before = r.graph.Pose(0).Inverse() * r.graph.Pose(r.revisit_id);
  LoopClosureOptions loop = options.loop_closure;
  loop.consistency = 1;  // one revisiting keyframe (the gate itself is tested below)
  LoopCloser closer(loop, r.recognizer.get(), r.build.camera);
  const LoopReport report = closer.KeyframeFinished(&r.graph, &backend, r.revisit_id);
  ASSERT_TRUE(report.loop_keyframe.has_value()) << testing::PrintToString(report.rejections);
  EXPECT_EQ(*report.loop_keyframe, 0);
  EXPECT_GE(report.ransac_inliers, 30);
  ASSERT_TRUE(report.optimisation.has_value());
  // The loop edge is the true relative pose (metric ground-truth depth: scale 1).
  const PoseGraphEdge& edge = r.graph.Poses().Edges().back();
  ASSERT_EQ(edge.kind, EdgeKind::kLoop);
  const Sim3d S_loop = edge.i == 0 ? edge.S_i_j : edge.S_i_j.Inverse();
  const Sim3d loop_error = r.S_first_revisit_true.Inverse() * S_loop;
  EXPECT_LT(RotationDeg(loop_error), 0.1);            // measured 0.003
  EXPECT_LT(loop_error.Translation().norm(), 0.005);  // metres; measured 0.0002
  EXPECT_LT(std::abs(std::log(loop_error.Scale())), 0.01);
  // The chain's drift at the revisit (1.4 degrees and 8 cm by construction) is pulled back.
  const Sim3d after = r.graph.Pose(0).Inverse() * r.graph.Pose(r.revisit_id);
  const Sim3d error_before = r.S_first_revisit_true.Inverse() * before;
  const Sim3d error_after = r.S_first_revisit_true.Inverse() * after;
  EXPECT_GT(RotationDeg(error_before), 1.0);
  EXPECT_LT(RotationDeg(error_after), 0.25 * RotationDeg(error_before));
  EXPECT_LT(error_after.Translation().norm(), 0.25 * error_before.Translation().norm());
}

TEST(LoopCloser, ASingleRevisitingKeyframeIsNotEnoughUnderTheConsistencyGate) {
  SystemOptions options;
  test::Revisit r = test::MakeRevisit(options);
  GraphBackend backend(options.backend, r.build);
  ASSERT_EQ(options.loop_closure.consistency, 2);
  LoopCloser closer(options.loop_closure, r.recognizer.get(), r.build.camera);
  const LoopReport report = closer.KeyframeFinished(&r.graph, &backend, r.revisit_id);
  EXPECT_GE(report.candidates, 1);
  EXPECT_EQ(report.consistent, 0);
  EXPECT_FALSE(report.loop_keyframe.has_value());
  EXPECT_EQ(r.graph.CountEdges().loop, 0);
}

}  // namespace
}  // namespace parallax
