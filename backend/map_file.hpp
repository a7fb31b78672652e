#pragma once
// Map files: the whole map (keyframes with image and frozen depth, poses, gauges, map ids,
// edges, ORB features for place recognition) in a versioned little-endian binary format with
// a CRC-32, written atomically (docs/map_files.md).

#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "backend/keyframe_graph.hpp"
#include "backend/orb_features.hpp"
#include "core/pinhole_camera.hpp"

namespace parallax {

/// A map file that cannot be read, is corrupt, truncated, of another version or does not
/// fit the system; the message names the file and the byte where the problem was found.
class MapFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Everything a map file holds. Keyframes in `graph` are compact (no frame pyramid or
/// tracking reference; Materialize rebuilds them).
struct MapContents {
  /// The ideal pinhole camera the keyframe images were taken with (after undistortion).
  PinholeCamera camera{1, 1, 1.0, 1.0, 0.0, 0.0};
  KeyframeGraph graph;
  /// ORB features of every keyframe (its vectors are recomputed with the running
  /// vocabulary, so a map does not depend on the vocabulary it was made with).
  std::map<std::int64_t, OrbFeatures> features;
  /// The id the next frame gets (every keyframe id is below it), and the next map's id.
  std::int64_t next_frame_id = 0;
  int next_map_id = 1;
};

/// The file's bytes (format: docs/map_files.md). `graph` must have at least one keyframe
/// and every keyframe an entry in `features`.
std::vector<std::uint8_t> EncodeMap(const PinholeCamera& camera, const KeyframeGraph& graph,
                                    const std::map<std::int64_t, const OrbFeatures*>& features,
                                    std::int64_t next_frame_id, int next_map_id);

/// Parses and validates a map (every count, index, pose and edge is checked before it is
/// used); throws MapFileError naming `source` and the byte offset.
MapContents DecodeMap(std::span<const std::uint8_t> bytes, const std::string& source);

/// Writes atomically (temporary file + rename); throws MapFileError naming the path.
void WriteMapFile(const std::string& path, std::span<const std::uint8_t> bytes);
/// Reads and decodes; throws MapFileError naming the path.
MapContents ReadMapFile(const std::string& path);

}  // namespace parallax
