/* Import throughput: OBJ parsing (MB/s per file) and GLB encoding, on the shared real
 * data sets when present and on generated ~200k-triangle files. Prints figures only. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>

#include "core/demo_building.h"
#include "io/glb.h"
#include "io/obj.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static double total_parse_s, total_glb_s, total_mb;
static size_t total_tris, nfiles;

static int bench_file(const char *path, ag_up_axis up)
{
    struct stat sb;
    if (stat(path, &sb) != 0)
        return -1;
    double mb = sb.st_size / 1e6;
    ag_obj_read_options o = {.up = up};
    ag_mesh *m;
    ag_error e;
    double t0 = now();
    ag_status st = ag_obj_read_file(path, &o, &m, &e);
    double t1 = now();
    if (st != AG_OK) {
        printf("  %-40s FAILED: %s\n", path, e.text);
        return -1;
    }
    uint8_t *glb;
    size_t len;
    double t2 = now();
    st = ag_glb_write(m, &glb, &len, &e);
    double t3 = now();
    if (st == AG_OK)
        free(glb);
    const char *name = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    printf("  %-32s %8.2f MB %9zu tris %6zu comps  parse %7.1f ms %7.1f MB/s  glb %6.1f ms "
           "(%.1f MB)\n",
           name, mb, m->ntris, m->ncomponents, (t1 - t0) * 1e3, mb / (t1 - t0), (t3 - t2) * 1e3,
           len / 1e6);
    total_parse_s += t1 - t0;
    total_glb_s += t3 - t2;
    total_mb += mb;
    total_tris += m->ntris;
    nfiles++;
    ag_mesh_free(m);
    return 0;
}

static int cmp(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static void bench_dir(const char *dir, ag_up_axis up)
{
    DIR *d = opendir(dir);
    if (!d) {
        printf("%s: absent, skipped\n", dir);
        return;
    }
    printf("%s:\n", dir);
    char *names[4096];
    size_t n = 0;
    struct dirent *de;
    while ((de = readdir(d)) && n < 4096) {
        size_t l = strlen(de->d_name);
        if (l > 4 && !strcmp(de->d_name + l - 4, ".obj"))
            names[n++] = strdup(de->d_name);
    }
    closedir(d);
    qsort(names, n, sizeof *names, cmp);
    for (size_t i = 0; i < n; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        bench_file(path, up);
        free(names[i]);
    }
}

/* Rows of demo buildings until at least min_tris triangles, written with typical
 * exporter precision (4 decimals) so the parse speed is representative. */
static int write_city(const char *path, size_t min_tris)
{
    ag_mesh *b[2] = {ag_demo_building(0), ag_demo_building(1)};
    if (!b[0] || !b[1])
        return -1;
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    size_t tris = 0, base = 0;
    fprintf(f, "# archgram bench: a generated city of demo buildings, y up\n");
    for (int k = 0; tris < min_tris; k++) {
        const ag_mesh *m = b[k % 2];
        double ox = (k % 40) * 20.0, oy = (k / 40) * 20.0;
        fprintf(f, "o building_%d\n", k);
        for (size_t i = 0; i < m->nverts; i++) {
            const double *p = m->pos + 3 * i;
            fprintf(f, "v %.4f %.4f %.4f\n", p[0] + ox, p[2], -(p[1] + oy));
        }
        for (size_t t = 0; t < m->ntris; t++) {
            const uint32_t *v = m->tri + 3 * t;
            fprintf(f, "f %zu %zu %zu\n", base + v[0] + 1, base + v[1] + 1, base + v[2] + 1);
        }
        base += m->nverts;
        tris += m->ntris;
    }
    ag_mesh_free(b[0]);
    ag_mesh_free(b[1]);
    return fclose(f);
}

int main(void)
{
    double t0 = now();
    bench_dir(AG_REPO_DIR "/../shared/data/meshes_0ad", AG_UP_Y);
    bench_dir(AG_REPO_DIR "/../shared/data/lod3_ingolstadt/obj", AG_UP_Z);

    printf("generated:\n");
    const char *city = "/tmp/archgram_bench_city.obj";
    if (write_city(city, 200000) == 0) {
        bench_file(city, AG_UP_Y);
        /* The same mesh written by archgram itself (%.17g: exact, long numbers). */
        ag_mesh *m;
        ag_error e;
        if (ag_obj_read_file(city, NULL, &m, &e) == AG_OK) {
            const char *exact = "/tmp/archgram_bench_city_exact.obj";
            double w0 = now();
            if (ag_obj_write_file(m, AG_UP_Y, exact, &e) == AG_OK) {
                double w1 = now();
                printf("  write %%.17g OBJ: %.1f ms\n", (w1 - w0) * 1e3);
                bench_file(exact, AG_UP_Y);
                remove(exact);
            }
            ag_mesh_free(m);
        }
        remove(city);
    } else {
        printf("  cannot write %s\n", city);
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("total: %zu files, %.1f MB, %zu triangles; parse %.3f s (%.1f MB/s), glb %.3f s; "
           "wall %.3f s; peak RSS %.1f MB\n",
           nfiles, total_mb, total_tris, total_parse_s, total_mb / total_parse_s, total_glb_s,
           now() - t0, ru.ru_maxrss / 1024.0);
    return 0;
}
