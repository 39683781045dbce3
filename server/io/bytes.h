/* Little- and big-endian loads and stores of fixed-size values at unaligned addresses, for
 * the binary point formats (PLY, LAS, LAZ). Independent of the host's byte order. */
#ifndef AG_BYTES_H
#define AG_BYTES_H

#include <stdint.h>
#include <string.h>

static inline uint16_t ag_bytes_u16le(const uint8_t *p)
{
    return (uint16_t)(p[0] | (unsigned)p[1] << 8);
}

static inline uint32_t ag_bytes_u32le(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static inline uint64_t ag_bytes_u64le(const uint8_t *p)
{
    return (uint64_t)ag_bytes_u32le(p) | (uint64_t)ag_bytes_u32le(p + 4) << 32;
}

static inline double ag_bytes_f64le(const uint8_t *p)
{
    uint64_t u = ag_bytes_u64le(p);
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

static inline float ag_bytes_f32le(const uint8_t *p)
{
    uint32_t u = ag_bytes_u32le(p);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static inline void ag_bytes_put_u16le(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

static inline void ag_bytes_put_u32le(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static inline void ag_bytes_put_u64le(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static inline void ag_bytes_put_f64le(uint8_t *p, double d)
{
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    ag_bytes_put_u64le(p, u);
}

static inline void ag_bytes_put_f32le(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    ag_bytes_put_u32le(p, u);
}

/* Copies a value of `size` bytes stored in the given byte order (big = 1) into host order. */
static inline void ag_bytes_load(void *dst, const uint8_t *src, size_t size, int big)
{
    static const union {
        uint16_t u;
        uint8_t b[2];
    } probe = {1};
    int host_big = probe.b[0] == 0;
    if (big == host_big) {
        memcpy(dst, src, size);
    } else {
        uint8_t *d = dst;
        for (size_t i = 0; i < size; i++)
            d[i] = src[size - 1 - i];
    }
}

/* The reverse of ag_bytes_load: a host-order value stored in the given byte order. */
static inline void ag_bytes_store(uint8_t *dst, const void *src, size_t size, int big)
{
    ag_bytes_load(dst, src, size, big);
}

#endif
