/* A folder of frames for the C API examples and tests (C11, no dependencies):
 *   camera.txt  one line: model width height fx fy cx cy d0 d1 d2 d3 d4 rectification
 *               (model: 0 pinhole, 1 radtan, 2 equidistant, 3 fov; rectification: 0 crop,
 *               1 full; the px_camera fields)
 *   frames.txt  one line per frame: timestamp_s file (a binary 8-bit PGM, P5, beside it)
 * Any camera's raw grey frames can be written this way; tests/capi/export_frames.cpp writes
 * a dataset's. */
#ifndef PARALLAX_EXAMPLES_FRAME_FOLDER_H
#define PARALLAX_EXAMPLES_FRAME_FOLDER_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "parallax/parallax.h"

typedef struct {
  double timestamp_s;
  char file[512];
} ff_frame;

typedef struct {
  px_camera camera;
  ff_frame* frames;
  int count;
} ff_folder;

static int ff_read_camera(const char* folder, px_camera* camera) {
  char path[1024];
  snprintf(path, sizeof path, "%s/camera.txt", folder);
  FILE* f = fopen(path, "r");
  if (!f) {
    fprintf(stderr, "%s: cannot open\n", path);
    return 0;
  }
  memset(camera, 0, sizeof *camera);
  const int n =
      fscanf(f, "%d %d %d %lf %lf %lf %lf %lf %lf %lf %lf %lf %d", &camera->model,
             &camera->intrinsics.width, &camera->intrinsics.height, &camera->intrinsics.fx,
             &camera->intrinsics.fy, &camera->intrinsics.cx, &camera->intrinsics.cy,
             &camera->distortion[0], &camera->distortion[1], &camera->distortion[2],
             &camera->distortion[3], &camera->distortion[4], &camera->rectification);
  fclose(f);
  if (n != 13) {
    fprintf(stderr, "%s:1: expected 13 numbers, read %d\n", path, n < 0 ? 0 : n);
    return 0;
  }
  return 1;
}

/* Reads camera.txt and frames.txt; returns 0 (with a message naming the file and line) on
 * failure. ff_free releases the list. */
static int ff_open(const char* folder, ff_folder* out) {
  memset(out, 0, sizeof *out);
  if (!ff_read_camera(folder, &out->camera)) return 0;
  char path[1024];
  snprintf(path, sizeof path, "%s/frames.txt", folder);
  FILE* f = fopen(path, "r");
  if (!f) {
    fprintf(stderr, "%s: cannot open\n", path);
    return 0;
  }
  int capacity = 0;
  char line[1024];
  for (int number = 1; fgets(line, sizeof line, f); ++number) {
    if (line[0] == '#' || line[0] == '\n') continue;
    if (out->count == capacity) {
      capacity = capacity ? 2 * capacity : 64;
      ff_frame* grown = realloc(out->frames, (size_t)capacity * sizeof *grown);
      if (!grown) break;
      out->frames = grown;
    }
    ff_frame* frame = &out->frames[out->count];
    char name[400];
    if (sscanf(line, "%lf %399s", &frame->timestamp_s, name) != 2) {
      fprintf(stderr, "%s:%d: expected: timestamp file\n", path, number);
      fclose(f);
      return 0;
    }
    snprintf(frame->file, sizeof frame->file, "%s/%s", folder, name);
    ++out->count;
  }
  fclose(f);
  return 1;
}

static void ff_free(ff_folder* folder) {
  free(folder->frames);
  folder->frames = NULL;
  folder->count = 0;
}

/* Reads a binary 8-bit PGM into *pixels (malloc'd, row-major, stride = width). */
static int ff_read_pgm(const char* path, uint8_t** pixels, int* width, int* height) {
  FILE* f = fopen(path, "rb");
  if (!f) {
    fprintf(stderr, "%s: cannot open\n", path);
    return 0;
  }
  int maxval = 0;
  if (fscanf(f, "P5 %d %d %d", width, height, &maxval) != 3 || maxval != 255 || *width <= 0 ||
      *height <= 0 || fgetc(f) == EOF) {
    fprintf(stderr, "%s: not an 8-bit binary PGM\n", path);
    fclose(f);
    return 0;
  }
  const size_t size = (size_t)*width * (size_t)*height;
  *pixels = malloc(size);
  const int ok = *pixels && fread(*pixels, 1, size, f) == size;
  fclose(f);
  if (!ok) {
    fprintf(stderr, "%s: truncated\n", path);
    free(*pixels);
    *pixels = NULL;
  }
  return ok;
}

/* One line of a poses file: timestamp, then the 3x4 row-major camera-to-world pose (the
 * KITTI layout). */
static void ff_write_pose(FILE* out, double timestamp_s, const double T[16]) {
  fprintf(out, "%.6f", timestamp_s);
  for (int k = 0; k < 12; ++k) fprintf(out, " %.17g", T[k]);
  fputc('\n', out);
}

#endif /* PARALLAX_EXAMPLES_FRAME_FOLDER_H */
