/* Reading back a binary glTF in unit tests: the container is checked (magic, version, length,
 * chunk types and alignment) and split into its parsed JSON and its BIN chunk. Include after
 * <cmocka.h> and <jansson.h>. */
#ifndef AG_TEST_GLB_FIXTURE_H
#define AG_TEST_GLB_FIXTURE_H

#include <stdint.h>
#include <string.h>

static inline uint32_t u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static inline float f32(const uint8_t *p)
{
    uint32_t u = u32(p);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

typedef struct {
    json_t *root;
    const uint8_t *bin; /* NULL without a BIN chunk */
    size_t binlen;
} glb_view;

static inline glb_view check_container(const uint8_t *buf, size_t len)
{
    glb_view v = {0};
    assert_true(len >= 20);
    assert_int_equal(u32(buf), 0x46546C67);
    assert_int_equal(u32(buf + 4), 2);
    assert_int_equal(u32(buf + 8), len);
    assert_int_equal(len % 4, 0);
    uint32_t jlen = u32(buf + 12);
    assert_int_equal(u32(buf + 16), 0x4E4F534A);
    assert_int_equal(jlen % 4, 0);
    assert_true(20 + (size_t)jlen <= len);
    json_error_t je;
    v.root = json_loadb((const char *)buf + 20, jlen, 0, &je);
    if (!v.root)
        fail_msg("the JSON chunk does not parse: %s", je.text);
    size_t off = 20 + jlen;
    if (off < len) {
        uint32_t blen = u32(buf + off);
        assert_int_equal(u32(buf + off + 4), 0x004E4942);
        assert_int_equal(blen % 4, 0);
        assert_int_equal(off + 8 + blen, len);
        v.bin = buf + off + 8;
        v.binlen = blen;
    }
    return v;
}

#endif
