/* An AR-style loop on the Parallax C API: frames in, pose and tracking state out, events
 * polled, the map saved at the end (or a saved map loaded at the start).
 *
 *   ar_loop FRAMES_DIR POSES_OUT [--load-map FILE] [--save-map FILE] [--first N] [--count N]
 *
 * FRAMES_DIR: camera.txt + frames.txt + PGM images (frame_folder.h). POSES_OUT gets one line
 * per frame that had a live pose: timestamp and the 3x4 row-major camera-to-world pose.
 * Build: cc -std=c11 ar_loop.c $(pkg-config --cflags --libs parallax), or CMake with
 * find_package(Parallax) (CMakeLists.txt beside this file). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "frame_folder.h"
#include "parallax/parallax.h"

static const char* state_name(px_tracking_state state) {
  switch (state) {
    case PX_STATE_INITIALIZING:
      return "initializing";
    case PX_STATE_TRACKING:
      return "tracking";
    case PX_STATE_POOR:
      return "poor";
    case PX_STATE_LOST:
      return "lost";
    case PX_STATE_RELOCALIZED:
      return "relocalized";
  }
  return "?";
}

static int fail(const char* what, px_status status) {
  fprintf(stderr, "ar_loop: %s: %s: %s\n", what, px_status_string(status), px_last_error());
  return 1;
}

/* Events an app would react to (re-anchor content on a loop or relocalisation). */
static void drain_events(px_system* system) {
  px_event event;
  int available = 1;
  while (px_system_poll_event(system, &event, &available, NULL) == PX_OK && available) {
    if (event.type == PX_EVENT_LOOP_CLOSED) {
      printf("  loop closed: keyframe %lld with %lld\n", (long long)event.keyframe_id,
             (long long)event.other_keyframe_id);
    } else if (event.type == PX_EVENT_RELOCALIZED) {
      printf("  relocalized on keyframe %lld\n", (long long)event.keyframe_id);
    }
  }
}

/* Feeds frames [first, first + count) and writes their live poses. */
static int run(px_system* system, const ff_folder* folder, int first, int count, FILE* poses) {
  int posed = 0;
  const int end = count > 0 && first + count < folder->count ? first + count : folder->count;
  for (int k = first; k < end; ++k) {
    uint8_t* pixels = NULL;
    int width = 0, height = 0;
    if (!ff_read_pgm(folder->frames[k].file, &pixels, &width, &height)) return -1;
    px_frame_result result;
    const px_status status = px_system_process_frame(system, pixels, width, height, width,
                                                     folder->frames[k].timestamp_s, &result);
    free(pixels);
    if (status != PX_OK) return fail("process_frame", status), -1;
    printf("frame %lld %s%s\n", (long long)result.frame_id, state_name(result.state),
           result.is_keyframe ? " keyframe" : "");
    if (result.has_pose) {
      ff_write_pose(poses, folder->frames[k].timestamp_s, result.T_w_c);
      ++posed;
    }
    drain_events(system);
  }
  return posed;
}

int main(int argc, char** argv) {
  if (argc < 3) {
    fprintf(stderr,
            "usage: ar_loop FRAMES_DIR POSES_OUT [--load-map F] [--save-map F] "
            "[--first N] [--count N]\n");
    return 2;
  }
  const char* load_map = NULL;
  const char* save_map = NULL;
  int first = 0, count = 0;
  for (int i = 3; i + 1 < argc; i += 2) {
    if (strcmp(argv[i], "--load-map") == 0)
      load_map = argv[i + 1];
    else if (strcmp(argv[i], "--save-map") == 0)
      save_map = argv[i + 1];
    else if (strcmp(argv[i], "--first") == 0)
      first = atoi(argv[i + 1]);
    else if (strcmp(argv[i], "--count") == 0)
      count = atoi(argv[i + 1]);
  }
  ff_folder folder;
  if (!ff_open(argv[1], &folder)) return 1;
  px_system* system = NULL;
  px_status status = px_system_create_distorted(&folder.camera, NULL, 0, &system);
  if (status != PX_OK) return ff_free(&folder), fail("create", status);
  if (load_map && (status = px_system_load_map(system, load_map)) != PX_OK) {
    px_system_destroy(system);
    ff_free(&folder);
    return fail("load_map", status);
  }
  FILE* poses = fopen(argv[2], "w");
  const int posed = poses ? run(system, &folder, first, count, poses) : -1;
  if (poses) fclose(poses);
  int exit_code = posed < 0 ? 1 : 0;
  size_t points = 0;
  if (exit_code == 0 && px_system_map_points(system, NULL, 0, &points) == PX_OK) {
    printf("%d frames posed, %zu map points (Parallax %s)\n", posed, points, px_version());
  }
  if (exit_code == 0 && save_map && (status = px_system_save_map(system, save_map)) != PX_OK) {
    exit_code = fail("save_map", status);
  }
  px_system_destroy(system);
  ff_free(&folder);
  return exit_code;
}
