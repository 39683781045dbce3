#include "usecase_import_cloud.h"

#include <stdlib.h>
#include <string.h>

#include "../core/points/lod.h"
#include "../io/cloud_import.h"

int ag_usecase_import_cloud_accepts(const ag_mesh_source *src)
{
    ag_cloud_format named = src->format ? ag_cloud_format_from_name(src->format)
                                        : AG_CLOUD_FORMAT_UNKNOWN;
    if (named != AG_CLOUD_FORMAT_UNKNOWN && named != AG_CLOUD_FORMAT_PLY)
        return 1;
    if (src->format && named != AG_CLOUD_FORMAT_PLY)
        return 0; /* a mesh format by name */
    ag_mesh_file file;
    if (ag_usecase_import_map(src, &file, NULL) != AG_OK)
        return 0;
    int cloud = ag_cloud_import_is_cloud(file.data, file.len,
                                         src->filename ? src->filename : src->path);
    /* named ply: a PLY without faces; sniffed: a LAS, a faceless PLY or lines of numbers */
    if (cloud && named == AG_CLOUD_FORMAT_PLY &&
        ag_cloud_format_sniff(file.data, file.len, NULL) != AG_CLOUD_FORMAT_PLY)
        cloud = 0;
    ag_usecase_import_release(&file);
    return cloud;
}

ag_status ag_usecase_import_cloud_run(ag_workspace *ws, const ag_mesh_source *src,
                                      const char *name, int64_t *model, ag_error *err)
{
    *model = 0;
    ag_mesh_file file;
    ag_status s = ag_usecase_import_map(src, &file, err);
    if (s != AG_OK)
        return s;
    ag_cloud_format fmt = src->format ? ag_cloud_format_from_name(src->format)
                                      : ag_cloud_format_sniff(file.data, file.len,
                                                              src->filename ? src->filename
                                                                            : src->path);
    uint64_t count = 0;
    ag_cloud *c = NULL;
    uint32_t *lod = NULL;
    if (fmt == AG_CLOUD_FORMAT_UNKNOWN)
        s = ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                         "%s is not a point cloud archgram reads (PLY, LAS, LAZ, XYZ)%s%s",
                         src->what ? src->what : "the file", src->format_hint ? "; " : "",
                         src->format_hint ? src->format_hint : "");
    if (s == AG_OK && ag_workspace_progress(ws, 0.05, "parse"))
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
    if (s == AG_OK)
        s = ag_cloud_import_count(file.data, file.len, fmt, &count, err);
    if (s == AG_OK && count > AG_CLOUD_MAX_POINTS)
        s = ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                         "the cloud holds %llu points; archgram takes at most %zu (cut a tile "
                         "into buildings first: archgram cut)",
                         (unsigned long long)count, AG_CLOUD_MAX_POINTS);
    if (s == AG_OK)
        s = ag_cloud_import_buffer(file.data, file.len, fmt, &c, err);
    if (s == AG_OK && c->n == 0)
        s = ag_error_set(err, AG_ERR_EMPTY, 0, "%s holds no points",
                         src->what ? src->what : "the cloud");
    if (s == AG_OK && ag_workspace_progress(ws, 0.6, "order"))
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
    if (s == AG_OK && !(lod = malloc((c->n ? c->n : 1) * sizeof *lod)))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory for %zu points", c->n);
    if (s == AG_OK)
        s = ag_lod_order(c, 0, lod, err);
    if (s == AG_OK && ag_workspace_progress(ws, 0.8, "store"))
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
    if (s == AG_OK) {
        ag_cloud_new n = {.cloud = c,
                          .lod = lod,
                          .source = file.data,
                          .source_len = file.len,
                          .source_format = ag_cloud_format_name(fmt)};
        s = ag_workspace_add_cloud(ws, name, &n, model, err);
    }
    free(lod);
    ag_cloud_free(c);
    ag_usecase_import_release(&file);
    return s;
}
