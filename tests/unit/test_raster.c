/* The thumbnail rasterizer (core/raster.h) and PNG files (io/image_png.h). Pictures are checked
 * against what the geometry says independently: the covered area of a box seen face-on is its
 * projected area in pixels, a nearer box hides a farther one, corners land where the fit puts
 * them; PNG bytes decode back to the same pixels, and bytes that are not a PNG are refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/raster.h"
#include "io/image_png.h"

/* An axis-aligned box as 12 triangles in a component of its own (group g, -1 for none). */
static void add_box(ag_mesh *m, const double lo[3], const double hi[3], int32_t g, int flip)
{
    size_t c, v0 = m->nverts;
    assert_int_equal(ag_mesh_add_component(m, g, &c), AG_OK);
    for (int i = 0; i < 8; i++)
        assert_int_equal(ag_mesh_add_vertex(m, i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1],
                                            i & 4 ? hi[2] : lo[2]),
                         AG_OK);
    static const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int f = 0; f < 6; f++) {
        const int *k = q[f];
        if (flip) { /* the other diagonal */
            assert_int_equal(ag_mesh_add_triangle(m, v0 + k[0], v0 + k[1], v0 + k[3], c), AG_OK);
            assert_int_equal(ag_mesh_add_triangle(m, v0 + k[1], v0 + k[2], v0 + k[3], c), AG_OK);
        } else {
            assert_int_equal(ag_mesh_add_triangle(m, v0 + k[0], v0 + k[1], v0 + k[2], c), AG_OK);
            assert_int_equal(ag_mesh_add_triangle(m, v0 + k[0], v0 + k[2], v0 + k[3], c), AG_OK);
        }
    }
}

static size_t covered(const ag_raster_image *im)
{
    size_t n = 0;
    for (size_t i = 0; i < (size_t)im->width * im->height; i++)
        n += im->rgba[4 * i + 3] >= 128;
    return n;
}

/* A box seen face-on along y covers its face's area: the fit makes its larger side span the
 * image less the margins, at UTM-sized offsets and with either triangulation. */
static void a_box_face_on_covers_its_projected_area(void **state)
{
    (void)state;
    const double offsets[3][3] = {{0, 0, 0}, {690512.3, 5402311.7, 371.2}, {-40, 7, -3}};
    for (int o = 0; o < 3; o++)
        for (int flip = 0; flip < 2; flip++) {
            ag_mesh *m = ag_mesh_create();
            double lo[3] = {offsets[o][0], offsets[o][1], offsets[o][2]};
            double hi[3] = {lo[0] + 2.0, lo[1] + 0.3, lo[2] + 1.0}; /* 2 wide, 1 tall */
            add_box(m, lo, hi, -1, flip);
            ag_raster_view v = {.dir = {0, 1, 0}, .up = {0, 0, 1}, .margin = 0.1,
                                .colour = {200, 100, 50}};
            ag_raster_image im;
            ag_error err;
            assert_int_equal(ag_raster_mesh(m, &v, 100, 80, &im, &err), AG_OK);
            /* width 2 m spans 80 px (100 less 2 x 10 %), so 1 m is 40 px: 80 x 40 */
            double want = 80.0 * 40.0;
            double got = (double)covered(&im);
            if (fabs(got - want) > 2 * (80 + 40))
                fail_msg("offset %d flip %d: %.0f pixels covered, the face is %.0f", o, flip, got,
                         want);
            /* the corners are background, the centre is the box, shaded but not black */
            assert_int_equal(im.rgba[3], 0);
            const uint8_t *c = im.rgba + 4 * (40 * 100 + 50);
            assert_int_equal(c[3], 255);
            assert_true(c[0] > c[1] && c[1] > c[2] && c[0] > 60);
            /* the box's min corner projects to the left edge, bottom of the box */
            double px, py;
            ag_raster_project(m, &v, 100, 80, lo, &px, &py);
            assert_true(fabs(px - 10) < 1e-6 && fabs(py - 60) < 1e-6);
            ag_raster_image_clear(&im);
            ag_mesh_free(m);
        }
}

/* Two boxes one behind the other: the nearer one's colour shows where they overlap, from
 * either side (the farther one shows when the view turns round). */
static void the_nearer_box_hides_the_farther(void **state)
{
    (void)state;
    ag_mesh *m = ag_mesh_create();
    size_t g0, g1;
    assert_int_equal(ag_mesh_add_group(m, "front", &g0), AG_OK);
    assert_int_equal(ag_mesh_add_group(m, "back", &g1), AG_OK);
    add_box(m, (double[]){0, 0, 0}, (double[]){1, 0.1, 1}, (int32_t)g0, 0);
    add_box(m, (double[]){-1, 2, -1}, (double[]){2, 2.1, 2}, (int32_t)g1, 1);
    const uint8_t rgb[2][3] = {{255, 0, 0}, {0, 0, 255}};
    for (int side = 0; side < 2; side++) {
        ag_raster_view v = {.dir = {0, side ? -1 : 1, 0}, .up = {0, 0, 1}, .group_rgb = rgb,
                            .ngroups = 2, .background = {255, 255, 255, 255}};
        ag_raster_image im;
        assert_int_equal(ag_raster_mesh(m, &v, 64, 64, &im, NULL), AG_OK);
        double px, py;
        ag_raster_project(m, &v, 64, 64, (double[]){0.5, 0, 0.5}, &px, &py);
        const uint8_t *c = im.rgba + 4 * ((size_t)py * 64 + (size_t)px);
        if (!side)
            assert_true(c[0] > 0 && c[2] == 0); /* red in front */
        else
            assert_true(c[2] > 0 && c[0] == 0); /* from behind the blue one hides it */
        /* outside the small box but inside the large one: blue either way */
        ag_raster_project(m, &v, 64, 64, (double[]){1.8, 0, 1.8}, &px, &py);
        c = im.rgba + 4 * ((size_t)py * 64 + (size_t)px);
        assert_true(c[2] > 0 && c[0] == 0);
        ag_raster_image_clear(&im);
    }
    ag_mesh_free(m);
}

static void bad_views_and_sizes_are_refused(void **state)
{
    (void)state;
    ag_mesh *m = ag_mesh_create();
    add_box(m, (double[]){0, 0, 0}, (double[]){1, 1, 1}, -1, 0);
    ag_raster_image im;
    ag_error err;
    ag_raster_view v = {.dir = {0, 0, 1}, .up = {0, 0, 1}};
    assert_int_equal(ag_raster_mesh(m, &v, 32, 32, &im, &err), AG_ERR_INVALID);
    assert_null(im.rgba);
    v.dir[2] = 0;
    assert_int_equal(ag_raster_mesh(m, &v, 32, 32, &im, &err), AG_ERR_INVALID);
    v.dir[0] = 1;
    assert_int_equal(ag_raster_mesh(m, &v, 0, 32, &im, &err), AG_ERR_INVALID);
    assert_int_equal(ag_raster_mesh(m, &v, 32, AG_RASTER_MAX_SIDE + 1, &im, &err),
                     AG_ERR_INVALID);
    /* an empty mesh is the background alone */
    ag_mesh *empty = ag_mesh_create();
    v.background[0] = 9;
    v.background[3] = 255;
    assert_int_equal(ag_raster_mesh(empty, &v, 8, 8, &im, &err), AG_OK);
    for (size_t i = 0; i < 64; i++)
        assert_int_equal(im.rgba[4 * i], 9);
    ag_raster_image_clear(&im);
    ag_mesh_free(empty);
    ag_mesh_free(m);
}

static void png_round_trips_and_refuses_what_is_not_one(void **state)
{
    (void)state;
    ag_mesh *m = ag_mesh_create();
    add_box(m, (double[]){0, 0, 0}, (double[]){1, 2, 3}, -1, 0);
    ag_raster_view v = {.dir = {-1, 1, -0.6}, .up = {0, 0, 1}, .margin = 0.05,
                        .colour = {120, 160, 200}};
    ag_raster_image im, back;
    ag_error err;
    assert_int_equal(ag_raster_mesh(m, &v, 128, 96, &im, &err), AG_OK);
    uint8_t *png;
    size_t len;
    assert_int_equal(ag_image_png_encode(&im, &png, &len, &err), AG_OK);
    assert_true(len > 8 && memcmp(png, "\x89PNG\r\n\x1a\n", 8) == 0);
    assert_int_equal(ag_image_png_decode(png, len, &back, &err), AG_OK);
    assert_int_equal(back.width, 128);
    assert_int_equal(back.height, 96);
    assert_memory_equal(back.rgba, im.rgba, 128 * 96 * 4);
    ag_raster_image_clear(&back);
    /* truncated, and not a PNG at all */
    assert_int_equal(ag_image_png_decode(png, len / 2, &back, &err), AG_ERR_PARSE);
    assert_null(back.rgba);
    assert_int_equal(ag_image_png_decode("GIF89a....", 10, &back, &err), AG_ERR_PARSE);
    free(png);
    ag_raster_image none = {0};
    assert_int_equal(ag_image_png_encode(&none, &png, &len, &err), AG_ERR_INVALID);
    assert_null(png);
    ag_raster_image_clear(&im);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_box_face_on_covers_its_projected_area),
        cmocka_unit_test(the_nearer_box_hides_the_farther),
        cmocka_unit_test(bad_views_and_sizes_are_refused),
        cmocka_unit_test(png_round_trips_and_refuses_what_is_not_one),
    };
    return cmocka_run_group_tests_name("raster", tests, NULL, NULL);
}
