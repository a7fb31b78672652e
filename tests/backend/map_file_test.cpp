// Map files: an exact round trip, rejection of damaged or foreign files, saving that changes
// nothing, and a loaded map that relocalises a later part of the sequence in its world frame.

#include "backend/map_file.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "backend/system.hpp"
#include "core/crc32.hpp"
#include "tests/tracking/render_fixture.hpp"
#include "tools/synth/motion.hpp"
#include "tools/synth/scene.hpp"

namespace parallax {
namespace {

const synth::Scene& Room() {
  static const synth::Scene scene = synth::MakeScene("room", 1);
  return scene;
}

/// Orbit view k of the room (30 frames/s).
ImageU8 View(int k) {
  return test::RenderTestImage(Room(),
                               synth::CameraPose(synth::Motion::kOrbit, Room().rig, k / 30.0, 5.0));
}

/// Frames [first, last) of the orbit into `system`; returns the results.
std::vector<FrameResult> Feed(System* system, int first, int last) {
  std::vector<FrameResult> results;
  for (int k = first; k < last; ++k) results.push_back(system->ProcessFrame(View(k), k / 30.0));
  return results;
}

/// One system fed 70 orbit frames, shared by the tests that only read its map.
const std::vector<std::uint8_t>& SavedOrbitMap() {
  static const std::vector<std::uint8_t> bytes = [] {
    System system(test::TestCamera());
    Feed(&system, 0, 70);
    return system.EncodeMapBytes();
  }();
  return bytes;
}

/// The CRC is recomputed after an edit, so that the content checks (not the checksum) are
/// what rejects it.
void ResealCrc(std::vector<std::uint8_t>* bytes) {
  const std::uint32_t crc = Crc32(std::span(*bytes).first(bytes->size() - 4));
  std::memcpy(bytes->data() + bytes->size() - 4, &crc, 4);
}

void ExpectRejected(const std::vector<std::uint8_t>& bytes, const std::string& why) {
  try {
    DecodeMap(bytes, "orbit.pxmap");
    ADD_FAILURE() << "accepted: " << why;
  } catch (const MapFileError& e) {
    EXPECT_NE(std::string(e.what()).find("orbit.pxmap: byte "), std::string::npos) << e.what();
  }
}

TEST(MapFile, RoundTripIsExact) {
  const MapContents map = DecodeMap(SavedOrbitMap(), "orbit.pxmap");
  ASSERT_GE(map.graph.Size(), 4u);
  EXPECT_EQ(map.next_frame_id, 70);
  // Encoding what was decoded gives the same bytes: every field survives.
  std::map<std::int64_t, const OrbFeatures*> features;
  for (const auto& [id, f] : map.features) features[id] = &f;
  EXPECT_EQ(EncodeMap(map.camera, map.graph, features, map.next_frame_id, map.next_map_id),
            SavedOrbitMap());
  const KeyframeGraph& g = map.graph;
  EXPECT_TRUE(g.Poses().IsFixed(g.Ids().front()));
  EXPECT_GE(g.CountEdges().odometry, static_cast<int>(g.Size()) - 1);
  for (const std::int64_t id : g.Ids()) {
    EXPECT_TRUE(g.Get(id).IsCompact());
    EXPECT_GT(g.Get(id).depth.Size(), 1000u);
    EXPECT_GT(map.features.at(id).Size(), 100u);
  }
}

TEST(MapFile, DamagedFilesAreRejectedWithTheByteOfTheProblem) {
  const std::vector<std::uint8_t>& good = SavedOrbitMap();
  for (const std::size_t size :
       {std::size_t{0}, std::size_t{7}, std::size_t{12}, good.size() / 2, good.size() - 1}) {
    ExpectRejected(
        std::vector<std::uint8_t>(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(size)),
        "truncated to " + std::to_string(size));
  }
  std::vector<std::uint8_t> flipped = good;
  flipped[good.size() / 3] ^= 0x10;
  ExpectRejected(flipped, "a flipped bit");
  std::vector<std::uint8_t> magic = good;
  magic[0] = 'Q';
  ExpectRejected(magic, "another magic");
  std::vector<std::uint8_t> version = good;
  version[8] = 2;
  ResealCrc(&version);
  ExpectRejected(version, "format version 2");
  // The first keyframe's map id (after magic, version, camera 40 bytes, counters 12, count
  // 4, id 8, timestamp 8) set beyond next_map_id, with a valid checksum.
  std::vector<std::uint8_t> map_id = good;
  map_id[8 + 4 + 40 + 12 + 4 + 16] = 0x7f;
  ResealCrc(&map_id);
  ExpectRejected(map_id, "map id out of range");
  // The camera's fx (first intrinsic) negative, with a valid checksum.
  std::vector<std::uint8_t> focal = good;
  const double negative = -525.0;
  std::memcpy(focal.data() + 8 + 4 + 8, &negative, sizeof(double));
  ResealCrc(&focal);
  ExpectRejected(focal, "negative focal length");
  // The last edge's information (49 doubles before its kind and robust bytes and the CRC)
  // made asymmetric, then indefinite, with a valid checksum: found by fuzz_map, which
  // crashed on the exception the pose graph threw for it.
  const std::size_t information = good.size() - 4 - 2 - 49 * sizeof(double);
  std::vector<std::uint8_t> asymmetric = good;
  const double large = 1e6;
  std::memcpy(asymmetric.data() + information + sizeof(double), &large, sizeof(double));
  ResealCrc(&asymmetric);
  ExpectRejected(asymmetric, "asymmetric edge information");
  std::vector<std::uint8_t> indefinite = good;
  const double minus = -1.0;
  std::memcpy(indefinite.data() + information, &minus, sizeof(double));
  ResealCrc(&indefinite);
  ExpectRejected(indefinite, "indefinite edge information");
}

TEST(MapFile, AMapOfAnotherCameraOrIntoAUsedSystemIsRefusedAndChangesNothing) {
  System other(PinholeCamera(640, 480, 500.0, 500.0, 319.5, 239.5));
  EXPECT_THROW(other.LoadMapBytes(SavedOrbitMap(), "orbit.pxmap"), MapFileError);
  EXPECT_FALSE(other.AwaitingRelocalisation());
  System used(test::TestCamera());
  Feed(&used, 0, 2);
  EXPECT_THROW(used.LoadMapBytes(SavedOrbitMap(), "orbit.pxmap"), std::logic_error);
  EXPECT_EQ(used.FramesProcessed(), 2);
  System fresh(test::TestCamera());
  EXPECT_THROW(fresh.EncodeMapBytes(), std::logic_error);  // nothing initialised yet
  EXPECT_THROW(fresh.LoadMap("/nonexistent/orbit.pxmap"), MapFileError);
}

TEST(MapFile, SavingChangesNothingInTheRunningSystem) {
  System plain(test::TestCamera());
  System saved(test::TestCamera());
  Feed(&plain, 0, 40);
  Feed(&saved, 0, 40);
  ASSERT_FALSE(saved.EncodeMapBytes().empty());
  Feed(&plain, 40, 70);
  Feed(&saved, 40, 70);
  const auto a = plain.Trajectory();
  const auto b = saved.Trajectory();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].T_w_c.Translation(), b[k].T_w_c.Translation()) << "frame " << k;
  }
  // ... and the second save is the same map the shared one is.
  EXPECT_EQ(saved.EncodeMapBytes(), SavedOrbitMap());
}

TEST(MapFile, ALoadedMapRelocalisesTheRestOfTheSequenceInItsWorldFrame) {
  System single(test::TestCamera());
  Feed(&single, 0, 110);
  System loaded(test::TestCamera());
  loaded.LoadMapBytes(SavedOrbitMap(), "orbit.pxmap");
  EXPECT_TRUE(loaded.AwaitingRelocalisation());
  const std::vector<FrameResult> results = Feed(&loaded, 70, 110);
  int relocalised_at = -1;
  for (std::size_t k = 0; k < results.size() && relocalised_at < 0; ++k) {
    const auto& e = results[k].events;
    if (std::any_of(e.begin(), e.end(),
                    [](const SystemEvent& s) { return s.kind == SystemEvent::Kind::kRelocalised; }))
      relocalised_at = static_cast<int>(k);
  }
  ASSERT_GE(relocalised_at, 0);
  RecordProperty("relocalised_at_frame", relocalised_at);
  EXPECT_LE(relocalised_at, 4);  // within 5 frames
  EXPECT_EQ(loaded.Backend().maps_started, 0);
  // Frame ids continue after the map's; the poses are those of the uninterrupted run (the
  // same world frame and scale) to within 2 cm on a 5 m orbit.
  const auto poses = loaded.Trajectory();
  ASSERT_GE(poses.size(), 35u);
  EXPECT_GE(poses.front().frame_id, 70);
  std::map<std::int64_t, SE3d> reference;
  for (const FramePose& p : single.Trajectory()) reference[p.frame_id] = p.T_w_c;
  double sq = 0.0;
  for (const FramePose& p : poses) {
    sq += (p.T_w_c.Translation() - reference.at(p.frame_id).Translation()).squaredNorm();
  }
  const double rms = std::sqrt(sq / static_cast<double>(poses.size()));
  RecordProperty("rms_difference", std::to_string(rms));
  EXPECT_LT(rms, 0.02);
}

}  // namespace
}  // namespace parallax
