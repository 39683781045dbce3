#include "import.h"

#include "assimp_import.h"
#include "ply_mesh_positions.h"

#include <string.h>
#include <strings.h>

static const struct {
    ag_format f;
    const char *name;
} formats[] = {
    {AG_FORMAT_OBJ, "obj"},   {AG_FORMAT_PLY, "ply"}, {AG_FORMAT_STL, "stl"},
    {AG_FORMAT_GLTF, "gltf"}, {AG_FORMAT_GLB, "glb"}, {AG_FORMAT_FBX, "fbx"},
    {AG_FORMAT_DAE, "dae"},
};

ag_format ag_format_from_name(const char *name)
{
    if (!name)
        return AG_FORMAT_UNKNOWN;
    if (name[0] == '.')
        name++;
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; i++)
        if (strcasecmp(name, formats[i].name) == 0)
            return formats[i].f;
    return AG_FORMAT_UNKNOWN;
}

const char *ag_format_name(ag_format f)
{
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; i++)
        if (formats[i].f == f)
            return formats[i].name;
    return "unknown";
}

static int starts(const uint8_t *d, size_t len, const char *s)
{
    size_t n = strlen(s);
    return len >= n && memcmp(d, s, n) == 0;
}

/* An OBJ statement keyword at the start of a line, followed by a blank. */
static int obj_keyword(const char *p, const char *e)
{
    static const char *const kw[] = {"v",  "vt", "vn", "vp",     "f",      "g",  "o",
                                     "s",  "l",  "p",  "mtllib", "usemtl", NULL};
    const char *k = p;
    while (p < e && *p != ' ' && *p != '\t' && *p != '\r')
        p++;
    if (p >= e)
        return 0;
    for (int i = 0; kw[i]; i++)
        if (strlen(kw[i]) == (size_t)(p - k) && memcmp(kw[i], k, (size_t)(p - k)) == 0)
            return 1;
    return 0;
}

/* Looks at the first statements (skipping comments and blank lines) of a text. */
static int looks_like_obj(const uint8_t *data, size_t len)
{
    size_t n = len < 16384 ? len : 16384;
    if (memchr(data, '\0', n))
        return 0;
    const char *p = (const char *)data, *e = p + n;
    if (n >= 3 && (uint8_t)p[0] == 0xEF && (uint8_t)p[1] == 0xBB && (uint8_t)p[2] == 0xBF)
        p += 3;
    int seen = 0;
    while (p < e && seen < 8) {
        while (p < e && (*p == ' ' || *p == '\t' || *p == '\r'))
            p++;
        if (p >= e)
            break;
        const char *nl = memchr(p, '\n', (size_t)(e - p));
        const char *le = nl ? nl : e;
        if (p < le && *p != '#') {
            if (!obj_keyword(p, le))
                return 0;
            seen++;
        }
        if (!nl)
            break;
        p = nl + 1;
    }
    return seen > 0;
}

/* Binary STL: an 80-byte header (which may well begin with "solid"), a triangle count and
 * exactly 50 bytes per triangle; ASCII STL: "solid" then a facet. */
static int looks_like_stl(const uint8_t *data, size_t len)
{
    if (len >= 84) {
        uint64_t n = (uint64_t)data[80] | (uint64_t)data[81] << 8 | (uint64_t)data[82] << 16 |
                     (uint64_t)data[83] << 24;
        if (n > 0 && 84 + 50 * n == len)
            return 1;
    }
    size_t i = 0;
    while (i < len && (data[i] == ' ' || data[i] == '\t' || data[i] == '\r' || data[i] == '\n'))
        i++;
    return len - i >= 5 && !memcmp(data + i, "solid", 5) &&
           memmem(data, len < 4096 ? len : 4096, "facet", 5);
}

ag_format ag_format_sniff(const uint8_t *data, size_t len, const char *filename)
{
    if (data && len) {
        if (starts(data, len, "glTF"))
            return AG_FORMAT_GLB;
        if (starts(data, len, "ply\n") || starts(data, len, "ply\r\n"))
            return AG_FORMAT_PLY;
        if (starts(data, len, "Kaydara FBX Binary"))
            return AG_FORMAT_FBX;
        if (looks_like_obj(data, len))
            return AG_FORMAT_OBJ;
    }
    if (filename) {
        const char *dot = strrchr(filename, '.');
        const char *slash = strrchr(filename, '/');
        if (dot && (!slash || dot > slash))
            return ag_format_from_name(dot + 1);
    }
    if (data && len) {
        /* Weaker content hints, used only when the name says nothing. */
        if (starts(data, len, "{") && memmem(data, len < 4096 ? len : 4096, "\"asset\"", 7))
            return AG_FORMAT_GLTF;
        if (memmem(data, len < 4096 ? len : 4096, "<COLLADA", 8))
            return AG_FORMAT_DAE;
        if (looks_like_stl(data, len))
            return AG_FORMAT_STL;
    }
    return AG_FORMAT_UNKNOWN;
}

const char *ag_import_up_basis_name(ag_up_basis b)
{
    switch (b) {
    case AG_UP_BY_REQUEST: return "request";
    case AG_UP_BY_FILE: return "file";
    case AG_UP_BY_CONTENT: return "content";
    case AG_UP_BY_CONVENTION: return "convention";
    }
    return "convention";
}

static json_t *cues_json(const ag_upaxis_cues *c)
{
    return json_pack("{s:f, s:f, s:f, s:f, s:f, s:f, s:f}", "base", c->base, "top", c->top,
                     "vertical", c->vertical, "extent", c->extent, "origin", c->origin, "roof",
                     c->roof, "roof_strict", c->roof_strict);
}

json_t *ag_import_up_json(const ag_up_decision *d)
{
    const ag_upaxis_evidence *e = &d->evidence;
    json_t *ev = json_pack("{s:o, s:f, s:b, s:b, s:b, s:[f,f,f], s:o, s:o}", "content",
                           e->axis ? json_string(e->axis == 2 ? "z" : "y") : json_null(),
                           "score", e->score, "georeferenced", e->georeferenced, "storey",
                           e->storey, "roof", e->roof, "centre",
                           e->centre[0], e->centre[1], e->centre[2], "y", cues_json(&e->cue[0]),
                           "z", cues_json(&e->cue[1]));
    return json_pack("{s:s, s:s, s:o}", "axis", d->axis == AG_UP_Z ? "z" : "y", "decided",
                     ag_import_up_basis_name(d->basis), "evidence", ev ? ev : json_null());
}

/* Reads the file as it is (no axis change), then decides the axis and turns a y-up mesh to
 * z up: the decision needs the coordinates as the file holds them. */
static ag_status read_raw(const uint8_t *data, size_t len, ag_format fmt,
                          const ag_import_options *opt, ag_mesh **out, ag_error *err)
{
    ag_import_options raw = opt ? *opt : (ag_import_options){0};
    raw.up = AG_UP_Z;
    if (fmt == AG_FORMAT_OBJ) {
        ag_obj_read_options o = {.up = AG_UP_Z,
                                 .progress = raw.progress,
                                 .user = raw.user};
        return ag_obj_read_buffer((const char *)data, len, &o, out, err);
    }
    ag_status st = ag_assimp_import_buffer(data, len, fmt, &raw, out, NULL, err);
    if (st == AG_OK && fmt == AG_FORMAT_PLY)
        ag_ply_mesh_restore_positions(*out, data, len); /* assimp's floats, the file's doubles */
    return st;
}

ag_status ag_import_buffer(const uint8_t *data, size_t len, ag_format fmt,
                           const ag_import_options *opt, ag_mesh **out, ag_error *err)
{
    *out = NULL;
    if (fmt == AG_FORMAT_UNKNOWN)
        fmt = ag_format_sniff(data, len, NULL);
    switch (fmt) {
    case AG_FORMAT_OBJ:
    case AG_FORMAT_PLY:
    case AG_FORMAT_STL:
    case AG_FORMAT_GLTF:
    case AG_FORMAT_GLB:
    case AG_FORMAT_FBX:
    case AG_FORMAT_DAE: {
        ag_status st = read_raw(data, len, fmt, opt, out, err);
        if (st)
            return st;
        ag_up_decision d = {.basis = AG_UP_BY_REQUEST, .axis = opt ? opt->up : AG_UP_DEFAULT};
        if ((st = ag_upaxis_decide(*out, &d.evidence, err))) {
            ag_mesh_free(*out);
            *out = NULL;
            return st;
        }
        if (d.axis != AG_UP_Y && d.axis != AG_UP_Z) {
            /* glTF is y-up by its specification; assimp hands out Collada and FBX scenes
             * y-up; OBJ, PLY and STL say nothing */
            int declared = fmt == AG_FORMAT_GLTF || fmt == AG_FORMAT_GLB ||
                           fmt == AG_FORMAT_FBX || fmt == AG_FORMAT_DAE;
            if (declared) {
                d.basis = AG_UP_BY_FILE;
                d.axis = AG_UP_Y;
            } else if (d.evidence.axis) {
                d.basis = AG_UP_BY_CONTENT;
                d.axis = d.evidence.axis == 2 ? AG_UP_Z : AG_UP_Y;
            } else {
                d.basis = AG_UP_BY_CONVENTION;
                d.axis = fmt == AG_FORMAT_OBJ ? AG_UP_Y : AG_UP_Z;
            }
        }
        if (d.axis == AG_UP_Y)
            ag_upaxis_turn_y_to_z(*out);
        if (opt && opt->up_decision)
            *opt->up_decision = d;
        return AG_OK;
    }
    case AG_FORMAT_UNKNOWN:
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                            "unrecognised file format (archgram reads obj, ply, stl, gltf, "
                            "glb, fbx and dae; name it with the file's extension or format)");
    default:
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                            "%s files cannot be imported (archgram reads obj, ply, stl, gltf, "
                            "glb, fbx and dae)",
                            ag_format_name(fmt));
    }
}
