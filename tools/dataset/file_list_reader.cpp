#include "tools/dataset/file_list_reader.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

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

/// OpenCV picks a decoder by the file's content and links many (DICOM, JPEG 2000, OpenEXR,
/// ...); some abort the process or exhaust memory on malformed input (fuzz_image found GDCM
/// asserting, and allocating 3.8 GB). Only the formats image sequences come in reach a
/// decoder.
void CheckImageSignature(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char b[132] = {};
  in.read(reinterpret_cast<char*>(b), sizeof(b));
  const auto n = static_cast<std::size_t>(in.gcount());
  // DICOM's signature is "DICM" after a 128-byte preamble, which may start like any format
  // above; OpenCV then hands the file to GDCM whatever its first bytes (fuzz_image: a "P2"
  // file with DICM at 128 made GDCM allocate 3.8 GB).
  if (n >= 132 && b[128] == 'D' && b[129] == 'I' && b[130] == 'C' && b[131] == 'M') {
    throw InputError(path, "a DICOM file, not an image sequence's frame");
  }
  const auto starts = [&](std::initializer_list<unsigned char> sig) {
    return n >= sig.size() && std::equal(sig.begin(), sig.end(), b);
  };
  const bool png = starts({0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a});
  const bool jpeg = starts({0xff, 0xd8, 0xff});
  const bool bmp = starts({'B', 'M'});
  const bool tiff = starts({'I', 'I', 0x2a, 0x00}) || starts({'M', 'M', 0x00, 0x2a});
  const bool pnm = n >= 2 && b[0] == 'P' && b[1] >= '1' && b[1] <= '6';
  const bool webp = n >= 12 && starts({'R', 'I', 'F', 'F'}) && b[8] == 'W' && b[9] == 'E' &&
                    b[10] == 'B' && b[11] == 'P';
  if (!(png || jpeg || bmp || tiff || pnm || webp)) {
    throw InputError(path, "not a PNG, JPEG, BMP, TIFF, PGM/PPM or WebP image");
  }
}

cv::Mat DecodeGrey(const std::string& path) {
  if (!std::filesystem::exists(path)) throw InputError(path, "image file does not exist");
  CheckImageSignature(path);
  cv::Mat grey;
  try {
    grey = cv::imread(path, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    throw InputError(path, std::string("cannot decode: ") + e.what());
  }
  if (grey.empty()) throw InputError(path, "unreadable or corrupt image");
  return grey;
}

}  // namespace

ImageU8 ReadGreyImage(const std::string& path, int expected_width, int expected_height) {
  ImageU8 image = ReadGreyImage(path);
  if (image.Width() != expected_width || image.Height() != expected_height) {
    throw InputError(path, "image is " + std::to_string(image.Width()) + "x" +
                               std::to_string(image.Height()) + " but the camera is " +
                               std::to_string(expected_width) + "x" +
                               std::to_string(expected_height));
  }
  return image;
}

ImageU8 ReadGreyImage(const std::string& path) { return ImageFromGreyMat(DecodeGrey(path)); }

std::pair<int, int> ProbeImageSize(const std::string& path) {
  const cv::Mat image = DecodeGrey(path);
  return {image.cols, image.rows};
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
