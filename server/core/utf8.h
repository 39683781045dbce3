/* UTF-8 as archgram's texts need it: JSON strings must be valid UTF-8, so a message that
 * quotes input (a file name, a member name, a URL) is checked or repaired before it goes into
 * a reply, and a text cut to fit a buffer is cut between characters. Strict: overlong forms,
 * surrogates and code points past U+10FFFF are invalid, as jansson has them. */
#ifndef AG_UTF8_H
#define AG_UTF8_H

#include <stddef.h>

/* Bytes of the valid character starting at s (1..4), or 0 when s[0..len) does not start with
 * one (len 0, a stray continuation byte, an overlong form, a truncated sequence …). */
size_t ag_utf8_char_len(const char *s, size_t len);

/* Length of the longest valid prefix of s[0..len): len when all of it is valid. */
size_t ag_utf8_valid_prefix(const char *s, size_t len);

/* Shortens the NUL-terminated s so that it does not end inside a character: a lead byte
 * whose continuation bytes are missing at the end goes, with what follows it. */
void ag_utf8_trim_partial(char *s);

/* Copies s[0..len) into dst (cap > 0 bytes, always NUL-terminated) with every byte that does
 * not belong to a valid character replaced by U+FFFD, cut on a character boundary when it
 * does not fit. Returns the bytes written (without the NUL). */
size_t ag_utf8_repair(const char *s, size_t len, char *dst, size_t cap);

#endif
