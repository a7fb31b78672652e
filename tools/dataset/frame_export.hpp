#pragma once
// The frames as the engine sees them, written out for another system (a peer in parallax
// bench, docs/benchmarks.md): grey, photometrically corrected when the dataset has a
// calibration, undistorted to the engine's pinhole camera.

#include <string>

#include "tools/dataset/dataset_reader.hpp"

namespace parallax {

struct FrameExportOptions {
  std::string dataset;
  DatasetOptions dataset_options;
  std::string out_dir;      ///< created; receives images/, times.txt and camera.txt
  int max_frames = 0;       ///< the first N frames (0: all)
  bool photometric = true;  ///< apply the dataset's photometric calibration, as `run` does
};

struct FrameExportSummary {
  int frames = 0;      ///< written
  int unreadable = 0;  ///< skipped (and left out of times.txt), as `run` skips them
};

/// Writes out_dir/images/NNNNNN.png (6 digits, frame index), out_dir/times.txt ("NNNNNN
/// timestamp" per written frame) and out_dir/camera.txt ("fx fy cx cy" of the pinhole
/// camera, then "width height"). Throws InputError for an unreadable dataset or an output
/// that cannot be written.
FrameExportSummary ExportFrames(const FrameExportOptions& options);

}  // namespace parallax
