#include "las.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bytes.h"
#include "laz.h"

#define VLR_HEADER 54
#define EXTRA_BYTES_DESCRIPTOR 192
#define MAX_EXTRA 64

/* Offsets of the optional parts of each point format (-1 when absent). */
static const struct {
    int size, gps, rgb, nir, wave;
} layouts[11] = {
    {20, -1, -1, -1, -1}, {28, 20, -1, -1, -1}, {26, -1, 20, -1, -1}, {34, 20, 28, -1, -1},
    {57, 20, -1, -1, 28}, {63, 20, 28, -1, 34}, {30, 22, -1, -1, -1}, {36, 22, 30, -1, -1},
    {38, 22, 30, 36, -1}, {59, 22, -1, -1, 30}, {67, 22, 30, 36, 38},
};

size_t ag_las_record_size(int format)
{
    return format >= 0 && format <= 10 ? (size_t)layouts[format].size : 0;
}

ag_status ag_las_read_header(const uint8_t *d, size_t len, ag_las_header *h, ag_error *err)
{
    memset(h, 0, sizeof *h);
    if (len < 4 || memcmp(d, "LASF", 4) != 0)
        return ag_error_set(err, AG_ERR_PARSE, 0, "not a LAS file (no LASF signature)");
    if (len < 227)
        return ag_error_set(err, AG_ERR_PARSE, 0,
                            "the file has %zu bytes, less than a LAS header (227)", len);
    h->version_major = d[24];
    h->version_minor = d[25];
    if (h->version_major != 1 || h->version_minor > 4)
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0, "LAS version %u.%u is not supported (1.0-1.4)",
                            h->version_major, h->version_minor);
    h->header_size = ag_bytes_u16le(d + 94);
    h->point_offset = ag_bytes_u32le(d + 96);
    h->nvlrs = ag_bytes_u32le(d + 100);
    uint8_t pf = d[104];
    h->compressed = (pf & 0xC0) != 0;
    h->point_format = pf & 0x3F;
    h->record_length = ag_bytes_u16le(d + 105);
    h->count = ag_bytes_u32le(d + 107);
    for (int a = 0; a < 3; a++) {
        h->scale[a] = ag_bytes_f64le(d + 131 + 8 * a);
        h->offset[a] = ag_bytes_f64le(d + 155 + 8 * a);
        h->max[a] = ag_bytes_f64le(d + 179 + 16 * a);
        h->min[a] = ag_bytes_f64le(d + 187 + 16 * a);
    }
    if (h->header_size < 227 || h->header_size > len)
        return ag_error_set(err, AG_ERR_PARSE, 0,
                            "header size %u is outside the file (227..%zu bytes)", h->header_size, len);
    if (h->version_minor >= 4 && h->header_size >= 375) {
        uint64_t count64 = ag_bytes_u64le(d + 247);
        if (count64)
            h->count = count64;
    }
    if (h->point_format > 10)
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0, "LAS point format %u is not defined (0-10)",
                            h->point_format);
    size_t need = ag_las_record_size(h->point_format);
    if (h->record_length < need)
        return ag_error_set(err, AG_ERR_PARSE, 0,
                            "point format %u needs records of at least %zu bytes, the header says %u",
                            h->point_format, need, h->record_length);
    if (h->point_offset < h->header_size || h->point_offset > len)
        return ag_error_set(err, AG_ERR_PARSE, 0,
                            "the point data offset %u is outside the file (%u..%zu)",
                            h->point_offset, h->header_size, len);
    for (int a = 0; a < 3; a++)
        if (!isfinite(h->scale[a]) || h->scale[a] == 0 || !isfinite(h->offset[a]))
            return ag_error_set(err, AG_ERR_PARSE, 0, "the %c scale or offset is not usable (%g, %g)",
                                "xyz"[a], h->scale[a], h->offset[a]);
    if (!h->compressed) {
        uint64_t avail = len - h->point_offset;
        if (h->count > avail / h->record_length)
            return ag_error_set(err, AG_ERR_PARSE, 0,
                                "the header says %llu points of %u bytes from byte %u (%llu bytes), "
                                "but the file has only %zu bytes",
                                (unsigned long long)h->count, h->record_length, h->point_offset,
                                (unsigned long long)h->count * h->record_length +
                                    h->point_offset,
                                len);
    }
    return AG_OK;
}

/* ---- extra bytes ----------------------------------------------------------------------- */

static const ag_scalar_type extra_types[11] = {
    AG_SCALAR_COUNT,   AG_SCALAR_UINT8,  AG_SCALAR_INT8,   AG_SCALAR_UINT16,
    AG_SCALAR_INT16,   AG_SCALAR_UINT32, AG_SCALAR_INT32,  AG_SCALAR_UINT64,
    AG_SCALAR_INT64,   AG_SCALAR_FLOAT32, AG_SCALAR_FLOAT64,
};

static int extra_code(ag_scalar_type t)
{
    for (int i = 1; i <= 10; i++)
        if (extra_types[i] == t)
            return i;
    return 0;
}

typedef struct {
    char name[33];
    size_t offset, size;   /* within the record */
    ag_scalar_type type;   /* raw type; AG_SCALAR_COUNT = skipped */
    int scaled;
    double scale, add;
    size_t prop;           /* cloud property (float64 when scaled) */
    int normal;            /* 0, or 1 + axis for nx ny nz */
} extra_field;

/* Reads the extra-bytes descriptors; they describe record bytes [base, record_length). A
 * descriptor list that does not add up to that span is ignored (the bytes are skipped). */
static size_t parse_extra(const ag__las_vlr *v, size_t base, size_t record_length,
                          extra_field *out)
{
    size_t n = 0, at = base;
    for (size_t k = 0; k + EXTRA_BYTES_DESCRIPTOR <= v->len && n < MAX_EXTRA; k += EXTRA_BYTES_DESCRIPTOR) {
        const uint8_t *d = v->data + k;
        extra_field *f = &out[n];
        memset(f, 0, sizeof *f);
        unsigned type = d[2], options = d[3];
        memcpy(f->name, d + 4, 32);
        f->name[32] = 0;
        f->offset = at;
        f->type = AG_SCALAR_COUNT;
        static const size_t sizes[11] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
        if (type == 0) {
            f->size = options; /* undocumented bytes: options holds their count */
        } else if (type <= 10) {
            f->size = sizes[type];
            f->type = extra_types[type];
            f->scaled = (options & 0x18) != 0;
            f->scale = options & 0x08 ? ag_bytes_f64le(d + 112) : 1;
            f->add = options & 0x10 ? ag_bytes_f64le(d + 136) : 0;
            if (!isfinite(f->scale) || !isfinite(f->add))
                f->scaled = 0;
        } else if (type <= 30) {
            f->size = sizes[(type - 11) % 10 + 1] * (type <= 20 ? 2 : 3); /* deprecated arrays */
        } else {
            return 0;
        }
        at += f->size;
        n++;
    }
    return at == record_length ? n : 0;
}

/* ---- reading --------------------------------------------------------------------------- */

typedef struct {
    ag_cloud *c;
    const ag_las_header *h;
    int legacy; /* formats 0-5 */
    double add[3];
    uint16_t *intensity, *psid, *rgb[3], *nir;
    uint8_t *ret, *nret, *sdir, *edge, *cls, *synth, *key, *withheld, *overlap, *channel, *user;
    int8_t *angle_rank;
    int16_t *angle;
    double *gps;
    uint8_t *wp_index;
    uint64_t *wp_offset;
    uint32_t *wp_size;
    float *wp_f[4];
    size_t nextra;
    extra_field extra[MAX_EXTRA];
} las_reader;

static ag_status add(las_reader *r, const char *name, ag_scalar_type t, void **values, ag_error *err)
{
    size_t i;
    ag_status st = ag_cloud_add_property(r->c, name, t, &i, err);
    if (st == AG_OK)
        *values = r->c->props[i].values;
    return st;
}

static ag_status setup_fields(las_reader *r, ag_error *err)
{
    int f = r->h->point_format;
    ag_status st = AG_OK;
#define ADD(name, type, ptr)                                                                    \
    if (st == AG_OK)                                                                           \
    st = add(r, name, type, (void **)&(ptr), err)
    ADD("intensity", AG_SCALAR_UINT16, r->intensity);
    ADD("return_number", AG_SCALAR_UINT8, r->ret);
    ADD("number_of_returns", AG_SCALAR_UINT8, r->nret);
    ADD("scan_direction_flag", AG_SCALAR_UINT8, r->sdir);
    ADD("edge_of_flight_line", AG_SCALAR_UINT8, r->edge);
    ADD("classification", AG_SCALAR_UINT8, r->cls);
    ADD("synthetic", AG_SCALAR_UINT8, r->synth);
    ADD("key_point", AG_SCALAR_UINT8, r->key);
    ADD("withheld", AG_SCALAR_UINT8, r->withheld);
    if (!r->legacy) {
        ADD("overlap", AG_SCALAR_UINT8, r->overlap);
        ADD("scanner_channel", AG_SCALAR_UINT8, r->channel);
        ADD("scan_angle", AG_SCALAR_INT16, r->angle);
    } else {
        ADD("scan_angle_rank", AG_SCALAR_INT8, r->angle_rank);
    }
    ADD("user_data", AG_SCALAR_UINT8, r->user);
    ADD("point_source_id", AG_SCALAR_UINT16, r->psid);
    if (layouts[f].gps >= 0)
        ADD("gps_time", AG_SCALAR_FLOAT64, r->gps);
    if (layouts[f].rgb >= 0) {
        ADD("red", AG_SCALAR_UINT16, r->rgb[0]);
        ADD("green", AG_SCALAR_UINT16, r->rgb[1]);
        ADD("blue", AG_SCALAR_UINT16, r->rgb[2]);
    }
    if (layouts[f].nir >= 0)
        ADD("nir", AG_SCALAR_UINT16, r->nir);
    if (layouts[f].wave >= 0) {
        ADD("wavepacket_index", AG_SCALAR_UINT8, r->wp_index);
        ADD("wavepacket_offset", AG_SCALAR_UINT64, r->wp_offset);
        ADD("wavepacket_size", AG_SCALAR_UINT32, r->wp_size);
        ADD("wavepacket_location", AG_SCALAR_FLOAT32, r->wp_f[0]);
        ADD("wavepacket_xt", AG_SCALAR_FLOAT32, r->wp_f[1]);
        ADD("wavepacket_yt", AG_SCALAR_FLOAT32, r->wp_f[2]);
        ADD("wavepacket_zt", AG_SCALAR_FLOAT32, r->wp_f[3]);
    }
#undef ADD
    /* extra bytes: nx ny nz (all three, float) are normals, the rest properties */
    int normal_axes = 0;
    for (size_t i = 0; i < r->nextra; i++) {
        extra_field *e = &r->extra[i];
        static const char *const nn[3] = {"nx", "ny", "nz"};
        for (int a = 0; a < 3; a++)
            if (e->type != AG_SCALAR_COUNT && !strcmp(e->name, nn[a]))
                normal_axes |= 1 << a;
    }
    if (normal_axes == 7 && st == AG_OK)
        st = ag_cloud_add_normals(r->c, err);
    for (size_t i = 0; st == AG_OK && i < r->nextra; i++) {
        extra_field *e = &r->extra[i];
        if (e->type == AG_SCALAR_COUNT)
            continue;
        if (normal_axes == 7 && e->name[0] == 'n' && e->name[1] >= 'x' && e->name[1] <= 'z' &&
            !e->name[2]) {
            e->normal = 1 + (e->name[1] - 'x');
            continue;
        }
        if (!e->name[0] || ag_cloud_find(r->c, e->name)) {
            e->type = AG_SCALAR_COUNT; /* unnamed or clashing: skipped */
            continue;
        }
        st = ag_cloud_add_property(r->c, e->name, e->scaled ? AG_SCALAR_FLOAT64 : e->type, &e->prop,
                                   err);
    }
    return st;
}

static void store_record(void *user, size_t i, const uint8_t *p)
{
    las_reader *r = user;
    const ag_las_header *h = r->h;
    for (int a = 0; a < 3; a++)
        r->c->xyz[3 * i + a] = (int32_t)ag_bytes_u32le(p + 4 * a) * h->scale[a] + r->add[a];
    r->intensity[i] = ag_bytes_u16le(p + 12);
    int f = h->point_format;
    if (r->legacy) {
        r->ret[i] = p[14] & 7;
        r->nret[i] = (p[14] >> 3) & 7;
        r->sdir[i] = (p[14] >> 6) & 1;
        r->edge[i] = p[14] >> 7;
        r->cls[i] = p[15] & 31;
        r->synth[i] = (p[15] >> 5) & 1;
        r->key[i] = (p[15] >> 6) & 1;
        r->withheld[i] = p[15] >> 7;
        r->angle_rank[i] = (int8_t)p[16];
        r->user[i] = p[17];
        r->psid[i] = ag_bytes_u16le(p + 18);
    } else {
        r->ret[i] = p[14] & 15;
        r->nret[i] = p[14] >> 4;
        r->synth[i] = p[15] & 1;
        r->key[i] = (p[15] >> 1) & 1;
        r->withheld[i] = (p[15] >> 2) & 1;
        r->overlap[i] = (p[15] >> 3) & 1;
        r->channel[i] = (p[15] >> 4) & 3;
        r->sdir[i] = (p[15] >> 6) & 1;
        r->edge[i] = p[15] >> 7;
        r->cls[i] = p[16];
        r->user[i] = p[17];
        r->angle[i] = (int16_t)ag_bytes_u16le(p + 18);
        r->psid[i] = ag_bytes_u16le(p + 20);
    }
    if (layouts[f].gps >= 0)
        r->gps[i] = ag_bytes_f64le(p + layouts[f].gps);
    if (layouts[f].rgb >= 0)
        for (int a = 0; a < 3; a++)
            r->rgb[a][i] = ag_bytes_u16le(p + layouts[f].rgb + 2 * a);
    if (layouts[f].nir >= 0)
        r->nir[i] = ag_bytes_u16le(p + layouts[f].nir);
    if (layouts[f].wave >= 0) {
        const uint8_t *w = p + layouts[f].wave;
        r->wp_index[i] = w[0];
        r->wp_offset[i] = ag_bytes_u64le(w + 1);
        r->wp_size[i] = ag_bytes_u32le(w + 9);
        for (int k = 0; k < 4; k++)
            r->wp_f[k][i] = ag_bytes_f32le(w + 13 + 4 * k);
    }
    for (size_t k = 0; k < r->nextra; k++) {
        const extra_field *e = &r->extra[k];
        if (e->type == AG_SCALAR_COUNT)
            continue;
        uint8_t v[8];
        ag_bytes_load(v, p + e->offset, e->size, 0);
        if (e->normal) {
            ag_cloud_property tmp = {.type = e->type, .values = v};
            r->c->normals[3 * i + (size_t)(e->normal - 1)] = (float)ag_cloud_get(&tmp, 0);
        } else if (e->scaled) {
            ag_cloud_property tmp = {.type = e->type, .values = v};
            ((double *)r->c->props[e->prop].values)[i] = ag_cloud_get(&tmp, 0) * e->scale + e->add;
        } else {
            memcpy((char *)r->c->props[e->prop].values + i * e->size, v, e->size);
        }
    }
}

ag_status ag_las_read_buffer(const uint8_t *data, size_t len, ag_cloud **out, ag_error *err)
{
    *out = NULL;
    ag_las_header h;
    ag_status st = ag_las_read_header(data, len, &h, err);
    if (st != AG_OK)
        return st;
    /* the VLRs between the header and the point data */
    ag__las_vlr laszip = {NULL, 0}, extra = {NULL, 0};
    size_t pos = h.header_size;
    for (uint32_t i = 0; i < h.nvlrs; i++) {
        if (pos + VLR_HEADER > h.point_offset)
            return ag_error_set(err, AG_ERR_PARSE, 0,
                                "VLR %u of %u at byte %zu runs past the point data (byte %u)", i + 1,
                                h.nvlrs, pos, h.point_offset);
        const uint8_t *v = data + pos;
        uint16_t record = ag_bytes_u16le(v + 18), length = ag_bytes_u16le(v + 20);
        if (pos + VLR_HEADER + length > h.point_offset)
            return ag_error_set(err, AG_ERR_PARSE, 0,
                                "VLR %u of %u at byte %zu (%u bytes) runs past the point data "
                                "(byte %u)",
                                i + 1, h.nvlrs, pos, length, h.point_offset);
        char user[17];
        memcpy(user, v + 2, 16);
        user[16] = 0;
        if (!strcmp(user, "laszip encoded") && record == 22204)
            laszip = (ag__las_vlr){v + VLR_HEADER, length};
        else if (!strcmp(user, "LASF_Spec") && record == 4)
            extra = (ag__las_vlr){v + VLR_HEADER, length};
        pos += VLR_HEADER + (size_t)length;
    }
    if (h.compressed && !laszip.data)
        return ag_error_set(err, AG_ERR_PARSE, 0,
                            "the point format says LAZ but there is no LASzip VLR");
    /* LASzip takes several bytes per point (AHN3: 5.5); more than one point per byte of file
     * is refused before anything is allocated, which bounds memory for a count that lies */
    if (h.compressed && h.count > len)
        return ag_error_set(err, AG_ERR_PARSE, 0,
                            "the header says %llu points, more than a %zu-byte LAZ file holds "
                            "(archgram reads at most one point per byte)",
                            (unsigned long long)h.count, len);
    las_reader r;
    memset(&r, 0, sizeof r);
    r.h = &h;
    r.legacy = h.point_format < 6;
    size_t base = ag_las_record_size(h.point_format);
    if (extra.data && h.record_length > base)
        r.nextra = parse_extra(&extra, base, h.record_length, r.extra);
    r.c = ag_cloud_create();
    if (!r.c)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (h.count > SIZE_MAX / 64)
        st = ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%llu points are too many",
                          (unsigned long long)h.count);
    else
        st = ag_cloud_resize(r.c, (size_t)h.count, err);
    if (st == AG_OK)
        st = setup_fields(&r, err);
    /* absolute coordinates first (doubles hold them to well below the LAS resolution),
     * then the local origin from the real bounds: the header's bounds may lie */
    for (int a = 0; a < 3; a++) {
        r.add[a] = h.offset[a];
        r.c->scale[a] = h.scale[a];
    }
    if (st == AG_OK) {
        if (h.compressed) {
            st = ag_laz_decode(data, len, &h, &laszip, store_record, &r, err);
        } else {
            const uint8_t *p = data + h.point_offset;
            for (size_t i = 0; i < r.c->n; i++, p += h.record_length)
                store_record(&r, i, p);
        }
    }
    if (st == AG_OK)
        st = ag_cloud_check_finite(r.c, err);
    if (st != AG_OK) {
        ag_cloud_free(r.c);
        return st;
    }
    double mn[3], mx[3], want[3];
    ag_cloud_bounds(r.c, mn, mx);
    ag_cloud_choose_origin(mn, mx, want);
    ag_cloud_rebase(r.c, want);
    *out = r.c;
    return AG_OK;
}

/* ---- writing --------------------------------------------------------------------------- */

static const char *const legacy_fields[] = {
    "intensity", "return_number", "number_of_returns", "scan_direction_flag",
    "edge_of_flight_line", "classification", "synthetic", "key_point", "withheld",
    "scan_angle_rank", "user_data", "point_source_id", NULL};
static const char *const modern_fields[] = {
    "intensity", "return_number", "number_of_returns", "scan_direction_flag",
    "edge_of_flight_line", "classification", "synthetic", "key_point", "withheld", "overlap",
    "scanner_channel", "scan_angle", "user_data", "point_source_id", NULL};
static const char *const wave_fields[] = {"wavepacket_index", "wavepacket_offset",
                                          "wavepacket_size", "wavepacket_location",
                                          "wavepacket_xt", "wavepacket_yt", "wavepacket_zt",
                                          NULL};

static int in_list(const char *const *list, const char *name)
{
    for (; *list; list++)
        if (!strcmp(*list, name))
            return 1;
    return 0;
}

/* Whether property `name` is a field of point format f. */
static int is_format_field(int f, const char *name)
{
    if (in_list(f < 6 ? legacy_fields : modern_fields, name))
        return 1;
    if (layouts[f].gps >= 0 && !strcmp(name, "gps_time"))
        return 1;
    if (layouts[f].rgb >= 0 && (!strcmp(name, "red") || !strcmp(name, "green") || !strcmp(name, "blue")))
        return 1;
    if (layouts[f].nir >= 0 && !strcmp(name, "nir"))
        return 1;
    return layouts[f].wave >= 0 && in_list(wave_fields, name);
}

static double prop_max(const ag_cloud *c, const char *name)
{
    const ag_cloud_property *p = ag_cloud_find(c, name);
    double m = 0;
    for (size_t i = 0; p && i < c->n; i++) {
        double v = ag_cloud_get(p, i);
        if (v > m)
            m = v;
    }
    return m;
}

static int choose_format(const ag_cloud *c)
{
    int rgb = ag_cloud_find(c, "red") && ag_cloud_find(c, "green") && ag_cloud_find(c, "blue");
    int gps = ag_cloud_find(c, "gps_time") != NULL;
    int nir = ag_cloud_find(c, "nir") != NULL;
    int wave = ag_cloud_find(c, "wavepacket_index") != NULL;
    int modern = nir || ag_cloud_find(c, "overlap") || ag_cloud_find(c, "scanner_channel") ||
                 ag_cloud_find(c, "scan_angle") || prop_max(c, "classification") > 31 ||
                 prop_max(c, "return_number") > 7 || prop_max(c, "number_of_returns") > 7;
    if (modern) {
        if (wave)
            return nir || rgb ? 10 : 9;
        return nir ? 8 : rgb ? 7 : 6;
    }
    if (wave)
        return rgb ? 5 : 4;
    return gps ? (rgb ? 3 : 1) : (rgb ? 2 : 0);
}

typedef struct {
    const ag_cloud_property *p; /* NULL: normals axis */
    int axis;
    ag_scalar_type type;
    size_t offset;
} extra_out;

static double field(const ag_cloud *c, const ag_cloud_property *p, size_t i)
{
    (void)c;
    return p ? ag_cloud_get(p, i) : 0;
}

ag_status ag_las_write(const ag_cloud *c, const ag_las_write_options *opt, FILE *f, ag_error *err)
{
    int fmt = opt && opt->point_format >= 0 ? opt->point_format : choose_format(c);
    if (fmt > 10)
        return ag_error_set(err, AG_ERR_INVALID, 0, "LAS point format %d does not exist (0-10)", fmt);
    double scale[3];
    for (int a = 0; a < 3; a++) {
        scale[a] = opt && opt->scale[a] > 0 ? opt->scale[a] : c->scale[a] > 0 ? c->scale[a] : 0.001;
    }
    int legacy = fmt < 6;
    /* extra bytes: normals and every property that is not a field of the format */
    extra_out extra[AG_CLOUD_MAX_PROPERTIES + 3];
    size_t nextra = 0, base = ag_las_record_size(fmt), rec = base;
    if (c->normals)
        for (int a = 0; a < 3; a++)
            extra[nextra++] = (extra_out){NULL, a, AG_SCALAR_FLOAT32, 0};
    for (size_t p = 0; p < c->nprops; p++)
        if (!is_format_field(fmt, c->props[p].name)) {
            if (strlen(c->props[p].name) > 32)
                return ag_error_set(err, AG_ERR_INVALID, 0,
                                    "property '%s' has a longer name than LAS allows (32)",
                                    c->props[p].name);
            extra[nextra++] = (extra_out){&c->props[p], 0, c->props[p].type, 0};
        }
    for (size_t k = 0; k < nextra; k++) {
        extra[k].offset = rec;
        rec += ag_scalar_size(extra[k].type);
    }
    if (rec > UINT16_MAX || nextra * EXTRA_BYTES_DESCRIPTOR > UINT16_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0, "too many properties for one LAS record");
    /* quantise and check the coordinates, and gather the header's statistics */
    double mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < c->n; i++)
        for (int a = 0; a < 3; a++) {
            double q = nearbyint(c->xyz[3 * i + a] / scale[a]);
            if (!(fabs(q) <= INT32_MAX))
                return ag_error_set(err, AG_ERR_INVALID, 0,
                                    "point %zu: the %c coordinate does not fit LAS's 32-bit "
                                    "integers at scale %g",
                                    i + 1, "xyz"[a], scale[a]);
            double v = q * scale[a] + c->offset[a];
            if (v < mn[a])
                mn[a] = v;
            if (v > mx[a])
                mx[a] = v;
        }
    if (!c->n)
        for (int a = 0; a < 3; a++)
            mn[a] = mx[a] = c->offset[a];
    const ag_cloud_property *ret = ag_cloud_find(c, "return_number");
    uint64_t by_return[15] = {0};
    for (size_t i = 0; i < c->n; i++) {
        int r = ret ? (int)ag_cloud_get(ret, i) : 1;
        if (r >= 1 && r <= 15)
            by_return[r - 1]++;
    }
    int minor = legacy ? 2 : 4;
    size_t header = legacy ? 227 : 375;
    size_t vlr_len = nextra ? VLR_HEADER + nextra * EXTRA_BYTES_DESCRIPTOR : 0;
    uint8_t h[375];
    memset(h, 0, sizeof h);
    memcpy(h, "LASF", 4);
    if (!legacy)
        ag_bytes_put_u16le(h + 6, 1 << 4); /* WKT coordinate system bit, required for 6-10 */
    h[24] = 1;
    h[25] = (uint8_t)minor;
    memcpy(h + 26, "archgram", 8);
    memcpy(h + 58, "archgram", 8);
    ag_bytes_put_u16le(h + 94, (uint16_t)header);
    ag_bytes_put_u32le(h + 96, (uint32_t)(header + vlr_len));
    ag_bytes_put_u32le(h + 100, nextra ? 1 : 0);
    h[104] = (uint8_t)fmt;
    ag_bytes_put_u16le(h + 105, (uint16_t)rec);
    int legacy_counts = (fmt < 6) && c->n <= UINT32_MAX;
    if (legacy_counts) {
        ag_bytes_put_u32le(h + 107, (uint32_t)c->n);
        for (int k = 0; k < 5; k++)
            ag_bytes_put_u32le(h + 111 + 4 * k, (uint32_t)by_return[k]);
    } else if (legacy) {
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                            "%zu points are too many for LAS point format %d", c->n, fmt);
    }
    for (int a = 0; a < 3; a++) {
        ag_bytes_put_f64le(h + 131 + 8 * a, scale[a]);
        ag_bytes_put_f64le(h + 155 + 8 * a, c->offset[a]);
        ag_bytes_put_f64le(h + 179 + 16 * a, mx[a]);
        ag_bytes_put_f64le(h + 187 + 16 * a, mn[a]);
    }
    if (!legacy) {
        ag_bytes_put_u64le(h + 247, c->n);
        for (int k = 0; k < 15; k++)
            ag_bytes_put_u64le(h + 255 + 8 * k, by_return[k]);
    }
    fwrite(h, 1, header, f);
    if (nextra) {
        uint8_t v[VLR_HEADER];
        memset(v, 0, sizeof v);
        memcpy(v + 2, "LASF_Spec", 9);
        ag_bytes_put_u16le(v + 18, 4);
        ag_bytes_put_u16le(v + 20, (uint16_t)(nextra * EXTRA_BYTES_DESCRIPTOR));
        memcpy(v + 22, "archgram properties", 19);
        fwrite(v, 1, sizeof v, f);
        for (size_t k = 0; k < nextra; k++) {
            uint8_t d[EXTRA_BYTES_DESCRIPTOR];
            memset(d, 0, sizeof d);
            d[2] = (uint8_t)extra_code(extra[k].type);
            const char *name = extra[k].p ? extra[k].p->name : (const char *[]){"nx", "ny", "nz"}[extra[k].axis];
            memcpy(d + 4, name, strlen(name)); /* checked: at most 32 characters */
            fwrite(d, 1, sizeof d, f);
        }
    }
    /* the records */
    const char *const *names = legacy ? legacy_fields : modern_fields;
    const ag_cloud_property *fp[16] = {0};
    for (int k = 0; names[k]; k++)
        fp[k] = ag_cloud_find(c, names[k]);
    const ag_cloud_property *gps = ag_cloud_find(c, "gps_time"), *nir = ag_cloud_find(c, "nir");
    const ag_cloud_property *rgb[3] = {ag_cloud_find(c, "red"), ag_cloud_find(c, "green"),
                                       ag_cloud_find(c, "blue")};
    int widen = 1; /* 8-bit colour is spread over 16 bits (255 -> 65535) */
    for (int a = 0; a < 3; a++)
        if (!rgb[a] || rgb[a]->type != AG_SCALAR_UINT8)
            widen = 0;
    const ag_cloud_property *wave[7];
    for (int k = 0; k < 7; k++)
        wave[k] = ag_cloud_find(c, wave_fields[k]);
    uint8_t *r = malloc(rec);
    if (!r)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t i = 0; i < c->n; i++) {
        memset(r, 0, rec);
        for (int a = 0; a < 3; a++)
            ag_bytes_put_u32le(r + 4 * a,
                               (uint32_t)(int32_t)nearbyint(c->xyz[3 * i + a] / scale[a]));
        /* field order as in legacy_fields / modern_fields */
        unsigned v[16];
        for (int k = 0; names[k]; k++) {
            double x = field(c, fp[k], i);
            v[k] = fp[k] && !strcmp(names[k], legacy ? "scan_angle_rank" : "scan_angle")
                       ? (unsigned)(int)x
                       : (unsigned)(x < 0 ? 0 : x);
        }
        ag_bytes_put_u16le(r + 12, (uint16_t)v[0]);
        if (legacy) {
            r[14] = (uint8_t)((v[1] & 7) | (v[2] & 7) << 3 | (v[3] & 1) << 6 | (v[4] & 1) << 7);
            r[15] = (uint8_t)((v[5] & 31) | (v[6] & 1) << 5 | (v[7] & 1) << 6 | (v[8] & 1) << 7);
            r[16] = (uint8_t)(int8_t)(int)v[9];
            r[17] = (uint8_t)v[10];
            ag_bytes_put_u16le(r + 18, (uint16_t)v[11]);
        } else {
            r[14] = (uint8_t)((v[1] & 15) | (v[2] & 15) << 4);
            r[15] = (uint8_t)((v[6] & 1) | (v[7] & 1) << 1 | (v[8] & 1) << 2 | (v[9] & 1) << 3 |
                              (v[10] & 3) << 4 | (v[3] & 1) << 6 | (v[4] & 1) << 7);
            r[16] = (uint8_t)v[5];
            r[17] = (uint8_t)v[12];
            ag_bytes_put_u16le(r + 18, (uint16_t)(int16_t)(int)v[11]);
            ag_bytes_put_u16le(r + 20, (uint16_t)v[13]);
        }
        if (layouts[fmt].gps >= 0)
            ag_bytes_put_f64le(r + layouts[fmt].gps, field(c, gps, i));
        if (layouts[fmt].rgb >= 0)
            for (int a = 0; a < 3; a++) {
                double x = field(c, rgb[a], i) * (widen ? 257 : 1);
                ag_bytes_put_u16le(r + layouts[fmt].rgb + 2 * a,
                                   (uint16_t)(x < 0 ? 0 : x > 65535 ? 65535 : x));
            }
        if (layouts[fmt].nir >= 0)
            ag_bytes_put_u16le(r + layouts[fmt].nir, (uint16_t)field(c, nir, i));
        if (layouts[fmt].wave >= 0) {
            uint8_t *w = r + layouts[fmt].wave;
            w[0] = (uint8_t)field(c, wave[0], i);
            uint64_t off = 0;
            if (wave[1])
                off = wave[1]->type == AG_SCALAR_UINT64 ? ((const uint64_t *)wave[1]->values)[i]
                                                        : (uint64_t)field(c, wave[1], i);
            ag_bytes_put_u64le(w + 1, off);
            ag_bytes_put_u32le(w + 9, (uint32_t)field(c, wave[2], i));
            for (int k = 0; k < 4; k++)
                ag_bytes_put_f32le(w + 13 + 4 * k, (float)field(c, wave[3 + k], i));
        }
        for (size_t k = 0; k < nextra; k++) {
            const extra_out *e = &extra[k];
            size_t s = ag_scalar_size(e->type);
            if (e->p)
                ag_bytes_store(r + e->offset, (const char *)e->p->values + i * s, s, 0);
            else
                ag_bytes_put_f32le(r + e->offset, c->normals[3 * i + (size_t)e->axis]);
        }
        if (fwrite(r, 1, rec, f) != rec)
            break;
    }
    free(r);
    if (ferror(f))
        return ag_error_set(err, AG_ERR_IO, 0, "write error: %s", strerror(errno));
    return AG_OK;
}

ag_status ag_las_write_file(const ag_cloud *c, const ag_las_write_options *opt, const char *path,
                            ag_error *err)
{
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot create %s: %s", path, strerror(errno));
    ag_status st = ag_las_write(c, opt, fp, err);
    if (fclose(fp) != 0 && st == AG_OK)
        st = ag_error_set(err, AG_ERR_IO, 0, "cannot write %s: %s", path, strerror(errno));
    if (st != AG_OK)
        remove(path);
    return st;
}
