#include "glb.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GLB_MAGIC 0x46546C67u /* "glTF" */
#define GLB_VERSION 2u
#define CHUNK_JSON 0x4E4F534Au
#define CHUNK_BIN 0x004E4942u
#define GL_FLOAT 5126
#define GL_ARRAY_BUFFER 34962
#define MODE_TRIANGLES 4

static void put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static void put_f32(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    put_u32(p, u);
}

static void to_yup(const double *p, const double *centre, double *o)
{
    ag_glb_yup(p, centre, o);
}

static json_t *vec3(const double *v)
{
    return json_pack("[f,f,f]", v[0], v[1], v[2]);
}

static json_t *extras(size_t c, const ag_mesh *m, const ag_glb_component_meta *meta,
                      size_t nmeta)
{
    int32_t g = m->component_group[c];
    json_t *name = g >= 0 && (size_t)g < m->ngroups ? json_string(m->group_names[g]) : json_null();
    if (!name) /* a group name that is not UTF-8 */
        name = json_null();
    json_t *e = json_pack("{s:I,s:o}", "component", (json_int_t)c, "group", name);
    if (e && meta && c < nmeta) {
        json_t *label = meta[c].label ? json_string(meta[c].label) : NULL;
        if (label)
            json_object_set_new(e, "label", label);
        if (meta[c].node >= 0)
            json_object_set_new(e, "node", json_integer((json_int_t)meta[c].node));
    }
    return e;
}

ag_status ag_glb_write(const ag_mesh *m, uint8_t **out, size_t *len, ag_error *err)
{
    return ag_glb_write_meta(m, NULL, 0, out, len, err);
}

ag_status ag_glb_write_meta(const ag_mesh *m, const ag_glb_component_meta *meta, size_t nmeta,
                            uint8_t **out, size_t *len, ag_error *err)
{
    *out = NULL;
    *len = 0;
    size_t nc = m->ncomponents;
    size_t *count = calloc(nc + 1, sizeof *count);
    size_t *start = calloc(nc + 1, sizeof *start);
    uint32_t *order = malloc((m->ntris ? m->ntris : 1) * sizeof *order);
    json_t *root = NULL;
    uint8_t *bin = NULL;
    ag_status st = AG_ERR_NOMEM;
    if (!count || !start || !order)
        goto out;
    ag_mesh_component_triangle_counts(m, count);
    for (size_t c = 0; c < nc; c++)
        start[c + 1] = start[c] + count[c];
    {
        size_t *fill = calloc(nc + 1, sizeof *fill);
        if (!fill)
            goto out;
        memcpy(fill, start, (nc + 1) * sizeof *fill);
        for (size_t t = 0; t < m->ntris; t++)
            order[fill[m->tri_component[t]]++] = (uint32_t)t;
        free(fill);
    }

    /* Positions relative to the bounds' centre keep float32 precise for geo-referenced
     * (e.g. UTM) coordinates; each node carries the centre as its translation. */
    ag_box b = ag_mesh_bounds(m);
    double centre_z[3] = {0, 0, 0}, centre[3] = {0, 0, 0};
    if (m->ntris)
        for (int k = 0; k < 3; k++)
            centre_z[k] = 0.5 * (b.min[k] + b.max[k]);
    to_yup(centre_z, centre, centre); /* centre in glTF axes (centre starts at 0) */

    /* Every triangle: 3 vertices × (position + normal) × 3 floats. */
    if (m->ntris > (SIZE_MAX - 16) / 72 || m->ntris * 72 > UINT32_MAX - 1024) {
        st = ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%zu triangles do not fit in one GLB",
                          m->ntris);
        goto out;
    }
    size_t binlen = m->ntris * 72;
    bin = malloc(binlen ? binlen : 1);
    root = json_object();
    json_t *nodes = json_array(), *meshes = json_array(), *accessors = json_array(),
           *views = json_array(), *scene_nodes = json_array();
    if (!bin || !root || !nodes || !meshes || !accessors || !views || !scene_nodes) {
        json_decref(nodes);
        json_decref(meshes);
        json_decref(accessors);
        json_decref(views);
        json_decref(scene_nodes);
        goto out;
    }
    json_object_set_new(root, "asset", json_pack("{s:s,s:s}", "version", "2.0", "generator",
                                                 "archgram"));
    json_object_set_new(root, "nodes", nodes);
    json_object_set_new(root, "meshes", meshes);
    json_object_set_new(root, "accessors", accessors);
    json_object_set_new(root, "bufferViews", views);
    json_object_set_new(root, "materials",
                        json_pack("[{s:s,s:{s:[f,f,f,f],s:f,s:f},s:b}]", "name", "default",
                                  "pbrMetallicRoughness", "baseColorFactor", 0.8, 0.8, 0.8, 1.0,
                                  "metallicFactor", 0.0, "roughnessFactor", 0.9, "doubleSided",
                                  1));

    size_t off = 0;
    for (size_t c = 0; c < nc; c++) {
        if (!count[c])
            continue;
        size_t nvert = 3 * count[c];
        size_t pos_off = off, nrm_off = off + nvert * 12;
        ag_box range = ag_box_empty(); /* of the values actually stored, as the spec requires */
        for (size_t i = 0; i < count[c]; i++) {
            const uint32_t *t = m->tri + 3 * (size_t)order[start[c] + i];
            double v[3][3];
            for (int k = 0; k < 3; k++)
                to_yup(m->pos + 3 * (size_t)t[k], centre, v[k]);
            double e1[3], e2[3], n[3];
            for (int k = 0; k < 3; k++) {
                e1[k] = v[1][k] - v[0][k];
                e2[k] = v[2][k] - v[0][k];
            }
            n[0] = e1[1] * e2[2] - e1[2] * e2[1];
            n[1] = e1[2] * e2[0] - e1[0] * e2[2];
            n[2] = e1[0] * e2[1] - e1[1] * e2[0];
            double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            if (l > 0 && isfinite(l)) {
                n[0] /= l;
                n[1] /= l;
                n[2] /= l;
            } else { /* a flat triangle still needs a unit normal */
                n[0] = 0;
                n[1] = 1;
                n[2] = 0;
            }
            for (int k = 0; k < 3; k++) {
                uint8_t *pp = bin + pos_off + (3 * i + (size_t)k) * 12;
                uint8_t *np = bin + nrm_off + (3 * i + (size_t)k) * 12;
                double stored[3];
                for (int a = 0; a < 3; a++) {
                    float f = (float)v[k][a];
                    stored[a] = f;
                    put_f32(pp + 4 * a, f);
                    put_f32(np + 4 * a, (float)n[a]);
                }
                ag_box_extend_point(&range, stored);
            }
        }
        size_t acc = json_array_size(accessors);
        size_t view = json_array_size(views);
        json_array_append_new(views, json_pack("{s:i,s:I,s:I,s:i}", "buffer", 0, "byteOffset",
                                               (json_int_t)pos_off, "byteLength",
                                               (json_int_t)(nvert * 12), "target",
                                               GL_ARRAY_BUFFER));
        json_array_append_new(views, json_pack("{s:i,s:I,s:I,s:i}", "buffer", 0, "byteOffset",
                                               (json_int_t)nrm_off, "byteLength",
                                               (json_int_t)(nvert * 12), "target",
                                               GL_ARRAY_BUFFER));
        json_array_append_new(accessors,
                              json_pack("{s:I,s:i,s:I,s:s,s:o,s:o}", "bufferView",
                                        (json_int_t)view, "componentType", GL_FLOAT, "count",
                                        (json_int_t)nvert, "type", "VEC3", "min", vec3(range.min),
                                        "max", vec3(range.max)));
        json_array_append_new(accessors, json_pack("{s:I,s:i,s:I,s:s}", "bufferView",
                                                   (json_int_t)(view + 1), "componentType",
                                                   GL_FLOAT, "count", (json_int_t)nvert, "type",
                                                   "VEC3"));
        char name[48];
        snprintf(name, sizeof name, "component %zu", c);
        size_t mesh = json_array_size(meshes);
        json_array_append_new(
            meshes, json_pack("{s:s,s:[{s:{s:I,s:I},s:i,s:i}],s:o}", "name", name, "primitives",
                              "attributes", "POSITION", (json_int_t)acc, "NORMAL",
                              (json_int_t)(acc + 1), "material", 0, "mode", MODE_TRIANGLES,
                              "extras", extras(c, m, meta, nmeta)));
        json_array_append_new(scene_nodes, json_integer((json_int_t)json_array_size(nodes)));
        json_array_append_new(nodes, json_pack("{s:s,s:I,s:o,s:o}", "name", name, "mesh",
                                               (json_int_t)mesh, "translation", vec3(centre),
                                               "extras", extras(c, m, meta, nmeta)));
        off = nrm_off + nvert * 12;
    }
    json_t *scene = json_object();
    if (json_array_size(scene_nodes))
        json_object_set_new(scene, "nodes", scene_nodes);
    else
        json_decref(scene_nodes); /* glTF forbids an empty nodes array */
    json_object_set_new(root, "scenes", json_pack("[o]", scene));
    json_object_set_new(root, "scene", json_integer(0));
    if (binlen)
        json_object_set_new(root, "buffers", json_pack("[{s:I}]", "byteLength",
                                                       (json_int_t)binlen));
    else {
        json_object_del(root, "bufferViews");
        json_object_del(root, "accessors");
        json_object_del(root, "meshes");
        json_object_del(root, "nodes");
    }

    st = ag_glb_frame(root, bin, binlen, out, len, err);
    goto done;
out:
    if (st == AG_ERR_NOMEM)
        ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while writing GLB");
done:
    free(count);
    free(start);
    free(order);
    free(bin);
    json_decref(root);
    return st;
}

ag_status ag_glb_frame(const json_t *root, const uint8_t *bin, size_t binlen, uint8_t **out,
                       size_t *len, ag_error *err)
{
    *out = NULL;
    *len = 0;
    char *text = json_dumps(root, JSON_COMPACT);
    if (!text)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while writing GLB");
    size_t tlen = strlen(text);
    size_t jpad = (tlen + 3) & ~(size_t)3;
    size_t bpad = (binlen + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jpad + (binlen ? 8 + bpad : 0);
    if (binlen > UINT32_MAX || total > UINT32_MAX) {
        free(text);
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "the GLB would exceed 4 GiB");
    }
    uint8_t *glb = malloc(total);
    if (!glb) {
        free(text);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while writing GLB");
    }
    put_u32(glb, GLB_MAGIC);
    put_u32(glb + 4, GLB_VERSION);
    put_u32(glb + 8, (uint32_t)total);
    put_u32(glb + 12, (uint32_t)jpad);
    put_u32(glb + 16, CHUNK_JSON);
    memcpy(glb + 20, text, tlen);
    memset(glb + 20 + tlen, ' ', jpad - tlen);
    if (binlen) {
        uint8_t *c = glb + 20 + jpad;
        put_u32(c, (uint32_t)bpad);
        put_u32(c + 4, CHUNK_BIN);
        memcpy(c + 8, bin, binlen);
        memset(c + 8 + binlen, 0, bpad - binlen);
    }
    free(text);
    *out = glb;
    *len = total;
    return AG_OK;
}

ag_status ag_glb_write_file(const ag_mesh *m, const char *path, ag_error *err)
{
    uint8_t *buf;
    size_t len;
    ag_status st = ag_glb_write(m, &buf, &len, err);
    if (st != AG_OK)
        return st;
    FILE *f = fopen(path, "wb");
    if (!f) {
        st = ag_error_set(err, AG_ERR_IO, 0, "cannot create %s: %s", path, strerror(errno));
        free(buf);
        return st;
    }
    size_t w = fwrite(buf, 1, len, f);
    free(buf);
    if (fclose(f) != 0 || w != len)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot write %s: %s", path, strerror(errno));
    return AG_OK;
}
