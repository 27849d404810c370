/* Scene loading for the host tool: mesh files through assimp, or procedural
 * scenes by name.  Every failure is a one-line message in err and -1. */
#ifndef CBVH_HOST_SCENE_LOAD_H
#define CBVH_HOST_SCENE_LOAD_H

#include <stddef.h>

#include "cbvh/scene.h"

/* Import a mesh file (OBJ, PLY, OFF, STL, glTF/GLB, ... anything assimp
 * reads): all meshes, node transforms applied, triangles only, plus glTF
 * morph targets and the first morph animation.  Rejects a missing file or
 * one that is not a regular file, unreadable/malformed data (OFF and PLY
 * records checked against their header first), out-of-range indices, faces
 * assimp dropped, non-finite vertices, and files without triangles. */
int cbvh_scene_import(const char *path, cbvh_scene *out, char *err, size_t errlen);

/* The time cbvh_scene_import gives the importer before it is stopped as
 * hung, in ms: 5 s plus 1 s per MB of the file and, for glTF (.gltf, .glb),
 * of the distinct files its buffers and images name by relative URI (read
 * with cJSON; JSON that does not parse, holds a NUL or is over 256 MiB
 * counts the file's own size only). */
long long cbvh_scene_import_limit_ms(const char *path);

/* Procedural scenes (names for cbvh_scene_open); size 0 = the default, a
 * size outside the range is an error:
 *   cloth      finely tessellated plane at z = -0.4 (degenerate z axis) with a
 *              draped bump in the middle; `size` = grid cells per side (0: 256;
 *              1..20000)
 *   far        small sphere (radius 0.01) far from the origin (~(1000,-2000,3000));
 *              `size` = sphere segments (0: 48; 4..4096)
 *   instanced  grid of sphere instances, >= 10M triangles for size 0
 *              (size = instances per side; 40 -> 10.2M triangles; 1..200)
 *   wave       a grid surface for the procedural twist/wave refit; `size` =
 *              grid cells per side (0: 64; 1..20000) */
int cbvh_scene_procedural(const char *name, unsigned size, cbvh_scene *out, char *err, size_t errlen);

/* One entry point: "proc:NAME[:SIZE]" -> procedural, anything else -> file. */
int cbvh_scene_open(const char *spec, cbvh_scene *out, char *err, size_t errlen);

#endif
