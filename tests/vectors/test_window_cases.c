/* The committed vectors pin the compressor's window check, OUTSIDE
 * (docs/datapath.md §6, docs/vectors.md "Generator 9").
 *
 * vectors_model checks every expected value against the model; this test
 * checks that the files hold the cases that make an RTL's window test
 * observable, so that a generator change cannot drop them unnoticed:
 *   - every axis_compress file: at least MIN_OUTSIDE vectors with OUTSIDE
 *     alone (not NO_FIT, which sets it too), at least MIN_INSIDE with status
 *     0 whose node_clb is not the box's own lower bound, and generator 9's
 *     84 node_clb NaN, signalling NaN and +Inf faults, each rejected as
 *     NAN_INF alone;
 *   - the example in the N = 3 file: node [0, 7] (window [0, 8) at
 *     scale 0), child [8, 8]: codes (0, 1) with OUTSIDE;
 *   - every nodepair_encode file: at least MIN_PAIR vectors with OUTSIDE
 *     alone.
 * Usage: test_window_cases VECTOR_DIR */
#include <dirent.h>
#include <stdio.h>
#include <string.h>

#include "cbvh/datapath.h"
#include "test_util.h"
#include "vectors/vecfile.h"

static int fails;
#define CHECK(c, ...) TU_CHECK(fails, stdout, c, __VA_ARGS__)

enum { MIN_OUTSIDE = 90, MIN_INSIDE = 100, NODE_FAULTS = 84, MIN_PAIR = 6 };

static void compressor_file(const char *path, const cbvh_vecfile *vf) {
    long outside = 0, inside = 0, nan_node = 0;
    for (size_t i = 0; i < vf->count; i++) {
        const uint32_t *in = vf->in + i * 4, *out = vf->out + i * 6;
        uint32_t st = out[5];
        if ((st & CBVH_ST_OUTSIDE) && !(st & CBVH_ST_NO_FIT)) outside++;
        if (st == 0 && in[3] != in[0]) inside++;
        if (cbvh_f32_is_nan_or_inf(in[3]) && in[3] != CBVH_F32_NEG_INF) {
            nan_node++;
            CHECK(st == CBVH_ST_NAN_INF, "%s:%zu: node_clb %08X: status %02X, expected NAN_INF alone", path,
                  vf->first_line + i, in[3], st);
        }
    }
    printf("%s: %ld OUTSIDE alone, %ld inside another window, %ld node_clb NaN/+Inf\n", path, outside, inside,
           nan_node);
    CHECK(outside >= MIN_OUTSIDE, "%s: %ld vectors with OUTSIDE alone, expected >= %d", path, outside, MIN_OUTSIDE);
    CHECK(inside >= MIN_INSIDE, "%s: %ld inside another window, expected >= %d", path, inside, MIN_INSIDE);
    CHECK(nan_node >= NODE_FAULTS, "%s: %ld node_clb NaN/+Inf vectors, expected >= %d", path, nan_node, NODE_FAULTS);
    if (vf->cfg.params.quant_bits != 3 || vf->cfg.params.min_scale != -30) return;
    int example = 0;
    for (size_t i = 0; i < vf->count; i++) {
        const uint32_t *in = vf->in + i * 4, *out = vf->out + i * 6;
        if (in[0] == 0x41000000u && in[1] == 0x41000000u && in[2] == 0 && in[3] == 0) /* [8, 8], e = 0, node_clb 0 */
            example |= out[0] == 0 && out[1] == 1 && out[5] == CBVH_ST_OUTSIDE;
    }
    CHECK(example, "%s: the example (node [0, 7], child [8, 8]: codes (0, 1), OUTSIDE) is missing", path);
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: test_window_cases VECTOR_DIR\n");
        return 2;
    }
    DIR *d = opendir(argv[1]);
    if (!d) {
        printf("FAIL cannot open %s\n", argv[1]);
        return 1;
    }
    int n_comp = 0, n_pair = 0;
    const struct dirent *de;
    while ((de = readdir(d))) {
        int comp = strncmp(de->d_name, "axis_compress-", 14) == 0, pair = strncmp(de->d_name, "nodepair_encode-", 16) == 0;
        if (!comp && !pair) continue;
        char path[4096], err[512];
        snprintf(path, sizeof path, "%s/%s", argv[1], de->d_name);
        cbvh_vecfile vf;
        if (cbvh_vecfile_load(path, &vf, err, sizeof err) != CBVH_VEC_OK) {
            printf("FAIL %s\n", err);
            fails++;
            continue;
        }
        if (comp) {
            n_comp++;
            compressor_file(path, &vf);
        } else {
            n_pair++;
            long outside = 0;
            for (size_t i = 0; i < vf.count; i++) {
                uint32_t st = vf.out[i * (size_t)vf.layout.n_out + (size_t)vf.layout.n_out - 1];
                outside += (st & CBVH_ST_OUTSIDE) && !(st & CBVH_ST_NO_FIT);
            }
            CHECK(outside >= MIN_PAIR, "%s: %ld pairs with OUTSIDE alone, expected >= %d", path, outside, MIN_PAIR);
        }
        cbvh_vecfile_free(&vf);
    }
    closedir(d);
    CHECK(n_comp == 10 && n_pair == 16, "%d compressor and %d node-pair encoder files, expected 10 and 16", n_comp, n_pair);
    printf("test_window_cases: %d compressor files, %d node-pair encoder files, %d failures\n", n_comp, n_pair, fails);
    return fails ? 1 : 0;
}
