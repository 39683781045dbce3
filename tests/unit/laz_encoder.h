/* A LASzip encoder for tests only: the arithmetic coder, the integer compressor and the
 * item encoders for POINT10 v1, GPSTIME11 v1, RGB12 v1 and v2, BYTE v1 and v2, written from
 * the format's description as the mirror image of a decoder. It lets the tests make LAZ
 * files with the item versions and chunk layouts that no shared data file has, so that the
 * decoder in server/io/laz.c is checked on them (the real AHN3 file checks POINT10 v2 and
 * GPSTIME11 v2 against an independently decoded PLY). */
#ifndef AG_TEST_LAZ_ENCODER_H
#define AG_TEST_LAZ_ENCODER_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define E_MIN_LENGTH 0x01000000u
#define E_MAX_LENGTH 0xFFFFFFFFu

typedef struct {
    uint8_t *buf;
    size_t n, cap;
    uint32_t base, length;
} enc;

static void enc_byte(enc *e, uint8_t b)
{
    if (e->n == e->cap) {
        e->cap = e->cap ? 2 * e->cap : 4096;
        e->buf = realloc(e->buf, e->cap);
    }
    e->buf[e->n++] = b;
}

static void enc_init(enc *e)
{
    e->base = 0;
    e->length = E_MAX_LENGTH;
}

static void enc_carry(enc *e)
{
    size_t p = e->n;
    while (p > 0 && e->buf[p - 1] == 0xFF)
        e->buf[--p] = 0;
    if (p > 0)
        e->buf[p - 1]++;
}

static void enc_renorm(enc *e)
{
    do {
        enc_byte(e, (uint8_t)(e->base >> 24));
        e->base <<= 8;
    } while ((e->length <<= 8) < E_MIN_LENGTH);
}

static void enc_done(enc *e)
{
    uint32_t init = e->base;
    if (e->length > 2 * E_MIN_LENGTH) {
        e->base += E_MIN_LENGTH;
        e->length = E_MIN_LENGTH >> 1;
    } else {
        e->base += E_MIN_LENGTH >> 1;
        e->length = E_MIN_LENGTH >> 9;
    }
    if (init > e->base)
        enc_carry(e);
    enc_renorm(e);
    for (int i = 0; i < 4; i++) /* slack for a decoder that reads ahead */
        enc_byte(e, 0);
}

typedef struct {
    uint32_t *dist, *count;
    uint32_t symbols, last, total, cycle, until;
} emodel;

static void emodel_update(emodel *m)
{
    if ((m->total += m->cycle) > (1u << 15)) {
        m->total = 0;
        for (uint32_t i = 0; i < m->symbols; i++)
            m->total += (m->count[i] = (m->count[i] + 1) >> 1);
    }
    uint32_t sum = 0, scale = 0x80000000u / m->total;
    for (uint32_t k = 0; k < m->symbols; k++) {
        m->dist[k] = (scale * sum) >> (31 - 15);
        sum += m->count[k];
    }
    m->cycle = (5 * m->cycle) >> 2;
    uint32_t max = (m->symbols + 6) << 3;
    if (m->cycle > max)
        m->cycle = max;
    m->until = m->cycle;
}

static void emodel_init(emodel *m, uint32_t symbols)
{
    if (!m->dist) {
        m->dist = calloc(2 * symbols, sizeof *m->dist);
        m->count = m->dist + symbols;
    }
    m->symbols = symbols;
    m->last = symbols - 1;
    m->total = 0;
    m->cycle = symbols;
    for (uint32_t k = 0; k < symbols; k++)
        m->count[k] = 1;
    emodel_update(m);
    m->until = m->cycle = (symbols + 6) >> 1;
}

static void emodel_free(emodel *m)
{
    free(m->dist);
    m->dist = m->count = NULL;
}

static void enc_symbol(enc *e, emodel *m, uint32_t sym)
{
    uint32_t x, init = e->base;
    if (sym == m->last) {
        x = m->dist[sym] * (e->length >> 15);
        e->base += x;
        e->length -= x;
    } else {
        x = m->dist[sym] * (e->length >>= 15);
        e->base += x;
        e->length = m->dist[sym + 1] * e->length - x;
    }
    if (init > e->base)
        enc_carry(e);
    if (e->length < E_MIN_LENGTH)
        enc_renorm(e);
    ++m->count[sym];
    if (--m->until == 0)
        emodel_update(m);
}

typedef struct {
    uint32_t b0, bc, p0, until, cycle;
} ebit;

static void ebit_init(ebit *m)
{
    m->b0 = 1;
    m->bc = 2;
    m->p0 = 1u << 12;
    m->cycle = m->until = 4;
}

static void enc_bit(enc *e, ebit *m, uint32_t bit)
{
    uint32_t x = m->p0 * (e->length >> 13);
    if (!bit) {
        e->length = x;
        ++m->b0;
    } else {
        uint32_t init = e->base;
        e->base += x;
        e->length -= x;
        if (init > e->base)
            enc_carry(e);
    }
    if (e->length < E_MIN_LENGTH)
        enc_renorm(e);
    if (--m->until == 0) {
        if ((m->bc += m->cycle) > (1u << 13)) {
            m->bc = (m->bc + 1) >> 1;
            m->b0 = (m->b0 + 1) >> 1;
            if (m->b0 == m->bc)
                ++m->bc;
        }
        m->p0 = (m->b0 * (0x80000000u / m->bc)) >> (31 - 13);
        m->cycle = (5 * m->cycle) >> 2;
        if (m->cycle > 64)
            m->cycle = 64;
        m->until = m->cycle;
    }
}

static void enc_bits(enc *e, uint32_t bits, uint32_t sym)
{
    if (bits > 19) {
        enc_bits(e, 16, sym & 0xFFFF);
        sym >>= 16;
        bits -= 16;
    }
    uint32_t init = e->base;
    e->base += sym * (e->length >>= bits);
    if (init > e->base)
        enc_carry(e);
    if (e->length < E_MIN_LENGTH)
        enc_renorm(e);
}

static void enc_int(enc *e, uint32_t v)
{
    enc_bits(e, 16, v & 0xFFFF);
    enc_bits(e, 16, v >> 16);
}

static void enc_int64(enc *e, uint64_t v)
{
    enc_int(e, (uint32_t)v);
    enc_int(e, (uint32_t)(v >> 32));
}

typedef struct {
    uint32_t corr_bits, corr_range, contexts, k;
    int32_t corr_min, corr_max;
    emodel *bits;
    ebit corr0;
    emodel *corr;
} eic;

static void eic_init(eic *c, uint32_t bits, uint32_t contexts)
{
    if (!c->bits) {
        c->contexts = contexts;
        if (bits && bits < 32) {
            c->corr_bits = bits;
            c->corr_range = 1u << bits;
            c->corr_min = -(int32_t)(c->corr_range / 2);
            c->corr_max = c->corr_min + (int32_t)c->corr_range - 1;
        } else {
            c->corr_bits = 32;
            c->corr_range = 0;
            c->corr_min = INT32_MIN;
            c->corr_max = INT32_MAX;
        }
        c->bits = calloc(contexts, sizeof *c->bits);
        c->corr = calloc(c->corr_bits, sizeof *c->corr);
    }
    for (uint32_t i = 0; i < c->contexts; i++)
        emodel_init(&c->bits[i], c->corr_bits + 1);
    ebit_init(&c->corr0);
    for (uint32_t i = 1; i <= c->corr_bits; i++)
        emodel_init(&c->corr[i - 1], i <= 8 ? 1u << i : 1u << 8);
}

static void eic_compress(eic *c, enc *e, int32_t pred, int32_t real, uint32_t ctx)
{
    int64_t corr = (int64_t)real - pred;
    if (c->corr_range) {
        if (corr < c->corr_min)
            corr += c->corr_range;
        else if (corr > c->corr_max)
            corr -= c->corr_range;
    } else {
        corr = (int32_t)(uint32_t)corr; /* 32 bits wrap */
    }
    int32_t cv = (int32_t)corr;
    uint32_t mag = cv <= 0 ? (uint32_t)(-(int64_t)cv) : (uint32_t)cv - 1, k = 0;
    while (mag) {
        mag >>= 1;
        k++;
    }
    c->k = k;
    enc_symbol(e, &c->bits[ctx], k);
    if (k) {
        uint32_t u = cv < 0 ? (uint32_t)(cv + (int32_t)((1u << k) - 1)) : (uint32_t)cv - 1;
        if (k <= 8) {
            enc_symbol(e, &c->corr[k - 1], u);
        } else {
            uint32_t k1 = k - 8;
            enc_symbol(e, &c->corr[k - 1], u >> k1);
            enc_bits(e, k1, u & ((1u << k1) - 1));
        }
    } else {
        enc_bit(e, &c->corr0, (uint32_t)cv);
    }
}

static void eic_free(eic *c)
{
    for (uint32_t i = 0; c->bits && i < c->contexts; i++)
        emodel_free(&c->bits[i]);
    for (uint32_t i = 0; c->corr && i < c->corr_bits; i++)
        emodel_free(&c->corr[i]);
    free(c->bits);
    free(c->corr);
    c->bits = c->corr = NULL;
}

#endif
