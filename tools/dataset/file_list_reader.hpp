#pragma once
// Internal: the DatasetReader shared by all layouts that are a list of image files.

#include <filesystem>
#include <functional>

#include "tools/dataset/dataset_reader.hpp"

namespace parallax {

struct ImageEntry {
  double timestamp = 0.0;
  std::string path;
  std::optional<double> exposure_ms;
  std::string list_file;  ///< where the entry came from, for error messages
  int list_line = 0;
};

struct FileListSpec {
  DatasetFormat format = DatasetFormat::kImages;
  std::optional<Camera> camera;  ///< required
  std::vector<ImageEntry> entries;
  std::function<std::optional<Trajectory>()> groundtruth;  ///< may be empty
  UndistorterOptions rectification;
  std::optional<PhotometricCalibration> photometric;
};

/// Throws InputError at the first entry whose timestamp does not increase.
void CheckTimestampsIncrease(const std::vector<ImageEntry>& entries);

/// Reads an image file as 8-bit grey (colour converted with OpenCV's BT.601 weights) and
/// checks its size. Throws InputError naming the file.
ImageU8 ReadGreyImage(const std::string& path, int expected_width, int expected_height);
/// The same without a size check.
ImageU8 ReadGreyImage(const std::string& path);

/// Width and height of an image file; throws InputError naming it if unreadable.
std::pair<int, int> ProbeImageSize(const std::string& path);

class FileListReader final : public DatasetReader {
 public:
  explicit FileListReader(FileListSpec spec);

  DatasetFormat Format() const override { return spec_.format; }
  const Camera& GetCamera() const override { return *spec_.camera; }
  UndistorterOptions SuggestedRectification() const override { return spec_.rectification; }
  std::size_t NumFrames() const override { return spec_.entries.size(); }
  std::optional<DatasetFrame> Next() override;
  std::optional<Trajectory> GroundTruth() const override;
  std::optional<PhotometricCalibration> Photometric() const override { return spec_.photometric; }
  std::vector<double> FrameTimestamps() const override;

 private:
  FileListSpec spec_;
  std::size_t next_ = 0;
};

// Openers of the individual layouts (one source file each); `calibration` overrides.
std::unique_ptr<DatasetReader> OpenTumRgbd(const std::string& path, const std::string& calibration);
std::unique_ptr<DatasetReader> OpenTumMono(const std::string& path, const std::string& calibration);
std::unique_ptr<DatasetReader> OpenEuroc(const std::string& path, const std::string& calibration);
std::unique_ptr<DatasetReader> OpenKitti(const std::string& path, const std::string& calibration);
std::unique_ptr<DatasetReader> OpenImageFolder(const std::string& path,
                                               const std::string& calibration);
std::unique_ptr<DatasetReader> OpenVideo(const std::string& path, const std::string& calibration);

/// True for the image extensions the folder reader accepts (png, jpg, pgm, bmp, tif).
bool IsImageFile(const std::filesystem::path& path);
/// Natural order: "img2.png" < "img10.png".
bool NaturalLess(const std::string& a, const std::string& b);

/// The calibration file to use for a folder: `explicit_file` if given, else
/// `<folder>/calibration.yaml` or `<folder>/camera.yaml` if present, else empty.
std::string FindCalibrationFile(const std::string& folder, const std::string& explicit_file);

}  // namespace parallax
