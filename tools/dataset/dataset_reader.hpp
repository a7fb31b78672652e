#pragma once
// Streaming readers for the supported dataset layouts (docs/datasets.md).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.hpp"
#include "core/image.hpp"
#include "core/undistorter.hpp"
#include "tools/dataset/trajectory.hpp"

namespace parallax {

enum class DatasetFormat { kAuto, kTumRgbd, kTumMono, kEuroc, kKitti, kImages, kVideo };

/// "auto", "tum", "monovo", "euroc", "kitti", "images", "video".
std::string ToString(DatasetFormat format);
/// Inverse of ToString; throws std::invalid_argument for an unknown name.
DatasetFormat DatasetFormatFromString(const std::string& name);

/// One image of a sequence, as recorded (not yet undistorted).
struct DatasetFrame {
  std::size_t index = 0;              ///< 0-based position in the sequence
  double timestamp = 0.0;             ///< seconds, as in the source (EuRoC: ns / 1e9)
  ImageU8 image;                      ///< 8-bit grey (colour sources converted)
  std::optional<double> exposure_ms;  ///< TUM monoVO only
  std::string source;                 ///< image file, or "<video>#<frame>"
};

/// Photometric calibration of TUM monoVO: inverse response G^-1 (256 entries) and vignette
/// V in [0, 1] (camera-sized); corrected intensity = G^-1(I) / V.
struct PhotometricCalibration {
  std::vector<float> inverse_response;
  std::optional<ImageF> vignette;
};

/// A sequence read frame by frame. Memory stays bounded: only file lists are kept, each
/// image is read when Next() reaches it.
class DatasetReader {
 public:
  virtual ~DatasetReader() = default;

  /// Layout name, e.g. "tum".
  virtual DatasetFormat Format() const = 0;
  /// The recorded (possibly distorted) camera.
  virtual const Camera& GetCamera() const = 0;
  /// How the dataset suggests rectifying (monoVO's camera.txt); default: crop.
  virtual UndistorterOptions SuggestedRectification() const { return {}; }
  /// Number of frames (for videos: the container's count, which may be approximate).
  virtual std::size_t NumFrames() const = 0;
  /// The next frame, or nullopt at the end. Throws InputError naming the image file when an
  /// image is unreadable or has the wrong size.
  virtual std::optional<DatasetFrame> Next() = 0;
  /// Ground-truth trajectory (T_w_c of this camera) if the dataset has one. Throws
  /// InputError if the file exists but is malformed.
  virtual std::optional<Trajectory> GroundTruth() const { return std::nullopt; }
  virtual std::optional<PhotometricCalibration> Photometric() const { return std::nullopt; }
  /// Timestamps of every image (seconds), without reading them; empty where unknown (video).
  virtual std::vector<double> FrameTimestamps() const { return {}; }
};

struct DatasetOptions {
  DatasetFormat format = DatasetFormat::kAuto;
  /// Calibration YAML (docs/calibration.md); overrides what the dataset provides.
  std::string calibration_file;
};

/// The layout at `path`; throws InputError when none is recognised.
DatasetFormat DetectDatasetFormat(const std::string& path);

/// Opens a dataset. Throws InputError (missing files, malformed lists, unknown camera) naming
/// the file and line.
std::unique_ptr<DatasetReader> OpenDataset(const std::string& path,
                                           const DatasetOptions& options = {});

}  // namespace parallax
