#include "points_glb.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bytes.h"
#include "glb.h"

#define GL_FLOAT 5126
#define GL_UNSIGNED_BYTE 5121
#define GL_ARRAY_BUFFER 34962
#define MODE_POINTS 0

static json_t *vec3(const double *v)
{
    return json_pack("[f,f,f]", v[0], v[1], v[2]);
}

/* A buffer view of len bytes at off and its accessor; returns the accessor's index. */
static size_t add_accessor(json_t *views, json_t *accessors, size_t off, size_t len, int type,
                           const char *shape, size_t count, int normalized)
{
    size_t view = json_array_size(views);
    json_array_append_new(views, json_pack("{s:i,s:I,s:I,s:i}", "buffer", 0, "byteOffset",
                                           (json_int_t)off, "byteLength", (json_int_t)len,
                                           "target", GL_ARRAY_BUFFER));
    json_t *a = json_pack("{s:I,s:i,s:I,s:s}", "bufferView", (json_int_t)view, "componentType",
                          type, "count", (json_int_t)count, "type", shape);
    if (a && normalized)
        json_object_set_new(a, "normalized", json_true());
    json_array_append_new(accessors, a);
    return json_array_size(accessors) - 1;
}

ag_status ag_points_glb_write(const ag_points_glb *in, uint8_t **out, size_t *len,
                              ag_error *err)
{
    *out = NULL;
    *len = 0;
    size_t n = in->n;
    for (size_t a = 0; a < in->nattributes; a++)
        if (!in->attributes[a].name || in->attributes[a].name[0] != '_')
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "a point attribute's name must start with \"_\"");
    size_t per = 12 + (in->rgba ? 4 : 0) + 4 * in->nattributes;
    if (n > (UINT32_MAX - (1u << 20)) / (per ? per : 1))
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%zu points do not fit in one GLB", n);
    size_t binlen = n * per;
    uint8_t *bin = malloc(binlen ? binlen : 1);
    json_t *root = json_object(), *views = json_array(), *accessors = json_array();
    ag_status st = AG_OK;
    if (!bin || !root || !views || !accessors) {
        json_decref(views);
        json_decref(accessors);
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while writing GLB");
        goto out;
    }
    json_object_set_new(root, "asset",
                        json_pack("{s:s,s:s}", "version", "2.0", "generator", "archgram"));
    json_object_set_new(root, "scene", json_integer(0));
    if (!n) {
        json_decref(views);
        json_decref(accessors);
        json_object_set_new(root, "scenes", json_pack("[{}]"));
        st = ag_glb_frame(root, NULL, 0, out, len, err);
        goto out;
    }
    /* centre of the bounds, in glTF axes */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], in->xyz[3 * i + k]);
            hi[k] = fmax(hi[k], in->xyz[3 * i + k]);
        }
    double mid[3], zero[3] = {0, 0, 0}, centre[3];
    for (int k = 0; k < 3; k++)
        mid[k] = 0.5 * (lo[k] + hi[k]);
    ag_glb_yup(mid, zero, centre);
    double smin[3] = {INFINITY, INFINITY, INFINITY}, smax[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; i++) {
        double v[3];
        ag_glb_yup(in->xyz + 3 * i, centre, v);
        for (int k = 0; k < 3; k++) {
            float f = (float)v[k];
            ag_bytes_put_f32le(bin + 12 * i + 4 * (size_t)k, f);
            smin[k] = fmin(smin[k], f); /* of the values stored, as the spec asks */
            smax[k] = fmax(smax[k], f);
        }
    }
    json_t *attributes = json_object();
    size_t off = 12 * n;
    size_t acc = add_accessor(views, accessors, 0, 12 * n, GL_FLOAT, "VEC3", n, 0);
    json_object_set_new(json_array_get(accessors, acc), "min", vec3(smin));
    json_object_set_new(json_array_get(accessors, acc), "max", vec3(smax));
    json_object_set_new(attributes, "POSITION", json_integer((json_int_t)acc));
    if (in->rgba) {
        memcpy(bin + off, in->rgba, 4 * n);
        acc = add_accessor(views, accessors, off, 4 * n, GL_UNSIGNED_BYTE, "VEC4", n, 1);
        json_object_set_new(attributes, "COLOR_0", json_integer((json_int_t)acc));
        off += 4 * n;
    }
    for (size_t a = 0; a < in->nattributes; a++) {
        for (size_t i = 0; i < n; i++)
            ag_bytes_put_f32le(bin + off + 4 * i, in->attributes[a].values[i]);
        acc = add_accessor(views, accessors, off, 4 * n, GL_FLOAT, "SCALAR", n, 0);
        json_object_set_new(attributes, in->attributes[a].name, json_integer((json_int_t)acc));
        off += 4 * n;
    }
    json_t *extras = in->extras ? json_deep_copy(in->extras) : json_object();
    json_object_set_new(root, "bufferViews", views);
    json_object_set_new(root, "accessors", accessors);
    json_object_set_new(root, "meshes",
                        json_pack("[{s:s,s:[{s:o,s:i}]}]", "name", "points", "primitives",
                                  "attributes", attributes, "mode", MODE_POINTS));
    json_object_set_new(root, "nodes",
                        json_pack("[{s:s,s:i,s:o,s:o}]", "name", "points", "mesh", 0,
                                  "translation", vec3(centre), "extras",
                                  extras ? extras : json_object()));
    json_object_set_new(root, "scenes", json_pack("[{s:[i]}]", "nodes", 0));
    json_object_set_new(root, "buffers", json_pack("[{s:I}]", "byteLength", (json_int_t)binlen));
    st = ag_glb_frame(root, bin, binlen, out, len, err);
out:
    free(bin);
    json_decref(root);
    return st;
}
