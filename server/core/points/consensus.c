#include "consensus.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/kdtree.h"
#include "../proc/label.h"
#include "normals.h"
#include "resample.h"

/* The surfaces' areas for the thinning target are compared as cells of this many spacings
 * occupied (large enough that a sampled surface leaves hardly a cell empty). */
#define AREA_CELL 4.0

void ag_consensus_model_clear(ag_consensus_model *m)
{
    if (!m)
        return;
    ag_cloud_free(m->points);
    free(m->members);
    memset(m, 0, sizeof *m);
}

ag_status ag_consensus_build(const ag_cloud *c, const uint32_t *idx, const uint32_t *start,
                             const ag_box *boxes, size_t k, const double *offsets,
                             const ag_consensus_options *o, ag_consensus_model *out,
                             ag_error *err)
{
    memset(out, 0, sizeof *out);
    if (!k)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a consensus needs members");
    if (!c->normals)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a consensus needs the cloud's normals");
    if (!(o->spacing > 0))
        return ag_error_set(err, AG_ERR_INVALID, 0, "a consensus needs the point spacing");
    double max_rms = o->max_rms > 0 ? o->max_rms : 1.5 * o->spacing;
    double min_in = o->min_inliers > 0 ? o->min_inliers : 0.6;
    out->members = calloc(k, sizeof *out->members);
    if (!out->members)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    out->nmembers = k;
    size_t base = 0, total = 0;
    for (size_t j = 0; j < k; j++) {
        size_t m = start[j + 1] - start[j];
        total += m;
        if (m > start[base + 1] - start[base])
            base = j;
    }
    out->base = base;
    const uint32_t *bidx = idx + start[base];
    size_t nb = start[base + 1] - start[base];
    out->points_before = nb;
    out->mean_before = (double)total / (double)k;
    if (!nb)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a consensus needs points");

    /* the base: positions and normals together, a tree over them */
    double *bxyz = malloc(3 * nb * sizeof *bxyz);
    float *bn = malloc(3 * nb * sizeof *bn);
    ag_kdtree *tree = NULL;
    double *pool = NULL;
    uint32_t *src = NULL, *keep = NULL, *from = NULL;
    ag_cloud *cm = NULL;
    ag_status st = AG_OK;
    if (!bxyz || !bn) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < nb; i++) {
        memcpy(bxyz + 3 * i, c->xyz + 3 * (size_t)bidx[i], 3 * sizeof *bxyz);
        memcpy(bn + 3 * i, c->normals + 3 * (size_t)bidx[i], 3 * sizeof *bn);
    }
    if ((st = ag_kdtree_build(bxyz, NULL, nb, &tree, err)) != AG_OK)
        goto done;
    ag_register_base rb = {bxyz, bn, nb, tree, boxes[base]};
    out->members[base].merged = 1;
    ag_box_centre(&boxes[base], out->members[base].reg.pivot);
    out->members[base].reg.inliers = 1;
    size_t pooled = nb;
    for (size_t j = 0; j < k; j++) {
        if (j == base)
            continue;
        size_t m = start[j + 1] - start[j];
        if (!m)
            continue;
        ag_register_options ro = {.samples = o->samples, .spacing = o->spacing};
        if (offsets) {
            ro.has_offset = 1;
            memcpy(ro.offset, offsets + 3 * j, sizeof ro.offset);
        }
        ag_consensus_member *mb = &out->members[j];
        if ((st = ag_register_member(&rb, c->xyz, idx + start[j], m, &boxes[j], &ro, &mb->reg,
                                     err)) != AG_OK)
            goto done;
        mb->merged = mb->reg.rms <= max_rms && mb->reg.inliers >= min_in;
        if (mb->merged)
            pooled += m;
    }
    /* the pool: the base and the merged members in the base's coordinates */
    pool = malloc(3 * pooled * sizeof *pool);
    src = malloc(pooled * sizeof *src);
    keep = malloc(pooled * sizeof *keep);
    from = malloc(pooled * sizeof *from);
    if (!pool || !src || !keep || !from) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    size_t at = 0;
    for (size_t jj = 0; jj < k; jj++) {
        /* the base first: the thinning keeps its points where it has them */
        size_t j = jj == 0 ? base : jj <= base ? jj - 1 : jj;
        if (!out->members[j].merged)
            continue;
        out->merged++;
        for (uint32_t s = start[j]; s < start[j + 1]; s++) {
            const double *p = c->xyz + 3 * (size_t)idx[s];
            if (j == base)
                memcpy(pool + 3 * at, p, 3 * sizeof *pool);
            else
                ag_register_apply(&out->members[j].reg, p, pool + 3 * at);
            from[at] = (uint32_t)j;
            src[at++] = idx[s];
        }
    }
    out->pooled = pooled;
    /* the target: the base's density over the pooled surface */
    size_t target = nb;
    if (out->merged > 1) {
        double h = AREA_CELL * o->spacing;
        size_t occ_base, occ_pool;
        const double *origin = boxes[base].min;
        if ((st = ag_resample_occupied(bxyz, NULL, nb, h, origin, &occ_base, err)) != AG_OK)
            goto done;
        /* the pool's area measured at one member's density (every merged-th point, a few
         * phases averaged): the whole pool, merged times denser, would also fill the cells a
         * slanted surface only grazes, which one member mostly misses */
        size_t stride = out->merged, phases = stride < 4 ? stride : 4, occ_sum = 0;
        for (size_t ph = 0; ph < phases; ph++) {
            size_t ns = 0;
            for (size_t i = ph; i < pooled; i += stride)
                keep[ns++] = (uint32_t)i;
            if ((st = ag_resample_occupied(pool, keep, ns, h, origin, &occ_pool, err)) != AG_OK)
                goto done;
            occ_sum += occ_pool;
        }
        double occ_mean = (double)occ_sum / (double)phases;
        target = (size_t)llround((double)nb * occ_mean / (double)(occ_base ? occ_base : 1));
        if (target < nb)
            target = nb;
    }
    size_t nkeep;
    if ((st = ag_resample_thin(pool, pooled, target, keep, &nkeep, &out->cell, err)) != AG_OK)
        goto done;
    /* the kept points with their properties, at their pooled positions */
    for (size_t i = 0; i < nkeep; i++)
        src[i] = src[keep[i]];
    if ((st = ag_cloud_subset(c, src, nkeep, &cm, err)) != AG_OK)
        goto done;
    for (size_t i = 0; i < nkeep; i++) {
        memcpy(cm->xyz + 3 * i, pool + 3 * (size_t)keep[i], 3 * sizeof *cm->xyz);
        /* the input normal turned with its member: the orientation the new ones follow */
        float *nv = cm->normals + 3 * i;
        double x = nv[0], y = nv[1];
        ag_label_rotate(out->members[from[keep[i]]].reg.turn, &x, &y);
        nv[0] = (float)x;
        nv[1] = (float)y;
    }
    out->box = ag_cloud_box(cm);
    out->points_after = nkeep;
    /* kNN normals of the consensus itself */
    if (nkeep >= 3) {
        ag_kdtree *ct;
        if ((st = ag_kdtree_build(cm->xyz, NULL, nkeep, &ct, err)) != AG_OK)
            goto done;
        float *keepn = cm->normals;
        cm->normals = NULL;
        ag_normals_options no = {0};
        st = ag_normals_compute(cm, ct, &no, NULL, NULL, NULL, err);
        ag_kdtree_free(ct);
        if (st != AG_OK) {
            cm->normals = keepn;
            goto done;
        }
        for (size_t i = 0; i < nkeep; i++) {
            float *nv = cm->normals + 3 * i, *ov = keepn + 3 * i;
            if (nv[0] * ov[0] + nv[1] * ov[1] + nv[2] * ov[2] < 0)
                for (int a = 0; a < 3; a++)
                    nv[a] = -nv[a];
        }
        free(keepn);
    }
    out->points = cm;
    cm = NULL;
done:
    ag_cloud_free(cm);
    ag_kdtree_free(tree);
    free(bxyz);
    free(bn);
    free(pool);
    free(src);
    free(keep);
    free(from);
    if (st != AG_OK) {
        ag_consensus_model_clear(out);
    }
    return st;
}
