/* The generator of tests/data/points/box_walls.{las,laz}: a 12 x 8 x 6 m box (four walls and a
 * flat roof) at RD New coordinates, 3000 points of LAS point format 3, the LAZ written by the
 * LASzip encoder of the unit tests (tests/unit/laz_encoder.h, through test_laz.c). Not built
 * by make; from the repository root:
 *   cc -std=c11 -D_GNU_SOURCE -DAG_REPO_DIR=\"$PWD\" -Itests/unit -Iserver tests/data/points/make_box_walls.c \
 *      build/lib/libag_io.a build/lib/libag_core.a -lcmocka -ljansson -lm -o /tmp/make_box_walls
 *   /tmp/make_box_walls tests/data/points/box_walls.las tests/data/points/box_walls.laz */
#define main test_laz_main
#include "test_laz.c"
#undef main
int main(int argc, char **argv)
{
    size_t n = 3000;
    uint16_t reclen = 34;
    uint8_t *recs = calloc(n, reclen);
    ag_rng g;
    ag_rng_seed(&g, 2024);
    double t = 312000.25;
    for (size_t i = 0; i < n; i++) {
        uint8_t *p = recs + i * reclen;
        double u = ag_rng_unit(&g), v = ag_rng_unit(&g), x, y, z;
        int face = (int)(i % 5);
        switch (face) {
        case 0: x = u * 12; y = 0; z = v * 6; break;
        case 1: x = 12; y = u * 8; z = v * 6; break;
        case 2: x = u * 12; y = 8; z = v * 6; break;
        case 3: x = 0; y = u * 8; z = v * 6; break;
        default: x = u * 12; y = v * 8; z = 6; break;
        }
        int32_t X = (int32_t)llround((85100.0 + x - 84000) / 0.001);
        int32_t Y = (int32_t)llround((446200.0 + y - 447000) / 0.001);
        int32_t Z = (int32_t)llround((1.0 + z) / 0.001);
        memcpy(p, &X, 4);
        memcpy(p + 4, &Y, 4);
        memcpy(p + 8, &Z, 4);
        uint16_t in = (uint16_t)(100 + ag_rng_below(&g, 3000));
        memcpy(p + 12, &in, 2);
        p[14] = (uint8_t)(1 | 1 << 3);
        p[15] = (uint8_t)(face == 4 ? 6 : i % 9 ? 6 : 1);
        p[16] = (uint8_t)(int8_t)((int)(i % 30) - 15);
        p[17] = 0;
        uint16_t ps = 37;
        memcpy(p + 18, &ps, 2);
        t += 1e-4 * (double)(1 + ag_rng_below(&g, 5));
        memcpy(p + 20, &t, 8);
        uint16_t rgb[3] = {(uint16_t)(face * 12000 + 500), (uint16_t)(40000 - face * 7000),
                           (uint16_t)(ag_rng_below(&g, 65535))};
        memcpy(p + 28, rgb, 6);
    }
    laz_layout L = {3, 0, 1, 1, 2, 0, 2, 1000, NULL, 0, 0};
    buf_t las = {0};
    las_header(&las, 3, reclen, (uint32_t)n, NULL, 0, NULL, 0);
    bput(&las, recs, n * reclen);
    buf_t laz = make_laz(&L, recs, n, reclen);
    FILE *f = fopen(argv[1], "wb"); fwrite(las.b, 1, las.n, f); fclose(f);
    f = fopen(argv[2], "wb"); fwrite(laz.b, 1, laz.n, f); fclose(f);
    printf("las %zu bytes, laz %zu bytes\n", las.n, laz.n);
    return 0;
}
