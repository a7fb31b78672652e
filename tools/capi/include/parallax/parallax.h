/* Parallax: direct semi-dense monocular SLAM, embedded C API (C11; docs/c_api.md).
 *
 * Conventions
 * - Every function returns a px_status (or a value that cannot fail). On failure the
 *   message is available from px_last_error() on the same thread, and the system is left as
 *   it was before the call.
 * - Poses are camera-to-world (p_w = T_w_c * p_c), 4x4 row-major, camera x right, y down,
 *   z forward. The world is the first keyframe's (or a loaded map's) frame; monocular scale
 *   is arbitrary but consistent (the first keyframe's mean depth is 1).
 * - Thread safety: every function may be called from any thread. A px_system is locked
 *   internally, so calls on one system are serialised; different systems run in parallel.
 *   px_last_error() is per thread.
 * - Buffers belong to the caller; lists use two calls (NULL buffer: count only).
 * - No exception, signal or abort crosses this boundary on bad input; an internal error
 *   during px_system_process_frame is reported as PX_ERROR_INTERNAL (or
 *   PX_ERROR_OUT_OF_MEMORY) and leaves the system refusing frames (PX_ERROR_INVALID_STATE)
 *   until px_system_reset or px_system_load_map.
 */
#ifndef PARALLAX_PARALLAX_H
#define PARALLAX_PARALLAX_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__) || defined(__clang__)
#define PX_API __attribute__((visibility("default")))
#else
#define PX_API
#endif

#define PX_VERSION_MAJOR 0
#define PX_VERSION_MINOR 1
#define PX_VERSION_PATCH 0

typedef struct px_system px_system; /* opaque */

typedef enum {
  PX_OK = 0,
  PX_ERROR_INVALID_ARGUMENT,
  PX_ERROR_INVALID_STATE,
  PX_ERROR_IO,
  PX_ERROR_OUT_OF_MEMORY,
  PX_ERROR_INTERNAL
} px_status;

typedef enum {
  PX_STATE_INITIALIZING, /* no map yet (has_pose may be 1: a provisional pose; in real-time
                            mode 0: px_system_frame_pose has it once the start completes) */
  PX_STATE_TRACKING,
  PX_STATE_POOR,       /* tracked with few consistent pixels: the pose is less certain */
  PX_STATE_LOST,       /* no pose for this frame (never an invented one) */
  PX_STATE_RELOCALIZED /* found again on the map after being lost (or on a loaded map) */
} px_tracking_state;

/* An ideal pinhole camera, pixels; (0,0) is the centre of the top-left pixel. */
typedef struct {
  int width, height;
  double fx, fy, cx, cy;
} px_pinhole;

typedef struct {
  px_tracking_state state;
  int has_pose;
  double T_w_c[16]; /* row-major, camera-to-world; identity when has_pose is 0 */
  int is_keyframe;
  int64_t frame_id;
} px_frame_result;

/* "0.1.0" */
PX_API const char* px_version(void);
/* The message of the last failed call on this thread ("" after none); never NULL. */
PX_API const char* px_last_error(void);
/* A fixed name for a status ("PX_OK", ...); never NULL. */
PX_API const char* px_status_string(px_status status);

/* A system for undistorted images of `camera`. `options_yaml_or_null` holds options in the
 * sections and keys of `parallax run --config` (docs/configuration.md); NULL or "" keeps the
 * defaults. `realtime` 0: deterministic (every stage runs inside process_frame; results
 * are repeatable); 1: tracking inside process_frame, mapping and the backend on a thread
 * the system owns (docs/realtime.md): process_frame answers at once, poses of earlier
 * frames, keyframes and points follow as mapping catches up.
 * On failure *out is set to NULL. */
PX_API px_status px_system_create(const px_pinhole* camera, const char* options_yaml_or_null,
                                  int realtime, px_system** out);
/* NULL is a no-op. */
PX_API void px_system_destroy(px_system* system);

/* One 8-bit grey image, row `y` at gray + y * stride_bytes; width and height must be the
 * camera's (the distorted camera's for a system made by px_system_create_distorted).
 * Timestamps (seconds) must be finite and strictly increasing. */
PX_API px_status px_system_process_frame(px_system* system, const uint8_t* gray, int width,
                                         int height, int stride_bytes, double timestamp_s,
                                         px_frame_result* out);

/* Confirmed semi-dense map points, world coordinates, x y z per point, through the current
 * (optimised) keyframe poses. xyz NULL: *count is set to the number of points. Otherwise
 * up to `capacity` points are needed: with fewer, nothing is written, *count is set to the
 * number needed and PX_ERROR_INVALID_ARGUMENT is returned. */
PX_API px_status px_system_map_points(px_system* system, float* xyz, size_t capacity,
                                      size_t* count);

/* Waits until every frame given so far is mapped and the current keyframe is finished (and
 * optimised), as at the end of a sequence: in real-time mode the poses of frames answered
 * before they were mapped (PX_STATE_INITIALIZING, has_pose 0) are then known to
 * px_system_frame_pose. More frames may follow. Its events are queued for
 * px_system_poll_event. */
PX_API px_status px_system_finish_mapping(px_system* system);

/* Writes the whole map (docs/map_files.md) atomically. PX_ERROR_INVALID_STATE before the
 * first keyframe is initialised; PX_ERROR_IO when the file cannot be written. */
PX_API px_status px_system_save_map(px_system* system, const char* path);
/* Replaces the system's map and session by the map in `path`: the next frames are
 * relocalised on it and continue in its world frame (frame ids continue after the map's).
 * PX_ERROR_IO for a missing, truncated, corrupt or foreign (other camera) file; the system
 * is then unchanged. */
PX_API px_status px_system_load_map(px_system* system, const char* path);
/* Forgets everything (map, frames, events); options and camera stay. */
PX_API px_status px_system_reset(px_system* system);

/* ---- Beyond the core contract -------------------------------------------------------- */

typedef enum {
  PX_CAMERA_PINHOLE = 0,
  PX_CAMERA_RADTAN = 1,      /* k1 k2 p1 p2 k3 (OpenCV order) */
  PX_CAMERA_EQUIDISTANT = 2, /* k1 k2 k3 k4 (Kannala-Brandt / OpenCV fisheye) */
  PX_CAMERA_FOV = 3          /* omega, radians (Devernay-Faugeras) */
} px_camera_model;

typedef enum {
  PX_RECTIFY_CROP = 0, /* largest pinhole view without black borders */
  PX_RECTIFY_FULL = 1  /* pinhole view containing the whole input image */
} px_rectification;

/* A real lens: intrinsics of the distorted image and a distortion model acting on
 * normalised coordinates (docs/conventions.md, "Camera models"). Unused coefficients are
 * ignored. */
typedef struct {
  px_pinhole intrinsics;
  int model;            /* px_camera_model */
  double distortion[5]; /* as the model says */
  int rectification;    /* px_rectification */
} px_camera;

/* A system for images straight from a distorted camera: each frame is rectified to the
 * pinhole camera px_system_camera reports (the one poses and points refer to). */
PX_API px_status px_system_create_distorted(const px_camera* camera,
                                            const char* options_yaml_or_null, int realtime,
                                            px_system** out);
/* The ideal pinhole camera the engine works in (after rectification). */
PX_API px_status px_system_camera(px_system* system, px_pinhole* out);

typedef struct {
  int64_t id; /* the id of the frame it was made from */
  double timestamp_s;
  double T_w_kf[16]; /* row-major keyframe-to-world rotation and translation */
  double scale;      /* the keyframe's depth unit in world units */
  int map_id;        /* maps started after a long loss have their own world until merged */
} px_keyframe;

/* Every keyframe (optimised poses), oldest first; the two-call pattern of map_points. */
PX_API px_status px_system_keyframes(px_system* system, px_keyframe* keyframes, size_t capacity,
                                     size_t* count);

/* The pose of an earlier frame as the optimised map holds it now (it moves with loop
 * closures). *has_pose is 0 for a frame without a pose (lost, or unknown). */
PX_API px_status px_system_frame_pose(px_system* system, int64_t frame_id, double T_w_c[16],
                                      int* has_pose);

typedef enum {
  PX_EVENT_KEYFRAME = 0,      /* keyframe_id: a new keyframe */
  PX_EVENT_LOOP_CLOSED = 1,   /* keyframe_id closed a loop with other_keyframe_id */
  PX_EVENT_LOST = 2,          /* frame_id got no pose */
  PX_EVENT_RELOCALIZED = 3,   /* frame_id was found again on keyframe_id */
  PX_EVENT_MAP_OPTIMIZED = 4, /* keyframe (and so frame and point) poses moved */
  PX_EVENT_NEW_MAP = 5,       /* lost too long: map_id started */
  PX_EVENT_MAPS_MERGED = 6,   /* map_id was joined to the map of other_keyframe_id */
  PX_EVENT_POSES_REVISED = 7, /* earlier frames' poses were revised (initialisation) */
  PX_EVENT_RECOVERED = 8,     /* frame_id tracked again on a recent keyframe_id */
  PX_EVENT_RESTARTED = 9,     /* the start failed and began again at frame_id */
  PX_EVENT_DIVERGED = 10      /* a numerical divergence was caught and its result dropped:
                                 keyframe_id stays as it was (docs/reliability.md) */
} px_event_type;

typedef struct {
  int type; /* px_event_type */
  int64_t frame_id;
  int64_t keyframe_id;       /* -1 when none */
  int64_t other_keyframe_id; /* -1 when none */
  int map_id;                /* -1 when none */
} px_event;

/* Takes the oldest pending event: *available is 1 and *event filled, or 0 when there is
 * none. At most 4096 events are kept; older ones are dropped first (*dropped, if not NULL,
 * reports how many were dropped since the last poll). */
PX_API px_status px_system_poll_event(px_system* system, px_event* event, int* available,
                                      uint64_t* dropped);

#ifdef __cplusplus
}
#endif

#endif /* PARALLAX_PARALLAX_H */
