/* Uploads never read another file: every way a format can name one (glTF 2 buffers and images
 * by URI, a GLB's extra buffer, glTF 1 buffers, Collada images, FBX textures) is refused with
 * AG_ERR_EXTERNAL_REF naming the reference, inline data: URIs still import, and an OBJ's
 * mtllib is ignored: the mesh imports and the library is not opened.
 *
 * The references point at a real file holding a valid triangle buffer, so an importer that
 * read it would succeed; an inotify watch on its folder checks independently that nothing
 * there was opened. With external files allowed (the CLI) the same inputs import and the
 * watch sees the open, which shows the check can fail. */
#include <errno.h>
#include <limits.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <unistd.h>
#include <cmocka.h>

#include "io/import.h"

/* The triangle (0,0,0) (1,0,0) (0,2,0) as 9 floats and 3 uint16 indices, padded to 44 bytes. */
static const char TRI_BASE64[] = "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAAEAAAAAAAAABAAIAAAA=";
#define TRI_LEN 44

static void tri_bytes(uint8_t out[TRI_LEN])
{
    const float v[9] = {0, 0, 0, 1, 0, 0, 0, 2, 0};
    const uint16_t i[3] = {0, 1, 2};
    memset(out, 0, TRI_LEN);
    memcpy(out, v, sizeof v);
    memcpy(out + 36, i, sizeof i);
}

static char dir[PATH_MAX];     /* holds tri.bin, a valid buffer */
static char old_cwd[PATH_MAX];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/archgram-refs-XXXXXX");
    if (!mkdtemp(dir) || !getcwd(old_cwd, sizeof old_cwd))
        return -1;
    char p[PATH_MAX + 16];
    snprintf(p, sizeof p, "%s/tri.bin", dir);
    FILE *f = fopen(p, "wb");
    uint8_t b[TRI_LEN];
    tri_bytes(b);
    if (!f || fwrite(b, 1, TRI_LEN, f) != TRI_LEN)
        return -1;
    fclose(f);
    /* relative references resolve against the working directory: make it the folder */
    return chdir(dir);
}

static int teardown(void **state)
{
    (void)state;
    char p[PATH_MAX + 16];
    snprintf(p, sizeof p, "%s/tri.bin", dir);
    unlink(p);
    if (chdir(old_cwd) != 0)
        return -1;
    rmdir(dir);
    return 0;
}

/* ---- generators ------------------------------------------------------------------------- */

typedef struct {
    char *data;
    size_t len;
} blob;

static blob text(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static blob text(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    char *s = NULL;
    int n = vasprintf(&s, fmt, ap);
    va_end(ap);
    assert_true(n > 0);
    return (blob){s, (size_t)n};
}

static const char *data_uri(void)
{
    static char u[128];
    snprintf(u, sizeof u, "data:application/octet-stream;base64,%s", TRI_BASE64);
    return u;
}

/* glTF 2 JSON with the triangle in one buffer by URI, and, when image_uri is set, a material
 * whose base colour texture is that image. For a GLB (glb_extra): buffer 0 is the BIN chunk
 * and the indices come from a second buffer, by URI when one is given. */
static blob gltf2_json_buffers(const char *buffer_uri, const char *image_uri, int glb_extra)
{
    char buffer[512], image[512] = "", material[64] = "";
    if (glb_extra && buffer_uri)
        snprintf(buffer, sizeof buffer, "{\"byteLength\":%d},{\"byteLength\":%d,\"uri\":\"%s\"}",
                 TRI_LEN, TRI_LEN, buffer_uri);
    else if (buffer_uri)
        snprintf(buffer, sizeof buffer, "{\"byteLength\":%d,\"uri\":\"%s\"}", TRI_LEN, buffer_uri);
    else
        snprintf(buffer, sizeof buffer, "{\"byteLength\":%d}", TRI_LEN);
    if (image_uri) {
        snprintf(image, sizeof image,
                 ",\"images\":[{\"uri\":\"%s\"}],\"textures\":[{\"source\":0}],"
                 "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]",
                 image_uri);
        snprintf(material, sizeof material, ",\"material\":0");
    }
    return text("{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
                "\"nodes\":[{\"name\":\"W\",\"mesh\":0}],"
                "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1%s}]}],"
                "\"buffers\":[%s],"
                "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"
                "{\"buffer\":%d,\"byteOffset\":36,\"byteLength\":6}],"
                "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,"
                "\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,2,0]},"
                "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]%s}",
                material, buffer, glb_extra && buffer_uri ? 1 : 0, image);
}

static blob gltf2_json(const char *buffer_uri, const char *image_uri)
{
    return gltf2_json_buffers(buffer_uri, image_uri, 0);
}

static void put32(uint8_t *p, uint32_t v)
{
    memcpy(p, &v, 4);
}

/* A binary glTF around json (freed) with the triangle after it: version 2 as a JSON and a
 * BIN chunk, version 1 (KHR_binary_glTF) as content (format 0, JSON) and body. */
static blob binary_gltf(uint32_t version, blob json)
{
    size_t jl = (json.len + 3) & ~(size_t)3;
    size_t bin_header = version == 2 ? 8 : 0;
    size_t total = 20 + jl + bin_header + TRI_LEN;
    uint8_t *b = calloc(1, total);
    assert_non_null(b);
    memcpy(b, "glTF", 4);
    put32(b + 4, version);
    put32(b + 8, (uint32_t)total);
    put32(b + 12, (uint32_t)jl);
    if (version == 2)
        memcpy(b + 16, "JSON", 4);
    memset(b + 20, ' ', jl);
    memcpy(b + 20, json.data, json.len);
    if (version == 2) {
        put32(b + 20 + jl, TRI_LEN);
        memcpy(b + 24 + jl, "BIN\0", 4);
    }
    tri_bytes(b + 20 + jl + bin_header);
    free(json.data);
    return (blob){(char *)b, total};
}

/* GLB: the triangle in the BIN chunk; with buffer_uri the indices come from a second buffer
 * by that URI. */
static blob glb(const char *buffer_uri)
{
    return binary_gltf(2, gltf2_json_buffers(buffer_uri, NULL, 1));
}

/* glTF 1.0 (objects keyed by id) with its buffer by URI. */
static blob gltf1(const char *buffer_uri)
{
    return text("{\"asset\":{\"version\":\"1.0\"},"
                "\"buffers\":{\"b0\":{\"uri\":\"%s\",\"byteLength\":%d}},"
                "\"bufferViews\":{\"bv0\":{\"buffer\":\"b0\",\"byteOffset\":0,\"byteLength\":36,"
                "\"target\":34962},\"bv1\":{\"buffer\":\"b0\",\"byteOffset\":36,"
                "\"byteLength\":6,\"target\":34963}},"
                "\"accessors\":{\"a0\":{\"bufferView\":\"bv0\",\"byteOffset\":0,\"byteStride\":12,"
                "\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},\"a1\":{\"bufferView\":"
                "\"bv1\",\"byteOffset\":0,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}},"
                "\"meshes\":{\"m0\":{\"primitives\":[{\"attributes\":{\"POSITION\":\"a0\"},"
                "\"indices\":\"a1\",\"mode\":4}]}},\"nodes\":{\"n0\":{\"name\":\"N\","
                "\"meshes\":[\"m0\"]}},\"scenes\":{\"s0\":{\"nodes\":[\"n0\"]}},\"scene\":\"s0\"}",
                buffer_uri, TRI_LEN);
}

/* Binary glTF 1 (KHR_binary_glTF): the positions in the body, the indices from buffer `uri`. */
static blob gltf1_binary(const char *buffer_uri)
{
    blob j = text("{\"asset\":{\"version\":\"1.0\"},\"extensionsUsed\":[\"KHR_binary_glTF\"],"
                  "\"buffers\":{\"binary_glTF\":{\"uri\":\"data:,\",\"byteLength\":%d},"
                  "\"b0\":{\"uri\":\"%s\",\"byteLength\":%d}},"
                  "\"bufferViews\":{\"bv0\":{\"buffer\":\"binary_glTF\",\"byteOffset\":0,"
                  "\"byteLength\":36,\"target\":34962},"
                  "\"bv1\":{\"buffer\":\"b0\",\"byteOffset\":36,"
                  "\"byteLength\":6,\"target\":34963}},"
                  "\"accessors\":{\"a0\":{\"bufferView\":\"bv0\",\"byteOffset\":0,"
                  "\"byteStride\":12,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
                  "\"a1\":{\"bufferView\":\"bv1\",\"byteOffset\":0,\"componentType\":5123,"
                  "\"count\":3,\"type\":\"SCALAR\"}},"
                  "\"meshes\":{\"m0\":{\"primitives\":[{\"attributes\":{\"POSITION\":\"a0\"},"
                  "\"indices\":\"a1\",\"mode\":4}]}},\"nodes\":{\"n0\":{\"name\":\"N\","
                  "\"meshes\":[\"m0\"]}},\"scenes\":{\"s0\":{\"nodes\":[\"n0\"]}},"
                  "\"scene\":\"s0\"}",
                  TRI_LEN, buffer_uri, TRI_LEN);
    return binary_gltf(1, j);
}

/* Collada: one triangle whose material's diffuse texture is the image `ref`. */
static blob dae(const char *ref)
{
    return text(
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
        "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
        "<asset><unit name=\"meter\" meter=\"1\"/><up_axis>Z_UP</up_axis></asset>\n"
        "<library_images><image id=\"img0\"><init_from>%s</init_from></image></library_images>\n"
        "<library_effects><effect id=\"fx\"><profile_COMMON>\n"
        "<newparam sid=\"surf\"><surface type=\"2D\"><init_from>img0</init_from></surface>"
        "</newparam>\n"
        "<newparam sid=\"samp\"><sampler2D><source>surf</source></sampler2D></newparam>\n"
        "<technique sid=\"common\"><lambert><diffuse><texture texture=\"samp\" "
        "texcoord=\"UV0\"/></diffuse></lambert></technique>\n"
        "</profile_COMMON></effect></library_effects>\n"
        "<library_materials><material id=\"mat\" name=\"mat\"><instance_effect url=\"#fx\"/>"
        "</material></library_materials>\n"
        "<library_geometries><geometry id=\"g\" name=\"g\"><mesh>\n"
        "<source id=\"g-pos\"><float_array id=\"g-pos-array\" count=\"9\">0 0 0 1 0 0 0 2 0"
        "</float_array><technique_common><accessor source=\"#g-pos-array\" count=\"3\" "
        "stride=\"3\"><param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/>"
        "<param name=\"Z\" type=\"float\"/></accessor></technique_common></source>\n"
        "<vertices id=\"g-vtx\"><input semantic=\"POSITION\" source=\"#g-pos\"/></vertices>\n"
        "<triangles count=\"1\" material=\"m\"><input semantic=\"VERTEX\" source=\"#g-vtx\" "
        "offset=\"0\"/><p>0 1 2</p></triangles>\n"
        "</mesh></geometry></library_geometries>\n"
        "<library_visual_scenes><visual_scene id=\"s\" name=\"s\"><node id=\"Door\" "
        "name=\"Door\"><instance_geometry url=\"#g\"><bind_material><technique_common>"
        "<instance_material symbol=\"m\" target=\"#mat\"/></technique_common></bind_material>"
        "</instance_geometry></node></visual_scene></library_visual_scenes>\n"
        "<scene><instance_visual_scene url=\"#s\"/></scene>\n</COLLADA>\n",
        ref);
}

/* ASCII FBX 7.4: one triangle whose material's diffuse colour is a texture file `ref`. */
static blob fbx(const char *ref)
{
    return text("; FBX 7.4.0 project file\n"
                "FBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 7400\n}\n"
                "GlobalSettings:  {\n\tVersion: 1000\n\tProperties70:  {\n"
                "\t\tP: \"UnitScaleFactor\", \"double\", \"Number\", \"\",100\n\t}\n}\n"
                "Objects:  {\n"
                "\tGeometry: 1000, \"Geometry::tri\", \"Mesh\" {\n"
                "\t\tVertices: *9 {\n\t\t\ta: 0,0,0,1,0,0,0,2,0\n\t\t}\n"
                "\t\tPolygonVertexIndex: *3 {\n\t\t\ta: 0,1,-3\n\t\t}\n"
                "\t\tGeometryVersion: 124\n"
                "\t\tLayerElementMaterial: 0 {\n\t\t\tVersion: 101\n\t\t\tName: \"\"\n"
                "\t\t\tMappingInformationType: \"AllSame\"\n"
                "\t\t\tReferenceInformationType: \"IndexToDirect\"\n"
                "\t\t\tMaterials: *1 {\n\t\t\t\ta: 0\n\t\t\t}\n\t\t}\n"
                "\t\tLayer: 0 {\n\t\t\tVersion: 100\n\t\t\tLayerElement:  {\n"
                "\t\t\t\tType: \"LayerElementMaterial\"\n\t\t\t\tTypedIndex: 0\n\t\t\t}\n\t\t}\n"
                "\t}\n"
                "\tModel: 2000, \"Model::Wall\", \"Mesh\" {\n\t\tVersion: 232\n\t}\n"
                "\tMaterial: 3000, \"Material::mat\", \"\" {\n\t\tVersion: 102\n"
                "\t\tShadingModel: \"phong\"\n\t}\n"
                "\tTexture: 4000, \"Texture::tex\", \"\" {\n\t\tType: \"TextureVideoClip\"\n"
                "\t\tVersion: 202\n\t\tTextureName: \"Texture::tex\"\n"
                "\t\tFileName: \"%s\"\n\t\tRelativeFilename: \"%s\"\n\t}\n"
                "}\n"
                "Connections:  {\n\tC: \"OO\",2000,0\n\tC: \"OO\",1000,2000\n"
                "\tC: \"OO\",3000,2000\n\tC: \"OP\",4000,3000, \"DiffuseColor\"\n}\n",
                ref, ref);
}

static blob obj(const char *ref)
{
    return text("# exported\nmtllib %s\nv 0 0 0\nv 1 0 0\nv 0 2 0\nf 1 2 3\n", ref);
}

/* ---- the independent check: nothing in `dir` was opened --------------------------------- */

static int watch_open(int *wd)
{
    int fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    assert_true(fd >= 0);
    *wd = inotify_add_watch(fd, dir, IN_OPEN | IN_ACCESS);
    assert_true(*wd >= 0);
    return fd;
}

/* Number of open/access events queued since watch_open. */
static int opened(int fd)
{
    char buf[4096] __attribute__((aligned(__alignof__(struct inotify_event))));
    int n = 0;
    for (;;) {
        ssize_t k = read(fd, buf, sizeof buf);
        if (k <= 0)
            break;
        for (char *p = buf; p < buf + k;) {
            struct inotify_event *ev = (struct inotify_event *)p;
            n++;
            p += sizeof *ev + ev->len;
        }
    }
    close(fd);
    return n;
}

/* ---- cases ------------------------------------------------------------------------------ */

typedef enum {
    GLTF2_BUFFER,
    GLTF2_IMAGE,
    GLB_BUFFER,
    GLTF1_BUFFER,
    GLTF1_BINARY_BUFFER,
    DAE_IMAGE,
    FBX_TEXTURE,
    OBJ_MTLLIB
} kind;

static const struct {
    kind k;
    ag_format fmt;
    const char *name;
} kinds[] = {
    {GLTF2_BUFFER, AG_FORMAT_GLTF, "glTF 2 buffer"},
    {GLTF2_IMAGE, AG_FORMAT_GLTF, "glTF 2 image"},
    {GLB_BUFFER, AG_FORMAT_GLB, "GLB buffer"},
    {GLTF1_BUFFER, AG_FORMAT_GLTF, "glTF 1 buffer"},
    {GLTF1_BINARY_BUFFER, AG_FORMAT_GLB, "binary glTF 1 buffer"},
    {DAE_IMAGE, AG_FORMAT_DAE, "Collada image"},
    {FBX_TEXTURE, AG_FORMAT_FBX, "FBX texture"},
};

static blob make(kind k, const char *ref)
{
    switch (k) {
    case GLTF2_BUFFER: return gltf2_json(ref, NULL);
    case GLTF2_IMAGE: return gltf2_json(data_uri(), ref);
    case GLB_BUFFER: return glb(ref);
    case GLTF1_BUFFER: return gltf1(ref);
    case GLTF1_BINARY_BUFFER: return gltf1_binary(ref);
    case DAE_IMAGE: return dae(ref);
    case FBX_TEXTURE: return fbx(ref);
    case OBJ_MTLLIB: return obj(ref);
    }
    return (blob){0};
}

/* The reference as the message may show it: importers strip a file:// scheme. */
static int names(const char *text, const char *ref)
{
    char q[PATH_MAX + 8];
    snprintf(q, sizeof q, "\"%s\"", ref);
    if (strstr(text, q))
        return 1;
    if (strncmp(ref, "file://", 7) == 0) {
        snprintf(q, sizeof q, "\"%s\"", ref + 7);
        return strstr(text, q) != NULL;
    }
    return 0;
}

static void test_every_reference_is_refused(void **state)
{
    (void)state;
    char abs_ref[PATH_MAX + 16], file_ref[PATH_MAX + 32], up_ref[PATH_MAX + 16];
    snprintf(abs_ref, sizeof abs_ref, "%s/tri.bin", dir);
    snprintf(file_ref, sizeof file_ref, "file://%s/tri.bin", dir);
    /* ../<folder>/tri.bin from inside the folder */
    snprintf(up_ref, sizeof up_ref, "../%s/tri.bin", strrchr(dir, '/') + 1);
    const char *refs[] = {"/etc/passwd", "../../etc/passwd", abs_ref, "tri.bin",
                          "./tri.bin",   file_ref,           up_ref};
    int checked = 0;
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++)
        for (size_t r = 0; r < sizeof refs / sizeof refs[0]; r++) {
            blob b = make(kinds[k].k, refs[r]);
            int wd, fd = watch_open(&wd);
            ag_mesh *m = (ag_mesh *)1;
            ag_error e = {0};
            ag_status st = ag_import_buffer((const uint8_t *)b.data, b.len, kinds[k].fmt, NULL, &m,
                                            &e);
            int n = opened(fd);
            if (st != AG_ERR_EXTERNAL_REF || !names(e.text, refs[r]) ||
                !strstr(e.text, "not allowed in an upload"))
                fail_msg("%s \"%s\": status %d, %s", kinds[k].name, refs[r], st, e.text);
            assert_int_equal(e.code, AG_ERR_EXTERNAL_REF);
            assert_null(m);
            if (n != 0)
                fail_msg("%s \"%s\": %d opens in the referenced folder", kinds[k].name, refs[r],
                         n);
            /* the same input, sniffed rather than named, is refused too (a GLB is recognised by
             * its magic, Collada and glTF JSON by their content) */
            if (kinds[k].k != FBX_TEXTURE) {
                m = (ag_mesh *)1;
                assert_int_equal(ag_import_buffer((const uint8_t *)b.data, b.len,
                                                  AG_FORMAT_UNKNOWN, NULL, &m, &e),
                                 AG_ERR_EXTERNAL_REF);
                assert_null(m);
            }
            free(b.data);
            checked++;
        }
    assert_int_equal(checked, 49);
}

/* An OBJ's material library, wherever it points (the valid buffer in the watched folder
 * included), is ignored by an upload: the mesh imports and nothing there is opened. */
static void test_obj_mtllib_is_ignored(void **state)
{
    (void)state;
    char abs_ref[PATH_MAX + 16], file_ref[PATH_MAX + 32];
    snprintf(abs_ref, sizeof abs_ref, "%s/tri.bin", dir);
    snprintf(file_ref, sizeof file_ref, "file://%s/tri.bin", dir);
    const char *refs[] = {"/etc/passwd", "../../etc/passwd", abs_ref, "tri.bin", file_ref};
    for (size_t r = 0; r < sizeof refs / sizeof refs[0]; r++) {
        blob b = make(OBJ_MTLLIB, refs[r]);
        for (int sniffed = 0; sniffed < 2; sniffed++) {
            int wd, fd = watch_open(&wd);
            ag_mesh *m = NULL;
            ag_error e = {0};
            ag_status st = ag_import_buffer((const uint8_t *)b.data, b.len,
                                            sniffed ? AG_FORMAT_UNKNOWN : AG_FORMAT_OBJ, NULL,
                                            &m, &e);
            int n = opened(fd);
            if (st != AG_OK)
                fail_msg("mtllib \"%s\": status %d, %s", refs[r], st, e.text);
            assert_int_equal(m->ntris, 1);
            ag_mesh_free(m);
            if (n != 0)
                fail_msg("mtllib \"%s\": %d opens in the referenced folder", refs[r], n);
        }
        free(b.data);
    }
}

/* Allowed (the CLI, reading the user's own file): the references resolve and import. The
 * watch sees the buffer being read, so the check above is able to fail. */
static void test_allowed_references_resolve(void **state)
{
    (void)state;
    const kind buffers[] = {GLTF2_BUFFER, GLB_BUFFER, GLTF1_BUFFER, GLTF1_BINARY_BUFFER};
    for (size_t i = 0; i < sizeof buffers / sizeof buffers[0]; i++) {
        blob b = make(buffers[i], "tri.bin");
        char src[PATH_MAX + 16];
        int binary = buffers[i] == GLB_BUFFER || buffers[i] == GLTF1_BINARY_BUFFER;
        snprintf(src, sizeof src, "%s/model.%s", dir, binary ? "glb" : "gltf");
        ag_import_options o = {.allow_external_files = 1, .source_path = src};
        int wd, fd = watch_open(&wd);
        ag_mesh *m = NULL;
        ag_error e = {0};
        ag_status st = ag_import_buffer((const uint8_t *)b.data, b.len,
                                        binary ? AG_FORMAT_GLB : AG_FORMAT_GLTF,
                                        &o, &m, &e);
        int n = opened(fd);
        if (st != AG_OK)
            fail_msg("case %zu: %s", i, e.text);
        assert_int_equal(m->ntris, 1);
        ag_box bb = ag_mesh_bounds(m);
        /* the buffer's triangle, y up turned z up: height 2 along z */
        assert_true(bb.max[0] == 1 && bb.max[2] == 2);
        assert_true(n > 0);
        ag_mesh_free(m);
        free(b.data);
    }
    /* textures (and material libraries, ignored for uploads too) are accepted and not read */
    const kind named[] = {GLTF2_IMAGE, DAE_IMAGE, FBX_TEXTURE, OBJ_MTLLIB};
    const ag_format fmts[] = {AG_FORMAT_GLTF, AG_FORMAT_DAE, AG_FORMAT_FBX, AG_FORMAT_OBJ};
    for (size_t i = 0; i < sizeof named / sizeof named[0]; i++) {
        blob b = make(named[i], "/etc/passwd");
        ag_import_options o = {.allow_external_files = 1};
        ag_mesh *m = NULL;
        ag_error e = {0};
        if (ag_import_buffer((const uint8_t *)b.data, b.len, fmts[i], &o, &m, &e) != AG_OK)
            fail_msg("case %zu: %s", i, e.text);
        assert_int_equal(m->ntris, 1);
        ag_mesh_free(m);
        free(b.data);
    }
}

/* Inline data stays importable: a data: buffer, a data: image, a GLB's own BIN chunk. */
static void test_inline_data_imports(void **state)
{
    (void)state;
    blob cases[3] = {gltf2_json(data_uri(), NULL),
                     gltf2_json(data_uri(), "data:image/png;base64,iVBORw0KGgo="), glb(NULL)};
    const ag_format fmts[3] = {AG_FORMAT_GLTF, AG_FORMAT_GLTF, AG_FORMAT_GLB};
    for (int i = 0; i < 3; i++) {
        int wd, fd = watch_open(&wd);
        ag_mesh *m = NULL;
        ag_error e = {0};
        if (ag_import_buffer((const uint8_t *)cases[i].data, cases[i].len, fmts[i], NULL, &m, &e))
            fail_msg("case %d: %s", i, e.text);
        assert_int_equal(opened(fd), 0);
        assert_int_equal(m->ntris, 1);
        ag_box bb = ag_mesh_bounds(m);
        assert_true(bb.max[0] == 1 && bb.max[2] == 2);
        ag_mesh_free(m);
        free(cases[i].data);
    }
}

/* glTF URIs are checked before assimp runs; a JSON text that check cannot read (a NUL in a
 * string, which assimp's parser takes as the end of the name) reaches assimp, and its open of
 * "tri.bin" is refused by the file system assimp is given: nothing is read either way. */
static void test_sandbox_refuses_what_the_scan_misses(void **state)
{
    (void)state;
    blob cases[2] = {gltf2_json("tri.bin\\u0000.ignored", NULL),
                     glb("tri.bin\\u0000.ignored")};
    const ag_format fmts[2] = {AG_FORMAT_GLTF, AG_FORMAT_GLB};
    for (int i = 0; i < 2; i++) {
        int wd, fd = watch_open(&wd);
        ag_mesh *m = (ag_mesh *)1;
        ag_error e = {0};
        ag_status st = ag_import_buffer((const uint8_t *)cases[i].data, cases[i].len, fmts[i],
                                        NULL, &m, &e);
        int n = opened(fd);
        if (st != AG_ERR_EXTERNAL_REF || !strstr(e.text, "\"tri.bin\""))
            fail_msg("case %d: status %d, %s", i, st, e.text);
        assert_null(m);
        assert_int_equal(n, 0);
        free(cases[i].data);
    }
}

/* A name that is not text is shown with '?' so the message stays valid UTF-8 and bounded. */
static void test_reference_is_shown_safely(void **state)
{
    (void)state;
    char longref[400];
    memset(longref, 'a', sizeof longref - 1);
    longref[sizeof longref - 1] = '\0';
    const char *refs[] = {"caf\xc3\xa9\xff.bin", longref};
    const char *shown[] = {"\"caf???.bin\"", "aaa...\""};
    for (int i = 0; i < 2; i++) {
        blob b = gltf2_json(refs[i], NULL);
        ag_mesh *m = NULL;
        ag_error e = {0};
        assert_int_equal(ag_import_buffer((const uint8_t *)b.data, b.len, AG_FORMAT_GLTF, NULL, &m,
                                          &e),
                         AG_ERR_EXTERNAL_REF);
        if (!strstr(e.text, shown[i]))
            fail_msg("case %d: %s", i, e.text);
        for (const char *c = e.text; *c; c++)
            assert_true((unsigned char)*c >= 0x20 && (unsigned char)*c < 0x7f);
        free(b.data);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_reference_is_refused),
        cmocka_unit_test(test_obj_mtllib_is_ignored),
        cmocka_unit_test(test_allowed_references_resolve),
        cmocka_unit_test(test_inline_data_imports),
        cmocka_unit_test(test_sandbox_refuses_what_the_scan_misses),
        cmocka_unit_test(test_reference_is_shown_safely),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
