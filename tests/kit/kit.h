/* kit.h — the C test kit (tests/kit/kit.c, library splat_testkit): what
 * the device test programs share, through the public splatrt.h alone.
 *
 *   CHECK(cond, fmt, ...)   a failed check is printed and counted, and the
 *                           program goes on; kit_finish() at the end of
 *                           main turns the count into the exit status.
 *   kit_device, kit_pack    a device (validation as $SPLAT_VALIDATE says)
 *                           and a loaded pack, NULL and a failure counted
 *                           when they cannot be had; kit_device_close
 *                           counts a failure for any validation message
 *                           over the device's life, teardown included.
 *   kit_build_pack          a fresh pack built with splatc's library.
 *   kit_frame, kit_render   one frame read back as RGBA32F.
 *   kit_image_near/_equal   pictures compared within a tolerance.
 *   kit_read_file           a whole file.
 */
#ifndef SPLAT_TESTS_KIT_H
#define SPLAT_TESTS_KIT_H

#include "scene.h"
#include "splatrt.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* ---- checks ------------------------------------------------------------ */

#define CHECK(cond, ...)                                                    \
    do {                                                                    \
        if (!(cond))                                                        \
            kit_fail(__FILE__, __LINE__, #cond, __VA_ARGS__);               \
    } while (0)

/* Print "FAIL file:line: cond: message" and count it. */
void kit_fail(const char *file, int line, const char *cond, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* Failures counted so far. */
int  kit_failures(void);
/* main's exit status: 1 (and "N failures") if any check failed, else 0
 * (and "NAME: all checks passed"). */
int  kit_finish(const char *name);

/* ---- files ------------------------------------------------------------- */

/* "dir/name", malloc'd. */
char *kit_join(const char *dir, const char *name);
/* The whole file, NUL-terminated (n: its size without the NUL; may be
 * NULL); NULL and a failure counted if it cannot be read. */
char *kit_read_file(const char *path, size_t *n);

/* ---- packs, devices, frames --------------------------------------------- */

/* Build scene file `sg` into folder `pack` (removed first), imports
 * searched in "." (the repository root); the diagnostics in *d (free
 * them).  No failure counted: tests of refused scenes call it too. */
bool kit_build_pack(const char *sg, const char *pack, splat_painted_format painted,
                    sg_diags *d);
/* kit_build_pack for a scene that must build: diagnostics printed and a
 * failure counted if not. */
bool kit_build_pack_ok(const char *sg, const char *pack);

/* rt_device_open with the defaults; NULL and a failure counted. */
rt_device *kit_device(void);
/* rt_device_close, a failure counted for each validation message. */
void kit_device_close(rt_device *d);
/* rt_pack_open; NULL and a failure counted. */
rt_pack *kit_pack(const char *dir);
/* The pack's rt_pack_info. */
rt_pack_info kit_pack_info(const rt_pack *p);

/* One frame of renderer r from cam, read back (w x h RGBA32F, free it);
 * NULL and a failure counted if it cannot be drawn. */
float *kit_frame(rt_renderer *r, const rt_camera *cam, int w, int h);
/* A renderer of `rd` (its width, height, reference, shading, clear,
 * light), one frame of `view` (`material` for the MASK view) from cam,
 * read back; NULL and a failure counted if any step fails. */
float *kit_render(rt_device *dev, const rt_pack *p, const rt_render_desc *rd,
                  splat_view view, int material, const rt_camera *cam);
/* DIR/NAME as a PNG, tone-mapped as the view's screenshots are. */
void kit_write_picture(const char *dir, const char *name, const float *rgba, int w, int h,
                       splat_view view);

/* ---- pictures ------------------------------------------------------------ */

/* The largest absolute difference of n floats. */
double kit_max_diff(const float *a, const float *b, size_t n);
/* a and b (w x h RGBA32F) agree within tol in every channel of every
 * pixel; else a failure counted, naming `what`, the worst pixel and how
 * many are off.  NULL pictures fail. */
#define kit_image_near(a, b, w, h, tol, what)                               \
    kit_image_near_at(__FILE__, __LINE__, a, b, w, h, tol, what)
/* kit_image_near with tol 0: bit for bit equal values. */
#define kit_image_equal(a, b, w, h, what)                                   \
    kit_image_near_at(__FILE__, __LINE__, a, b, w, h, 0.0, what)
/* The two above, failures reported at file:line. */
bool kit_image_near_at(const char *file, int line, const float *a, const float *b, int w,
                       int h, double tol, const char *what);

#endif
