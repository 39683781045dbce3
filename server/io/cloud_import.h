/* Point cloud formats: detection and one entry point from bytes to an ag_cloud.
 *
 * A cloud is self-contained: every reader works on the buffer it is given and never opens
 * another file (LAS waveform data kept in external files is not read; PLY texture comments
 * are ignored), so a cloud uploaded over the network cannot make the server read a path. */
#ifndef AG_CLOUD_IMPORT_H
#define AG_CLOUD_IMPORT_H

#include <stddef.h>
#include <stdint.h>

#include "../core/points/cloud.h"
#include "../core/status.h"

typedef enum {
    AG_CLOUD_FORMAT_UNKNOWN = 0,
    AG_CLOUD_FORMAT_PLY,
    AG_CLOUD_FORMAT_LAS,
    AG_CLOUD_FORMAT_LAZ,
    AG_CLOUD_FORMAT_XYZ,
} ag_cloud_format;

/* "ply", "las", "laz", "xyz" (also "txt", "pts"); AG_CLOUD_FORMAT_UNKNOWN otherwise.
 * Case-insensitive. */
ag_cloud_format ag_cloud_format_from_name(const char *name);
const char *ag_cloud_format_name(ag_cloud_format f);

/* From the content (LASF signature and the compression bit; ply magic; lines of 3, 6 or 9
 * numbers); the file name's extension only for an empty .xyz/.txt/.pts file. */
ag_cloud_format ag_cloud_format_sniff(const uint8_t *data, size_t len, const char *filename);

/* Whether a file is a point cloud rather than a mesh: LAS, LAZ and XYZ always, PLY when its
 * header parses and declares no faces (one that does not parse is left to the mesh import). */
int ag_cloud_import_is_cloud(const uint8_t *data, size_t len, const char *filename);

/* How many points reading the data would make, from the header alone (LAS, LAZ, PLY) or an
 * upper bound (XYZ: its lines), so a caller with a budget can refuse a cloud before anything
 * is allocated. The reader's own error when the header does not parse; AG_ERR_UNSUPPORTED
 * when the format cannot be told. */
ag_status ag_cloud_import_count(const uint8_t *data, size_t len, ag_cloud_format fmt,
                                uint64_t *count, ag_error *err);

/* Reads a cloud; AG_CLOUD_FORMAT_UNKNOWN is sniffed. AG_ERR_UNSUPPORTED when the format
 * cannot be told, AG_ERR_EMPTY for no bytes. */
ag_status ag_cloud_import_buffer(const uint8_t *data, size_t len, ag_cloud_format fmt,
                                 ag_cloud **out, ag_error *err);
ag_status ag_cloud_import_file(const char *path, ag_cloud **out, ag_error *err);

#endif
