// A video file read with OpenCV (through the media module), with a calibration YAML
// (docs/datasets.md).

#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "tools/dataset/calibration_yaml.hpp"
#include "tools/dataset/file_list_reader.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/media_module.hpp"
#include "tools/dataset/opencv_image.hpp"

namespace fs = std::filesystem;

namespace parallax {
namespace {

class VideoReader final : public DatasetReader {
 public:
  VideoReader(std::string path, CalibrationFile calib)
      : path_(std::move(path)), calib_(std::move(calib)) {
    try {
      video_ = LoadMediaModule().OpenVideo(path_);
    } catch (const std::runtime_error& e) {
      throw InputError(path_, e.what());
    }
    if (!video_) throw InputError(path_, "cannot open video");
    const double container_fps = video_->ContainerFps();
    fps_ = calib_.fps ? *calib_.fps : container_fps;
    if (!(fps_ > 0.0)) throw InputError(path_, "frame rate unknown: set 'fps' in the calibration");
    const double count = video_->ContainerFrameCount();
    num_frames_ = count > 0 ? static_cast<std::size_t>(count) : 0;
  }

  DatasetFormat Format() const override { return DatasetFormat::kVideo; }
  const Camera& GetCamera() const override { return calib_.camera; }
  std::size_t NumFrames() const override { return num_frames_; }

  std::optional<DatasetFrame> Next() override {
    cv::Mat bgr;
    if (!video_->Read(&bgr)) return std::nullopt;
    cv::Mat grey;
    if (bgr.channels() == 1) {
      grey = bgr;
    } else {
      cv::cvtColor(bgr, grey, bgr.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
    }
    DatasetFrame frame;
    frame.index = index_++;
    frame.source = path_ + "#" + std::to_string(frame.index);
    if (grey.cols != calib_.camera.Width() || grey.rows != calib_.camera.Height()) {
      throw InputError(frame.source, "frame size differs from the calibration");
    }
    // The container's presentation time when it has one and it increases, else index / fps.
    const double msec = video_->PositionMs();
    double t = calib_.fps ? static_cast<double>(frame.index) / fps_ : msec * 1e-3;
    if (!(t > last_timestamp_)) t = static_cast<double>(frame.index) / fps_;
    if (!(t > last_timestamp_)) t = last_timestamp_ + 1.0 / fps_;
    last_timestamp_ = t;
    frame.timestamp = t;
    frame.image = ImageFromGreyMat(grey);
    return frame;
  }

 private:
  std::string path_;
  CalibrationFile calib_;
  std::unique_ptr<VideoSource> video_;
  double fps_ = 0.0;
  std::size_t num_frames_ = 0;
  std::size_t index_ = 0;
  double last_timestamp_ = -1e300;
};

}  // namespace

std::unique_ptr<DatasetReader> OpenVideo(const std::string& path, const std::string& calibration) {
  if (!fs::is_regular_file(path)) throw InputError(path, "video file does not exist");
  std::string calib_file = calibration;
  if (calib_file.empty()) {
    const fs::path beside = fs::path(path).replace_extension(".yaml");
    calib_file = fs::exists(beside)
                     ? beside.string()
                     : FindCalibrationFile(fs::path(path).parent_path().string(), "");
  }
  if (calib_file.empty()) {
    throw InputError(path, "video needs a calibration: <video>.yaml beside it or --calib");
  }
  return std::make_unique<VideoReader>(path, ReadCalibrationYaml(calib_file));
}

}  // namespace parallax
