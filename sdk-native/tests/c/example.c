/*
 * A C client of the splitstream C ABI (include/splitstream.h), built and run
 * by tests/c_abi.rs.
 *
 *   example decode STREAM.sps   decodes the stream progressively (head
 *                               first, then each level's byte range;
 *                               levels 0, 3, ... whole, levels 1, 4, ...
 *                               round by round, levels 2, 5, ... whole on
 *                               two threads) and
 *                               prints "ok HASH VERTICES TRIANGLES" or
 *                               "error CLASS: MESSAGE".
 *   example grid                simplifies two synthetic tiles and prints
 *                               "grid CELLS RECTANGLES TRIANGLES RATIO".
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "splitstream.h"

static int fail(void) {
    printf("error %s: %s\n", ss_last_error_class(), ss_last_error_message());
    return 0;
}

static unsigned char *read_file(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *buf = malloc(n > 0 ? (size_t)n : 1);
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    *len = (size_t)n;
    return buf;
}

static int decode(const char *path) {
    size_t len = 0;
    unsigned char *stream = read_file(path, &len);
    if (!stream) {
        fprintf(stderr, "cannot read %s\n", path);
        return 2;
    }
    /* What a network client does: 96 bytes, then the head, then levels. */
    size_t head = 0;
    if (ss_head_len(stream, len < 96 ? len : 96, &head) != SS_STATUS_OK) {
        free(stream);
        return fail();
    }
    SsDecoder *d = NULL;
    if (ss_decoder_open(stream, head < len ? head : len, &d) != SS_STATUS_OK) {
        free(stream);
        return fail();
    }
    /* A memory budget: the levels that fit; one byte holds none. */
    SsDecoder *tiny = NULL;
    if (ss_decoder_open_within(stream, head < len ? head : len, 1, &tiny) != SS_STATUS_CAPACITY_EXCEEDED
        || tiny != NULL) {
        fprintf(stderr, "a 1-byte budget accepted\n");
        return 3;
    }
    if (ss_decoder_levels_that_fit(d) != ss_decoder_level_count(d)) {
        fprintf(stderr, "a full decoder holds fewer levels than the stream\n");
        return 3;
    }
    /* How many levels a viewer 500 units away needs (2 pixels, 1080 p,
       60 degrees); a field of view of 4 radians is no camera. */
    uint16_t needed = 0;
    if (ss_decoder_level_for_screen_error(d, 1080.0f, 1.0472f, 500.0f, 2.0f, &needed) != SS_STATUS_OK)
        goto failed;
    if (ss_decoder_level_for_screen_error(d, 1080.0f, 4.0f, 500.0f, 2.0f, &needed) != SS_STATUS_INVALID_ARGUMENT) {
        fprintf(stderr, "a field of view of 4 radians accepted\n");
        return 3;
    }
    int32_t k;
    while ((k = ss_decoder_next_level(d)) >= 0) {
        SsLevelInfo info;
        if (ss_decoder_level_info(d, (uint16_t)k, &info) != SS_STATUS_OK) goto failed;
        const unsigned char *bytes = stream + (info.offset < len ? info.offset : len);
        if (info.offset + info.length > len) {
            /* The bytes are not all there (a cut file, a short range
               response): the decoder refuses what there is without failing,
               so a client may fetch the level again; here the stream is
               truncated. */
            size_t have = info.offset < len ? (size_t)(len - info.offset) : 0;
            if (ss_decoder_decode_level(d, (uint16_t)k, bytes, have) != SS_STATUS_INVALID_ARGUMENT
                || ss_decoder_next_level(d) != k) {
                fprintf(stderr, "a short level was not refused, or failed the decoder\n");
                return 3;
            }
            printf("error truncated: %s\n", ss_last_error_message());
            ss_decoder_free(d);
            free(stream);
            return 0;
        }
        if (k % 3 == 0) {
            if (ss_decoder_decode_level(d, (uint16_t)k, bytes, info.length) != SS_STATUS_OK)
                goto failed;
        } else if (k % 3 == 2) {
            if (ss_decoder_decode_level_two_threads(d, (uint16_t)k, bytes, info.length) !=
                SS_STATUS_OK)
                goto failed;
        } else {
            if (ss_decoder_begin_level(d, (uint16_t)k, bytes, info.length) != SS_STATUS_OK)
                goto failed;
            bool decoded = true;
            while (decoded) {
                if (ss_decoder_next_round(d, &decoded) != SS_STATUS_OK) goto failed;
                /* A viewer would draw here: positions and triangles are live. */
                (void)ss_decoder_positions(d);
            }
        }
    }
    uint32_t nv = ss_decoder_vertex_count(d), nt = ss_decoder_triangle_count(d);
    /* Every triangle index is a vertex; real positions are finite. */
    const uint32_t *tri = ss_decoder_triangles(d);
    for (size_t i = 0; i < 3 * (size_t)nt; i++) {
        if (tri[i] >= nv) {
            fprintf(stderr, "triangle index out of range\n");
            return 3;
        }
    }
    double *real = malloc(sizeof(double) * 3 * (nv ? nv : 1));
    if (ss_decoder_positions_f64(d, real, 3 * (size_t)nv) != SS_STATUS_OK) goto failed;
    for (size_t i = 0; i < 3 * (size_t)nv; i++) {
        if (!isfinite(real[i])) {
            fprintf(stderr, "non-finite position\n");
            return 3;
        }
    }
    /* A buffer too short is refused, not overrun. */
    if (nv > 0 && ss_decoder_positions_f64(d, real, 3 * (size_t)nv - 1) != SS_STATUS_INVALID_ARGUMENT) {
        fprintf(stderr, "short buffer accepted\n");
        return 3;
    }
    free(real);
    printf("ok %016llx %u %u\n", (unsigned long long)ss_decoder_state_hash(d), nv, nt);
    ss_decoder_free(d);
    free(stream);
    return 0;
failed:
    fail();
    ss_decoder_free(d);
    free(stream);
    return 0;
}

static int grid(void) {
    enum { N = 65 };
    static double h[N * N];
    SsGridSimplifier *s = ss_grid_new(N, N);
    for (int pass = 0; pass < 2; pass++) {
        for (int r = 0; r < N; r++)
            for (int c = 0; c < N; c++)
                h[r * N + c] = pass == 0 ? 3.0 + 0.5 * c - 0.25 * r
                                         : 40.0 * sin(c * 32.0 / 170.0) * cos(r * 32.0 / 230.0);
        SsGridTile tile = {N, N, h, {32.0, 32.0}, {0.0, 0.0}};
        SsGridParams params = {700.0, {0.0, 64.0, 0.0, 0.0}, {1, 1, 1, 1}};
        SsGridStats stats;
        if (ss_grid_simplify(s, &tile, &params, &stats) != SS_STATUS_OK) return fail();
        size_t nv = 0, nt = 0;
        const double *pos = ss_grid_positions(s, &nv);
        const uint32_t *tri = ss_grid_triangles(s, &nt);
        if (!pos || !tri || nv != stats.vertices_after || nt != stats.triangles_after) {
            fprintf(stderr, "result does not match the stats\n");
            return 3;
        }
        for (size_t i = 0; i < 3 * nt; i++)
            if (tri[i] >= nv) return 3;
        printf("grid %zu %zu %zu %.6f\n", stats.cells, stats.rectangles, stats.triangles_after,
               stats.max_error_ratio);
    }
    /* Bad input is reported, not crashed on. */
    SsGridTile bad = {1, 1, h, {32.0, 32.0}, {0.0, 0.0}};
    SsGridParams params = {700.0, {0}, {0}};
    if (ss_grid_simplify(s, &bad, &params, NULL) != SS_STATUS_GRID_TILE) return 3;
    printf("error %s: %s\n", ss_last_error_class(), ss_last_error_message());
    ss_grid_free(s);
    return 0;
}

int main(int argc, char **argv) {
    if (argc == 3 && strcmp(argv[1], "decode") == 0) return decode(argv[2]);
    if (argc == 2 && strcmp(argv[1], "grid") == 0) return grid();
    fprintf(stderr, "usage: %s decode STREAM.sps | grid\n", argv[0]);
    return 2;
}
