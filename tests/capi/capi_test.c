/* Tests of the C API, in C11 against parallax/parallax.h only (docs/c_api.md).
 *   capi_test table                     every function with bad arguments (no frames needed)
 *   capi_test functions FRAMES_DIR MAP  every function on a real clip (a frame folder)
 *   capi_test realtime FRAMES_DIR MAP   the clip with realtime = 1, and a mid-stream destroy
 *   capi_test save FRAMES_DIR N MAP     frames [0, N), then the map saved
 *   capi_test load FRAMES_DIR N MAP REF frames [N, end) on the loaded map: relocalised within
 *                                       5 frames, live poses near REF's (a poses file of the
 *                                       uninterrupted run, ar_loop's format)
 * Exit 0 when every check passed; each failed check prints its line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "frame_folder.h"
#include "parallax/parallax.h"

static int failures = 0;

#define CHECK(condition)                                                            \
  do {                                                                              \
    if (!(condition)) {                                                             \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #condition); \
      ++failures;                                                                   \
    }                                                                               \
  } while (0)

/* A call that must fail with `expected` and leave a message naming the function. */
static void expect_status(px_status status, px_status expected, const char* function, int line) {
  const char* message = px_last_error();
  if (status != expected || message == NULL || strstr(message, function) == NULL) {
    fprintf(stderr, "capi_test.c:%d: %s: got %s (\"%s\"), expected %s\n", line, function,
            px_status_string(status), message ? message : "(null)", px_status_string(expected));
    ++failures;
  }
}
#define EXPECT_STATUS(call, expected, function) \
  expect_status((call), (expected), (function), __LINE__)

static const px_pinhole kCamera = {64, 48, 50.0, 50.0, 31.5, 23.5};

/* A height x stride image (the first `width` columns are the picture, the rest padding). */
static uint8_t* textured_image(int height, int stride, unsigned seed) {
  uint8_t* pixels = malloc((size_t)stride * (size_t)height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < stride; ++x) {
      seed = seed * 1103515245u + 12345u;
      pixels[y * stride + x] = (uint8_t)((x * 7 + y * 13) % 200 + (seed >> 24) % 50);
    }
  }
  return pixels;
}

static void bad_create_arguments(void) {
  px_system* system = (px_system*)&failures; /* must be set to NULL on failure */
  px_pinhole camera = kCamera;
  EXPECT_STATUS(px_system_create(NULL, NULL, 0, &system), PX_ERROR_INVALID_ARGUMENT,
                "px_system_create");
  CHECK(system == NULL);
  EXPECT_STATUS(px_system_create(&camera, NULL, 0, NULL), PX_ERROR_INVALID_ARGUMENT,
                "px_system_create");
  camera.width = 0;
  EXPECT_STATUS(px_system_create(&camera, NULL, 0, &system), PX_ERROR_INVALID_ARGUMENT,
                "px_system_create");
  camera = kCamera;
  camera.fx = NAN;
  EXPECT_STATUS(px_system_create(&camera, NULL, 0, &system), PX_ERROR_INVALID_ARGUMENT,
                "px_system_create");
  camera = kCamera;
  camera.fy = -1.0;
  EXPECT_STATUS(px_system_create(&camera, NULL, 0, &system), PX_ERROR_INVALID_ARGUMENT,
                "px_system_create");
  EXPECT_STATUS(px_system_create(&kCamera, NULL, 7, &system), PX_ERROR_INVALID_ARGUMENT,
                "px_system_create");
  EXPECT_STATUS(px_system_create(&kCamera, "tracker: [unclosed", 0, &system),
                PX_ERROR_INVALID_ARGUMENT, "px_system_create");
  EXPECT_STATUS(px_system_create(&kCamera, "tracker:\n  no_such_key: 1\n", 0, &system),
                PX_ERROR_INVALID_ARGUMENT, "px_system_create");
  CHECK(strstr(px_last_error(), "no_such_key") != NULL);
  EXPECT_STATUS(px_system_create(&kCamera, "tracker:\n  max_iterations: -3\n", 0, &system),
                PX_ERROR_INVALID_ARGUMENT, "px_system_create");
  CHECK(system == NULL);
  px_camera distorted = {kCamera, PX_CAMERA_RADTAN, {0.1, NAN, 0.0, 0.0, 0.0}, PX_RECTIFY_CROP};
  EXPECT_STATUS(px_system_create_distorted(&distorted, NULL, 0, &system), PX_ERROR_INVALID_ARGUMENT,
                "px_system_create_distorted");
  distorted.distortion[1] = 0.0;
  distorted.model = 9;
  EXPECT_STATUS(px_system_create_distorted(&distorted, NULL, 0, &system), PX_ERROR_INVALID_ARGUMENT,
                "px_system_create_distorted");
  distorted.model = PX_CAMERA_FOV;
  distorted.distortion[0] = 5.0; /* omega outside (0, pi) */
  EXPECT_STATUS(px_system_create_distorted(&distorted, NULL, 0, &system), PX_ERROR_INVALID_ARGUMENT,
                "px_system_create_distorted");
  distorted.distortion[0] = 0.9;
  distorted.rectification = 5;
  EXPECT_STATUS(px_system_create_distorted(&distorted, NULL, 0, &system), PX_ERROR_INVALID_ARGUMENT,
                "px_system_create_distorted");
  EXPECT_STATUS(px_system_create_distorted(NULL, NULL, 0, &system), PX_ERROR_INVALID_ARGUMENT,
                "px_system_create_distorted");
  /* Calls after a failed create get the NULL it left. */
  px_frame_result result;
  uint8_t* image = textured_image(48, 64, 1);
  EXPECT_STATUS(px_system_process_frame(system, image, 64, 48, 64, 0.0, &result),
                PX_ERROR_INVALID_ARGUMENT, "px_system_process_frame");
  free(image);
  px_system_destroy(NULL);
}

static void bad_frame_arguments(px_system* system) {
  px_frame_result result;
  uint8_t* image = textured_image(48, 80, 2);
  const char* f = "px_system_process_frame";
  EXPECT_STATUS(px_system_process_frame(system, NULL, 64, 48, 64, 0.0, &result),
                PX_ERROR_INVALID_ARGUMENT, f);
  EXPECT_STATUS(px_system_process_frame(system, image, 64, 48, 64, 0.0, NULL),
                PX_ERROR_INVALID_ARGUMENT, f);
  EXPECT_STATUS(px_system_process_frame(system, image, 63, 48, 64, 0.0, &result),
                PX_ERROR_INVALID_ARGUMENT, f);
  EXPECT_STATUS(px_system_process_frame(system, image, 64, 49, 64, 0.0, &result),
                PX_ERROR_INVALID_ARGUMENT, f);
  EXPECT_STATUS(px_system_process_frame(system, image, -64, 48, 64, 0.0, &result),
                PX_ERROR_INVALID_ARGUMENT, f);
  EXPECT_STATUS(px_system_process_frame(system, image, 64, 48, 63, 0.0, &result),
                PX_ERROR_INVALID_ARGUMENT, f);
  EXPECT_STATUS(px_system_process_frame(system, image, 64, 48, 64, NAN, &result),
                PX_ERROR_INVALID_ARGUMENT, f);
  EXPECT_STATUS(px_system_process_frame(system, image, 64, 48, 64, INFINITY, &result),
                PX_ERROR_INVALID_ARGUMENT, f);
  /* A padded stride is fine; then time must go forward. */
  CHECK(px_system_process_frame(system, image, 64, 48, 80, 1.0, &result) == PX_OK);
  CHECK(result.frame_id == 0);
  CHECK(result.has_pose == 0 || result.state == PX_STATE_INITIALIZING);
  EXPECT_STATUS(px_system_process_frame(system, image, 64, 48, 64, 0.5, &result),
                PX_ERROR_INVALID_ARGUMENT, f);
  EXPECT_STATUS(px_system_process_frame(system, image, 64, 48, 64, 1.0, &result),
                PX_ERROR_INVALID_ARGUMENT, f);
  /* ... and none of the failures counted as a frame. */
  CHECK(px_system_process_frame(system, image, 64, 48, 64, 1.1, &result) == PX_OK);
  CHECK(result.frame_id == 1);
  free(image);
}

static void bad_query_arguments(px_system* system) {
  size_t count = 0;
  float xyz[3];
  px_keyframe keyframe;
  double T[16];
  int flag = 0;
  px_event event;
  px_pinhole camera;
  EXPECT_STATUS(px_system_map_points(NULL, xyz, 1, &count), PX_ERROR_INVALID_ARGUMENT,
                "px_system_map_points");
  EXPECT_STATUS(px_system_map_points(system, xyz, 1, NULL), PX_ERROR_INVALID_ARGUMENT,
                "px_system_map_points");
  EXPECT_STATUS(px_system_keyframes(NULL, &keyframe, 1, &count), PX_ERROR_INVALID_ARGUMENT,
                "px_system_keyframes");
  EXPECT_STATUS(px_system_keyframes(system, &keyframe, 1, NULL), PX_ERROR_INVALID_ARGUMENT,
                "px_system_keyframes");
  EXPECT_STATUS(px_system_frame_pose(NULL, 0, T, &flag), PX_ERROR_INVALID_ARGUMENT,
                "px_system_frame_pose");
  EXPECT_STATUS(px_system_frame_pose(system, 0, NULL, &flag), PX_ERROR_INVALID_ARGUMENT,
                "px_system_frame_pose");
  EXPECT_STATUS(px_system_frame_pose(system, 0, T, NULL), PX_ERROR_INVALID_ARGUMENT,
                "px_system_frame_pose");
  EXPECT_STATUS(px_system_poll_event(NULL, &event, &flag, NULL), PX_ERROR_INVALID_ARGUMENT,
                "px_system_poll_event");
  EXPECT_STATUS(px_system_poll_event(system, NULL, &flag, NULL), PX_ERROR_INVALID_ARGUMENT,
                "px_system_poll_event");
  EXPECT_STATUS(px_system_poll_event(system, &event, NULL, NULL), PX_ERROR_INVALID_ARGUMENT,
                "px_system_poll_event");
  EXPECT_STATUS(px_system_camera(NULL, &camera), PX_ERROR_INVALID_ARGUMENT, "px_system_camera");
  EXPECT_STATUS(px_system_camera(system, NULL), PX_ERROR_INVALID_ARGUMENT, "px_system_camera");
  EXPECT_STATUS(px_system_save_map(NULL, "x.pxmap"), PX_ERROR_INVALID_ARGUMENT,
                "px_system_save_map");
  EXPECT_STATUS(px_system_save_map(system, NULL), PX_ERROR_INVALID_ARGUMENT, "px_system_save_map");
  EXPECT_STATUS(px_system_save_map(system, ""), PX_ERROR_INVALID_ARGUMENT, "px_system_save_map");
  /* Nothing initialised yet: no map to save. */
  EXPECT_STATUS(px_system_save_map(system, "x.pxmap"), PX_ERROR_INVALID_STATE,
                "px_system_save_map");
  EXPECT_STATUS(px_system_load_map(NULL, "x.pxmap"), PX_ERROR_INVALID_ARGUMENT,
                "px_system_load_map");
  EXPECT_STATUS(px_system_load_map(system, NULL), PX_ERROR_INVALID_ARGUMENT, "px_system_load_map");
  EXPECT_STATUS(px_system_load_map(system, "/nonexistent/x.pxmap"), PX_ERROR_IO,
                "px_system_load_map");
  EXPECT_STATUS(px_system_reset(NULL), PX_ERROR_INVALID_ARGUMENT, "px_system_reset");
  CHECK(strcmp(px_status_string(PX_ERROR_IO), "PX_ERROR_IO") == 0);
  CHECK(strlen(px_version()) > 0);
}

static int table(void) {
  bad_create_arguments();
  px_system* system = NULL;
  CHECK(px_system_create(&kCamera, "", 0, &system) == PX_OK);
  if (!system) return 1;
  bad_query_arguments(system);
  bad_frame_arguments(system);
  CHECK(px_system_reset(system) == PX_OK);
  px_frame_result result;
  uint8_t* image = textured_image(48, 64, 3);
  CHECK(px_system_process_frame(system, image, 64, 48, 64, 0.0, &result) == PX_OK);
  CHECK(result.frame_id == 0); /* a reset forgets the frames and their times */
  free(image);
  px_system_destroy(system);
  return failures == 0 ? 0 : 1;
}

/* Frames [first, end) of `folder`; returns the index (from `first`) of the first
 * relocalised frame, or -1. Live poses go to `poses` when it is not NULL. */
static int feed(px_system* system, const ff_folder* folder, int first, int end, FILE* poses,
                int* posed) {
  int relocalised = -1;
  for (int k = first; k < end; ++k) {
    uint8_t* pixels = NULL;
    int width = 0, height = 0;
    if (!ff_read_pgm(folder->frames[k].file, &pixels, &width, &height)) {
      ++failures;
      return -1;
    }
    px_frame_result result;
    const px_status status = px_system_process_frame(system, pixels, width, height, width,
                                                     folder->frames[k].timestamp_s, &result);
    free(pixels);
    CHECK(status == PX_OK);
    if (result.state == PX_STATE_RELOCALIZED && relocalised < 0) relocalised = k - first;
    if (result.has_pose) {
      ++*posed;
      if (poses) ff_write_pose(poses, folder->frames[k].timestamp_s, result.T_w_c);
    }
  }
  return relocalised;
}

static void copy_truncated(const char* from, const char* to, long keep, long flip_at) {
  FILE* in = fopen(from, "rb");
  FILE* out = fopen(to, "wb");
  CHECK(in && out);
  if (!in || !out) return;
  for (long k = 0;; ++k) {
    int c = fgetc(in);
    if (c == EOF || (keep >= 0 && k >= keep)) break;
    if (k == flip_at) c ^= 0x20;
    fputc(c, out);
  }
  fclose(in);
  fclose(out);
}

static void check_lists(px_system* system) {
  size_t count = 0, needed = 0;
  CHECK(px_system_map_points(system, NULL, 0, &count) == PX_OK);
  CHECK(count > 1000);
  float* xyz = malloc(3 * count * sizeof *xyz);
  EXPECT_STATUS(px_system_map_points(system, xyz, count - 1, &needed), PX_ERROR_INVALID_ARGUMENT,
                "px_system_map_points");
  CHECK(needed == count);
  CHECK(px_system_map_points(system, xyz, count, &needed) == PX_OK && needed == count);
  CHECK(isfinite(xyz[0]) && isfinite(xyz[3 * count - 1]));
  free(xyz);
  CHECK(px_system_keyframes(system, NULL, 0, &count) == PX_OK && count >= 2);
  px_keyframe* keyframes = malloc(count * sizeof *keyframes);
  CHECK(px_system_keyframes(system, keyframes, count, &needed) == PX_OK);
  CHECK(keyframes[0].id == 0 && keyframes[0].scale > 0.0 && keyframes[0].T_w_kf[15] == 1.0);
  CHECK(keyframes[count - 1].id > keyframes[0].id);
  free(keyframes);
}

static void check_events_and_poses(px_system* system, int frames) {
  px_event event;
  int available = 0, keyframe_events = 0;
  uint64_t dropped = 1;
  while (px_system_poll_event(system, &event, &available, &dropped) == PX_OK && available) {
    keyframe_events += event.type == PX_EVENT_KEYFRAME;
    CHECK(event.frame_id >= 0 && event.frame_id < frames);
  }
  CHECK(keyframe_events >= 2);
  CHECK(dropped == 0);
  double T[16];
  int has_pose = 0;
  CHECK(px_system_frame_pose(system, frames - 1, T, &has_pose) == PX_OK && has_pose == 1);
  CHECK(T[15] == 1.0 && fabs(T[0] * T[0] + T[4] * T[4] + T[8] * T[8] - 1.0) < 1e-9);
  CHECK(px_system_frame_pose(system, 100000, T, &has_pose) == PX_OK && has_pose == 0);
}

/* Damaged map files are refused with PX_ERROR_IO and leave the system running. */
static void check_bad_maps(px_system* system, const char* map, const ff_folder* folder) {
  char damaged[1100];
  snprintf(damaged, sizeof damaged, "%s.damaged", map);
  copy_truncated(map, damaged, 1000, -1);
  EXPECT_STATUS(px_system_load_map(system, damaged), PX_ERROR_IO, "px_system_load_map");
  copy_truncated(map, damaged, -1, 5000);
  EXPECT_STATUS(px_system_load_map(system, damaged), PX_ERROR_IO, "px_system_load_map");
  CHECK(strstr(px_last_error(), "checksum") != NULL);
  remove(damaged);
  /* A map of another camera. */
  px_system* other = NULL;
  px_camera camera = folder->camera;
  camera.intrinsics.fx *= 1.1;
  CHECK(px_system_create_distorted(&camera, NULL, 0, &other) == PX_OK);
  EXPECT_STATUS(px_system_load_map(other, map), PX_ERROR_IO, "px_system_load_map");
  px_system_destroy(other);
}

static int functions(const char* frames_dir, const char* map) {
  ff_folder folder;
  if (!ff_open(frames_dir, &folder)) return 1;
  px_system* system = NULL;
  CHECK(px_system_create_distorted(&folder.camera, NULL, 0, &system) == PX_OK);
  px_pinhole engine;
  CHECK(px_system_camera(system, &engine) == PX_OK);
  CHECK(engine.width == folder.camera.intrinsics.width && engine.fx > 0.0);
  int posed = 0;
  feed(system, &folder, 0, folder.count, NULL, &posed);
  CHECK(posed == folder.count); /* the TUM clip: every frame posed */
  check_lists(system);
  check_events_and_poses(system, folder.count);
  CHECK(px_system_save_map(system, map) == PX_OK);
  EXPECT_STATUS(px_system_save_map(system, "/nonexistent/dir/x.pxmap"), PX_ERROR_IO,
                "px_system_save_map");
  check_bad_maps(system, map, &folder);
  /* The failed loads changed nothing: the next frame still comes in order. */
  px_frame_result result;
  uint8_t* pixels = NULL;
  int width = 0, height = 0;
  if (ff_read_pgm(folder.frames[folder.count - 1].file, &pixels, &width, &height)) {
    CHECK(px_system_process_frame(system, pixels, width, height, width,
                                  folder.frames[folder.count - 1].timestamp_s + 1.0,
                                  &result) == PX_OK);
    CHECK(result.frame_id == folder.count);
    free(pixels);
  }
  px_system_destroy(system);
  ff_free(&folder);
  return failures == 0 ? 0 : 1;
}

static int save(const char* frames_dir, int n, const char* map) {
  ff_folder folder;
  if (!ff_open(frames_dir, &folder)) return 1;
  px_system* system = NULL;
  CHECK(px_system_create_distorted(&folder.camera, NULL, 0, &system) == PX_OK);
  int posed = 0;
  feed(system, &folder, 0, n, NULL, &posed);
  CHECK(px_system_save_map(system, map) == PX_OK);
  px_system_destroy(system);
  ff_free(&folder);
  return failures == 0 ? 0 : 1;
}

/* Mean distance between this run's live positions and the reference's at the same times,
 * relative to the reference's path length. */
static double relative_difference(const char* poses, const char* reference) {
  FILE* a = fopen(poses, "r");
  FILE* b = fopen(reference, "r");
  double sum = 0.0, path = 0.0, last[3] = {0, 0, 0};
  int matched = 0, lines = 0;
  double t, T[12], ta, Ta[12];
  while (b &&
         fscanf(b, "%lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf", &t, &T[0], &T[1], &T[2],
                &T[3], &T[4], &T[5], &T[6], &T[7], &T[8], &T[9], &T[10], &T[11]) == 13) {
    if (lines++ > 0) {
      path += sqrt(pow(T[3] - last[0], 2) + pow(T[7] - last[1], 2) + pow(T[11] - last[2], 2));
    }
    last[0] = T[3], last[1] = T[7], last[2] = T[11];
    rewind(a);
    while (a && fscanf(a, "%lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf", &ta, &Ta[0],
                       &Ta[1], &Ta[2], &Ta[3], &Ta[4], &Ta[5], &Ta[6], &Ta[7], &Ta[8], &Ta[9],
                       &Ta[10], &Ta[11]) == 13) {
      if (fabs(ta - t) < 1e-6) {
        sum += sqrt(pow(Ta[3] - T[3], 2) + pow(Ta[7] - T[7], 2) + pow(Ta[11] - T[11], 2));
        ++matched;
      }
    }
  }
  if (a) fclose(a);
  if (b) fclose(b);
  return matched > 0 && path > 0.0 ? sum / matched / path : INFINITY;
}

static int load(const char* frames_dir, int n, const char* map, const char* reference) {
  ff_folder folder;
  if (!ff_open(frames_dir, &folder)) return 1;
  px_system* system = NULL;
  CHECK(px_system_create_distorted(&folder.camera, NULL, 0, &system) == PX_OK);
  CHECK(px_system_load_map(system, map) == PX_OK);
  char poses_path[1100];
  snprintf(poses_path, sizeof poses_path, "%s.poses.txt", map);
  FILE* poses = fopen(poses_path, "w");
  int posed = 0;
  const int relocalised = feed(system, &folder, n, folder.count, poses, &posed);
  fclose(poses);
  printf("relocalised on frame %d of the second part; %d of %d frames posed\n", relocalised, posed,
         folder.count - n);
  CHECK(relocalised >= 0 && relocalised < 5);
  CHECK(posed >= folder.count - n - 5);
  const double difference = relative_difference(poses_path, reference);
  printf("mean distance from the uninterrupted run: %.4f of its path\n", difference);
  CHECK(difference < 0.05);
  px_system_destroy(system);
  ff_free(&folder);
  return failures == 0 ? 0 : 1;
}

/* The same calls with the threaded mode behind them. */
static int realtime(const char* frames_dir, const char* map) {
  ff_folder folder;
  if (!ff_open(frames_dir, &folder)) return 1;
  px_system* system = NULL;
  CHECK(px_system_create_distorted(&folder.camera, NULL, 1, &system) == PX_OK);
  int posed = 0;
  feed(system, &folder, 0, folder.count, NULL, &posed);
  /* The start is answered at once (PX_STATE_INITIALIZING, no pose); its frames' poses come
   * with the map. */
  CHECK(px_system_finish_mapping(system) == PX_OK);
  int posed_now = 0;
  for (int k = 0; k < folder.count; ++k) {
    double T_w_c[16];
    int has_pose = 0;
    CHECK(px_system_frame_pose(system, k, T_w_c, &has_pose) == PX_OK);
    posed_now += has_pose;
  }
  printf("real-time mode: %d of %d frames answered with a pose, %d posed when mapping finished\n",
         posed, folder.count, posed_now);
  CHECK(posed_now >= folder.count * 9 / 10);
  size_t count = 0;
  CHECK(px_system_keyframes(system, NULL, 0, &count) == PX_OK && count >= 1);
  CHECK(px_system_map_points(system, NULL, 0, &count) == PX_OK && count > 1000);
  CHECK(px_system_save_map(system, map) == PX_OK);
  px_system_destroy(system);
  /* Destroyed mid-stream, with frames waiting for mapping. */
  CHECK(px_system_create_distorted(&folder.camera, NULL, 1, &system) == PX_OK);
  feed(system, &folder, 0, folder.count / 2, NULL, &posed);
  px_system_destroy(system);
  ff_free(&folder);
  return failures == 0 ? 0 : 1;
}

int main(int argc, char** argv) {
  if (argc == 4 && strcmp(argv[1], "realtime") == 0) return realtime(argv[2], argv[3]);
  if (argc == 2 && strcmp(argv[1], "table") == 0) return table();
  if (argc == 4 && strcmp(argv[1], "functions") == 0) return functions(argv[2], argv[3]);
  if (argc == 5 && strcmp(argv[1], "save") == 0) return save(argv[2], atoi(argv[3]), argv[4]);
  if (argc == 6 && strcmp(argv[1], "load") == 0) {
    return load(argv[2], atoi(argv[3]), argv[4], argv[5]);
  }
  fprintf(stderr, "usage: see the comment at the top of capi_test.c\n");
  return 2;
}
