#include "assimp_import.h"

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct {
    ag_mesh *m;
    const struct aiScene *s;
    double scale;
    int yup;
    size_t nodes;
    ag_status st;
    ag_error *err;
} walk;

static void mul(const struct aiMatrix4x4 *a, const struct aiMatrix4x4 *b, struct aiMatrix4x4 *o)
{
    const ai_real *x = &a->a1, *y = &b->a1;
    ai_real r[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r[4 * i + j] = x[4 * i] * y[j] + x[4 * i + 1] * y[4 + j] + x[4 * i + 2] * y[8 + j] +
                           x[4 * i + 3] * y[12 + j];
    memcpy(&o->a1, r, sizeof r);
}

static void visit(walk *w, const struct aiNode *n, const struct aiMatrix4x4 *parent, int depth)
{
    if (w->st || !n)
        return;
    if (depth > 256) {
        w->st = ag_error_set(w->err, AG_ERR_PARSE, 0, "the scene graph is nested too deeply");
        return;
    }
    struct aiMatrix4x4 T;
    mul(parent, &n->mTransformation, &T);
    size_t index = w->nodes++;
    if (n->mNumMeshes) {
        char name[256];
        if (n->mName.length > 0)
            snprintf(name, sizeof name, "%.*s", (int)n->mName.length, n->mName.data);
        else
            snprintf(name, sizeof name, "node_%zu", index);
        size_t g, c;
        if ((w->st = ag_mesh_add_group(w->m, name, &g)) ||
            (w->st = ag_mesh_add_component(w->m, (int32_t)g, &c)))
            return;
        const ai_real *M = &T.a1;
        for (unsigned k = 0; k < n->mNumMeshes && !w->st; k++) {
            if (n->mMeshes[k] >= w->s->mNumMeshes)
                continue;
            const struct aiMesh *me = w->s->mMeshes[n->mMeshes[k]];
            if (w->m->nverts + me->mNumVertices >= UINT32_MAX) {
                w->st = ag_error_set(w->err, AG_ERR_TOO_LARGE, 0, "too many vertices");
                return;
            }
            uint32_t base = (uint32_t)w->m->nverts;
            for (unsigned v = 0; v < me->mNumVertices && !w->st; v++) {
                const struct aiVector3D *p = &me->mVertices[v];
                double q[3];
                for (int i = 0; i < 3; i++)
                    q[i] = (M[4 * i] * p->x + M[4 * i + 1] * p->y + M[4 * i + 2] * p->z +
                            M[4 * i + 3]) *
                           w->scale;
                if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) {
                    w->st = ag_error_set(w->err, AG_ERR_PARSE, 0,
                                         "node '%s' has a non-finite vertex", name);
                    return;
                }
                w->st = w->yup ? ag_mesh_add_vertex(w->m, q[0], -q[2], q[1])
                               : ag_mesh_add_vertex(w->m, q[0], q[1], q[2]);
            }
            for (unsigned f = 0; f < me->mNumFaces && !w->st; f++) {
                const struct aiFace *fc = &me->mFaces[f];
                if (fc->mNumIndices != 3)
                    continue;
                if (fc->mIndices[0] >= me->mNumVertices || fc->mIndices[1] >= me->mNumVertices ||
                    fc->mIndices[2] >= me->mNumVertices) {
                    w->st = ag_error_set(w->err, AG_ERR_PARSE, (long)f + 1,
                                         "face %u of node '%s' has a bad index", f + 1, name);
                    return;
                }
                w->st = ag_mesh_add_triangle(w->m, base + fc->mIndices[0], base + fc->mIndices[1],
                                             base + fc->mIndices[2], (uint32_t)c);
            }
        }
    }
    for (unsigned i = 0; i < n->mNumChildren && !w->st; i++)
        visit(w, n->mChildren[i], &T, depth + 1);
}

static double unit_scale(const struct aiScene *s, ag_format fmt)
{
    if (fmt != AG_FORMAT_FBX || !s->mMetaData)
        return 1.0;
    const struct aiMetadata *md = s->mMetaData;
    for (unsigned i = 0; i < md->mNumProperties; i++) {
        if (strcmp(md->mKeys[i].data, "UnitScaleFactor"))
            continue;
        const struct aiMetadataEntry *e = &md->mValues[i];
        double f = 0;
        if (e->mType == AI_DOUBLE)
            f = *(const double *)e->mData;
        else if (e->mType == AI_FLOAT)
            f = *(const float *)e->mData;
        if (f > 0 && isfinite(f))
            return f / 100.0; /* FBX units are centimetres times the factor */
    }
    return 0.01;
}

ag_status ag_assimp_import_buffer(const uint8_t *data, size_t len, ag_format fmt,
                                  const ag_import_options *opt, ag_mesh **out,
                                  ag_assimp_info *info, ag_error *err)
{
    *out = NULL;
    const char *hint;
    switch (fmt) {
    case AG_FORMAT_GLTF: hint = "gltf"; break;
    case AG_FORMAT_GLB: hint = "glb"; break;
    case AG_FORMAT_DAE: hint = "dae"; break;
    case AG_FORMAT_PLY: hint = "ply"; break;
    case AG_FORMAT_STL: hint = "stl"; break;
    case AG_FORMAT_FBX: hint = "fbx"; break;
    default:
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0, "not a format read through assimp");
    }
    if (!data || len == 0)
        return ag_error_set(err, AG_ERR_EMPTY, 0, "empty file");
    if (fmt == AG_FORMAT_PLY) {
        /* assimp 5.2 loops forever on a PLY header without end_header */
        size_t n = len < 65536 ? len : 65536;
        if (len < 4 || memcmp(data, "ply", 3) || !memmem(data, n, "end_header", 10))
            return ag_error_set(err, AG_ERR_PARSE, 1,
                                "ply: the header is missing or has no end_header");
    }
    if (len > UINT32_MAX)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "the file is larger than 4 GiB");
    const struct aiScene *s = aiImportFileFromMemory(
        (const char *)data, (unsigned)len,
        aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_ValidateDataStructure, hint);
    if (!s)
        return ag_error_set(err, AG_ERR_PARSE, 0, "%s: %s", ag_format_name(fmt),
                            aiGetErrorString());
    ag_up_axis up = opt ? opt->up : AG_UP_DEFAULT;
    int yup = up == AG_UP_Y ||
              (up == AG_UP_DEFAULT && fmt != AG_FORMAT_PLY && fmt != AG_FORMAT_STL);
    walk w = {.m = ag_mesh_create(), .s = s, .scale = unit_scale(s, fmt), .yup = yup, .err = err};
    if (!w.m) {
        aiReleaseImport(s);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    struct aiMatrix4x4 I = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    visit(&w, s->mRootNode, &I, 0);
    aiReleaseImport(s);
    if (!w.st && w.m->ntris == 0)
        w.st = ag_error_set(err, AG_ERR_EMPTY, 0, "the %s file holds no triangle",
                            ag_format_name(fmt));
    if (w.st) {
        if (w.st == AG_ERR_NOMEM)
            ag_error_set(err, w.st, 0, "out of memory");
        ag_mesh_free(w.m);
        return w.st;
    }
    if (info) {
        info->scale = w.scale;
        info->y_up = yup;
    }
    *out = w.m;
    return AG_OK;
}
