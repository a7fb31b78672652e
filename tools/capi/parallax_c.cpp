// The C entry points (tools/capi/include/parallax/parallax.h): argument checks, the handle's
// lock, and the translation of every exception into a status and a thread-local message.

#include <cmath>
#include <mutex>
#include <new>
#include <string>

#include "backend/map_file.hpp"
#include "parallax/parallax.h"
#include "tools/capi/session.hpp"
#include "tools/config_yaml.hpp"
#include "tools/dataset/input_error.hpp"

struct px_system {
  std::mutex mutex;
  std::unique_ptr<parallax::capi::Session> session;
};

namespace parallax::capi {
namespace {

thread_local std::string last_error;

px_status Fail(px_status status, const std::string& message) {
  try {
    last_error = message;
  } catch (...) {  // no memory for the message: the status still tells
  }
  return status;
}

/// Runs `body`, mapping every exception to a status (never lets one escape).
template <typename Body>
px_status Guarded(const char* function, Body&& body) noexcept {
  const std::string where = std::string(function) + ": ";
  try {
    body();
    return PX_OK;
  } catch (const StatusError& e) {
    return Fail(e.Status(), where + e.what());
  } catch (const MapFileError& e) {
    return Fail(PX_ERROR_IO, where + e.what());
  } catch (const InputError& e) {
    return Fail(PX_ERROR_INVALID_ARGUMENT, where + e.what());
  } catch (const std::invalid_argument& e) {
    return Fail(PX_ERROR_INVALID_ARGUMENT, where + e.what());
  } catch (const std::bad_alloc&) {
    return Fail(PX_ERROR_OUT_OF_MEMORY, where + "out of memory");
  } catch (const std::exception& e) {
    return Fail(PX_ERROR_INTERNAL, where + "internal error: " + e.what());
  } catch (...) {
    return Fail(PX_ERROR_INTERNAL, where + "internal error (unknown exception)");
  }
}

void Require(bool condition, const std::string& message) {
  if (!condition) throw StatusError(PX_ERROR_INVALID_ARGUMENT, message);
}

Session& Locked(px_system* system, std::unique_lock<std::mutex>* lock) {
  Require(system != nullptr, "system is NULL");
  *lock = std::unique_lock<std::mutex>(system->mutex);
  return *system->session;
}

CameraModel ModelOf(int model) {
  switch (model) {
    case PX_CAMERA_PINHOLE:
      return CameraModel::kPinhole;
    case PX_CAMERA_RADTAN:
      return CameraModel::kRadTan;
    case PX_CAMERA_EQUIDISTANT:
      return CameraModel::kEquidistant;
    case PX_CAMERA_FOV:
      return CameraModel::kFov;
    default:
      break;
  }
  throw StatusError(PX_ERROR_INVALID_ARGUMENT, "unknown camera model " + std::to_string(model));
}

Camera CameraOf(const px_camera& c) {
  const CameraModel model = ModelOf(c.model);
  const int n = NumDistortionParameters(model);
  std::vector<double> distortion(c.distortion, c.distortion + n);
  return Camera(model, c.intrinsics.width, c.intrinsics.height, c.intrinsics.fx, c.intrinsics.fy,
                c.intrinsics.cx, c.intrinsics.cy, std::move(distortion));
}

px_status Create(const char* function, const px_camera* camera, const char* options_yaml,
                 int realtime, px_system** out) {
  if (out != nullptr) *out = nullptr;
  return Guarded(function, [&] {
    Require(out != nullptr, "out is NULL");
    Require(camera != nullptr, "camera is NULL");
    Require(realtime == 0 || realtime == 1, "realtime must be 0 or 1");
    Require(camera->rectification == PX_RECTIFY_CROP || camera->rectification == PX_RECTIFY_FULL,
            "unknown rectification " + std::to_string(camera->rectification));
    SessionOptions options;
    options.rectification.mode =
        camera->rectification == PX_RECTIFY_FULL ? UndistortMode::kFull : UndistortMode::kCrop;
    if (options_yaml != nullptr) {
      ApplyConfigYamlText(options_yaml, "options_yaml", &options.system);
    }
    options.system.realtime.enabled = realtime == 1;
    auto system = std::make_unique<px_system>();
    system->session = std::make_unique<Session>(CameraOf(*camera), options);
    *out = system.release();
  });
}

/// The two-call pattern: count only without a buffer; nothing written when it is too small.
template <typename T>
void CopyList(const std::vector<T>& items, T* buffer, std::size_t capacity, std::size_t* count) {
  *count = items.size();
  if (buffer == nullptr) return;
  Require(capacity >= items.size(), "capacity " + std::to_string(capacity) + " is less than the " +
                                        std::to_string(items.size()) + " needed");
  std::copy(items.begin(), items.end(), buffer);
}

}  // namespace
}  // namespace parallax::capi

using parallax::capi::Guarded;
using parallax::capi::Locked;
using parallax::capi::Require;

extern "C" {

PX_API const char* px_version(void) { return "0.1.0"; }

PX_API const char* px_last_error(void) { return parallax::capi::last_error.c_str(); }

PX_API const char* px_status_string(px_status status) {
  switch (status) {
    case PX_OK:
      return "PX_OK";
    case PX_ERROR_INVALID_ARGUMENT:
      return "PX_ERROR_INVALID_ARGUMENT";
    case PX_ERROR_INVALID_STATE:
      return "PX_ERROR_INVALID_STATE";
    case PX_ERROR_IO:
      return "PX_ERROR_IO";
    case PX_ERROR_OUT_OF_MEMORY:
      return "PX_ERROR_OUT_OF_MEMORY";
    case PX_ERROR_INTERNAL:
      return "PX_ERROR_INTERNAL";
  }
  return "unknown px_status";
}

PX_API px_status px_system_create(const px_pinhole* camera, const char* options_yaml_or_null,
                                  int realtime, px_system** out) {
  if (camera == nullptr) {
    if (out != nullptr) *out = nullptr;
    return parallax::capi::Fail(PX_ERROR_INVALID_ARGUMENT, "px_system_create: camera is NULL");
  }
  px_camera distorted{};
  distorted.intrinsics = *camera;
  distorted.model = PX_CAMERA_PINHOLE;
  distorted.rectification = PX_RECTIFY_CROP;
  return parallax::capi::Create("px_system_create", &distorted, options_yaml_or_null, realtime,
                                out);
}

PX_API px_status px_system_create_distorted(const px_camera* camera,
                                            const char* options_yaml_or_null, int realtime,
                                            px_system** out) {
  return parallax::capi::Create("px_system_create_distorted", camera, options_yaml_or_null,
                                realtime, out);
}

PX_API void px_system_destroy(px_system* system) {
  const std::unique_ptr<px_system> owned(system);  // NULL: nothing
}

PX_API px_status px_system_process_frame(px_system* system, const uint8_t* gray, int width,
                                         int height, int stride_bytes, double timestamp_s,
                                         px_frame_result* out) {
  return Guarded("px_system_process_frame", [&] {
    std::unique_lock<std::mutex> lock;
    auto& session = Locked(system, &lock);
    Require(out != nullptr, "out is NULL");
    *out = session.ProcessFrame(gray, width, height, stride_bytes, timestamp_s);
  });
}

PX_API px_status px_system_map_points(px_system* system, float* xyz, size_t capacity,
                                      size_t* count) {
  return Guarded("px_system_map_points", [&] {
    std::unique_lock<std::mutex> lock;
    auto& session = Locked(system, &lock);
    Require(count != nullptr, "count is NULL");
    const std::vector<float> points = session.MapPoints();
    *count = points.size() / 3;
    if (xyz == nullptr) return;
    Require(capacity >= *count, "capacity " + std::to_string(capacity) + " is less than the " +
                                    std::to_string(*count) + " points");
    std::copy(points.begin(), points.end(), xyz);
  });
}

PX_API px_status px_system_finish_mapping(px_system* system) {
  return Guarded("px_system_finish_mapping", [&] {
    std::unique_lock<std::mutex> lock;
    Locked(system, &lock).FinishMapping();
  });
}

PX_API px_status px_system_save_map(px_system* system, const char* path) {
  return Guarded("px_system_save_map", [&] {
    std::unique_lock<std::mutex> lock;
    auto& session = Locked(system, &lock);
    Require(path != nullptr && path[0] != '\0', "path is NULL or empty");
    session.SaveMap(path);
  });
}

PX_API px_status px_system_load_map(px_system* system, const char* path) {
  return Guarded("px_system_load_map", [&] {
    std::unique_lock<std::mutex> lock;
    auto& session = Locked(system, &lock);
    Require(path != nullptr && path[0] != '\0', "path is NULL or empty");
    session.LoadMap(path);
  });
}

PX_API px_status px_system_reset(px_system* system) {
  return Guarded("px_system_reset", [&] {
    std::unique_lock<std::mutex> lock;
    Locked(system, &lock).Reset();
  });
}

PX_API px_status px_system_camera(px_system* system, px_pinhole* out) {
  return Guarded("px_system_camera", [&] {
    std::unique_lock<std::mutex> lock;
    auto& session = Locked(system, &lock);
    Require(out != nullptr, "out is NULL");
    const parallax::PinholeCamera& c = session.EngineCamera();
    *out = px_pinhole{c.Width(), c.Height(), c.Fx(), c.Fy(), c.Cx(), c.Cy()};
  });
}

PX_API px_status px_system_keyframes(px_system* system, px_keyframe* keyframes, size_t capacity,
                                     size_t* count) {
  return Guarded("px_system_keyframes", [&] {
    std::unique_lock<std::mutex> lock;
    auto& session = Locked(system, &lock);
    Require(count != nullptr, "count is NULL");
    parallax::capi::CopyList(session.Keyframes(), keyframes, capacity, count);
  });
}

PX_API px_status px_system_frame_pose(px_system* system, int64_t frame_id, double T_w_c[16],
                                      int* has_pose) {
  return Guarded("px_system_frame_pose", [&] {
    std::unique_lock<std::mutex> lock;
    auto& session = Locked(system, &lock);
    Require(T_w_c != nullptr && has_pose != nullptr, "T_w_c or has_pose is NULL");
    const auto pose = session.FramePose(frame_id);
    *has_pose = pose ? 1 : 0;
    parallax::capi::ToRowMajor(pose.value_or(parallax::SE3d()), T_w_c);
  });
}

PX_API px_status px_system_poll_event(px_system* system, px_event* event, int* available,
                                      uint64_t* dropped) {
  return Guarded("px_system_poll_event", [&] {
    std::unique_lock<std::mutex> lock;
    auto& session = Locked(system, &lock);
    Require(event != nullptr && available != nullptr, "event or available is NULL");
    std::uint64_t dropped_since = 0;
    const auto next = session.PollEvent(&dropped_since);
    if (dropped != nullptr) *dropped = dropped_since;
    *available = next ? 1 : 0;
    if (next) *event = *next;
  });
}

}  // extern "C"
