// libparallax_media.so: OpenCV's image codecs and video capture behind the MediaModule
// interface (tools/dataset/media_module.hpp), loaded only when a reader needs them.

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "tools/dataset/media_module.hpp"

namespace parallax {
namespace {

class OpenCvVideo final : public VideoSource {
 public:
  explicit OpenCvVideo(std::unique_ptr<cv::VideoCapture> capture) : capture_(std::move(capture)) {}

  bool Read(cv::Mat* frame) override {
    try {
      return capture_->read(*frame) && !frame->empty();
    } catch (const cv::Exception&) {
      return false;
    }
  }
  double ContainerFps() const override { return Get(cv::CAP_PROP_FPS); }
  double ContainerFrameCount() const override { return Get(cv::CAP_PROP_FRAME_COUNT); }
  double PositionMs() const override { return Get(cv::CAP_PROP_POS_MSEC); }

 private:
  double Get(int property) const {
    try {
      return capture_->get(property);
    } catch (const cv::Exception&) {
      return 0.0;
    }
  }

  std::unique_ptr<cv::VideoCapture> capture_;
};

class OpenCvMedia final : public MediaModule {
 public:
  cv::Mat ReadImage(const std::string& path, bool unchanged) const override {
    try {
      return cv::imread(path, unchanged ? cv::IMREAD_UNCHANGED : cv::IMREAD_GRAYSCALE);
    } catch (const cv::Exception&) {
      return {};
    }
  }

  std::unique_ptr<VideoSource> OpenVideo(const std::string& path) const override {
    try {
      auto capture = std::make_unique<cv::VideoCapture>();
      if (!capture->open(path)) return nullptr;
      return std::make_unique<OpenCvVideo>(std::move(capture));
    } catch (const cv::Exception&) {
      return nullptr;
    }
  }
};

}  // namespace
}  // namespace parallax

extern "C" const parallax::MediaModule* ParallaxMediaModule() {
  static const parallax::OpenCvMedia module;
  return &module;
}
