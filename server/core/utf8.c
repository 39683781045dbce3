#include "utf8.h"

#include <string.h>

size_t ag_utf8_char_len(const char *str, size_t len)
{
    const unsigned char *s = (const unsigned char *)str;
    if (!len)
        return 0;
    unsigned char c = s[0];
    if (c < 0x80)
        return 1;
    size_t n;
    unsigned char lo = 0x80, hi = 0xbf; /* the allowed range of the second byte */
    if (c >= 0xc2 && c <= 0xdf)
        n = 2;
    else if (c >= 0xe0 && c <= 0xef) {
        n = 3;
        if (c == 0xe0)
            lo = 0xa0; /* overlong */
        else if (c == 0xed)
            hi = 0x9f; /* surrogates */
    } else if (c >= 0xf0 && c <= 0xf4) {
        n = 4;
        if (c == 0xf0)
            lo = 0x90; /* overlong */
        else if (c == 0xf4)
            hi = 0x8f; /* past U+10FFFF */
    } else {
        return 0;
    }
    if (len < n || s[1] < lo || s[1] > hi)
        return 0;
    for (size_t i = 2; i < n; i++)
        if ((s[i] & 0xc0) != 0x80)
            return 0;
    return n;
}

size_t ag_utf8_valid_prefix(const char *s, size_t len)
{
    size_t i = 0;
    while (i < len) {
        size_t n = ag_utf8_char_len(s + i, len - i);
        if (!n)
            break;
        i += n;
    }
    return i;
}

void ag_utf8_trim_partial(char *s)
{
    size_t len = strlen(s);
    /* a character has at most 3 continuation bytes: look back that far for its lead */
    for (size_t back = 1; back <= 4 && back <= len; back++) {
        unsigned char c = (unsigned char)s[len - back];
        if ((c & 0xc0) == 0x80)
            continue; /* a continuation byte: its lead is further back */
        size_t need = c < 0x80 ? 1 : c >= 0xf0 ? 4 : c >= 0xe0 ? 3 : c >= 0xc0 ? 2 : 1;
        if (need > back)
            s[len - back] = '\0';
        return;
    }
}

size_t ag_utf8_repair(const char *s, size_t len, char *dst, size_t cap)
{
    static const char replacement[] = "\xef\xbf\xbd"; /* U+FFFD */
    size_t out = 0, i = 0;
    while (i < len) {
        size_t n = ag_utf8_char_len(s + i, len - i);
        const char *from = n ? s + i : replacement;
        size_t m = n ? n : 3;
        if (out + m + 1 > cap)
            break;
        memcpy(dst + out, from, m);
        out += m;
        i += n ? n : 1;
    }
    dst[out] = '\0';
    return out;
}
