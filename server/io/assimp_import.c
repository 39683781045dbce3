#include "assimp_import.h"

#include "external_ref.h"
#include "ply.h"

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <threads.h>

/* --- the file system assimp sees ------------------------------------------------------------
 * assimp opens every file through an IO system; its in-memory import falls back to the real
 * file system for any other name (a glTF buffer's "uri", a texture), which would let an
 * upload read the server's files. This one serves the input under one name and, unless the
 * caller allows external files, opens nothing else: every other name is refused and
 * remembered so the import fails naming it. */

typedef struct {
    const uint8_t *data;
    size_t len;
    const char *main_name;
    int allow_external;
    char refused[200];  /* the first name refused, "" when none */
    size_t nrefused;
} sandbox;

typedef struct {
    const uint8_t *data; /* the input buffer, or NULL for a real file */
    size_t len, pos;
    FILE *f;
} sandbox_file;

static size_t sf_read(struct aiFile *af, char *buf, size_t size, size_t count)
{
    sandbox_file *sf = (sandbox_file *)af->UserData;
    if (sf->f)
        return fread(buf, size, count, sf->f);
    if (size == 0)
        return 0;
    size_t n = (sf->len - sf->pos) / size;
    if (n > count)
        n = count;
    memcpy(buf, sf->data + sf->pos, n * size);
    sf->pos += n * size;
    return n;
}

static size_t sf_write(struct aiFile *af, const char *buf, size_t size, size_t count)
{
    return 0; /* importers only read */
}

static size_t sf_tell(struct aiFile *af)
{
    sandbox_file *sf = (sandbox_file *)af->UserData;
    if (sf->f) {
        long t = ftell(sf->f);
        return t < 0 ? 0 : (size_t)t;
    }
    return sf->pos;
}

static size_t sf_size(struct aiFile *af)
{
    sandbox_file *sf = (sandbox_file *)af->UserData;
    return sf->len;
}

static enum aiReturn sf_seek(struct aiFile *af, size_t offset, enum aiOrigin origin)
{
    sandbox_file *sf = (sandbox_file *)af->UserData;
    if (sf->f) {
        int whence = origin == aiOrigin_SET ? SEEK_SET : origin == aiOrigin_CUR ? SEEK_CUR
                                                                                 : SEEK_END;
        return fseek(sf->f, (long)offset, whence) == 0 ? aiReturn_SUCCESS : aiReturn_FAILURE;
    }
    /* assimp passes a backward relative seek as a wrapped-around size_t */
    size_t base = origin == aiOrigin_SET ? 0 : origin == aiOrigin_CUR ? sf->pos : sf->len;
    size_t to = base + offset;
    if (to > sf->len)
        return aiReturn_FAILURE;
    sf->pos = to;
    return aiReturn_SUCCESS;
}

static void sf_flush(struct aiFile *af)
{
}

static struct aiFile *sandbox_open(struct aiFileIO *io, const char *name, const char *mode)
{
    sandbox *sb = (sandbox *)io->UserData;
    if (!name || !mode || mode[0] != 'r')
        return NULL;
    FILE *f = NULL;
    size_t len = sb->len;
    if (strcmp(name, sb->main_name) != 0) {
        if (!sb->allow_external) {
            if (sb->nrefused++ == 0)
                snprintf(sb->refused, sizeof sb->refused, "%s", name);
            return NULL;
        }
        if (!(f = fopen(name, "rb")))
            return NULL;
        long n = -1;
        if (fseek(f, 0, SEEK_END) == 0)
            n = ftell(f);
        if (n < 0 || fseek(f, 0, SEEK_SET) != 0) {
            fclose(f);
            return NULL;
        }
        len = (size_t)n;
    }
    struct aiFile *af = calloc(1, sizeof *af);
    sandbox_file *sf = calloc(1, sizeof *sf);
    if (!af || !sf) {
        free(af);
        free(sf);
        if (f)
            fclose(f);
        return NULL;
    }
    *sf = (sandbox_file){.data = f ? NULL : sb->data, .len = len, .f = f};
    *af = (struct aiFile){.ReadProc = sf_read,
                          .WriteProc = sf_write,
                          .TellProc = sf_tell,
                          .FileSizeProc = sf_size,
                          .SeekProc = sf_seek,
                          .FlushProc = sf_flush,
                          .UserData = (aiUserData)sf};
    return af;
}

static void sandbox_close(struct aiFileIO *io, struct aiFile *af)
{
    if (!af)
        return;
    sandbox_file *sf = (sandbox_file *)af->UserData;
    if (sf && sf->f)
        fclose(sf->f);
    free(sf);
    free(af);
}

/* A texture the scene names but does not embed ("*0" is embedded, a data: URI is inline) is a
 * file next to the input: assimp does not read images, so nothing was opened, but an upload
 * that depends on another file is refused all the same and the user is told which. */
static const char *external_texture(const struct aiScene *s, char *buf, size_t cap)
{
    for (unsigned i = 0; i < s->mNumMaterials; i++) {
        const struct aiMaterial *mat = s->mMaterials[i];
        for (int t = aiTextureType_NONE; t <= AI_TEXTURE_TYPE_MAX; t++) {
            unsigned n = aiGetMaterialTextureCount(mat, (enum aiTextureType)t);
            for (unsigned k = 0; k < n; k++) {
                struct aiString path;
                if (aiGetMaterialTexture(mat, (enum aiTextureType)t, k, &path, NULL, NULL, NULL,
                                         NULL, NULL, NULL) != aiReturn_SUCCESS)
                    continue;
                if (path.length == 0 || path.data[0] == '*' ||
                    strncmp(path.data, "data:", 5) == 0)
                    continue;
                int embedded = 0;
                for (unsigned e = 0; e < s->mNumTextures && !embedded; e++)
                    embedded = s->mTextures[e] && s->mTextures[e]->mFilename.length &&
                               strcmp(s->mTextures[e]->mFilename.data, path.data) == 0;
                if (embedded)
                    continue;
                snprintf(buf, cap, "%s", path.data);
                return buf;
            }
        }
    }
    return NULL;
}

/* The URIs a glTF names (buffers and images; shaders in glTF 1), checked before assimp sees
 * the file: refusing them here gives the member's name, and spares assimp's glTF importers a
 * failed open, after which they leak what they had read. The sandbox stays as the guarantee. */
static ag_status gltf_references(const uint8_t *data, size_t len, ag_format fmt, ag_error *err)
{
    const uint8_t *text = data;
    size_t tlen = len;
    if (fmt == AG_FORMAT_GLB) {
        /* the JSON follows a 20-byte header in both binary forms: glTF 2 (chunk length,
         * "JSON") and glTF 1 (content length, content format 0 = JSON) */
        uint32_t version, clen, ctype;
        if (len < 20)
            return AG_OK; /* not a GLB assimp can read: it says why */
        memcpy(&version, data + 4, 4);
        memcpy(&clen, data + 12, 4);
        memcpy(&ctype, data + 16, 4);
        int json2 = version == 2 && memcmp(data + 16, "JSON", 4) == 0;
        int json1 = version == 1 && ctype == 0;
        if (!(json2 || json1) || clen > len - 20)
            return AG_OK;
        text = data + 20;
        tlen = clen;
    }
    /* JSON that jansson refuses (a NUL in a string, nesting past its limit) goes on to assimp,
     * whose opens the sandbox still refuses */
    json_t *root = json_loadb((const char *)text, tlen, 0, NULL);
    if (!root)
        return AG_OK;
    static const char *const lists[] = {"buffers", "images", "shaders"};
    ag_status st = AG_OK;
    for (size_t l = 0; l < sizeof lists / sizeof lists[0] && !st; l++) {
        json_t *list = json_object_get(root, lists[l]);
        size_t n = json_is_array(list) ? json_array_size(list)
                   : json_is_object(list) ? json_object_size(list) : 0;
        void *it = json_is_object(list) ? json_object_iter(list) : NULL;
        for (size_t i = 0; i < n && !st; i++) {
            json_t *item =
                json_is_array(list) ? json_array_get(list, i) : json_object_iter_value(it);
            char where[96];
            if (json_is_array(list))
                snprintf(where, sizeof where, "%s: %s[%zu].uri", ag_format_name(fmt), lists[l], i);
            else
                snprintf(where, sizeof where, "%s: %s.%.40s.uri", ag_format_name(fmt), lists[l],
                         json_object_iter_key(it));
            if (it)
                it = json_object_iter_next(list, it);
            json_t *uri = json_object_get(item, "uri");
            if (!json_is_string(uri))
                continue;
            const char *u = json_string_value(uri);
            if (strncasecmp(u, "data:", 5) != 0)
                st = ag_external_ref_refuse(err, 0, where, u, json_string_length(uri));
        }
    }
    json_decref(root);
    return st;
}

/* assimp's C API keeps the last error in one global string: imports from several threads
 * take turns (they are a small part of an import job). */
static mtx_t import_lock;
static once_flag import_lock_once = ONCE_FLAG_INIT;
static void import_lock_init(void)
{
    mtx_init(&import_lock, mtx_plain);
}

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
        /* assimp 5.2 loops forever on a PLY header without an end_header line (one glued to
         * the line before it is enough), aborts on a face without corners and makes faces up
         * from a file cut short: archgram's own reader checks the file first */
        ag_status st = ag_ply_check_mesh(data, len, err);
        if (st)
            return st;
    }
    if (len > UINT32_MAX)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "the file is larger than 4 GiB");
    int allow = opt && opt->allow_external_files;
    if (!allow && (fmt == AG_FORMAT_GLTF || fmt == AG_FORMAT_GLB)) {
        ag_status st = gltf_references(data, len, fmt, err);
        if (st)
            return st;
    }
    char upload_name[16];
    snprintf(upload_name, sizeof upload_name, "upload.%s", hint);
    sandbox sb = {.data = data,
                  .len = len,
                  .main_name = allow && opt->source_path ? opt->source_path : upload_name,
                  .allow_external = allow};
    struct aiFileIO io = {.OpenProc = sandbox_open, .CloseProc = sandbox_close,
                          .UserData = (aiUserData)&sb};
    call_once(&import_lock_once, import_lock_init);
    mtx_lock(&import_lock);
    const struct aiScene *s = aiImportFileExWithProperties(
        sb.main_name,
        aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_ValidateDataStructure, &io,
        NULL);
    ag_status st = AG_OK;
    char texture[MAXLEN];
    const char *tex;
    if (sb.nrefused)
        st = ag_external_ref_refuse(err, 0, ag_format_name(fmt), sb.refused,
                                    strlen(sb.refused));
    else if (!s)
        st = ag_error_set(err, AG_ERR_PARSE, 0, "%s: %s", ag_format_name(fmt),
                          aiGetErrorString());
    else if (!allow && (tex = external_texture(s, texture, sizeof texture))) {
        char where[32];
        snprintf(where, sizeof where, "%s texture", ag_format_name(fmt));
        st = ag_external_ref_refuse(err, 0, where, tex, strlen(tex));
    }
    mtx_unlock(&import_lock);
    if (st) {
        if (s)
            aiReleaseImport(s);
        return st;
    }
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
