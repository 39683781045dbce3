/* LAZ decoding: the AHN3 tile against the PLY decoded independently (laz-perf) in
 * ../shared/data, files made by the test encoder (item versions 1 and 2, fixed, variable and
 * no chunks, a chunk table at the end of the file) against the same points stored as LAS,
 * precise refusals of the variants that are not supported, and damaged files. */
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

#include "core/points/rng.h"
#include "io/cloud_import.h"
#include "io/filemap.h"
#include "io/las.h"
#include "laz_encoder.h"

#define SHARED AG_REPO_DIR "/../shared/data"

/* ---- item encoders (mirror images of the decoders' prediction rules) ------------------ */

static uint16_t u16(const uint8_t *p) { return (uint16_t)(p[0] | p[1] << 8); }
static int32_t i32(const uint8_t *p) { return (int32_t)((uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24); }
static uint8_t fold(int32_t n) { return (uint8_t)(n < 0 ? n + 256 : n > 255 ? n - 256 : n); }
static int32_t clamp8(int32_t n) { return n <= 0 ? 0 : n >= 255 ? 255 : n; }

typedef struct {
    uint8_t last[20];
    int32_t lx[3], ly[3];
    int incr;
    eic dx, dy, z, inten, angle, psid;
    emodel changed, bitbyte[256], cls[256], user[256];
} p10_enc;

static int32_t med3(const int32_t *v)
{
    if (v[0] < v[1])
        return v[1] < v[2] ? v[1] : v[0] < v[2] ? v[2] : v[0];
    return v[0] < v[2] ? v[0] : v[1] < v[2] ? v[2] : v[1];
}

static void p10_init(p10_enc *s, const uint8_t *item)
{
    memcpy(s->last, item, 20);
    memset(s->lx, 0, sizeof s->lx);
    memset(s->ly, 0, sizeof s->ly);
    s->incr = 0;
    eic_init(&s->dx, 32, 1);
    eic_init(&s->dy, 32, 20);
    eic_init(&s->z, 32, 20);
    eic_init(&s->inten, 16, 1);
    eic_init(&s->angle, 8, 2);
    eic_init(&s->psid, 16, 1);
    emodel_init(&s->changed, 64);
    for (int i = 0; i < 256; i++) {
        if (s->bitbyte[i].dist)
            emodel_init(&s->bitbyte[i], 256);
        if (s->cls[i].dist)
            emodel_init(&s->cls[i], 256);
        if (s->user[i].dist)
            emodel_init(&s->user[i], 256);
    }
}

static emodel *lazy(emodel *m)
{
    if (!m->dist)
        emodel_init(m, 256);
    return m;
}

static void p10_write(p10_enc *s, enc *e, const uint8_t *it)
{
    uint8_t *l = s->last;
    int32_t x_diff = i32(it) - i32(l), y_diff = i32(it + 4) - i32(l + 4);
    eic_compress(&s->dx, e, med3(s->lx), x_diff, 0);
    uint32_t k = s->dx.k;
    eic_compress(&s->dy, e, med3(s->ly), y_diff, k < 19 ? k : 19);
    k = (k + s->dy.k) / 2;
    eic_compress(&s->z, e, i32(l + 8), i32(it + 8), k < 19 ? k : 19);
    uint32_t ch = (u16(it + 12) != u16(l + 12)) << 5 | (it[14] != l[14]) << 4 | (it[15] != l[15]) << 3 |
                  (it[16] != l[16]) << 2 | (it[17] != l[17]) << 1 | (u16(it + 18) != u16(l + 18));
    enc_symbol(e, &s->changed, ch);
    if (ch & 32)
        eic_compress(&s->inten, e, u16(l + 12), u16(it + 12), 0);
    if (ch & 16)
        enc_symbol(e, lazy(&s->bitbyte[l[14]]), it[14]);
    if (ch & 8)
        enc_symbol(e, lazy(&s->cls[l[15]]), it[15]);
    if (ch & 4)
        eic_compress(&s->angle, e, l[16], it[16], k < 3);
    if (ch & 2)
        enc_symbol(e, lazy(&s->user[l[17]]), it[17]);
    if (ch & 1)
        eic_compress(&s->psid, e, u16(l + 18), u16(it + 18), 0);
    s->lx[s->incr] = x_diff;
    s->ly[s->incr] = y_diff;
    if (++s->incr > 2)
        s->incr = 0;
    memcpy(l, it, 20);
}

typedef struct {
    int64_t last;
    int32_t last_diff, extreme;
    emodel multi, zero;
    eic ic;
} gps1_enc;

static void gps1_init(gps1_enc *s, const uint8_t *item)
{
    memcpy(&s->last, item, 8);
    s->last_diff = 0;
    s->extreme = 0;
    emodel_init(&s->multi, 512);
    emodel_init(&s->zero, 3);
    eic_init(&s->ic, 32, 6);
}

static void gps1_write(gps1_enc *s, enc *e, const uint8_t *item)
{
    int64_t now;
    memcpy(&now, item, 8);
    int64_t d64 = now - s->last;
    int fits = d64 == (int32_t)d64;
    int32_t d = (int32_t)d64;
    if (s->last_diff == 0) {
        if (!d64) {
            enc_symbol(e, &s->zero, 0);
        } else if (fits) {
            enc_symbol(e, &s->zero, 1);
            eic_compress(&s->ic, e, 0, d, 0);
            s->last_diff = d;
        } else {
            enc_symbol(e, &s->zero, 2);
            enc_int64(e, (uint64_t)now);
        }
    } else if (!d64) {
        enc_symbol(e, &s->multi, 511); /* unchanged */
    } else if (!fits) {
        enc_symbol(e, &s->multi, 510);
        enc_int64(e, (uint64_t)now);
    } else {
        int32_t multi = (int32_t)llround((double)d / s->last_diff);
        if (multi == 1) {
            enc_symbol(e, &s->multi, 1);
            eic_compress(&s->ic, e, s->last_diff, d, 1);
            s->last_diff = d;
            s->extreme = 0;
        } else if (multi >= 2 && multi < 10) {
            enc_symbol(e, &s->multi, (uint32_t)multi);
            eic_compress(&s->ic, e, (int32_t)((uint32_t)multi * (uint32_t)s->last_diff), d, 3);
        } else if (multi >= 10 && multi <= 509) {
            enc_symbol(e, &s->multi, (uint32_t)multi);
            eic_compress(&s->ic, e, (int32_t)((uint32_t)multi * (uint32_t)s->last_diff), d, multi < 50 ? 4 : 5);
            if (multi == 509 && ++s->extreme > 3) {
                s->last_diff = d;
                s->extreme = 0;
            }
        } else {
            enc_symbol(e, &s->multi, 0);
            eic_compress(&s->ic, e, s->last_diff / 4, d, 2);
            if (++s->extreme > 3) {
                s->last_diff = d;
                s->extreme = 0;
            }
        }
    }
    s->last = now;
}

typedef struct {
    uint16_t last[3];
    emodel used, diff[6];
    eic ic;
} rgb_enc;

static void rgb_init(rgb_enc *s, int version, const uint8_t *item)
{
    for (int a = 0; a < 3; a++)
        s->last[a] = u16(item + 2 * a);
    if (version == 1) {
        emodel_init(&s->used, 64);
        eic_init(&s->ic, 8, 6);
    } else {
        emodel_init(&s->used, 128);
        for (int i = 0; i < 6; i++)
            emodel_init(&s->diff[i], 256);
    }
}

static void rgb_write(rgb_enc *s, int version, enc *e, const uint8_t *item)
{
    uint16_t v[3] = {u16(item), u16(item + 2), u16(item + 4)};
    const uint16_t *l = s->last;
    if (version == 1) {
        uint32_t sym = 0;
        for (int a = 0; a < 3; a++)
            sym |= (uint32_t)((v[a] & 0xFF) != (l[a] & 0xFF)) << (2 * a) |
                   (uint32_t)((v[a] >> 8) != (l[a] >> 8)) << (2 * a + 1);
        enc_symbol(e, &s->used, sym);
        for (int a = 0; a < 3; a++) {
            if (sym & (1u << (2 * a)))
                eic_compress(&s->ic, e, l[a] & 255, v[a] & 255, 2 * (uint32_t)a);
            if (sym & (1u << (2 * a + 1)))
                eic_compress(&s->ic, e, l[a] >> 8, v[a] >> 8, 2 * (uint32_t)a + 1);
        }
    } else {
        int grey = v[0] == v[1] && v[0] == v[2];
        uint32_t sym = (uint32_t)((v[0] & 0xFF) != (l[0] & 0xFF)) | (uint32_t)((v[0] >> 8) != (l[0] >> 8)) << 1 |
                       (uint32_t)((v[1] & 0xFF) != (l[1] & 0xFF)) << 2 | (uint32_t)((v[1] >> 8) != (l[1] >> 8)) << 3 |
                       (uint32_t)((v[2] & 0xFF) != (l[2] & 0xFF)) << 4 | (uint32_t)((v[2] >> 8) != (l[2] >> 8)) << 5 |
                       (uint32_t)!grey << 6;
        if (grey) /* only red is coded; green and blue repeat it */
            sym &= 3;
        enc_symbol(e, &s->used, sym);
        int32_t dl = (v[0] & 0xFF) - (l[0] & 0xFF), dh = (v[0] >> 8) - (l[0] >> 8);
        if (sym & 1)
            enc_symbol(e, &s->diff[0], fold(dl));
        if (sym & 2)
            enc_symbol(e, &s->diff[1], fold(dh));
        if (sym & 64) {
            if (sym & 4)
                enc_symbol(e, &s->diff[2], fold((v[1] & 0xFF) - clamp8(dl + (l[1] & 0xFF))));
            if (sym & 16) {
                int32_t d2 = (dl + ((v[1] & 0xFF) - (l[1] & 0xFF))) / 2;
                enc_symbol(e, &s->diff[4], fold((v[2] & 0xFF) - clamp8(d2 + (l[2] & 0xFF))));
            }
            if (sym & 8)
                enc_symbol(e, &s->diff[3], fold((v[1] >> 8) - clamp8(dh + (l[1] >> 8))));
            if (sym & 32) {
                int32_t d2 = (dh + ((v[1] >> 8) - (l[1] >> 8))) / 2;
                enc_symbol(e, &s->diff[5], fold((v[2] >> 8) - clamp8(d2 + (l[2] >> 8))));
            }
        }
    }
    memcpy(s->last, v, sizeof v);
}

typedef struct {
    size_t n;
    uint8_t last[16];
    emodel m[16];
    eic ic;
} byte_enc;

static void byte_init(byte_enc *s, int version, const uint8_t *item)
{
    memcpy(s->last, item, s->n);
    if (version == 1)
        eic_init(&s->ic, 8, (uint32_t)s->n);
    else
        for (size_t i = 0; i < s->n; i++)
            emodel_init(&s->m[i], 256);
}

static void byte_write(byte_enc *s, int version, enc *e, const uint8_t *item)
{
    for (size_t i = 0; i < s->n; i++) {
        if (version == 1)
            eic_compress(&s->ic, e, s->last[i], item[i], (uint32_t)i);
        else
            enc_symbol(e, &s->m[i], fold(item[i] - s->last[i]));
    }
    memcpy(s->last, item, s->n);
}

/* ---- files ------------------------------------------------------------------------------ */

typedef struct {
    int format;        /* 0-3 */
    size_t extra;      /* extra bytes (BYTE item) */
    int p10v, gpsv, rgbv, bytev;
    int compressor;    /* 1 pointwise, 2 chunked */
    uint32_t chunk;    /* points per chunk; UINT32_MAX variable */
    const size_t *variable; /* chunk sizes when variable */
    size_t nvariable;
    int table_at_end;  /* write -1 and the table position in the last 8 bytes */
} laz_layout;

static const size_t base_size[4] = {20, 28, 26, 34};


typedef struct {
    uint8_t *b;
    size_t n, cap;
} buf_t;

static void bput(buf_t *o, const void *p, size_t k)
{
    if (o->n + k > o->cap) {
        o->cap = (o->n + k) * 2 + 4096;
        o->b = realloc(o->b, o->cap);
    }
    memcpy(o->b + o->n, p, k);
    o->n += k;
}

/* LAS header (1.2) with optional VLR payload; returns the point offset. */
static void las_header(buf_t *o, int fmt_byte, uint16_t reclen, uint32_t count, const uint8_t *vlr,
                       size_t vlr_len, const char *user, uint16_t record)
{
    uint8_t h[227] = {0};
    memcpy(h, "LASF", 4);
    h[24] = 1;
    h[25] = 2;
    uint16_t hs = 227;
    memcpy(h + 94, &hs, 2);
    uint32_t off = 227 + (vlr ? 54 + (uint32_t)vlr_len : 0);
    memcpy(h + 96, &off, 4);
    uint32_t nv = vlr ? 1 : 0;
    memcpy(h + 100, &nv, 4);
    h[104] = (uint8_t)fmt_byte;
    memcpy(h + 105, &reclen, 2);
    memcpy(h + 107, &count, 4);
    double scale[3] = {0.001, 0.001, 0.001}, offs[3] = {84000, 447000, 0};
    memcpy(h + 131, scale, sizeof scale);
    memcpy(h + 155, offs, sizeof offs);
    bput(o, h, sizeof h);
    if (vlr) {
        uint8_t v[54] = {0};
        memcpy(v + 2, user, strlen(user));
        memcpy(v + 18, &record, 2);
        uint16_t l = (uint16_t)vlr_len;
        memcpy(v + 20, &l, 2);
        bput(o, v, sizeof v);
        bput(o, vlr, vlr_len);
    }
}

static buf_t make_laz(const laz_layout *L, const uint8_t *recs, size_t n, uint16_t reclen)
{
    /* the LASzip VLR */
    uint8_t v[34 + 6 * 4] = {0};
    uint16_t comp = (uint16_t)L->compressor;
    memcpy(v, &comp, 2);
    v[4] = 2;
    v[5] = 2;
    memcpy(v + 12, &L->chunk, 4);
    memset(v + 16, 0xFF, 16);
    uint16_t items[4][3];
    uint16_t ni = 0;
    items[ni][0] = 6, items[ni][1] = 20, items[ni][2] = (uint16_t)L->p10v, ni++;
    if (L->format == 1 || L->format == 3)
        items[ni][0] = 7, items[ni][1] = 8, items[ni][2] = (uint16_t)L->gpsv, ni++;
    if (L->format >= 2)
        items[ni][0] = 8, items[ni][1] = 6, items[ni][2] = (uint16_t)L->rgbv, ni++;
    if (L->extra)
        items[ni][0] = 0, items[ni][1] = (uint16_t)L->extra, items[ni][2] = (uint16_t)L->bytev, ni++;
    memcpy(v + 32, &ni, 2);
    for (int i = 0; i < ni; i++)
        memcpy(v + 34 + 6 * i, items[i], 6);
    buf_t o = {0};
    las_header(&o, L->format | 0x80, reclen, (uint32_t)n, v, 34 + 6 * (size_t)ni, "laszip encoded", 22204);
    size_t table_ptr = o.n;
    if (L->compressor == 2) {
        int64_t zero = 0;
        bput(&o, &zero, 8);
    }
    /* chunks */
    size_t done = 0, nchunks = 0, sizes[256], counts[256];
    p10_enc p10;
    gps1_enc gps;
    rgb_enc rgb;
    byte_enc by;
    memset(&p10, 0, sizeof p10);
    memset(&gps, 0, sizeof gps);
    memset(&rgb, 0, sizeof rgb);
    memset(&by, 0, sizeof by);
    by.n = L->extra;
    size_t gps_at = 20, rgb_at = L->format == 3 ? 28 : 20, byte_at = base_size[L->format];
    while (done < n) {
        size_t k = L->compressor == 1 ? n
                   : L->chunk == UINT32_MAX ? L->variable[nchunks]
                                            : L->chunk;
        if (k > n - done)
            k = n - done;
        size_t start = o.n;
        const uint8_t *first = recs + done * reclen;
        bput(&o, first, reclen);
        p10_init(&p10, first);
        if (L->format == 1 || L->format == 3)
            gps1_init(&gps, first + gps_at);
        if (L->format >= 2)
            rgb_init(&rgb, L->rgbv, first + rgb_at);
        if (L->extra)
            byte_init(&by, L->bytev, first + byte_at);
        enc e = {0};
        enc_init(&e);
        for (size_t j = 1; j < k; j++) {
            const uint8_t *r = recs + (done + j) * reclen;
            p10_write(&p10, &e, r);
            if (L->format == 1 || L->format == 3)
                gps1_write(&gps, &e, r + gps_at);
            if (L->format >= 2)
                rgb_write(&rgb, L->rgbv, &e, r + rgb_at);
            if (L->extra)
                byte_write(&by, L->bytev, &e, r + byte_at);
        }
        enc_done(&e);
        bput(&o, e.buf, e.n);
        free(e.buf);
        sizes[nchunks] = o.n - start;
        counts[nchunks] = k;
        nchunks++;
        done += k;
    }
    /* the encoders' models */
    eic *ics[] = {&p10.dx, &p10.dy, &p10.z, &p10.inten, &p10.angle, &p10.psid, &gps.ic, &rgb.ic, &by.ic};
    for (size_t i = 0; i < sizeof ics / sizeof ics[0]; i++)
        eic_free(ics[i]);
    emodel_free(&p10.changed);
    for (int i = 0; i < 256; i++) {
        emodel_free(&p10.bitbyte[i]);
        emodel_free(&p10.cls[i]);
        emodel_free(&p10.user[i]);
    }
    emodel_free(&gps.multi);
    emodel_free(&gps.zero);
    emodel_free(&rgb.used);
    for (int i = 0; i < 6; i++)
        emodel_free(&rgb.diff[i]);
    for (int i = 0; i < 16; i++)
        emodel_free(&by.m[i]);
    if (L->compressor == 2) {
        int64_t at = (int64_t)o.n;
        uint32_t ver = 0, nc = (uint32_t)nchunks;
        bput(&o, &ver, 4);
        bput(&o, &nc, 4);
        enc e = {0};
        enc_init(&e);
        eic ic = {0};
        eic_init(&ic, 32, 2);
        uint32_t pc = 0, pb = 0;
        for (size_t c = 0; c < nchunks; c++) {
            if (L->chunk == UINT32_MAX) {
                eic_compress(&ic, &e, (int32_t)pc, (int32_t)counts[c], 0);
                pc = (uint32_t)counts[c];
            }
            eic_compress(&ic, &e, (int32_t)pb, (int32_t)sizes[c], 1);
            pb = (uint32_t)sizes[c];
        }
        enc_done(&e);
        bput(&o, e.buf, e.n);
        free(e.buf);
        eic_free(&ic);
        if (L->table_at_end) {
            int64_t minus = -1;
            memcpy(o.b + table_ptr, &minus, 8);
            bput(&o, &at, 8);
        } else {
            memcpy(o.b + table_ptr, &at, 8);
        }
    }
    return o;
}

/* Records of a plausible airborne strip: small steps, returns, repeats, time jumps. */
static uint8_t *make_records(int format, size_t extra, size_t n, uint16_t *reclen, uint64_t seed)
{
    *reclen = (uint16_t)(base_size[format] + extra);
    uint8_t *r = calloc(n, *reclen);
    ag_rng g;
    ag_rng_seed(&g, seed);
    int32_t x = 100000, y = 200000, z = 5000;
    double t = 230000.5;
    uint16_t col[3] = {1000, 2000, 3000};
    for (size_t i = 0; i < n; i++) {
        uint8_t *p = r + i * *reclen;
        x += (int32_t)ag_rng_below(&g, 400) - 150;
        y += (int32_t)ag_rng_below(&g, 60) - 30;
        z += (int32_t)ag_rng_below(&g, 200) - 100;
        if (i % 97 == 0)
            x += 5000000; /* a jump */
        memcpy(p, &x, 4);
        memcpy(p + 4, &y, 4);
        memcpy(p + 8, &z, 4);
        uint16_t in = (uint16_t)(i % 5 ? ag_rng_below(&g, 4000) : 0);
        memcpy(p + 12, &in, 2);
        uint8_t nret = (uint8_t)(1 + ag_rng_below(&g, 3)), ret = (uint8_t)(1 + ag_rng_below(&g, nret));
        p[14] = (uint8_t)(ret | nret << 3 | (i % 50 > 25) << 6 | (i % 31 == 0) << 7);
        p[15] = (uint8_t)(i % 7 ? 6 : 2);
        p[16] = (uint8_t)(int8_t)((int)(i % 40) - 20);
        p[17] = (uint8_t)(i % 13 == 0 ? ag_rng_below(&g, 256) : 3);
        uint16_t ps = (uint16_t)(i < n / 2 ? 44266 : 57140);
        memcpy(p + 18, &ps, 2);
        if (format == 1 || format == 3) {
            if (i % 11)
                t += 1e-5 * (double)(1 + ag_rng_below(&g, 3));
            if (i % 61 == 0)
                t += 3.0;      /* a large step */
            if (i % 89 == 0)
                t = -t;        /* a wild change of the bit pattern */
            memcpy(p + 20, &t, 8);
        }
        if (format >= 2) {
            for (int a = 0; a < 3; a++)
                if (ag_rng_below(&g, 3) == 0)
                    col[a] = (uint16_t)(col[a] + ag_rng_below(&g, 600) - 300);
            if (i % 17 == 0)
                col[1] = col[2] = col[0]; /* grey */
            memcpy(p + (format == 3 ? 28 : 20), col, 6);
        }
        for (size_t k = 0; k < extra; k++)
            p[base_size[format] + k] = (uint8_t)(k == 0 ? i % 256 : ag_rng_below(&g, 2) ? 7 : ag_rng_next(&g));
    }
    return r;
}

static void compare_clouds(const ag_cloud *a, const ag_cloud *b)
{
    assert_int_equal(a->n, b->n);
    assert_int_equal(a->nprops, b->nprops);
    for (size_t i = 0; i < a->n; i++) {
        for (int k = 0; k < 3; k++)
            assert_true(a->xyz[3 * i + k] + a->offset[k] == b->xyz[3 * i + k] + b->offset[k]);
        for (size_t p = 0; p < a->nprops; p++) {
            const ag_cloud_property *q = ag_cloud_find(b, a->props[p].name);
            assert_non_null(q);
            size_t s = ag_scalar_size(q->type);
            if (memcmp((const char *)a->props[p].values + i * s, (const char *)q->values + i * s, s))
                fail_msg("point %zu property %s differs", i, q->name);
        }
    }
}

static void run_layout(const laz_layout *L, size_t n)
{
    uint16_t reclen;
    uint8_t *recs = make_records(L->format, L->extra, n, &reclen, 7 + (uint64_t)L->format);
    buf_t las = {0};
    las_header(&las, L->format, reclen, (uint32_t)n, NULL, 0, NULL, 0);
    bput(&las, recs, n * reclen);
    buf_t laz = make_laz(L, recs, n, reclen);
    ag_cloud *a, *b;
    ag_error e;
    assert_int_equal(ag_las_read_buffer(las.b, las.n, &a, &e), AG_OK);
    if (ag_las_read_buffer(laz.b, laz.n, &b, &e) != AG_OK)
        fail_msg("format %d items v%d/%d/%d/%d: %s", L->format, L->p10v, L->gpsv, L->rgbv, L->bytev, e.text);
    compare_clouds(a, b);
    ag_cloud_free(a);
    ag_cloud_free(b);
    /* a count that lies is refused before anything is allocated */
    uint32_t lie = 4000000000u, keep;
    memcpy(&keep, laz.b + 107, 4);
    memcpy(laz.b + 107, &lie, 4);
    assert_int_equal(ag_las_read_buffer(laz.b, laz.n, &b, &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "one point per byte"));
    memcpy(laz.b + 107, &keep, 4);
    /* one point more than the chunks hold */
    uint32_t more = keep + (L->compressor == 2 ? 0 : 1);
    if (L->compressor == 2 && L->chunk != UINT32_MAX) {
        uint32_t nchunks = (uint32_t)((n + L->chunk - 1) / L->chunk);
        more = nchunks * L->chunk + 1;
        memcpy(laz.b + 107, &more, 4);
        assert_int_equal(ag_las_read_buffer(laz.b, laz.n, &b, &e), AG_ERR_PARSE);
        assert_non_null(strstr(e.text, "chunks hold at most"));
        memcpy(laz.b + 107, &keep, 4);
    }
    /* truncated: an error, never a crash or a read past the end */
    for (size_t cut = 230; cut < laz.n; cut += laz.n / 23 + 1) {
        uint8_t *t = malloc(cut);
        memcpy(t, laz.b, cut);
        ag_cloud *c = NULL;
        assert_int_not_equal(ag_las_read_buffer(t, cut, &c, &e), AG_OK);
        assert_true(e.text[0] != 0);
        free(t);
    }
    free(las.b);
    free(laz.b);
    free(recs);
}

static void test_encoded_layouts(void **state)
{
    (void)state;
    const size_t var[] = {40, 1, 70, 62};
    const laz_layout layouts[] = {
        {3, 3, 1, 1, 1, 1, 2, 50, NULL, 0, 0},      /* every v1 item, fixed chunks */
        {2, 2, 1, 0, 2, 2, 2, UINT32_MAX, var, 4, 0}, /* RGB12 v2, BYTE v2, variable chunks */
        {0, 0, 1, 0, 0, 0, 1, 0, NULL, 0, 0},       /* pointwise, no chunk table */
        {1, 0, 1, 1, 0, 0, 2, 64, NULL, 0, 1},      /* the table's position at the end */
        {3, 1, 1, 1, 2, 1, 2, 1000, NULL, 0, 0},    /* one chunk */
    };
    for (size_t i = 0; i < sizeof layouts / sizeof layouts[0]; i++)
        run_layout(&layouts[i], 173);
}

static void test_unsupported(void **state)
{
    (void)state;
    /* LAS 1.4 point format 7, layered compressor */
    buf_t o = {0};
    uint8_t v[48] = {0};
    v[0] = 3;
    uint16_t ni = 1;
    memcpy(v + 32, &ni, 2);
    uint16_t item[3] = {10, 30, 3};
    memcpy(v + 34, item, 6);
    las_header(&o, 7 | 0x80, 36, 5, v, sizeof v, "laszip encoded", 22204);
    uint8_t pad[64] = {0};
    bput(&o, pad, sizeof pad);
    ag_cloud *c = NULL;
    ag_error e;
    assert_int_equal(ag_las_read_buffer(o.b, o.n, &c, &e), AG_ERR_UNSUPPORTED);
    assert_string_equal(e.text, "LAZ point format 7 not supported; convert to LAS");
    /* wave packets */
    o.b[104] = 4 | 0x80;
    o.b[105] = 57;
    assert_int_equal(ag_las_read_buffer(o.b, o.n, &c, &e), AG_ERR_UNSUPPORTED);
    assert_non_null(strstr(e.text, "LAZ point format 4"));
    /* format 1 with an unknown item version */
    o.b[104] = 1 | 0x80;
    o.b[105] = 28;
    uint8_t *vp = o.b + 227 + 54;
    vp[0] = 2;
    ni = 2;
    memcpy(vp + 32, &ni, 2);
    uint16_t items2[6] = {6, 20, 3, 7, 8, 2};
    memcpy(vp + 34, items2, 12);
    assert_int_equal(ag_las_read_buffer(o.b, o.n, &c, &e), AG_ERR_UNSUPPORTED);
    assert_non_null(strstr(e.text, "POINT10 version 3"));
    /* items that do not spell the record */
    items2[2] = 2;
    items2[3] = 8;
    items2[4] = 6;
    memcpy(vp + 34, items2, 12);
    assert_int_equal(ag_las_read_buffer(o.b, o.n, &c, &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "do not make a point format 1 record"));
    assert_null(c);
    free(o.b);
}

static void test_ahn3_against_ply(void **state)
{
    (void)state;
    const char *laz = SHARED "/pointcloud_ahn3_delft/ahn3_cropped_1.laz";
    const char *xz = SHARED "/pointcloud_ahn3_delft/ahn3_cropped_1.ply.xz";
    if (access(laz, R_OK) || access(xz, R_OK)) {
        print_message("skipping: %s is absent\n", SHARED "/pointcloud_ahn3_delft");
        skip();
    }
    char dir[] = "/tmp/archgram_laz_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char ply[256], cmd[1024];
    snprintf(ply, sizeof ply, "%s/ahn3.ply", dir);
    snprintf(cmd, sizeof cmd, "xz -dc '%s' > '%s'", xz, ply);
    if (system(cmd) != 0) {
        print_message("skipping: xz could not decompress %s\n", xz);
        skip();
    }
    ag_cloud *a, *b;
    ag_error e;
    assert_int_equal(ag_cloud_import_file(laz, &a, &e), AG_OK);
    assert_int_equal(ag_cloud_import_file(ply, &b, &e), AG_OK);
    unlink(ply);
    rmdir(dir);
    assert_int_equal(a->n, 640510);
    assert_int_equal(b->n, 640510);
    const char *names[] = {"intensity", "classification", "return_number"};
    size_t class6 = 0;
    for (size_t i = 0; i < a->n; i++) {
        /* the PLY holds float offsets from 84808 447412 0: 230 m at float precision */
        for (int k = 0; k < 3; k++)
            if (fabs(a->xyz[3 * i + k] + a->offset[k] - b->xyz[3 * i + k] - b->offset[k]) > 1e-4)
                fail_msg("point %zu axis %d: %.4f vs %.4f", i, k, a->xyz[3 * i + k] + a->offset[k],
                         b->xyz[3 * i + k] + b->offset[k]);
        for (int p = 0; p < 3; p++)
            if (ag_cloud_get(ag_cloud_find(a, names[p]), i) != ag_cloud_get(ag_cloud_find(b, names[p]), i))
                fail_msg("point %zu: %s differs", i, names[p]);
        class6 += ag_cloud_get(ag_cloud_find(a, "classification"), i) == 6;
    }
    assert_int_equal(class6, 246753); /* the README's count of building points */
    ag_cloud_free(b);
    /* damaged copies of the real file: errors or clouds, never a crash */
    ag_filemap fm;
    assert_int_equal(ag_filemap_open(laz, &fm, &e), AG_OK);
    uint8_t *bad = malloc(fm.len);
    ag_rng r;
    ag_rng_seed(&r, 5);
    for (int k = 0; k < 6; k++) {
        memcpy(bad, fm.data, fm.len);
        for (int j = 0; j < 8; j++)
            bad[400 + ag_rng_below(&r, fm.len - 400)] ^= (uint8_t)(1 + ag_rng_below(&r, 255));
        ag_cloud *c = NULL;
        if (ag_las_read_buffer(bad, fm.len, &c, &e) == AG_OK)
            assert_int_equal(c->n, 640510);
        ag_cloud_free(c);
    }
    ag_cloud *c = NULL;
    assert_int_not_equal(ag_las_read_buffer(fm.data, fm.len / 2, &c, &e), AG_OK);
    assert_non_null(strstr(e.text, "LAZ"));
    free(bad);
    ag_filemap_close(&fm);
    ag_cloud_free(a);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_encoded_layouts),
        cmocka_unit_test(test_unsupported),
        cmocka_unit_test(test_ahn3_against_ply),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
