#include "image_png.h"

#include <png.h>
#include <stdlib.h>
#include <string.h>

ag_status ag_image_png_encode(const ag_raster_image *img, uint8_t **out, size_t *len, ag_error *err)
{
    *out = NULL;
    *len = 0;
    if (!img->rgba || img->width < 1 || img->height < 1 || img->width > AG_IMAGE_PNG_MAX_SIDE ||
        img->height > AG_IMAGE_PNG_MAX_SIDE)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a PNG is 1 to %d pixels on a side",
                            AG_IMAGE_PNG_MAX_SIDE);
    png_image im;
    memset(&im, 0, sizeof im);
    im.version = PNG_IMAGE_VERSION;
    im.width = img->width;
    im.height = img->height;
    im.format = PNG_FORMAT_RGBA;
    png_alloc_size_t size = 0;
    /* the first call measures, the second writes */
    if (!png_image_write_to_memory(&im, NULL, &size, 0, img->rgba, 0, NULL) || !size) {
        ag_status s = ag_error_set(err, AG_ERR_INTERNAL, 0, "cannot encode a PNG: %s",
                                   im.message);
        png_image_free(&im);
        return s;
    }
    uint8_t *buf = malloc(size);
    if (!buf)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory encoding a PNG");
    if (!png_image_write_to_memory(&im, buf, &size, 0, img->rgba, 0, NULL)) {
        free(buf);
        ag_status s = ag_error_set(err, AG_ERR_INTERNAL, 0, "cannot encode a PNG: %s",
                                   im.message);
        png_image_free(&im);
        return s;
    }
    *out = buf;
    *len = size;
    return AG_OK;
}

ag_status ag_image_png_decode(const void *data, size_t len, ag_raster_image *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    png_image im;
    memset(&im, 0, sizeof im);
    im.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&im, data, len)) {
        ag_status s = ag_error_set(err, AG_ERR_PARSE, 0, "not a PNG: %s", im.message);
        png_image_free(&im);
        return s;
    }
    if (im.width < 1 || im.height < 1 || im.width > AG_IMAGE_PNG_MAX_SIDE ||
        im.height > AG_IMAGE_PNG_MAX_SIDE) {
        png_image_free(&im);
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "a PNG of %u x %u pixels (at most %d)",
                            im.width, im.height, AG_IMAGE_PNG_MAX_SIDE);
    }
    im.format = PNG_FORMAT_RGBA;
    uint8_t *buf = malloc(PNG_IMAGE_SIZE(im));
    if (!buf) {
        png_image_free(&im);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory decoding a PNG");
    }
    if (!png_image_finish_read(&im, NULL, buf, 0, NULL)) {
        ag_status s = ag_error_set(err, AG_ERR_PARSE, 0, "a broken PNG: %s", im.message);
        free(buf);
        png_image_free(&im);
        return s;
    }
    out->width = im.width;
    out->height = im.height;
    out->rgba = buf;
    return AG_OK;
}
