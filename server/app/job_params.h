/* The parameters of each job kind, typed: made once where the job is asked for (REST, the
 * demo content), stored with the job's row as JSON (ag_job_params_encode, the one place they
 * are written) and handed to the kind's run function as they are. ag_job_params_decode reads
 * a row's JSON back (the same names), so what the store shows is what ran. */
#ifndef AG_JOB_PARAMS_H
#define AG_JOB_PARAMS_H

#include <stdint.h>

#include "../core/status.h"

typedef enum {
    AG_JOB_IMPORT = 1,
    AG_JOB_PROCEDURALIZE,
    AG_JOB_EXTRUDE,
    AG_JOB_DEMO_PARTS,
    AG_JOB_SEGMENT,
    AG_JOB_TEST, /* job kinds of tests: no parameters */
} ag_job_type;

/* An uploaded mesh file → a new model. */
typedef struct {
    char *upload;   /* the spooled file (the job removes it) */
    char *name;
    char *format;   /* NULL: sniffed */
    char *up;       /* "y", "z" or NULL */
    char *filename; /* the name it was uploaded as, or NULL */
} ag_import_job;

/* A model at version base → proceduralized, by author; exact: terminals shared by exact
 * copies only (every instance derives as it was); metres_per_unit: core/proc/units.h. */
typedef struct {
    int64_t model;
    int64_t base;
    char *author;
    int exact;
    double metres_per_unit; /* the mesh's length unit as the request named it; 0 = decided */
    char *cloud; /* a point cloud's options (app/points_proc_options.h) as JSON text, or NULL */
} ag_proceduralize_job;

/* A point cloud model at version base → segmented (§3.1), by author. Thresholds are
 * fractions of the cloud's diagonal, 0 = the defaults (core/points/segment_cloud.h). */
typedef struct {
    int64_t model;
    int64_t base;
    char *author;
    double threshold;         /* the refinement pass's plane threshold */
    double coarse_threshold;  /* the first pass's */
    double cluster_tolerance; /* T_C */
    int recompute_normals;
} ag_segment_job;

/* An uploaded building description, list of them or GeoJSON → a new extrusion model. */
typedef struct {
    char *upload;
    char *name;
    char *format;          /* "plan" | "buildings" | "geojson" | NULL (sniffed) */
    char *style;           /* a built-in style name */
    char *height_property; /* NULL: none */
    int64_t seed;          /* < 0: the style's own */
    int lonlat;            /* 1 lon/lat, -1 metres, 0 decided by the coordinates */
} ag_extrude_job;

/* The demo content's parts, saved from demo models once they are proceduralized. */
#define AG_DEMO_PARTS_MAX_MODELS 8
typedef struct {
    int64_t models[AG_DEMO_PARTS_MAX_MODELS];
    size_t n;
} ag_demo_parts_job;

typedef struct {
    ag_job_type type;
    /* the account that asks for the job (0: the server itself); kept in the job's row, not
     * in its params: it may read and cancel the job and owns the model the job makes */
    int64_t user;
    union {
        ag_import_job import;
        ag_proceduralize_job proceduralize;
        ag_extrude_job extrude;
        ag_demo_parts_job demo_parts;
        ag_segment_job segment;
    } u;
} ag_job_params;

/* The kind name a job of this type is stored under ("import", "proceduralize", "extrude",
 * "demo-parts", "segment");
 * test jobs name their own kind. */
const char *ag_job_params_kind(ag_job_type type);

/* JSON text for the job's row (malloc'd), NULL when out of memory. */
char *ag_job_params_encode(const ag_job_params *p);
/* The params of a row of the given kind. AG_ERR_INVALID naming what is missing. */
ag_status ag_job_params_decode(const char *kind, const char *json, ag_job_params *out,
                               ag_error *err);
/* A deep copy (the queue keeps one). */
ag_status ag_job_params_copy(ag_job_params *dst, const ag_job_params *src, ag_error *err);
void ag_job_params_clear(ag_job_params *p);

/* The uploaded file a job reads, NULL when it reads none. */
const char *ag_job_params_upload(const ag_job_params *p);

#endif
