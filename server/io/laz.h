/* LAZ (LASzip-compressed LAS) decoding, natively: no C library for LASzip is packaged in
 * Debian, and the format is public. Supported: point formats 0-3 as the items POINT10,
 * GPSTIME11 and RGB12 (item versions 1 and 2) plus BYTE items for extra bytes, written
 * pointwise or in fixed or variable chunks with a chunk table. Anything else (the layered
 * LAS 1.4 compressor for formats 6-10, wave packets) is refused with a message that says
 * what to do.
 *
 * The decoder is the adaptive arithmetic coder of LASzip (after Amir Said's FastAC) with
 * LASzip's integer compressor on top; each item decoder predicts a field from the previous
 * point and decodes the correction. Every read is bounds-checked: a truncated or corrupt
 * chunk gives a precise error, never a read past the buffer. */
#ifndef AG_LAZ_H
#define AG_LAZ_H

#include <stddef.h>
#include <stdint.h>

#include "../core/status.h"
#include "las.h"

/* Decodes the h->count points of a LAZ file whose LASzip VLR payload is vlr, calling fn
 * for each record in order (h->record_length bytes, LAS layout of h->point_format). */
ag_status ag_laz_decode(const uint8_t *data, size_t len, const ag_las_header *h,
                        const ag__las_vlr *laszip, ag__las_record_fn fn, void *user,
                        ag_error *err);

#endif
