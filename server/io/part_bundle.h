/* Part bundles (.agpart): one self-contained JSON file holding one part or a whole library
 * (schema/part_bundle.md). Terminals are OBJ texts keyed by the SHA-256 of their content and
 * shared between the bundle's parts; each part's grammar names them as
 * "terminals/<sha256>.obj", a key into the bundle, never a file: reading a bundle opens
 * nothing but the bundle.
 *
 * A bundle is untrusted input: reading checks everything and refuses the whole bundle at the
 * first problem, with the element named in err->text ("parts[0].grammar:12:3: ...",
 * "terminals.<hash>: line 4: ..."): bad JSON (line and column), an unknown format or version,
 * a missing or tampered terminal, a terminal OBJ with bad indices, rules that apply each other,
 * names that are not identifiers, sizes past the limits below. */
#ifndef AG_PART_BUNDLE_H
#define AG_PART_BUNDLE_H

#include <jansson.h>
#include <stddef.h>

#include "../core/parts/part.h"
#include "../core/status.h"

#define AG_PART_BUNDLE_FORMAT "archgram-part-bundle"
#define AG_PART_BUNDLE_VERSION 1
#define AG_PART_BUNDLE_MAX_BYTES (256u << 20)
#define AG_PART_BUNDLE_MAX_PARTS 10000
#define AG_PART_BUNDLE_MAX_TERMINALS 1000000
#define AG_PART_BUNDLE_MAX_NODES 1000000
#define AG_PART_BUNDLE_MAX_TRIANGLES 50000000
#define AG_PART_BUNDLE_MAX_ATTRS 256

/* The bundle text of n parts; *out malloc'd, NUL-terminated. */
ag_status ag_part_bundle_write(const ag_part *const *parts, size_t n, char **out, size_t *len,
                               ag_error *err);
/* The pieces of a bundle, for a library that keeps parts one by one (app/part_library.h):
 * one part's entry of "parts" (a new object) with its terminals added to `terminals` (an
 * object: SHA-256 hex -> OBJ text, each content once); and the bundle text of a "parts" array
 * and a "terminals" object, printed as ag_part_bundle_write prints it, terminals in the order
 * of their hashes (so entries kept and put together again give the same bytes). */
ag_status ag_part_bundle_entry(const ag_part *p, json_t *terminals, json_t **entry,
                               ag_error *err);
/* The entry as compact JSON text (*out malloc'd, NUL-terminated), as a library stores it:
 * written directly, every real as the shortest decimal that reads back to it; the same
 * members and values as ag_part_bundle_entry (which reads this text back). A name or text
 * that is not valid UTF-8, or a box that is not finite, is AG_ERR_INVALID naming it. */
ag_status ag_part_bundle_entry_text(const ag_part *p, json_t *terminals, char **out,
                                    size_t *len, ag_error *err);
ag_status ag_part_bundle_print(json_t *parts, json_t *terminals, char **out, size_t *len,
                               ag_error *err);
/* Writes the bundle to path through a temporary file renamed into place: on failure nothing
 * is left at path. */
ag_status ag_part_bundle_write_file(const ag_part *const *parts, size_t n, const char *path,
                                    ag_error *err);

/* Reads a bundle: *parts (malloc'd array of *n parts) or nothing. */
ag_status ag_part_bundle_read(const char *data, size_t len, ag_part ***parts, size_t *n,
                              ag_error *err);
ag_status ag_part_bundle_read_file(const char *path, ag_part ***parts, size_t *n, ag_error *err);
void ag_part_bundle_free(ag_part **parts, size_t n);

#endif
