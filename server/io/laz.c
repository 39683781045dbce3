/* LASzip decoding for point formats 0-3; see laz.h. Written from the public description of
 * the format (the LASzip paper and specification); constants below are the format's. */
#include "laz.h"

#include <stdlib.h>
#include <string.h>

#include "bytes.h"

/* ---- arithmetic decoder ---------------------------------------------------------------- */

#define AC_MIN_LENGTH 0x01000000u
#define AC_MAX_LENGTH 0xFFFFFFFFu
#define BM_LENGTH_SHIFT 13
#define BM_MAX_COUNT (1u << BM_LENGTH_SHIFT)
#define DM_LENGTH_SHIFT 15
#define DM_MAX_COUNT (1u << DM_LENGTH_SHIFT)

typedef struct {
    const uint8_t *p, *end;
    uint32_t value, length;
    int overrun; /* read past the end of the data */
    int corrupt; /* a state no valid stream reaches */
} ac_dec;

static inline uint32_t ac_byte(ac_dec *d)
{
    if (d->p < d->end)
        return *d->p++;
    d->overrun = 1;
    return 0;
}

static void ac_init(ac_dec *d, const uint8_t *p, const uint8_t *end)
{
    d->p = p;
    d->end = end;
    d->overrun = d->corrupt = 0;
    d->length = AC_MAX_LENGTH;
    d->value = ac_byte(d) << 24;
    d->value |= ac_byte(d) << 16;
    d->value |= ac_byte(d) << 8;
    d->value |= ac_byte(d);
}

static inline void ac_renorm(ac_dec *d)
{
    do {
        d->value = (d->value << 8) | ac_byte(d);
    } while ((d->length <<= 8) < AC_MIN_LENGTH);
}

/* An adaptive model over `symbols` symbols with a decoding table for large alphabets. */
typedef struct {
    uint32_t *distribution, *symbol_count, *decoder_table;
    uint32_t symbols, last_symbol, table_size, table_shift;
    uint32_t total_count, update_cycle, symbols_until_update;
} ac_model;

typedef struct {
    uint32_t bit_0_count, bit_count, bit_0_prob, bits_until_update, update_cycle;
} ac_bit_model;

static void model_update(ac_model *m)
{
    if ((m->total_count += m->update_cycle) > DM_MAX_COUNT) {
        m->total_count = 0;
        for (uint32_t n = 0; n < m->symbols; n++)
            m->total_count += (m->symbol_count[n] = (m->symbol_count[n] + 1) >> 1);
    }
    uint32_t sum = 0, s = 0, scale = 0x80000000u / m->total_count;
    if (!m->table_size) {
        for (uint32_t k = 0; k < m->symbols; k++) {
            m->distribution[k] = (scale * sum) >> (31 - DM_LENGTH_SHIFT);
            sum += m->symbol_count[k];
        }
    } else {
        for (uint32_t k = 0; k < m->symbols; k++) {
            m->distribution[k] = (scale * sum) >> (31 - DM_LENGTH_SHIFT);
            sum += m->symbol_count[k];
            uint32_t w = m->distribution[k] >> m->table_shift;
            while (s < w)
                m->decoder_table[++s] = k - 1;
        }
        m->decoder_table[0] = 0;
        while (s <= m->table_size)
            m->decoder_table[++s] = m->symbols - 1;
    }
    m->update_cycle = (5 * m->update_cycle) >> 2;
    uint32_t max_cycle = (m->symbols + 6) << 3;
    if (m->update_cycle > max_cycle)
        m->update_cycle = max_cycle;
    m->symbols_until_update = m->update_cycle;
}

static int model_create(ac_model *m, uint32_t symbols)
{
    memset(m, 0, sizeof *m);
    m->symbols = symbols;
    m->last_symbol = symbols - 1;
    size_t words = 2 * (size_t)symbols;
    if (symbols > 16) {
        uint32_t table_bits = 3;
        while (symbols > (1u << (table_bits + 2)))
            table_bits++;
        m->table_size = 1u << table_bits;
        m->table_shift = DM_LENGTH_SHIFT - table_bits;
        words += m->table_size + 2;
    }
    m->distribution = malloc(words * sizeof *m->distribution);
    if (!m->distribution)
        return -1;
    m->symbol_count = m->distribution + symbols;
    m->decoder_table = m->table_size ? m->distribution + 2 * symbols : NULL;
    return 0;
}

static void model_init(ac_model *m)
{
    m->total_count = 0;
    m->update_cycle = m->symbols;
    for (uint32_t k = 0; k < m->symbols; k++)
        m->symbol_count[k] = 1;
    model_update(m);
    m->symbols_until_update = m->update_cycle = (m->symbols + 6) >> 1;
}

static void model_free(ac_model *m)
{
    free(m->distribution);
    m->distribution = NULL;
}

static void bit_model_init(ac_bit_model *m)
{
    m->bit_0_count = 1;
    m->bit_count = 2;
    m->bit_0_prob = 1u << (BM_LENGTH_SHIFT - 1);
    m->update_cycle = m->bits_until_update = 4;
}

static void bit_model_update(ac_bit_model *m)
{
    if ((m->bit_count += m->update_cycle) > BM_MAX_COUNT) {
        m->bit_count = (m->bit_count + 1) >> 1;
        m->bit_0_count = (m->bit_0_count + 1) >> 1;
        if (m->bit_0_count == m->bit_count)
            ++m->bit_count;
    }
    uint32_t scale = 0x80000000u / m->bit_count;
    m->bit_0_prob = (m->bit_0_count * scale) >> (31 - BM_LENGTH_SHIFT);
    m->update_cycle = (5 * m->update_cycle) >> 2;
    if (m->update_cycle > 64)
        m->update_cycle = 64;
    m->bits_until_update = m->update_cycle;
}

static uint32_t decode_bit(ac_dec *d, ac_bit_model *m)
{
    uint32_t x = m->bit_0_prob * (d->length >> BM_LENGTH_SHIFT);
    uint32_t sym = d->value >= x;
    if (!sym) {
        d->length = x;
        ++m->bit_0_count;
    } else {
        d->value -= x;
        d->length -= x;
    }
    if (d->length < AC_MIN_LENGTH)
        ac_renorm(d);
    if (--m->bits_until_update == 0)
        bit_model_update(m);
    return sym;
}

static uint32_t decode_symbol(ac_dec *d, ac_model *m)
{
    uint32_t n, sym, x, y = d->length;
    if (d->value >= d->length) {
        /* a valid stream keeps value inside the interval; stop before tables overflow */
        d->corrupt = 1;
        d->value = 0;
    }
    if (m->decoder_table) {
        uint32_t dv = d->value / (d->length >>= DM_LENGTH_SHIFT);
        uint32_t t = dv >> m->table_shift;
        if (t > m->table_size)
            t = m->table_size;
        sym = m->decoder_table[t];
        n = m->decoder_table[t + 1] + 1;
        while (n > sym + 1) {
            uint32_t k = (sym + n) >> 1;
            if (m->distribution[k] > dv)
                n = k;
            else
                sym = k;
        }
        x = m->distribution[sym] * d->length;
        if (sym != m->last_symbol)
            y = m->distribution[sym + 1] * d->length;
    } else {
        x = sym = 0;
        d->length >>= DM_LENGTH_SHIFT;
        uint32_t k = (n = m->symbols) >> 1;
        do {
            uint32_t z = d->length * m->distribution[k];
            if (z > d->value) {
                n = k;
                y = z;
            } else {
                sym = k;
                x = z;
            }
        } while ((k = (sym + n) >> 1) != sym);
    }
    d->value -= x;
    d->length = y - x;
    if (d->length < AC_MIN_LENGTH)
        ac_renorm(d);
    ++m->symbol_count[sym];
    if (--m->symbols_until_update == 0)
        model_update(m);
    return sym;
}

static uint32_t read_short(ac_dec *d)
{
    uint32_t sym = d->value / (d->length >>= 16);
    d->value -= d->length * sym;
    if (d->length < AC_MIN_LENGTH)
        ac_renorm(d);
    return sym & 0xFFFF;
}

static uint32_t read_bits(ac_dec *d, uint32_t bits)
{
    if (bits > 19) {
        uint32_t lower = read_short(d);
        uint32_t upper = read_bits(d, bits - 16);
        return upper << 16 | lower;
    }
    uint32_t sym = d->value / (d->length >>= bits);
    d->value -= d->length * sym;
    if (d->length < AC_MIN_LENGTH)
        ac_renorm(d);
    return sym;
}

static uint32_t read_int(ac_dec *d)
{
    uint32_t lower = read_short(d);
    uint32_t upper = read_short(d);
    return upper << 16 | lower;
}

static uint64_t read_int64(ac_dec *d)
{
    uint64_t lower = read_int(d);
    uint64_t upper = read_int(d);
    return upper << 32 | lower;
}

/* ---- integer compressor ---------------------------------------------------------------- */

typedef struct {
    uint32_t contexts, bits_high, corr_bits, corr_range;
    int32_t corr_min;
    uint32_t k;
    ac_model *m_bits;     /* one per context, corr_bits + 1 symbols */
    ac_bit_model corr0;
    ac_model *corr;       /* corr[i - 1] for i = 1..corr_bits */
} ic_dec;

static int ic_create(ic_dec *ic, uint32_t bits, uint32_t contexts)
{
    memset(ic, 0, sizeof *ic);
    ic->contexts = contexts;
    ic->bits_high = 8;
    if (bits && bits < 32) {
        ic->corr_bits = bits;
        ic->corr_range = 1u << bits;
        ic->corr_min = -(int32_t)(ic->corr_range / 2);
    } else {
        ic->corr_bits = 32;
        ic->corr_range = 0;
        ic->corr_min = INT32_MIN;
    }
    ic->m_bits = calloc(contexts, sizeof *ic->m_bits);
    ic->corr = calloc(ic->corr_bits, sizeof *ic->corr);
    if (!ic->m_bits || !ic->corr)
        return -1;
    for (uint32_t i = 0; i < contexts; i++)
        if (model_create(&ic->m_bits[i], ic->corr_bits + 1))
            return -1;
    for (uint32_t i = 1; i <= ic->corr_bits; i++)
        if (model_create(&ic->corr[i - 1], i <= ic->bits_high ? 1u << i : 1u << ic->bits_high))
            return -1;
    return 0;
}

static void ic_init(ic_dec *ic)
{
    for (uint32_t i = 0; i < ic->contexts; i++)
        model_init(&ic->m_bits[i]);
    bit_model_init(&ic->corr0);
    for (uint32_t i = 0; i < ic->corr_bits; i++)
        model_init(&ic->corr[i]);
}

static void ic_free(ic_dec *ic)
{
    if (ic->m_bits)
        for (uint32_t i = 0; i < ic->contexts; i++)
            model_free(&ic->m_bits[i]);
    if (ic->corr)
        for (uint32_t i = 0; i < ic->corr_bits; i++)
            model_free(&ic->corr[i]);
    free(ic->m_bits);
    free(ic->corr);
    memset(ic, 0, sizeof *ic);
}

static int32_t ic_corrector(ic_dec *ic, ac_dec *d, ac_model *m_bits)
{
    int32_t c;
    ic->k = decode_symbol(d, m_bits);
    uint32_t k = ic->k;
    if (k) {
        if (k < 32) {
            uint32_t u;
            if (k <= ic->bits_high) {
                u = decode_symbol(d, &ic->corr[k - 1]);
            } else {
                uint32_t k1 = k - ic->bits_high;
                u = decode_symbol(d, &ic->corr[k - 1]);
                u = u << k1 | read_bits(d, k1);
            }
            /* back from [0, 2^k) to [-(2^k - 1), -2^(k-1)] or [2^(k-1) + 1, 2^k] */
            if (u >= (1u << (k - 1)))
                c = (int32_t)(u + 1);
            else
                c = (int32_t)(u - ((1u << k) - 1));
        } else {
            c = ic->corr_min;
        }
    } else {
        c = (int32_t)decode_bit(d, &ic->corr0);
    }
    return c;
}

static int32_t ic_decompress(ic_dec *ic, ac_dec *d, int32_t pred, uint32_t context)
{
    if (context >= ic->contexts) {
        d->corrupt = 1;
        context = 0;
    }
    int64_t real = (int64_t)pred + ic_corrector(ic, d, &ic->m_bits[context]);
    if (real < 0)
        real += ic->corr_range;
    else if ((uint64_t)real >= ic->corr_range)
        real -= ic->corr_range;
    return (int32_t)(uint32_t)(uint64_t)real;
}

/* ---- item decoders --------------------------------------------------------------------- */

static inline uint8_t u8_fold(int32_t n)
{
    return (uint8_t)(n < 0 ? n + 256 : n > 255 ? n - 256 : n);
}

static inline int32_t u8_clamp(int32_t n)
{
    return n <= 0 ? 0 : n >= 255 ? 255 : n;
}

static const uint8_t number_return_map[8][8] = {
    {15, 14, 13, 12, 11, 10, 9, 8},   {14, 0, 1, 3, 6, 10, 10, 9},
    {13, 1, 2, 4, 7, 11, 11, 10},     {12, 3, 4, 5, 8, 12, 12, 11},
    {11, 6, 7, 8, 9, 13, 13, 12},     {10, 10, 11, 12, 13, 14, 14, 13},
    {9, 10, 11, 12, 13, 14, 15, 14},  {8, 9, 10, 11, 12, 13, 14, 15},
};

static const uint8_t number_return_level[8][8] = {
    {0, 1, 2, 3, 4, 5, 6, 7}, {1, 0, 1, 2, 3, 4, 5, 6}, {2, 1, 0, 1, 2, 3, 4, 5},
    {3, 2, 1, 0, 1, 2, 3, 4}, {4, 3, 2, 1, 0, 1, 2, 3}, {5, 4, 3, 2, 1, 0, 1, 2},
    {6, 5, 4, 3, 2, 1, 0, 1}, {7, 6, 5, 4, 3, 2, 1, 0},
};

/* The median of the last five values, kept sorted incrementally. */
typedef struct {
    int32_t v[5];
    int high;
} median5;

static void median5_init(median5 *m)
{
    memset(m->v, 0, sizeof m->v);
    m->high = 1;
}

static void median5_add(median5 *m, int32_t x)
{
    int32_t *v = m->v;
    if (m->high) {
        if (x < v[2]) {
            v[4] = v[3];
            v[3] = v[2];
            if (x < v[0]) {
                v[2] = v[1];
                v[1] = v[0];
                v[0] = x;
            } else if (x < v[1]) {
                v[2] = v[1];
                v[1] = x;
            } else {
                v[2] = x;
            }
        } else {
            if (x < v[3]) {
                v[4] = v[3];
                v[3] = x;
            } else {
                v[4] = x;
            }
            m->high = 0;
        }
    } else {
        if (v[2] < x) {
            v[0] = v[1];
            v[1] = v[2];
            if (v[4] < x) {
                v[2] = v[3];
                v[3] = v[4];
                v[4] = x;
            } else if (v[3] < x) {
                v[2] = v[3];
                v[3] = x;
            } else {
                v[2] = x;
            }
        } else {
            if (v[1] < x) {
                v[0] = v[1];
                v[1] = x;
            } else {
                v[0] = x;
            }
            m->high = 1;
        }
    }
}

enum { ITEM_BYTE = 0, ITEM_POINT10 = 6, ITEM_GPSTIME11 = 7, ITEM_RGB12 = 8 };

/* Lazily created context models (one per previous byte value), kept across chunks. */
typedef struct {
    ac_model *m[256];
} lazy_models;

static ac_model *lazy_get(lazy_models *l, unsigned i, int *fail)
{
    if (!l->m[i]) {
        ac_model *m = malloc(sizeof *m);
        if (!m || model_create(m, 256)) {
            free(m);
            *fail = 1;
            return NULL;
        }
        model_init(m);
        l->m[i] = m;
    }
    return l->m[i];
}

/* A byte coded with the model chosen by the previous byte; `keep` when memory runs out. */
static uint8_t lazy_decode(lazy_models *l, unsigned context, ac_dec *d, uint8_t keep, int *fail)
{
    ac_model *m = lazy_get(l, context, fail);
    return m ? (uint8_t)decode_symbol(d, m) : keep;
}

static void lazy_init(lazy_models *l)
{
    for (int i = 0; i < 256; i++)
        if (l->m[i])
            model_init(l->m[i]);
}

static void lazy_free(lazy_models *l)
{
    for (int i = 0; i < 256; i++)
        if (l->m[i]) {
            model_free(l->m[i]);
            free(l->m[i]);
            l->m[i] = NULL;
        }
}

typedef struct {
    uint8_t last[20];
    /* v2 */
    uint16_t last_intensity[16];
    median5 last_x_diff_median[16], last_y_diff_median[16];
    int32_t last_height[8];
    ac_model scan_angle[2];
    /* v1 */
    int32_t last_x_diff[3], last_y_diff[3];
    int last_incr;
    ic_dec ic_scan_angle;
    /* both */
    ac_model changed_values;
    ic_dec ic_intensity, ic_psid, ic_dx, ic_dy, ic_z;
    lazy_models bit_byte, classification, user_data;
} point10_dec;

typedef struct {
    /* v2: four sequences; v1 uses index 0 only */
    uint64_t last_gpstime[4];
    int32_t last_gpstime_diff[4];
    int32_t multi_extreme_counter[4];
    unsigned last, next;
    ac_model m_multi, m_0diff;
    ic_dec ic_gpstime;
} gpstime_dec;

typedef struct {
    uint16_t last[3];
    ac_model m_byte_used, m_diff[6]; /* v2 */
    ic_dec ic_rgb;                   /* v1 */
} rgb_dec;

typedef struct {
    size_t n;
    uint8_t *last;
    ac_model *m_byte; /* v2 */
    ic_dec ic_byte;   /* v1 */
} byte_dec;

typedef struct {
    int type, version;
    size_t size, offset;
    union {
        point10_dec *p10;
        gpstime_dec *gps;
        rgb_dec *rgb;
        byte_dec *bytes;
    } u;
} item_dec;

static int32_t i32_at(const uint8_t *p)
{
    return (int32_t)ag_bytes_u32le(p);
}

static void put_i32(uint8_t *p, int32_t v)
{
    ag_bytes_put_u32le(p, (uint32_t)v);
}

static int point10_create(point10_dec *s, int version)
{
    memset(s, 0, sizeof *s);
    if (model_create(&s->changed_values, 64))
        return -1;
    if (version == 1)
        return ic_create(&s->ic_dx, 32, 1) || ic_create(&s->ic_dy, 32, 20) ||
                       ic_create(&s->ic_z, 32, 20) || ic_create(&s->ic_intensity, 16, 1) ||
                       ic_create(&s->ic_scan_angle, 8, 2) || ic_create(&s->ic_psid, 16, 1)
                   ? -1
                   : 0;
    return ic_create(&s->ic_intensity, 16, 4) || model_create(&s->scan_angle[0], 256) ||
                   model_create(&s->scan_angle[1], 256) || ic_create(&s->ic_psid, 16, 1) ||
                   ic_create(&s->ic_dx, 32, 2) || ic_create(&s->ic_dy, 32, 22) ||
                   ic_create(&s->ic_z, 32, 20)
               ? -1
               : 0;
}

static void point10_free(point10_dec *s)
{
    model_free(&s->changed_values);
    model_free(&s->scan_angle[0]);
    model_free(&s->scan_angle[1]);
    ic_free(&s->ic_intensity);
    ic_free(&s->ic_psid);
    ic_free(&s->ic_dx);
    ic_free(&s->ic_dy);
    ic_free(&s->ic_z);
    ic_free(&s->ic_scan_angle);
    lazy_free(&s->bit_byte);
    lazy_free(&s->classification);
    lazy_free(&s->user_data);
}

static void point10_init(point10_dec *s, int version, const uint8_t *item)
{
    model_init(&s->changed_values);
    ic_init(&s->ic_intensity);
    ic_init(&s->ic_psid);
    ic_init(&s->ic_dx);
    ic_init(&s->ic_dy);
    ic_init(&s->ic_z);
    lazy_init(&s->bit_byte);
    lazy_init(&s->classification);
    lazy_init(&s->user_data);
    memcpy(s->last, item, 20);
    if (version == 1) {
        memset(s->last_x_diff, 0, sizeof s->last_x_diff);
        memset(s->last_y_diff, 0, sizeof s->last_y_diff);
        s->last_incr = 0;
        ic_init(&s->ic_scan_angle);
        return;
    }
    for (int i = 0; i < 16; i++) {
        median5_init(&s->last_x_diff_median[i]);
        median5_init(&s->last_y_diff_median[i]);
        s->last_intensity[i] = 0;
        s->last_height[i / 2] = 0;
    }
    model_init(&s->scan_angle[0]);
    model_init(&s->scan_angle[1]);
    s->last[12] = s->last[13] = 0; /* the intensity is predicted from zero */
}

static int32_t median3(const int32_t *v)
{
    if (v[0] < v[1])
        return v[1] < v[2] ? v[1] : v[0] < v[2] ? v[2] : v[0];
    return v[0] < v[2] ? v[0] : v[1] < v[2] ? v[2] : v[1];
}

static void point10_read_v1(point10_dec *s, ac_dec *d, uint8_t *item, int *fail)
{
    int32_t median_x = median3(s->last_x_diff), median_y = median3(s->last_y_diff);
    uint8_t *last = s->last;
    memcpy(item, last, 20);
    int32_t x_diff = ic_decompress(&s->ic_dx, d, median_x, 0);
    put_i32(item, (int32_t)((uint32_t)i32_at(item) + (uint32_t)x_diff));
    uint32_t k_bits = s->ic_dx.k;
    int32_t y_diff = ic_decompress(&s->ic_dy, d, median_y, k_bits < 19 ? k_bits : 19);
    put_i32(item + 4, (int32_t)((uint32_t)i32_at(item + 4) + (uint32_t)y_diff));
    k_bits = (k_bits + s->ic_dy.k) / 2;
    put_i32(item + 8, ic_decompress(&s->ic_z, d, i32_at(last + 8), k_bits < 19 ? k_bits : 19));
    uint32_t changed = decode_symbol(d, &s->changed_values);
    if (changed) {
        if (changed & 32)
            ag_bytes_put_u16le(item + 12,
                               (uint16_t)ic_decompress(&s->ic_intensity, d, ag_bytes_u16le(last + 12), 0));
        if (changed & 16)
            item[14] = lazy_decode(&s->bit_byte, last[14], d, item[14], fail);
        if (changed & 8)
            item[15] = lazy_decode(&s->classification, last[15], d, item[15], fail);
        if (changed & 4)
            item[16] = (uint8_t)ic_decompress(&s->ic_scan_angle, d, last[16], k_bits < 3);
        if (changed & 2)
            item[17] = lazy_decode(&s->user_data, last[17], d, item[17], fail);
        if (changed & 1)
            ag_bytes_put_u16le(item + 18,
                               (uint16_t)ic_decompress(&s->ic_psid, d, ag_bytes_u16le(last + 18), 0));
    }
    s->last_x_diff[s->last_incr] = x_diff;
    s->last_y_diff[s->last_incr] = y_diff;
    if (++s->last_incr > 2)
        s->last_incr = 0;
    memcpy(last, item, 20);
}

static void point10_read_v2(point10_dec *s, ac_dec *d, uint8_t *item, int *fail)
{
    uint8_t *last = s->last;
    uint32_t changed = decode_symbol(d, &s->changed_values);
    if (changed & 32)
        last[14] = lazy_decode(&s->bit_byte, last[14], d, last[14], fail);
    /* contexts from the return number and the number of returns */
    unsigned r = last[14] & 7, n = (last[14] >> 3) & 7;
    unsigned m = number_return_map[n][r], l = number_return_level[n][r];
    if (changed) {
        if (changed & 16) {
            uint16_t v = (uint16_t)ic_decompress(&s->ic_intensity, d, s->last_intensity[m], m < 3 ? m : 3);
            ag_bytes_put_u16le(last + 12, v);
            s->last_intensity[m] = v;
        } else {
            ag_bytes_put_u16le(last + 12, s->last_intensity[m]);
        }
        if (changed & 8)
            last[15] = lazy_decode(&s->classification, last[15], d, last[15], fail);
        if (changed & 4) {
            int32_t v = (int32_t)decode_symbol(d, &s->scan_angle[(last[14] >> 6) & 1]);
            last[16] = u8_fold(v + last[16]);
        }
        if (changed & 2)
            last[17] = lazy_decode(&s->user_data, last[17], d, last[17], fail);
        if (changed & 1)
            ag_bytes_put_u16le(last + 18,
                               (uint16_t)ic_decompress(&s->ic_psid, d, ag_bytes_u16le(last + 18), 0));
    }
    int32_t median = s->last_x_diff_median[m].v[2];
    int32_t diff = ic_decompress(&s->ic_dx, d, median, n == 1);
    put_i32(last, (int32_t)((uint32_t)i32_at(last) + (uint32_t)diff));
    median5_add(&s->last_x_diff_median[m], diff);
    median = s->last_y_diff_median[m].v[2];
    uint32_t k_bits = s->ic_dx.k;
    diff = ic_decompress(&s->ic_dy, d, median, (n == 1) + (k_bits < 20 ? (k_bits & ~1u) : 20));
    put_i32(last + 4, (int32_t)((uint32_t)i32_at(last + 4) + (uint32_t)diff));
    median5_add(&s->last_y_diff_median[m], diff);
    k_bits = (s->ic_dx.k + s->ic_dy.k) / 2;
    int32_t z = ic_decompress(&s->ic_z, d, s->last_height[l], (n == 1) + (k_bits < 18 ? (k_bits & ~1u) : 18));
    put_i32(last + 8, z);
    s->last_height[l] = z;
    memcpy(item, last, 20);
}

#define GPS_MULTI 500
#define GPS_MULTI_MINUS (-10)
#define GPS_MULTI_UNCHANGED (GPS_MULTI - GPS_MULTI_MINUS + 1)
#define GPS_MULTI_CODE_FULL (GPS_MULTI - GPS_MULTI_MINUS + 2)
#define GPS_MULTI_TOTAL (GPS_MULTI - GPS_MULTI_MINUS + 6)
#define GPS_MULTIMAX_V1 512

static int gpstime_create(gpstime_dec *s, int version)
{
    memset(s, 0, sizeof *s);
    if (version == 1)
        return model_create(&s->m_multi, GPS_MULTIMAX_V1) || model_create(&s->m_0diff, 3) ||
                       ic_create(&s->ic_gpstime, 32, 6)
                   ? -1
                   : 0;
    return model_create(&s->m_multi, GPS_MULTI_TOTAL) || model_create(&s->m_0diff, 6) ||
                   ic_create(&s->ic_gpstime, 32, 9)
               ? -1
               : 0;
}

static void gpstime_free(gpstime_dec *s)
{
    model_free(&s->m_multi);
    model_free(&s->m_0diff);
    ic_free(&s->ic_gpstime);
}

static void gpstime_init(gpstime_dec *s, const uint8_t *item)
{
    s->last = s->next = 0;
    memset(s->last_gpstime_diff, 0, sizeof s->last_gpstime_diff);
    memset(s->multi_extreme_counter, 0, sizeof s->multi_extreme_counter);
    model_init(&s->m_multi);
    model_init(&s->m_0diff);
    ic_init(&s->ic_gpstime);
    s->last_gpstime[0] = ag_bytes_u64le(item);
    s->last_gpstime[1] = s->last_gpstime[2] = s->last_gpstime[3] = 0;
}

/* multi * diff with the 32-bit wrap-around the format relies on */
static int32_t mul32(int32_t a, int32_t b)
{
    return (int32_t)((uint32_t)a * (uint32_t)b);
}

static void gpstime_read_v1(gpstime_dec *s, ac_dec *d, uint8_t *item)
{
    int32_t *last_diff = &s->last_gpstime_diff[0];
    int32_t *extreme = &s->multi_extreme_counter[0];
    uint64_t *last = &s->last_gpstime[0];
    if (*last_diff == 0) {
        uint32_t multi = decode_symbol(d, &s->m_0diff);
        if (multi == 1) {
            *last_diff = ic_decompress(&s->ic_gpstime, d, 0, 0);
            *last += (uint64_t)(int64_t)*last_diff;
        } else if (multi == 2) {
            *last = read_int64(d);
        }
    } else {
        int32_t multi = (int32_t)decode_symbol(d, &s->m_multi);
        if (multi < GPS_MULTIMAX_V1 - 2) {
            int32_t diff;
            if (multi == 1) {
                diff = ic_decompress(&s->ic_gpstime, d, *last_diff, 1);
                *last_diff = diff;
                *extreme = 0;
            } else if (multi == 0) {
                diff = ic_decompress(&s->ic_gpstime, d, *last_diff / 4, 2);
                if (++*extreme > 3) {
                    *last_diff = diff;
                    *extreme = 0;
                }
            } else if (multi < 10) {
                diff = ic_decompress(&s->ic_gpstime, d, mul32(multi, *last_diff), 3);
            } else if (multi < 50) {
                diff = ic_decompress(&s->ic_gpstime, d, mul32(multi, *last_diff), 4);
            } else {
                diff = ic_decompress(&s->ic_gpstime, d, mul32(multi, *last_diff), 5);
                if (multi == GPS_MULTIMAX_V1 - 3 && ++*extreme > 3) {
                    *last_diff = diff;
                    *extreme = 0;
                }
            }
            *last += (uint64_t)(int64_t)diff;
        } else if (multi < GPS_MULTIMAX_V1 - 1) {
            *last = read_int64(d);
        }
    }
    ag_bytes_put_u64le(item, *last);
}

/* A time far from the last one: a new sequence, its upper half predicted, the lower raw. */
static void gpstime_v2_full(gpstime_dec *s, ac_dec *d, unsigned from)
{
    s->next = (s->next + 1) & 3;
    uint64_t hi = (uint32_t)ic_decompress(&s->ic_gpstime, d,
                                          (int32_t)(uint32_t)(s->last_gpstime[from] >> 32), 8);
    s->last_gpstime[s->next] = hi << 32 | read_int(d);
    s->last = s->next;
    s->last_gpstime_diff[s->last] = 0;
    s->multi_extreme_counter[s->last] = 0;
}

static void gpstime_read_v2(gpstime_dec *s, ac_dec *d, uint8_t *item)
{
    /* a switch to another sequence reads again; a valid stream switches at most once per
     * point, so more than a few switches means corrupt data */
    for (int attempt = 0; attempt < 8; attempt++) {
        unsigned L = s->last;
        if (s->last_gpstime_diff[L] == 0) {
            uint32_t multi = decode_symbol(d, &s->m_0diff);
            if (multi == 1) {
                s->last_gpstime_diff[L] = ic_decompress(&s->ic_gpstime, d, 0, 0);
                s->last_gpstime[L] += (uint64_t)(int64_t)s->last_gpstime_diff[L];
                s->multi_extreme_counter[L] = 0;
            } else if (multi == 2) {
                gpstime_v2_full(s, d, L);
            } else if (multi > 2) {
                s->last = (L + multi - 2) & 3;
                continue;
            }
        } else {
            int32_t multi = (int32_t)decode_symbol(d, &s->m_multi);
            if (multi == 1) {
                s->last_gpstime[L] += (uint64_t)(int64_t)ic_decompress(
                    &s->ic_gpstime, d, s->last_gpstime_diff[L], 1);
                s->multi_extreme_counter[L] = 0;
            } else if (multi < GPS_MULTI_UNCHANGED) {
                int32_t diff;
                int32_t *ld = &s->last_gpstime_diff[L], *ex = &s->multi_extreme_counter[L];
                if (multi == 0) {
                    diff = ic_decompress(&s->ic_gpstime, d, 0, 7);
                    if (++*ex > 3) {
                        *ld = diff;
                        *ex = 0;
                    }
                } else if (multi < GPS_MULTI) {
                    diff = ic_decompress(&s->ic_gpstime, d, mul32(multi, *ld), multi < 10 ? 2 : 3);
                } else if (multi == GPS_MULTI) {
                    diff = ic_decompress(&s->ic_gpstime, d, mul32(GPS_MULTI, *ld), 4);
                    if (++*ex > 3) {
                        *ld = diff;
                        *ex = 0;
                    }
                } else {
                    multi = GPS_MULTI - multi;
                    if (multi > GPS_MULTI_MINUS) {
                        diff = ic_decompress(&s->ic_gpstime, d, mul32(multi, *ld), 5);
                    } else {
                        diff = ic_decompress(&s->ic_gpstime, d, mul32(GPS_MULTI_MINUS, *ld), 6);
                        if (++*ex > 3) {
                            *ld = diff;
                            *ex = 0;
                        }
                    }
                }
                s->last_gpstime[L] += (uint64_t)(int64_t)diff;
            } else if (multi == GPS_MULTI_CODE_FULL) {
                gpstime_v2_full(s, d, L);
            } else if (multi > GPS_MULTI_CODE_FULL) {
                s->last = (L + (unsigned)(multi - GPS_MULTI_CODE_FULL)) & 3;
                continue;
            }
        }
        ag_bytes_put_u64le(item, s->last_gpstime[s->last]);
        return;
    }
    d->corrupt = 1;
    ag_bytes_put_u64le(item, s->last_gpstime[s->last]);
}

static int rgb_create(rgb_dec *s, int version)
{
    memset(s, 0, sizeof *s);
    if (version == 1)
        return model_create(&s->m_byte_used, 64) || ic_create(&s->ic_rgb, 8, 6) ? -1 : 0;
    if (model_create(&s->m_byte_used, 128))
        return -1;
    for (int i = 0; i < 6; i++)
        if (model_create(&s->m_diff[i], 256))
            return -1;
    return 0;
}

static void rgb_free(rgb_dec *s)
{
    model_free(&s->m_byte_used);
    for (int i = 0; i < 6; i++)
        model_free(&s->m_diff[i]);
    ic_free(&s->ic_rgb);
}

static void rgb_init(rgb_dec *s, int version, const uint8_t *item)
{
    model_init(&s->m_byte_used);
    if (version == 1)
        ic_init(&s->ic_rgb);
    else
        for (int i = 0; i < 6; i++)
            model_init(&s->m_diff[i]);
    for (int a = 0; a < 3; a++)
        s->last[a] = ag_bytes_u16le(item + 2 * a);
}

static void rgb_read_v1(rgb_dec *s, ac_dec *d, uint8_t *item)
{
    uint32_t sym = decode_symbol(d, &s->m_byte_used);
    uint16_t v[3];
    for (int a = 0; a < 3; a++) {
        unsigned lo = sym & (1u << (2 * a))
                          ? (uint8_t)ic_decompress(&s->ic_rgb, d, s->last[a] & 255, 2 * (uint32_t)a)
                          : s->last[a] & 0xFF;
        unsigned hi = sym & (1u << (2 * a + 1))
                          ? (unsigned)(uint8_t)ic_decompress(&s->ic_rgb, d, s->last[a] >> 8, 2 * (uint32_t)a + 1) << 8
                          : s->last[a] & 0xFF00u;
        v[a] = (uint16_t)(lo | hi);
    }
    for (int a = 0; a < 3; a++) {
        ag_bytes_put_u16le(item + 2 * a, v[a]);
        s->last[a] = v[a];
    }
}

static void rgb_read_v2(rgb_dec *s, ac_dec *d, uint8_t *item)
{
    const uint16_t *last = s->last;
    uint16_t v[3];
    int32_t diff;
    uint32_t sym = decode_symbol(d, &s->m_byte_used);
    if (sym & 1)
        v[0] = u8_fold((int32_t)(uint8_t)decode_symbol(d, &s->m_diff[0]) + (last[0] & 255));
    else
        v[0] = last[0] & 0xFF;
    if (sym & 2)
        v[0] |= (uint16_t)(u8_fold((int32_t)(uint8_t)decode_symbol(d, &s->m_diff[1]) + (last[0] >> 8)) << 8);
    else
        v[0] |= last[0] & 0xFF00;
    if (sym & 64) {
        diff = (v[0] & 0xFF) - (last[0] & 0xFF);
        if (sym & 4)
            v[1] = u8_fold((int32_t)(uint8_t)decode_symbol(d, &s->m_diff[2]) + u8_clamp(diff + (last[1] & 255)));
        else
            v[1] = last[1] & 0xFF;
        if (sym & 16) {
            diff = (diff + ((v[1] & 0xFF) - (last[1] & 0xFF))) / 2;
            v[2] = u8_fold((int32_t)(uint8_t)decode_symbol(d, &s->m_diff[4]) + u8_clamp(diff + (last[2] & 255)));
        } else {
            v[2] = last[2] & 0xFF;
        }
        diff = (v[0] >> 8) - (last[0] >> 8);
        if (sym & 8)
            v[1] |= (uint16_t)(u8_fold((int32_t)(uint8_t)decode_symbol(d, &s->m_diff[3]) +
                                       u8_clamp(diff + (last[1] >> 8)))
                               << 8);
        else
            v[1] |= last[1] & 0xFF00;
        if (sym & 32) {
            diff = (diff + ((v[1] >> 8) - (last[1] >> 8))) / 2;
            v[2] |= (uint16_t)(u8_fold((int32_t)(uint8_t)decode_symbol(d, &s->m_diff[5]) +
                                       u8_clamp(diff + (last[2] >> 8)))
                               << 8);
        } else {
            v[2] |= last[2] & 0xFF00;
        }
    } else {
        v[1] = v[2] = v[0];
    }
    for (int a = 0; a < 3; a++) {
        ag_bytes_put_u16le(item + 2 * a, v[a]);
        s->last[a] = v[a];
    }
}

static int byte_create(byte_dec *s, int version, size_t n)
{
    memset(s, 0, sizeof *s);
    s->n = n;
    s->last = malloc(n);
    if (!s->last)
        return -1;
    if (version == 1)
        return ic_create(&s->ic_byte, 8, (uint32_t)n);
    s->m_byte = calloc(n, sizeof *s->m_byte);
    if (!s->m_byte)
        return -1;
    for (size_t i = 0; i < n; i++)
        if (model_create(&s->m_byte[i], 256))
            return -1;
    return 0;
}

static void byte_free(byte_dec *s)
{
    if (s->m_byte)
        for (size_t i = 0; i < s->n; i++)
            model_free(&s->m_byte[i]);
    free(s->m_byte);
    free(s->last);
    ic_free(&s->ic_byte);
}

static void byte_init(byte_dec *s, int version, const uint8_t *item)
{
    if (version == 1)
        ic_init(&s->ic_byte);
    else
        for (size_t i = 0; i < s->n; i++)
            model_init(&s->m_byte[i]);
    memcpy(s->last, item, s->n);
}

static void byte_read(byte_dec *s, int version, ac_dec *d, uint8_t *item)
{
    for (size_t i = 0; i < s->n; i++)
        item[i] = version == 1 ? (uint8_t)ic_decompress(&s->ic_byte, d, s->last[i], (uint32_t)i)
                               : u8_fold(s->last[i] + (int32_t)decode_symbol(d, &s->m_byte[i]));
    memcpy(s->last, item, s->n);
}

static void item_free(item_dec *it)
{
    switch (it->type) {
    case ITEM_POINT10: if (it->u.p10) point10_free(it->u.p10); break;
    case ITEM_GPSTIME11: if (it->u.gps) gpstime_free(it->u.gps); break;
    case ITEM_RGB12: if (it->u.rgb) rgb_free(it->u.rgb); break;
    case ITEM_BYTE: if (it->u.bytes) byte_free(it->u.bytes); break;
    }
    free(it->u.p10);
    it->u.p10 = NULL;
}

static int item_create(item_dec *it)
{
    switch (it->type) {
    case ITEM_POINT10:
        it->u.p10 = malloc(sizeof *it->u.p10);
        return !it->u.p10 || point10_create(it->u.p10, it->version);
    case ITEM_GPSTIME11:
        it->u.gps = malloc(sizeof *it->u.gps);
        return !it->u.gps || gpstime_create(it->u.gps, it->version);
    case ITEM_RGB12:
        it->u.rgb = malloc(sizeof *it->u.rgb);
        return !it->u.rgb || rgb_create(it->u.rgb, it->version);
    default:
        it->u.bytes = malloc(sizeof *it->u.bytes);
        return !it->u.bytes || byte_create(it->u.bytes, it->version, it->size);
    }
}

static void item_init(item_dec *it, const uint8_t *rec)
{
    const uint8_t *p = rec + it->offset;
    switch (it->type) {
    case ITEM_POINT10: point10_init(it->u.p10, it->version, p); break;
    case ITEM_GPSTIME11: gpstime_init(it->u.gps, p); break;
    case ITEM_RGB12: rgb_init(it->u.rgb, it->version, p); break;
    default: byte_init(it->u.bytes, it->version, p); break;
    }
}

static void item_read(item_dec *it, ac_dec *d, uint8_t *rec, int *fail)
{
    uint8_t *p = rec + it->offset;
    switch (it->type) {
    case ITEM_POINT10:
        if (it->version == 1)
            point10_read_v1(it->u.p10, d, p, fail);
        else
            point10_read_v2(it->u.p10, d, p, fail);
        break;
    case ITEM_GPSTIME11:
        if (it->version == 1)
            gpstime_read_v1(it->u.gps, d, p);
        else
            gpstime_read_v2(it->u.gps, d, p);
        break;
    case ITEM_RGB12:
        if (it->version == 1)
            rgb_read_v1(it->u.rgb, d, p);
        else
            rgb_read_v2(it->u.rgb, d, p);
        break;
    default: byte_read(it->u.bytes, it->version, d, p); break;
    }
}

/* ---- the file: LASzip VLR, chunk table, chunks ----------------------------------------- */

#define MAX_ITEMS 8

static const char *item_name(int type)
{
    switch (type) {
    case 0: return "BYTE";
    case 6: return "POINT10";
    case 7: return "GPSTIME11";
    case 8: return "RGB12";
    case 9: return "WAVEPACKET13";
    case 10: return "POINT14";
    case 11: return "RGB14";
    case 12: return "RGBNIR14";
    case 13: return "WAVEPACKET14";
    case 14: return "BYTE14";
    default: return "unknown";
    }
}

/* Decodes the chunk table: per chunk its byte size and (variable chunks) point count. */
static ag_status read_chunk_table(const uint8_t *data, size_t len, uint64_t table_at,
                                  int variable, uint32_t *nchunks_out, uint64_t **bytes_out,
                                  uint64_t **points_out, ag_error *err)
{
    *bytes_out = *points_out = NULL;
    if (table_at > len || len - table_at < 8)
        return ag_error_set(err, AG_ERR_PARSE, 0, "the LAZ chunk table at byte %llu is outside the file",
                            (unsigned long long)table_at);
    const uint8_t *t = data + table_at;
    uint32_t version = ag_bytes_u32le(t), nchunks = ag_bytes_u32le(t + 4);
    if (version != 0)
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0, "LAZ chunk table version %u is not supported",
                            version);
    if (nchunks > len)
        return ag_error_set(err, AG_ERR_PARSE, 0, "the LAZ chunk table claims %u chunks", nchunks);
    uint64_t *bytes = calloc((size_t)nchunks + 1, sizeof *bytes);
    uint64_t *points = calloc((size_t)nchunks + 1, sizeof *points);
    ic_dec ic;
    if (!bytes || !points || ic_create(&ic, 32, 2)) {
        free(bytes);
        free(points);
        ic_free(&ic);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    if (nchunks) {
        ac_dec d;
        ac_init(&d, t + 8, data + len);
        ic_init(&ic);
        uint32_t prev_points = 0, prev_bytes = 0;
        for (uint32_t i = 0; i < nchunks; i++) {
            if (variable)
                prev_points = (uint32_t)ic_decompress(&ic, &d, (int32_t)prev_points, 0);
            prev_bytes = (uint32_t)ic_decompress(&ic, &d, (int32_t)prev_bytes, 1);
            points[i] = prev_points;
            bytes[i] = prev_bytes;
        }
        if (d.overrun || d.corrupt) {
            free(bytes);
            free(points);
            ic_free(&ic);
            return ag_error_set(err, AG_ERR_PARSE, 0, "the LAZ chunk table is truncated or corrupt");
        }
    }
    ic_free(&ic);
    *nchunks_out = nchunks;
    *bytes_out = bytes;
    *points_out = points;
    return AG_OK;
}

ag_status ag_laz_decode(const uint8_t *data, size_t len, const ag_las_header *h,
                        const ag__las_vlr *vlr, ag__las_record_fn fn, void *user, ag_error *err)
{
    if (h->point_format > 5)
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                            "LAZ point format %u not supported; convert to LAS", h->point_format);
    if (h->point_format == 4 || h->point_format == 5)
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                            "LAZ point format %u (wave packets) not supported; convert to LAS",
                            h->point_format);
    if (vlr->len < 34)
        return ag_error_set(err, AG_ERR_PARSE, 0, "the LASzip VLR is %zu bytes, too short", vlr->len);
    const uint8_t *v = vlr->data;
    unsigned compressor = ag_bytes_u16le(v), coder = ag_bytes_u16le(v + 2);
    uint32_t chunk_size = ag_bytes_u32le(v + 12);
    unsigned nitems = ag_bytes_u16le(v + 32);
    if (compressor == 3)
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                            "LAZ point format %u with the layered compressor not supported; "
                            "convert to LAS",
                            h->point_format);
    if (compressor != 1 && compressor != 2)
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0, "LAZ compressor %u is not supported", compressor);
    if (coder != 0)
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0, "LAZ coder %u is not supported", coder);
    if (nitems == 0 || nitems > MAX_ITEMS || 34 + 6 * (size_t)nitems > vlr->len)
        return ag_error_set(err, AG_ERR_PARSE, 0, "the LASzip VLR lists %u items", nitems);
    item_dec items[MAX_ITEMS];
    memset(items, 0, sizeof items);
    size_t offset = 0;
    for (unsigned i = 0; i < nitems; i++) {
        const uint8_t *it = v + 34 + 6 * i;
        items[i].type = ag_bytes_u16le(it);
        items[i].size = ag_bytes_u16le(it + 2);
        items[i].version = ag_bytes_u16le(it + 4);
        items[i].offset = offset;
        offset += items[i].size;
        int t = items[i].type;
        size_t want = t == ITEM_POINT10 ? 20 : t == ITEM_GPSTIME11 ? 8 : t == ITEM_RGB12 ? 6 : 0;
        if (t != ITEM_POINT10 && t != ITEM_GPSTIME11 && t != ITEM_RGB12 && t != ITEM_BYTE)
            return ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                                "LAZ item %s not supported (point format %u); convert to LAS",
                                item_name(t), h->point_format);
        if ((want && items[i].size != want) || (t == ITEM_BYTE && items[i].size == 0))
            return ag_error_set(err, AG_ERR_PARSE, 0, "LAZ item %s has size %zu", item_name(t),
                                items[i].size);
        if (items[i].version != 1 && items[i].version != 2)
            return ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                                "LAZ item %s version %d not supported; convert to LAS", item_name(t),
                                items[i].version);
    }
    /* the items must spell the LAS record of the point format */
    int f = h->point_format;
    int gps = f == 1 || f == 3, rgb = f == 2 || f == 3;
    unsigned k = 0;
    int layout_ok = items[k++].type == ITEM_POINT10;
    if (gps)
        layout_ok &= k < nitems && items[k++].type == ITEM_GPSTIME11;
    if (rgb)
        layout_ok &= k < nitems && items[k++].type == ITEM_RGB12;
    for (; k < nitems; k++)
        layout_ok &= items[k].type == ITEM_BYTE;
    if (!layout_ok || offset != h->record_length)
        return ag_error_set(err, AG_ERR_PARSE, 0,
                            "the LAZ items do not make a point format %u record of %u bytes", f,
                            h->record_length);

    ag_status st = AG_OK;
    uint64_t *chunk_bytes = NULL, *chunk_points = NULL;
    uint32_t nchunks = 0;
    int have_table = 0, variable = compressor == 2 && chunk_size == UINT32_MAX;
    size_t pos = h->point_offset;
    if (compressor == 2) {
        if (len - pos < 8)
            return ag_error_set(err, AG_ERR_PARSE, 0, "the LAZ point data is truncated");
        int64_t table_at = (int64_t)ag_bytes_u64le(data + pos);
        pos += 8;
        if (table_at == -1 && len >= 8)
            table_at = (int64_t)ag_bytes_u64le(data + len - 8); /* written at the end */
        /* a table pointer just before the chunks means the writer never wrote the table */
        if (table_at > 0 && (uint64_t)table_at + 8 != pos && (uint64_t)table_at >= pos) {
            st = read_chunk_table(data, len, (uint64_t)table_at, variable, &nchunks, &chunk_bytes,
                                  &chunk_points, err);
            if (st != AG_OK)
                return st;
            have_table = 1;
        } else if (variable) {
            return ag_error_set(err, AG_ERR_PARSE, 0,
                                "the LAZ file has variable chunks but no chunk table");
        }
        if (!variable && chunk_size == 0)
            return ag_error_set(err, AG_ERR_PARSE, 0, "the LAZ chunk size is 0");
    }
    if (have_table) {
        /* the table must account for every point */
        uint64_t total = 0;
        for (uint32_t i = 0; i < nchunks; i++)
            total += variable ? chunk_points[i] : chunk_size;
        if (total < h->count) {
            free(chunk_bytes);
            free(chunk_points);
            return ag_error_set(err, AG_ERR_PARSE, 0,
                                "the header says %llu points but the LAZ chunks hold at most %llu",
                                (unsigned long long)h->count, (unsigned long long)total);
        }
    }
    for (unsigned i = 0; i < nitems && st == AG_OK; i++)
        if (item_create(&items[i]))
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    uint8_t *rec = malloc(h->record_length);
    if (!rec && st == AG_OK)
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    uint64_t done = 0;
    size_t chunk_start = pos;
    for (uint32_t chunk = 0; st == AG_OK && done < h->count; chunk++) {
        uint64_t in_chunk = compressor == 1 ? h->count
                            : variable     ? (chunk < nchunks ? chunk_points[chunk] : 0)
                                           : chunk_size;
        if (in_chunk > h->count - done)
            in_chunk = h->count - done;
        if (have_table && chunk >= nchunks) {
            st = ag_error_set(err, AG_ERR_PARSE, 0, "the LAZ chunk table ends before the points do");
            break;
        }
        if (in_chunk == 0) {
            st = ag_error_set(err, AG_ERR_PARSE, 0, "LAZ chunk %u holds no points", chunk + 1);
            break;
        }
        if (chunk_start > len || len - chunk_start < h->record_length) {
            st = ag_error_set(err, AG_ERR_PARSE, 0, "LAZ chunk %u starts past the end of the file",
                              chunk + 1);
            break;
        }
        /* the first point of a chunk is stored raw; the decoder starts after it */
        memcpy(rec, data + chunk_start, h->record_length);
        for (unsigned i = 0; i < nitems; i++)
            item_init(&items[i], rec);
        fn(user, (size_t)done++, rec);
        ac_dec d;
        ac_init(&d, data + chunk_start + h->record_length, data + len);
        int fail = 0;
        for (uint64_t j = 1; j < in_chunk; j++) {
            for (unsigned i = 0; i < nitems; i++)
                item_read(&items[i], &d, rec, &fail);
            if (d.overrun || d.corrupt || fail) {
                st = fail ? ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory")
                          : ag_error_set(err, AG_ERR_PARSE, 0,
                                         "LAZ chunk %u is truncated or corrupt at point %llu",
                                         chunk + 1, (unsigned long long)done + 1);
                break;
            }
            fn(user, (size_t)done++, rec);
        }
        if (have_table)
            chunk_start += chunk_bytes[chunk];
        else
            chunk_start = (size_t)(d.p - data);
    }
    free(rec);
    for (unsigned i = 0; i < nitems; i++)
        item_free(&items[i]);
    free(chunk_bytes);
    free(chunk_points);
    return st;
}
