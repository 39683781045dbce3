#include "import.h"

#include "assimp_import.h"

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
    }
    return AG_FORMAT_UNKNOWN;
}

ag_status ag_import_buffer(const uint8_t *data, size_t len, ag_format fmt,
                           const ag_import_options *opt, ag_mesh **out, ag_error *err)
{
    *out = NULL;
    if (fmt == AG_FORMAT_UNKNOWN)
        fmt = ag_format_sniff(data, len, NULL);
    switch (fmt) {
    case AG_FORMAT_OBJ: {
        ag_obj_read_options o = {0};
        if (opt) {
            o.up = opt->up;
            o.progress = opt->progress;
            o.user = opt->user;
            o.allow_external_files = opt->allow_external_files;
        }
        return ag_obj_read_buffer((const char *)data, len, &o, out, err);
    }
    case AG_FORMAT_PLY:
    case AG_FORMAT_STL:
    case AG_FORMAT_GLTF:
    case AG_FORMAT_GLB:
    case AG_FORMAT_FBX:
    case AG_FORMAT_DAE:
        return ag_assimp_import_buffer(data, len, fmt, opt, out, NULL, err);
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
