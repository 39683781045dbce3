#include "cloud_import.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "filemap.h"
#include "las.h"
#include "ply.h"
#include "xyz.h"

static const struct {
    const char *name;
    ag_cloud_format fmt;
} names[] = {
    {"ply", AG_CLOUD_FORMAT_PLY}, {"las", AG_CLOUD_FORMAT_LAS}, {"laz", AG_CLOUD_FORMAT_LAZ},
    {"xyz", AG_CLOUD_FORMAT_XYZ}, {"txt", AG_CLOUD_FORMAT_XYZ}, {"pts", AG_CLOUD_FORMAT_XYZ},
};

ag_cloud_format ag_cloud_format_from_name(const char *name)
{
    for (size_t i = 0; name && i < sizeof names / sizeof names[0]; i++)
        if (!strcasecmp(name, names[i].name))
            return names[i].fmt;
    return AG_CLOUD_FORMAT_UNKNOWN;
}

const char *ag_cloud_format_name(ag_cloud_format f)
{
    switch (f) {
    case AG_CLOUD_FORMAT_PLY: return "ply";
    case AG_CLOUD_FORMAT_LAS: return "las";
    case AG_CLOUD_FORMAT_LAZ: return "laz";
    case AG_CLOUD_FORMAT_XYZ: return "xyz";
    default: return "unknown";
    }
}

/* The first few non-comment lines are 3, 6 or 9 numbers each. */
static int looks_like_xyz(const uint8_t *d, size_t len)
{
    size_t lines = 0, pos = 0, limit = len < 4096 ? len : 4096;
    while (pos < limit && lines < 5) {
        size_t end = pos;
        while (end < len && d[end] != '\n')
            end++;
        size_t n = 0;
        int in_num = 0, bad = 0, comment = 0;
        for (size_t i = pos; i < end; i++) {
            uint8_t c = d[i];
            if (i == pos && (c == '#' || c == '/'))
                comment = 1;
            if ((c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E') {
                if (!in_num)
                    n++;
                in_num = 1;
            } else if (c == ' ' || c == '\t' || c == ',' || c == ';' || c == '\r') {
                in_num = 0;
            } else {
                bad = 1;
            }
        }
        if (!comment && n) {
            if (bad || (n != 3 && n != 6 && n != 9))
                return 0;
            lines++;
        }
        pos = end + 1;
    }
    return lines > 0;
}

ag_cloud_format ag_cloud_format_sniff(const uint8_t *data, size_t len, const char *filename)
{
    if (len >= 4 && !memcmp(data, "LASF", 4)) {
        if (len > 104 && (data[104] & 0xC0))
            return AG_CLOUD_FORMAT_LAZ;
        return AG_CLOUD_FORMAT_LAS;
    }
    if (len >= 4 && !memcmp(data, "ply", 3) && (data[3] == '\n' || data[3] == '\r'))
        return AG_CLOUD_FORMAT_PLY;
    if (len && looks_like_xyz(data, len))
        return AG_CLOUD_FORMAT_XYZ;
    const char *dot = filename ? strrchr(filename, '.') : NULL;
    ag_cloud_format f = dot ? ag_cloud_format_from_name(dot + 1) : AG_CLOUD_FORMAT_UNKNOWN;
    /* an extension alone only names an empty text cloud (so that its error says so): binary
     * formats have signatures, and text that is not numbers is not a cloud */
    return f == AG_CLOUD_FORMAT_XYZ && len == 0 ? f : AG_CLOUD_FORMAT_UNKNOWN;
}

int ag_cloud_import_is_cloud(const uint8_t *data, size_t len, const char *filename)
{
    ag_cloud_format f = ag_cloud_format_sniff(data, len, filename);
    /* a PLY whose header this reader does not take goes to the mesh importer, which judges
     * it (as it did every PLY before clouds were read) */
    uint64_t vertices = 0;
    if (f == AG_CLOUD_FORMAT_PLY)
        return ag_ply_vertex_count(data, len, &vertices) == 0 && !ag_ply_has_faces(data, len);
    return f != AG_CLOUD_FORMAT_UNKNOWN;
}

ag_status ag_cloud_import_count(const uint8_t *data, size_t len, ag_cloud_format fmt,
                                uint64_t *count, ag_error *err)
{
    *count = 0;
    if (fmt == AG_CLOUD_FORMAT_UNKNOWN)
        fmt = ag_cloud_format_sniff(data, len, NULL);
    switch (fmt) {
    case AG_CLOUD_FORMAT_LAS:
    case AG_CLOUD_FORMAT_LAZ: {
        ag_las_header h;
        ag_status st = ag_las_read_header(data, len, &h, err);
        if (st == AG_OK)
            *count = h.count;
        return st;
    }
    case AG_CLOUD_FORMAT_PLY: {
        if (ag_ply_vertex_count(data, len, count) == 0)
            return AG_OK;
        ag_cloud *c = NULL; /* the reader names what is wrong with the header */
        ag_status st = ag_ply_read_buffer(data, len, &c, err);
        ag_cloud_free(c);
        return st != AG_OK ? st : ag_error_set(err, AG_ERR_PARSE, 0, "the PLY has no vertex element");
    }
    case AG_CLOUD_FORMAT_XYZ: {
        uint64_t lines = 0;
        for (const uint8_t *p = data, *end = data + len; p < end; lines++) {
            const uint8_t *nl = memchr(p, '\n', (size_t)(end - p));
            p = nl ? nl + 1 : end;
        }
        *count = lines;
        return AG_OK;
    }
    default:
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                            "not a point cloud format archgram reads (PLY, LAS, LAZ, XYZ)");
    }
}

ag_status ag_cloud_import_buffer(const uint8_t *data, size_t len, ag_cloud_format fmt,
                                 ag_cloud **out, ag_error *err)
{
    *out = NULL;
    if (!len)
        return ag_error_set(err, AG_ERR_EMPTY, 0, "empty file");
    if (fmt == AG_CLOUD_FORMAT_UNKNOWN)
        fmt = ag_cloud_format_sniff(data, len, NULL);
    switch (fmt) {
    case AG_CLOUD_FORMAT_PLY: return ag_ply_read_buffer(data, len, out, err);
    case AG_CLOUD_FORMAT_LAS:
    case AG_CLOUD_FORMAT_LAZ: return ag_las_read_buffer(data, len, out, err);
    case AG_CLOUD_FORMAT_XYZ: return ag_xyz_read_buffer(data, len, out, err);
    default:
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                            "not a point cloud format archgram reads (PLY, LAS, LAZ, XYZ)");
    }
}

ag_status ag_cloud_import_file(const char *path, ag_cloud **out, ag_error *err)
{
    *out = NULL;
    ag_filemap fm;
    ag_status st = ag_filemap_open(path, &fm, err);
    if (st != AG_OK)
        return st;
    ag_cloud_format f = ag_cloud_format_sniff(fm.data, fm.len, path);
    st = fm.len ? ag_cloud_import_buffer(fm.data, fm.len, f, out, err)
                : ag_error_set(err, AG_ERR_EMPTY, 0, "empty file");
    ag_filemap_close(&fm);
    return st;
}
