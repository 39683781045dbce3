/* PNG images, encoded and decoded with libpng (its simplified API): 8-bit RGBA, rows top to
 * bottom. */
#ifndef AG_IMAGE_PNG_H
#define AG_IMAGE_PNG_H

#include <stddef.h>
#include <stdint.h>

#include "../core/raster.h"
#include "../core/status.h"

#define AG_IMAGE_PNG_MAX_SIDE 4096

/* The image as PNG bytes; *out malloc'd. */
ag_status ag_image_png_encode(const ag_raster_image *img, uint8_t **out, size_t *len, ag_error *err);
/* PNG bytes as an RGBA image (at most AG_IMAGE_PNG_MAX_SIDE on a side); AG_ERR_PARSE for bytes
 * that are not a PNG libpng can read. */
ag_status ag_image_png_decode(const void *data, size_t len, ag_raster_image *out, ag_error *err);

#endif
