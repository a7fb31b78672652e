#include "tools/dataset/file_list_reader.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <optional>

#include "tools/dataset/image_file.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/opencv_image.hpp"

namespace parallax {

void CheckTimestampsIncrease(const std::vector<ImageEntry>& entries) {
  for (std::size_t i = 1; i < entries.size(); ++i) {
    if (!(entries[i].timestamp > entries[i - 1].timestamp)) {
      throw InputError(entries[i].list_file, entries[i].list_line,
                       "timestamps must increase (" + FormatTimestamp(entries[i].timestamp) +
                           " follows " + FormatTimestamp(entries[i - 1].timestamp) + ")");
    }
  }
}

namespace {

InputError SizeMismatch(const std::string& path, cv::Size size, cv::Size expected) {
  return InputError(path, "image is " + std::to_string(size.width) + "x" +
                              std::to_string(size.height) + " but the camera is " +
                              std::to_string(expected.width) + "x" +
                              std::to_string(expected.height));
}

}  // namespace

ImageU8 ReadGreyImage(const std::string& path, int expected_width, int expected_height) {
  const cv::Size expected(expected_width, expected_height);
  cv::Mat grey;
  try {
    // Decoded once; an image with more pixels than the camera's is refused from its header,
    // before its pixels are allocated.
    grey = ReadImageFile(path, ImageReadMode::kGrey8,
                         static_cast<long long>(expected_width) * expected_height);
  } catch (const InputError&) {
    // Only on failure is the header read again, to say which size the file has.
    std::optional<cv::Size> size;
    try {
      size = ProbeImageFile(path);
    } catch (const InputError&) {  // the header itself is unreadable: the decoder's error stands
    }
    if (size && *size != expected) throw SizeMismatch(path, *size, expected);
    throw;
  }
  if (grey.size() != expected) throw SizeMismatch(path, grey.size(), expected);
  return ImageFromGreyMat(grey);
}

ImageU8 ReadGreyImage(const std::string& path) {
  return ImageFromGreyMat(ReadImageFile(path, ImageReadMode::kGrey8));
}

std::pair<int, int> ProbeImageSize(const std::string& path) {
  const cv::Size size = ProbeImageFile(path);
  return {size.width, size.height};
}

FileListReader::FileListReader(FileListSpec spec) : spec_(std::move(spec)) {
  if (!spec_.camera) throw std::logic_error("FileListReader: the opener set no camera");
  CheckTimestampsIncrease(spec_.entries);
}

std::optional<DatasetFrame> FileListReader::Next() {
  if (next_ >= spec_.entries.size()) return std::nullopt;
  const ImageEntry& entry = spec_.entries[next_];
  DatasetFrame frame;
  frame.index = next_++;
  frame.timestamp = entry.timestamp;
  frame.exposure_ms = entry.exposure_ms;
  frame.source = entry.path;
  frame.image = ReadGreyImage(entry.path, spec_.camera->Width(), spec_.camera->Height());
  return frame;
}

std::vector<double> FileListReader::FrameTimestamps() const {
  std::vector<double> stamps;
  stamps.reserve(spec_.entries.size());
  for (const ImageEntry& e : spec_.entries) stamps.push_back(e.timestamp);
  return stamps;
}

std::optional<Trajectory> FileListReader::GroundTruth() const {
  if (!spec_.groundtruth) return std::nullopt;
  return spec_.groundtruth();
}

std::string FindCalibrationFile(const std::string& folder, const std::string& explicit_file) {
  if (!explicit_file.empty()) return explicit_file;
  for (const char* name : {"calibration.yaml", "camera.yaml"}) {
    const auto candidate = std::filesystem::path(folder) / name;
    if (std::filesystem::exists(candidate)) return candidate.string();
  }
  return {};
}

}  // namespace parallax
