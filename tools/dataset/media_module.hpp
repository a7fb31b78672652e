#pragma once
// The media module: libparallax_media.so, a plug-in built with the tools that links OpenCV's
// imgcodecs and videoio and is loaded (dlopen) the first time a video or an image format
// other than PNG and JPEG is read. Processes that read PNG/JPEG sequences never load those
// two libraries and the ~220 shared libraries they pull in (docs/architecture.md, "Image
// files").

#include <memory>
#include <opencv2/core.hpp>
#include <string>

namespace parallax {

/// A video file's frames, in order (OpenCV's VideoCapture behind it).
class VideoSource {
 public:
  virtual ~VideoSource() = default;
  /// The next frame as OpenCV decodes it (usually BGR); false at the end or on failure.
  virtual bool Read(cv::Mat* frame) = 0;
  /// Frames per second the container declares (<= 0 when unknown).
  virtual double ContainerFps() const = 0;
  /// Frame count the container declares (<= 0 when unknown).
  virtual double ContainerFrameCount() const = 0;
  /// Presentation time of the frame last read, in milliseconds.
  virtual double PositionMs() const = 0;
};

/// What the module provides. Every function catches OpenCV's exceptions and reports failure
/// by its return value, so nothing is thrown across the module boundary.
class MediaModule {
 public:
  virtual ~MediaModule() = default;
  /// cv::imread(path, IMREAD_GRAYSCALE or IMREAD_UNCHANGED); empty on failure.
  virtual cv::Mat ReadImage(const std::string& path, bool unchanged) const = 0;
  /// An opened video, or nullptr when OpenCV cannot open it.
  virtual std::unique_ptr<VideoSource> OpenVideo(const std::string& path) const = 0;
};

/// Loads the module on first use (thread-safe) from, in order: $PARALLAX_MEDIA_MODULE, the
/// build tree, the install tree. Throws std::runtime_error naming the paths it tried.
const MediaModule& LoadMediaModule();

}  // namespace parallax

/// The module's entry point (C linkage so dlsym finds it by this name).
extern "C" const parallax::MediaModule* ParallaxMediaModule();
