/* Compares live poses: a poses file of the C API (ar_loop's format: timestamp and 3x4
 * row-major camera-to-world) against `parallax run`'s trajectory_online.txt (TUM:
 * timestamp tx ty tz qx qy qz qw). Every frame must be in both, at the same time, with the
 * same pose to the precision TUM files are written with.
 *   capi_same_poses POSES TRAJECTORY_ONLINE */
#include <math.h>
#include <stdio.h>

int main(int argc, char** argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: capi_same_poses POSES TRAJECTORY_ONLINE\n");
    return 2;
  }
  FILE* a = fopen(argv[1], "r");
  FILE* b = fopen(argv[2], "r");
  if (!a || !b) {
    fprintf(stderr, "capi_same_poses: cannot open %s\n", a ? argv[2] : argv[1]);
    return 1;
  }
  int frames = 0, bad = 0;
  double t, T[12], tb, p[3], q[4];
  for (;;) {
    const int na =
        fscanf(a, "%lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf", &t, &T[0], &T[1], &T[2],
               &T[3], &T[4], &T[5], &T[6], &T[7], &T[8], &T[9], &T[10], &T[11]);
    const int nb = fscanf(b, "%lf %lf %lf %lf %lf %lf %lf %lf", &tb, &p[0], &p[1], &p[2], &q[0],
                          &q[1], &q[2], &q[3]);
    if (na != 13 || nb != 8) {
      if (na == 13 || nb == 8) {
        fprintf(stderr, "capi_same_poses: the files have different frame counts\n");
        ++bad;
      }
      break;
    }
    ++frames;
    /* Rotation of the unit quaternion (x y z w). */
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const double R[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
                         2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                         2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
    double worst = fabs(t - tb) > 1e-6 ? 1.0 : 0.0;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) worst = fmax(worst, fabs(T[4 * r + c] - R[3 * r + c]));
      worst = fmax(worst, fabs(T[4 * r + 3] - p[r]));
    }
    if (worst > 1e-8) {
      fprintf(stderr, "frame %d (t=%.6f): differs by %.3g\n", frames - 1, t, worst);
      ++bad;
    }
  }
  fclose(a);
  fclose(b);
  printf("%d frames compared, %d differ\n", frames, bad);
  return bad == 0 && frames > 0 ? 0 : 1;
}
