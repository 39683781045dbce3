/* LAS: every point format 0-10 built here byte by byte from the specification's field
 * order (independent of the reader's tables), read and compared field by field; the writer
 * round-trips every format; extra bytes; headers that lie; the shared urban.las. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/points/rng.h"
#include "io/cloud_import.h"
#include "io/las.h"

#define DATA AG_REPO_DIR "/tests/data/points/"
#define SHARED AG_REPO_DIR "/../shared/data"

typedef struct {
    uint8_t *b;
    size_t n, cap;
} bytes;

static void put(bytes *o, const void *v, size_t k)
{
    if (o->n + k > o->cap) {
        o->cap = (o->n + k) * 2 + 256;
        o->b = realloc(o->b, o->cap);
    }
    memcpy(o->b + o->n, v, k); /* the test host is little-endian, as LAS */
    o->n += k;
}
#define PUT(o, type, value)                                                                     \
    do {                                                                                       \
        type v_ = (type)(value);                                                               \
        put(o, &v_, sizeof v_);                                                                \
    } while (0)

typedef struct {
    int32_t X, Y, Z;
    uint16_t intensity;
    uint8_t ret, nret, sdir, edge, cls, synth, key, withheld, overlap, channel, user;
    int16_t angle; /* rank for 0-5 */
    uint16_t psid, r, g, b, nir;
    double gps;
    uint8_t wp_index;
    uint64_t wp_offset;
    uint32_t wp_size;
    float wp[4];
    float temperature; /* extra bytes */
    uint16_t tag;
} pt;

static int has_gps(int f) { return f == 1 || f >= 3; }
static int has_rgb(int f) { return f == 2 || f == 3 || f == 5 || f == 7 || f == 8 || f == 10; }
static int has_nir(int f) { return f == 8 || f == 10; }
static int has_wave(int f) { return f == 4 || f == 5 || f == 9 || f == 10; }

static void record(bytes *o, int f, const pt *p, int extra)
{
    PUT(o, int32_t, p->X);
    PUT(o, int32_t, p->Y);
    PUT(o, int32_t, p->Z);
    PUT(o, uint16_t, p->intensity);
    if (f < 6) {
        PUT(o, uint8_t, p->ret | p->nret << 3 | p->sdir << 6 | p->edge << 7);
        PUT(o, uint8_t, p->cls | p->synth << 5 | p->key << 6 | p->withheld << 7);
        PUT(o, int8_t, p->angle);
        PUT(o, uint8_t, p->user);
        PUT(o, uint16_t, p->psid);
        if (has_gps(f))
            PUT(o, double, p->gps);
        if (has_rgb(f)) {
            PUT(o, uint16_t, p->r);
            PUT(o, uint16_t, p->g);
            PUT(o, uint16_t, p->b);
        }
    } else {
        PUT(o, uint8_t, p->ret | p->nret << 4);
        PUT(o, uint8_t, p->synth | p->key << 1 | p->withheld << 2 | p->overlap << 3 | p->channel << 4 |
                            p->sdir << 6 | p->edge << 7);
        PUT(o, uint8_t, p->cls);
        PUT(o, uint8_t, p->user);
        PUT(o, int16_t, p->angle);
        PUT(o, uint16_t, p->psid);
        PUT(o, double, p->gps);
        if (has_rgb(f)) {
            PUT(o, uint16_t, p->r);
            PUT(o, uint16_t, p->g);
            PUT(o, uint16_t, p->b);
        }
        if (has_nir(f))
            PUT(o, uint16_t, p->nir);
    }
    if (has_wave(f)) {
        PUT(o, uint8_t, p->wp_index);
        PUT(o, uint64_t, p->wp_offset);
        PUT(o, uint32_t, p->wp_size);
        for (int k = 0; k < 4; k++)
            PUT(o, float, p->wp[k]);
    }
    if (extra) {
        PUT(o, float, p->temperature);
        PUT(o, uint16_t, p->tag);
    }
}

static size_t record_size(int f, int extra)
{
    bytes o = {0};
    pt p = {0};
    record(&o, f, &p, extra);
    free(o.b);
    return o.n;
}

static void extra_descriptor(bytes *o, uint8_t type, const char *name)
{
    uint8_t d[192] = {0};
    d[2] = type;
    memcpy(d + 4, name, strlen(name));
    put(o, d, sizeof d);
}

/* A whole file: header (227 bytes for 1.2, 375 for 1.4), optional extra-bytes VLR and an
 * unrelated VLR, the records. */
static bytes las_file(int f, const pt *pts, size_t n, int extra, uint64_t claimed)
{
    int modern = f >= 6;
    uint16_t header = modern ? 375 : 227;
    bytes vl = {0};
    /* an unrelated VLR (a GeoTIFF key directory) to be skipped */
    uint8_t vh[54] = {0};
    memcpy(vh + 2, "LASF_Projection", 15);
    vh[18] = 0xAF; /* 34735 */
    vh[19] = 0x87;
    vh[20] = 16;
    put(&vl, vh, sizeof vh);
    uint8_t keys[16] = {1, 0, 1, 0, 0, 0, 1, 0, 0x00, 0x0C, 0, 0, 1, 0, 0x6C, 0x70};
    put(&vl, keys, sizeof keys);
    uint32_t nvlr = 1;
    if (extra) {
        memset(vh, 0, sizeof vh);
        memcpy(vh + 2, "LASF_Spec", 9);
        vh[18] = 4;
        vh[20] = (uint8_t)(2 * 192);
        vh[21] = (uint8_t)((2 * 192) >> 8);
        put(&vl, vh, sizeof vh);
        extra_descriptor(&vl, 9, "temperature");
        extra_descriptor(&vl, 3, "tag");
        nvlr++;
    }
    bytes o = {0};
    uint8_t h[375] = {0};
    memcpy(h, "LASF", 4);
    h[24] = 1;
    h[25] = modern ? 4 : has_wave(f) ? 3 : 2;
    memcpy(h + 94, &header, 2);
    uint32_t offset = header + (uint32_t)vl.n;
    memcpy(h + 96, &offset, 4);
    memcpy(h + 100, &nvlr, 4);
    h[104] = (uint8_t)f;
    uint16_t rl = (uint16_t)record_size(f, extra);
    memcpy(h + 105, &rl, 2);
    uint32_t legacy = modern ? 0 : (uint32_t)claimed;
    memcpy(h + 107, &legacy, 4);
    double scale[3] = {0.01, 0.01, 0.001}, off[3] = {548000, 4176000, 100};
    memcpy(h + 131, scale, sizeof scale);
    memcpy(h + 155, off, sizeof off);
    double bounds[6] = {549000, 548000, 4177000, 4176000, 300, 100};
    memcpy(h + 179, bounds, sizeof bounds);
    if (modern)
        memcpy(h + 247, &claimed, 8);
    put(&o, h, header);
    put(&o, vl.b, vl.n);
    for (size_t i = 0; i < n; i++)
        record(&o, f, &pts[i], extra);
    free(vl.b);
    return o;
}

static pt random_point(ag_rng *r, int f)
{
    pt p;
    memset(&p, 0, sizeof p);
    p.X = (int32_t)(ag_rng_below(r, 100000)) - 50000;
    p.Y = (int32_t)(ag_rng_below(r, 100000));
    p.Z = (int32_t)(ag_rng_below(r, 200000)) - 100000;
    p.intensity = (uint16_t)ag_rng_below(r, 65536);
    p.ret = (uint8_t)(1 + ag_rng_below(r, f < 6 ? 7 : 15));
    p.nret = (uint8_t)(1 + ag_rng_below(r, f < 6 ? 7 : 15));
    p.sdir = (uint8_t)ag_rng_below(r, 2);
    p.edge = (uint8_t)ag_rng_below(r, 2);
    p.cls = (uint8_t)ag_rng_below(r, f < 6 ? 32 : 256);
    p.synth = (uint8_t)ag_rng_below(r, 2);
    p.key = (uint8_t)ag_rng_below(r, 2);
    p.withheld = (uint8_t)ag_rng_below(r, 2);
    p.overlap = f >= 6 ? (uint8_t)ag_rng_below(r, 2) : 0;
    p.channel = f >= 6 ? (uint8_t)ag_rng_below(r, 4) : 0;
    p.user = (uint8_t)ag_rng_below(r, 256);
    p.angle = f < 6 ? (int16_t)((int)ag_rng_below(r, 181) - 90) : (int16_t)((int)ag_rng_below(r, 60001) - 30000);
    p.psid = (uint16_t)ag_rng_below(r, 65536);
    p.gps = 2e5 + ag_rng_unit(r) * 1e4;
    p.r = (uint16_t)ag_rng_below(r, 65536);
    p.g = (uint16_t)ag_rng_below(r, 65536);
    p.b = (uint16_t)ag_rng_below(r, 65536);
    p.nir = (uint16_t)ag_rng_below(r, 65536);
    p.wp_index = (uint8_t)ag_rng_below(r, 256);
    p.wp_offset = ag_rng_next(r) >> 8;
    p.wp_size = (uint32_t)ag_rng_next(r);
    for (int k = 0; k < 4; k++)
        p.wp[k] = (float)ag_rng_gauss(r);
    p.temperature = (float)(ag_rng_gauss(r) * 20);
    p.tag = (uint16_t)ag_rng_below(r, 65536);
    return p;
}

static double prop(const ag_cloud *c, const char *name, size_t i)
{
    const ag_cloud_property *p = ag_cloud_find(c, name);
    if (!p)
        fail_msg("property %s missing", name);
    return ag_cloud_get(p, i);
}

static void check_points(const ag_cloud *c, int f, const pt *pts, size_t n, int extra)
{
    assert_int_equal(c->n, n);
    const double scale[3] = {0.01, 0.01, 0.001}, off[3] = {548000, 4176000, 100};
    for (size_t i = 0; i < n; i++) {
        const pt *p = &pts[i];
        const int32_t q[3] = {p->X, p->Y, p->Z};
        for (int a = 0; a < 3; a++)
            assert_true(fabs(c->xyz[3 * i + a] + c->offset[a] - (q[a] * scale[a] + off[a])) < 1e-6);
        assert_true(prop(c, "intensity", i) == p->intensity);
        assert_true(prop(c, "return_number", i) == p->ret);
        assert_true(prop(c, "number_of_returns", i) == p->nret);
        assert_true(prop(c, "scan_direction_flag", i) == p->sdir);
        assert_true(prop(c, "edge_of_flight_line", i) == p->edge);
        assert_true(prop(c, "classification", i) == p->cls);
        assert_true(prop(c, "synthetic", i) == p->synth);
        assert_true(prop(c, "key_point", i) == p->key);
        assert_true(prop(c, "withheld", i) == p->withheld);
        assert_true(prop(c, "user_data", i) == p->user);
        assert_true(prop(c, "point_source_id", i) == p->psid);
        if (f < 6) {
            assert_true(prop(c, "scan_angle_rank", i) == p->angle);
        } else {
            assert_true(prop(c, "scan_angle", i) == p->angle);
            assert_true(prop(c, "overlap", i) == p->overlap);
            assert_true(prop(c, "scanner_channel", i) == p->channel);
        }
        if (has_gps(f))
            assert_true(prop(c, "gps_time", i) == p->gps);
        else
            assert_null(ag_cloud_find(c, "gps_time"));
        if (has_rgb(f)) {
            assert_true(prop(c, "red", i) == p->r);
            assert_true(prop(c, "green", i) == p->g);
            assert_true(prop(c, "blue", i) == p->b);
        }
        if (has_nir(f))
            assert_true(prop(c, "nir", i) == p->nir);
        if (has_wave(f)) {
            assert_true(prop(c, "wavepacket_index", i) == p->wp_index);
            const ag_cloud_property *wo = ag_cloud_find(c, "wavepacket_offset");
            assert_int_equal(wo->type, AG_SCALAR_UINT64);
            assert_true(((const uint64_t *)wo->values)[i] == p->wp_offset);
            assert_true(prop(c, "wavepacket_size", i) == p->wp_size);
            assert_true(prop(c, "wavepacket_location", i) == p->wp[0]);
            assert_true(prop(c, "wavepacket_zt", i) == p->wp[3]);
        }
        if (extra) {
            assert_true(prop(c, "temperature", i) == p->temperature);
            assert_true(prop(c, "tag", i) == p->tag);
        }
    }
}

static void test_every_format(void **state)
{
    (void)state;
    ag_rng r;
    ag_rng_seed(&r, 2024);
    for (int f = 0; f <= 10; f++)
        for (int extra = 0; extra < 2; extra++) {
            pt pts[37];
            for (int i = 0; i < 37; i++)
                pts[i] = random_point(&r, f);
            bytes file = las_file(f, pts, 37, extra, 37);
            ag_cloud *c;
            ag_error e;
            if (ag_las_read_buffer(file.b, file.n, &c, &e) != AG_OK)
                fail_msg("format %d: %s", f, e.text);
            check_points(c, f, pts, 37, extra);
            assert_true(c->scale[2] == 0.001);
            /* the writer in the same format, then the reader again */
            char *buf = NULL;
            size_t len;
            FILE *mf = open_memstream(&buf, &len);
            ag_las_write_options wo = {.point_format = f};
            if (ag_las_write(c, &wo, mf, &e) != AG_OK)
                fail_msg("write format %d: %s", f, e.text);
            fclose(mf);
            assert_int_equal(buf[104], f);
            ag_cloud *back;
            if (ag_las_read_buffer((uint8_t *)buf, len, &back, &e) != AG_OK)
                fail_msg("format %d again: %s", f, e.text);
            check_points(back, f, pts, 37, extra);
            /* and the format the writer picks by itself holds every field too */
            free(buf);
            mf = open_memstream(&buf, &len);
            wo.point_format = -1;
            assert_int_equal(ag_las_write(c, &wo, mf, &e), AG_OK);
            fclose(mf);
            ag_cloud_free(back);
            assert_int_equal(ag_las_read_buffer((uint8_t *)buf, len, &back, &e), AG_OK);
            check_points(back, f, pts, 37, extra);
            ag_cloud_free(back);
            free(buf);
            ag_cloud_free(c);
            free(file.b);
        }
}

static void test_other_clouds(void **state)
{
    (void)state;
    /* a PLY-like cloud: 8-bit colour, an int segment, normals, a local origin */
    ag_cloud *c = ag_cloud_create();
    ag_error e;
    assert_int_equal(ag_cloud_resize(c, 10, &e), AG_OK);
    assert_int_equal(ag_cloud_add_normals(c, &e), AG_OK);
    size_t red, green, blue, seg;
    assert_int_equal(ag_cloud_add_property(c, "red", AG_SCALAR_UINT8, &red, &e), AG_OK);
    assert_int_equal(ag_cloud_add_property(c, "green", AG_SCALAR_UINT8, &green, &e), AG_OK);
    assert_int_equal(ag_cloud_add_property(c, "blue", AG_SCALAR_UINT8, &blue, &e), AG_OK);
    assert_int_equal(ag_cloud_add_property(c, "segment", AG_SCALAR_INT32, &seg, &e), AG_OK);
    c->offset[0] = 500000;
    c->offset[1] = 5700000;
    for (size_t i = 0; i < 10; i++) {
        c->xyz[3 * i] = (double)i * 0.125;
        c->xyz[3 * i + 1] = 3.5;
        c->xyz[3 * i + 2] = -1.25;
        c->normals[3 * i + 2] = 1;
        ag_cloud_set(&c->props[red], i, 255);
        ag_cloud_set(&c->props[seg], i, (double)i - 1);
    }
    char *buf = NULL;
    size_t len;
    FILE *mf = open_memstream(&buf, &len);
    ag_las_write_options wo = {.point_format = -1};
    assert_int_equal(ag_las_write(c, &wo, mf, &e), AG_OK);
    fclose(mf);
    assert_int_equal(buf[104], 2); /* colour, no time */
    ag_cloud *b;
    assert_int_equal(ag_las_read_buffer((uint8_t *)buf, len, &b, &e), AG_OK);
    assert_true(prop(b, "red", 3) == 65535);
    assert_true(prop(b, "segment", 0) == -1 && prop(b, "segment", 9) == 8);
    assert_int_equal(ag_cloud_find(b, "segment")->type, AG_SCALAR_INT32);
    assert_non_null(b->normals);
    assert_true(b->normals[2] == 1);
    for (size_t i = 0; i < 10; i++)
        assert_true(fabs(b->xyz[3 * i] + b->offset[0] - (500000 + i * 0.125)) < 1e-9);
    ag_cloud_free(b);
    free(buf);
    /* a coordinate beyond 32 bits at the scale is refused */
    c->xyz[0] = 3e6;
    mf = open_memstream(&buf, &len);
    assert_int_equal(ag_las_write(c, &wo, mf, &e), AG_ERR_INVALID);
    fclose(mf);
    assert_non_null(strstr(e.text, "32-bit"));
    free(buf);
    ag_cloud_free(c);
}

static void test_bad_headers(void **state)
{
    (void)state;
    ag_cloud *c = NULL;
    ag_error e;
    assert_int_equal(ag_cloud_import_file(DATA "lying_count.las", &c, &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "1000 points"));
    assert_non_null(strstr(e.text, "507 bytes"));
    ag_rng r;
    ag_rng_seed(&r, 1);
    pt pts[5];
    for (int i = 0; i < 5; i++)
        pts[i] = random_point(&r, 6);
    /* a 64-bit count that lies */
    bytes f = las_file(6, pts, 5, 0, 1ull << 40);
    assert_int_equal(ag_las_read_buffer(f.b, f.n, &c, &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "1099511627776"));
    free(f.b);
    f = las_file(6, pts, 5, 1, 5);
    uint8_t *b = malloc(f.n);
    /* a VLR longer than the space before the points */
    memcpy(b, f.b, f.n);
    b[375 + 20] = 0xFF;
    b[375 + 21] = 0xFF;
    assert_int_equal(ag_las_read_buffer(b, f.n, &c, &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "VLR 1"));
    /* point format 11, zero scale, a record shorter than the format */
    memcpy(b, f.b, f.n);
    b[104] = 11;
    assert_int_equal(ag_las_read_buffer(b, f.n, &c, &e), AG_ERR_UNSUPPORTED);
    memcpy(b, f.b, f.n);
    memset(b + 131, 0, 8);
    assert_int_equal(ag_las_read_buffer(b, f.n, &c, &e), AG_ERR_PARSE);
    memcpy(b, f.b, f.n);
    b[105] = 10;
    b[106] = 0;
    assert_int_equal(ag_las_read_buffer(b, f.n, &c, &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "at least 30"));
    /* a LAZ flag with no LASzip VLR */
    memcpy(b, f.b, f.n);
    b[104] |= 0x80;
    assert_int_equal(ag_las_read_buffer(b, f.n, &c, &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "LASzip"));
    /* every truncation and random damage: errors or clouds, no crash */
    for (size_t l = 0; l < f.n; l += 3) {
        ag_status st = ag_las_read_buffer(f.b, l, &c, &e);
        assert_int_not_equal(st, AG_OK);
    }
    for (int k = 0; k < 3000; k++) {
        memcpy(b, f.b, f.n);
        for (int j = 0; j < 3; j++)
            b[ag_rng_below(&r, f.n)] = (uint8_t)ag_rng_next(&r);
        if (ag_las_read_buffer(b, f.n, &c, &e) == AG_OK) {
            assert_true(c->n <= f.n);
            ag_cloud_free(c);
        }
    }
    free(b);
    free(f.b);
    c = NULL;
    assert_int_equal(ag_las_read_buffer((const uint8_t *)"LASF", 4, &c, &e), AG_ERR_PARSE);
    assert_null(c);
}

static void test_urban(void **state)
{
    (void)state;
    FILE *f = fopen(SHARED "/pointcloud_cgal_building/urban.las", "rb");
    if (!f) {
        print_message("skipping: %s is absent\n", SHARED "/pointcloud_cgal_building");
        skip();
    }
    uint8_t h[227];
    assert_int_equal(fread(h, 1, sizeof h, f), sizeof h);
    fclose(f);
    double bounds[6], scale[3];
    memcpy(bounds, h + 179, sizeof bounds);
    memcpy(scale, h + 131, sizeof scale);
    ag_cloud *c;
    ag_error e;
    assert_int_equal(ag_cloud_import_file(SHARED "/pointcloud_cgal_building/urban.las", &c, &e), AG_OK);
    assert_int_equal(c->n, 13511);
    double mn[3], mx[3];
    ag_cloud_bounds(c, mn, mx);
    for (int a = 0; a < 3; a++) {
        /* the header's max and min, to the file's own resolution */
        assert_true(fabs(mx[a] + c->offset[a] - bounds[2 * a]) < 1e-3);
        assert_true(fabs(mn[a] + c->offset[a] - bounds[2 * a + 1]) < 1e-3);
        assert_true(c->scale[a] == scale[a]);
    }
    assert_non_null(ag_cloud_find(c, "red"));
    assert_non_null(ag_cloud_find(c, "gps_time"));
    ag_cloud_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_format),
        cmocka_unit_test(test_other_clouds),
        cmocka_unit_test(test_bad_headers),
        cmocka_unit_test(test_urban),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
