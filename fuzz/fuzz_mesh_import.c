/* libFuzzer: mesh import (host/scene/scene_import.c: the OFF and PLY checks, then
 * assimp).  The first byte picks the extension (OFF, PLY, OBJ, STL, glTF),
 * the rest is the file.  Every input must give either a scene of finite triangles or
 * a one-line error naming the problem; never a crash. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "scene/scene_load.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static const char *const ext[] = {"off", "ply", "obj", "stl", "gltf"};
    if (size < 1) return 0;
    char path[64];
    snprintf(path, sizeof path, "/tmp/cbvh_fuzz_mesh_%d.%s", (int)getpid(), ext[data[0] % 5]);
    FILE *f = fopen(path, "wb");
    if (!f) abort();
    if (size > 1 && fwrite(data + 1, 1, size - 1, f) != size - 1) abort();
    if (fclose(f)) abort();
    cbvh_scene s;
    char err[512] = "";
    if (cbvh_scene_import(path, &s, err, sizeof err) == 0) {
        if (s.ntris == 0 || !s.tris) abort(); /* "contains no triangles" is an error */
        for (uint32_t i = 0; i < s.ntris; i++)
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++)
                    if (!isfinite(s.tris[i].v[v][a])) abort(); /* non-finite vertices are an error */
        cbvh_scene_free(&s);
    } else if (!err[0] || strchr(err, '\n')) {
        abort(); /* every rejection names its reason, on one line */
    }
    unlink(path);
    return 0;
}
