/* Cutting a tile per footprint: a generated street (ground, two row houses sharing a wall, a
 * courtyard hole, a tree by a wall) with and without classification, and the AHN3 tile with
 * its BGT footprints against the quality bar (kept points >= 95 % building class, holding
 * >= 95 % of the building points inside the footprints; every footprint with building points
 * gets points), with the point-in-polygon test written again here. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/points/cut.h"
#include "core/points/rng.h"
#include "io/cloud_import.h"
#include "io/footprints.h"

#define SHARED AG_REPO_DIR "/../shared/data"

enum { GROUND = 2, BUILDING = 6, TREE = 1 };

/* Independent even-odd test over the footprint's rings. */
static int inside_rings(const double *const *loops, const size_t *sizes, size_t nloops, double x, double y)
{
    int in = 0;
    for (size_t l = 0; l < nloops; l++)
        for (size_t i = 0; i < sizes[l]; i++) {
            const double *a = loops[l] + 2 * i, *b = loops[l] + 2 * ((i + 1) % sizes[l]);
            if ((a[1] > y) != (b[1] > y) && x < a[0] + (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]))
                in = !in;
        }
    return in;
}

/* Ground z = 0.01 x (a gentle slope) over 60 x 40 m; house A [10,20]x[10,20] with a
 * courtyard [13,17]x[13,17]; house B [20,30]x[10,20] sharing A's east wall; roofs at 8 m,
 * walls sampled; a tree (a blob 3-7 m up) growing from 0.25 m north of B. */
static ag_cloud *street(int classified, double far)
{
    ag_rng r;
    ag_rng_seed(&r, 21);
    ag_cloud *c = ag_cloud_create();
    size_t n = 60000;
    assert_int_equal(ag_cloud_resize(c, n, NULL), AG_OK);
    size_t cls;
    if (classified)
        assert_int_equal(ag_cloud_add_property(c, "classification", AG_SCALAR_UINT8, &cls, NULL), AG_OK);
    c->offset[0] = far;
    c->offset[1] = far;
    for (size_t i = 0; i < n; i++) {
        double x, y, z;
        int k;
        size_t kind = i % 10;
        if (kind < 4) { /* ground, not under roofs */
            do {
                x = ag_rng_unit(&r) * 60;
                y = ag_rng_unit(&r) * 40;
            } while (x > 10 && x < 30 && y > 10 && y < 20 && !(x > 13 && x < 17 && y > 13 && y < 17));
            z = 0.01 * x + 0.03 * ag_rng_gauss(&r);
            k = GROUND;
        } else if (kind < 8) { /* roofs */
            do {
                x = 10 + ag_rng_unit(&r) * 20;
                y = 10 + ag_rng_unit(&r) * 10;
            } while (x > 13 && x < 17 && y > 13 && y < 17);
            z = 8 + 0.02 * ag_rng_gauss(&r);
            k = BUILDING;
        } else if (kind == 8) { /* walls, slightly outside the footprint line */
            double t = ag_rng_unit(&r);
            int side = (int)ag_rng_below(&r, 4);
            x = side == 0 ? 10 - 0.1 : side == 1 ? 30 + 0.1 : 10 + 20 * t;
            y = side < 2 ? 10 + 10 * t : side == 2 ? 10 - 0.1 : 20 + 0.1;
            z = 1 + ag_rng_unit(&r) * 7;
            k = BUILDING;
        } else { /* the tree */
            x = 25 + ag_rng_gauss(&r) * 0.8;
            y = 20.25 + fabs(ag_rng_gauss(&r)) * 0.8;
            z = 5 + ag_rng_gauss(&r);
            k = TREE;
        }
        c->xyz[3 * i] = x;
        c->xyz[3 * i + 1] = y;
        c->xyz[3 * i + 2] = z;
        if (classified)
            ag_cloud_set(&c->props[cls], i, k);
        /* the truth travels in a property the cut does not read */
        (void)k;
    }
    return c;
}

static int truth_kind(const ag_cloud *c, size_t i)
{
    /* recomputed from geometry, as the generator placed it */
    double x = c->xyz[3 * i], y = c->xyz[3 * i + 1], z = c->xyz[3 * i + 2];
    if (z > 4.5 && z < 11 && fabs(z - 8) < 0.2 && x >= 10 && x <= 30 && y >= 10 && y <= 20)
        return BUILDING;
    if (z < 0.01 * x + 0.3)
        return GROUND;
    if ((fabs(x - 9.9) < 1e-9 || fabs(x - 30.1) < 1e-9 || fabs(y - 9.9) < 1e-9 || fabs(y - 20.1) < 1e-9))
        return BUILDING;
    return TREE;
}

static void test_street(void **state)
{
    (void)state;
    const double a_outer[] = {10, 10, 20, 10, 20, 20, 10, 20}, a_hole[] = {13, 13, 13, 17, 17, 17, 17, 13};
    const double b_outer[] = {20, 10, 30, 10, 30, 20, 20, 20};
    for (int classified = 0; classified < 2; classified++)
        for (int f = 0; f < 2; f++) {
            double far = f ? 485000 : 0;
            ag_cloud *c = street(classified, far);
            /* footprints in the cloud's local frame */
            const double *la[2] = {a_outer, a_hole}, *lb[1] = {b_outer};
            size_t sa[2] = {4, 4}, sb[1] = {4};
            ag_cut_footprint fp[2] = {{2, sa, la}, {1, sb, lb}};
            int32_t *owner = malloc(c->n * sizeof *owner);
            ag_cut_stats st[2];
            ag_cut_options o = {0};
            assert_int_equal(ag_cut_assign(c, fp, 2, &o, owner, st, NULL), AG_OK);
            assert_int_equal(st[0].by_class || st[1].by_class, classified);
            assert_int_equal(ag_cut_ground_method(c, AG_CUT_GROUND_AUTO),
                             classified ? AG_CUT_GROUND_CLASS : AG_CUT_GROUND_PLANE);
            size_t kept = 0, kept_building = 0, roof_inside = 0, roof_kept = 0;
            for (size_t i = 0; i < c->n; i++) {
                double x = c->xyz[3 * i], y = c->xyz[3 * i + 1];
                int k = truth_kind(c, i);
                int in_a = inside_rings(la, sa, 2, x, y), in_b = inside_rings(lb, sb, 1, x, y);
                /* a point inside a footprint goes to it, never to the neighbour */
                if (owner[i] >= 0) {
                    kept++;
                    kept_building += k == BUILDING;
                    if (in_a)
                        assert_int_equal(owner[i], 0);
                    if (in_b && !in_a)
                        assert_int_equal(owner[i], 1);
                    /* nothing from the courtyard's ground or far away */
                    assert_true(k != GROUND);
                }
                if (k == BUILDING && (in_a || in_b)) {
                    roof_inside++;
                    roof_kept += owner[i] >= 0;
                }
                /* the walls 10 cm outside come through the buffer */
                if (k == BUILDING && fabs(x - 9.9) < 1e-9 && y > 10.5 && y < 19.5)
                    assert_int_equal(owner[i], 0);
            }
            double purity = (double)kept_building / kept, recall = (double)roof_kept / roof_inside;
            print_message("street %s%s: kept %zu, building share %.4f, building kept %.4f\n",
                          classified ? "classified" : "unclassified", f ? " at UTM" : "", kept, purity, recall);
            assert_true(recall > 0.99);
            /* the tree's side within B's 0.5 m buffer comes along without classes; with them
             * the buffer takes building points only */
            if (classified)
                assert_true(purity > 0.999);
            else
                assert_true(purity > 0.9 && purity < 0.99);
            assert_int_equal(st[0].kept + st[1].kept, kept);
            free(owner);
            ag_cloud_free(c);
        }
}

static void test_ahn3_bar(void **state)
{
    (void)state;
    const char *tile = SHARED "/pointcloud_ahn3_delft/ahn3_cropped_1.laz";
    const char *bgt = SHARED "/pointcloud_ahn3_delft/bgt_pand_footprints.geojson";
    if (access(tile, R_OK) || access(bgt, R_OK)) {
        print_message("skipping: %s is absent\n", SHARED "/pointcloud_ahn3_delft");
        skip();
    }
    ag_cloud *c;
    ag_error e;
    assert_int_equal(ag_cloud_import_file(tile, &c, &e), AG_OK);
    ag_footprints_options fo = {.lonlat = -1};
    ag_footprints *fp;
    assert_int_equal(ag_footprints_read_file(bgt, &fo, &fp, &e), AG_OK);
    assert_int_equal(fp->n, 160);
    /* footprints into the tile's local frame */
    ag_cut_footprint *cf = calloc(fp->n, sizeof *cf);
    double ***loops = calloc(fp->n, sizeof *loops);
    for (size_t k = 0; k < fp->n; k++) {
        const ag_footprint *f = &fp->items[k];
        loops[k] = calloc(f->nloops, sizeof *loops[k]);
        for (size_t l = 0; l < f->nloops; l++) {
            loops[k][l] = malloc(2 * f->sizes[l] * sizeof(double));
            for (size_t v = 0; v < f->sizes[l]; v++) {
                loops[k][l][2 * v] = f->loops[l][2 * v] + fp->origin[0] - c->offset[0];
                loops[k][l][2 * v + 1] = f->loops[l][2 * v + 1] + fp->origin[1] - c->offset[1];
            }
        }
        cf[k] = (ag_cut_footprint){f->nloops, f->sizes, (const double *const *)loops[k]};
    }
    int32_t *owner = malloc(c->n * sizeof *owner);
    ag_cut_stats *st = calloc(fp->n, sizeof *st);
    assert_int_equal(ag_cut_assign(c, cf, fp->n, NULL, owner, st, &e), AG_OK);
    const ag_cloud_property *cls = ag_cloud_find(c, "classification");
    size_t kept = 0, kept6 = 0, inside6 = 0, inside6_kept = 0;
    size_t *building_pts = calloc(fp->n, sizeof *building_pts);
    for (size_t i = 0; i < c->n; i++) {
        int is6 = ag_cloud_get(cls, i) == 6;
        if (owner[i] >= 0) {
            kept++;
            kept6 += is6;
        }
        if (!is6)
            continue;
        for (size_t k = 0; k < fp->n; k++)
            if (inside_rings(cf[k].loops, cf[k].sizes, cf[k].nloops, c->xyz[3 * i], c->xyz[3 * i + 1])) {
                inside6++;
                inside6_kept += owner[i] >= 0;
                building_pts[k]++;
                break;
            }
    }
    double purity = (double)kept6 / kept, recall = (double)inside6_kept / inside6;
    size_t with_building = 0, with_points = 0;
    for (size_t k = 0; k < fp->n; k++) {
        with_building += building_pts[k] > 0;
        with_points += st[k].kept > 0;
        /* every footprint with building points gets a cloud */
        if (building_pts[k])
            assert_true(st[k].kept > 0);
    }
    print_message("AHN3: kept %zu points, %.2f %% class 6; %.2f %% of the %zu class-6 points inside the "
                  "footprints kept; %zu footprints with building points, %zu with a cloud\n",
                  kept, 100 * purity, 100 * recall, inside6, with_building, with_points);
    assert_true(purity >= 0.95);
    assert_true(recall >= 0.95);
    free(building_pts);
    free(owner);
    free(st);
    for (size_t k = 0; k < fp->n; k++) {
        for (size_t l = 0; l < fp->items[k].nloops; l++)
            free(loops[k][l]);
        free(loops[k]);
    }
    free(loops);
    free(cf);
    ag_footprints_free(fp);
    ag_cloud_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_street),
        cmocka_unit_test(test_ahn3_bar),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
