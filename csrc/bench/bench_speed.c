/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Speed of hbao_compute() at 1920x1080 (or --width/--height) on a synthetic
 * scene that fills the frame (a room corner with boxes, no background):
 * median time per frame over --runs runs for 4/8/16 directions x 4/6/8
 * steps, full and half resolution, without and with a 15-pixel blur, for
 * the portable scalar code on 1 thread and the fastest kernel on 1 and 2
 * threads, all in the same run. --quick: 8 x 6 only. Prints a Markdown
 * table. Not a test: it asserts nothing. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hbao.h"
#include "scene.h"

static double now_seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int compare_doubles(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv) {
    int width = 1920, height = 1080, runs = 3, quick = 0;
    float radius = 0.5f;
    for (int a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--width") && a + 1 < argc) width = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--height") && a + 1 < argc) height = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--runs") && a + 1 < argc) runs = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--quick")) quick = 1;
        else if (!strcmp(argv[a], "--radius") && a + 1 < argc) radius = (float)atof(argv[++a]);
        else {
            fprintf(stderr, "usage: %s [--width W] [--height H] [--runs N] [--radius R] [--quick]\n", argv[0]);
            return 2;
        }
    }
    if (width < 1 || height < 1 || runs < 1 || runs > 1000) {
        fprintf(stderr, "bench_speed: bad size or run count\n");
        return 2;
    }
    /* floor, back wall, side wall and a box: every pixel is geometry */
    scene s;
    memset(&s, 0, sizeof s);
    s.plane[s.planes] = scene_plane_make(0, 0, 0, 0, 0, 1);
    scene_plane_clip(&s.plane[s.planes++], 1, 0, 0, 0);
    s.plane[s.planes] = scene_plane_make(0, 0, 0, -1, 0, 0);
    scene_plane_clip(&s.plane[s.planes++], 0, 0, -1, 0);
    s.plane[s.planes++] = scene_plane_make(0, 4, 0, 0, -1, 0);
    scene_plane front = scene_plane_make(-1.5, 0, 0, -1, 0, 0);
    scene_plane_clip(&front, 0, 0, 1, 0.6);
    scene_plane_clip(&front, 0, 1, 0, 0.5);
    s.plane[s.planes++] = front;
    scene_plane top = scene_plane_make(0, 0, 0.6, 0, 0, 1);
    scene_plane_clip(&top, -1, 0, 0, 1.5);
    scene_plane_clip(&top, 0, 1, 0, 0.5);
    s.plane[s.planes++] = top;
    scene_view view;
    memset(&view, 0, sizeof view);
    view.width = width;
    view.height = height;
    hbao_camera_default(&view.camera);
    const double eye[3] = {-5.0, -2.0, 2.5}, target[3] = {-0.5, 1.0, 0.4};
    scene_look_at(&view, eye, target);
    float *depth, *normal;
    scene_render(&s, &view, &depth, &normal);
    float *ao = malloc((size_t)width * height * sizeof(float));
    hbao_channel d = {depth, 1, width};
    hbao_channel n = {normal, 3, 3 * (int64_t)width};

    printf("# hbao_compute at %dx%d, radius %g (scene ~3-7 units deep), median of %d runs, ms per frame\n\n", width, height, radius, runs);
    static const char *const kernel_names[] = {"auto", "scalar", "AVX2", "AVX-512"};
    printf("Fastest horizon kernel on this CPU: %s. Columns: the scalar reference horizon search on 1 "
           "thread, then that kernel on 1 and 2 threads (blur and upsample are the same code in every "
           "column).\n\n",
           kernel_names[hbao_best_implementation()]);
    printf("| integration | directions x steps | resolution | blur | scalar, 1 thread | 1 thread | "
           "2 threads | speed-up |\n");
    printf("|---|---|---|---|---|---|---|---|\n");
    const int directions[] = {4, 8, 16}, steps[] = {4, 6, 8};
    double *times = malloc((size_t)runs * sizeof(double));
    for (int integration = 0; integration <= 1; integration++) {
        for (int di = 0; di < 3; di++) {
            for (int si = 0; si < 3; si++) {
                if (quick && !(directions[di] == 8 && steps[si] == 6)) continue;
                for (int half = 0; half <= 1; half++) {
                    for (int blur = 0; blur <= 15; blur += 15) {
                        /* scalar on 1 thread, then the fastest kernel on 1 and 2 */
                        const int kernel[3] = {HBAO_IMPLEMENTATION_SCALAR, HBAO_IMPLEMENTATION_AUTO,
                                               HBAO_IMPLEMENTATION_AUTO};
                        const int thread_count[3] = {1, 1, 2};
                        double median[3];
                        for (int column = 0; column < 3; column++) {
                            hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
                            p.integration = integration;
                            p.directions = directions[di];
                            p.steps = steps[si];
                            p.half_resolution = half;
                            p.blur_size = blur;
                            p.threads = thread_count[column];
                            p.implementation = kernel[column];
                            p.radius = radius;
                            for (int r = 0; r < runs; r++) {
                                const double start = now_seconds();
                                const hbao_result result = hbao_compute(&p, &view.camera, width, height, &d, &n, ao, width);
                                times[r] = now_seconds() - start;
                                if (result != HBAO_SUCCESS) {
                                    fprintf(stderr, "bench_speed: %s\n", hbao_result_message(result));
                                    return 1;
                                }
                            }
                            qsort(times, (size_t)runs, sizeof(double), compare_doubles);
                            median[column] = times[runs / 2];
                        }
                        printf("| %s | %d x %d | %s | %d | %.1f | %.1f | %.1f | %.1fx |\n",
                               integration ? "cosine" : "hbao", directions[di], steps[si],
                               half ? "half" : "full", blur, 1e3 * median[0], 1e3 * median[1],
                               1e3 * median[2], median[0] / median[2]);
                        fflush(stdout);
                    }
                }
            }
        }
    }
    free(times);
    free(ao);
    free(depth);
    free(normal);
    return 0;
}
