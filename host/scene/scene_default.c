/* The default scene of a bare mesh (docs/scenes.md, "A mesh instead of a scene
 * file"): what `cbvh trace` and `cbvh sweep` use when given a mesh file or
 * proc:NAME instead of a scene file, so the per-mesh figures of
 * docs/results.md come from one command each. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "scene/scene_file.h"

static int has_suffix(const char *s, const char *suf) {
    size_t n = strlen(s), m = strlen(suf);
    return n >= m && strcmp(s + n - m, suf) == 0;
}

/* 1 unless arg ends in .scene or .json. */
static int arg_is_mesh(const char *arg) {
    return !(has_suffix(arg, ".scene") || has_suffix(arg, ".json"));
}

static cJSON *vec3(float x, float y, float z) {
    const double v[3] = {x, y, z};
    return cJSON_CreateDoubleArray(v, 3);
}

int cbvh_scene_file_default(const char *mesh, cbvh_scene_desc *d, char *err, size_t errlen) {
    /* The scene file's mesh path is looked up beside the file; the "file"
     * here is the mesh itself, so name it by its last path component.  The
     * camera, light and AO distance depend on the mesh's box: placeholders
     * here, set below from the mesh the parser has loaded (loaded once). */
    const char *slash = strrchr(mesh, '/');
    const char *name = strncmp(mesh, "proc:", 5) == 0 || !slash ? mesh : slash + 1;
    cJSON *root = cJSON_CreateObject(), *cam = cJSON_CreateObject(), *lights = cJSON_CreateArray();
    cJSON *light = cJSON_CreateObject(), *mats = cJSON_CreateArray(), *mat = cJSON_CreateObject();
    cJSON *floor_ = cJSON_CreateObject(), *fx = cJSON_CreateArray(), *ao = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "mesh", name);
    cJSON_AddStringToObject(cam, "type", "pinhole");
    cJSON_AddNumberToObject(cam, "width", 256);
    cJSON_AddNumberToObject(cam, "height", 192);
    cJSON_AddItemToObject(cam, "position", vec3(0, 0, 1));
    cJSON_AddItemToObject(cam, "target", vec3(0, 0, 0));
    cJSON_AddItemToObject(cam, "up", vec3(0, 1, 0));
    cJSON_AddNumberToObject(cam, "fov", 35);
    cJSON_AddItemToObject(root, "camera", cam);
    cJSON_AddStringToObject(light, "type", "point");
    cJSON_AddItemToObject(light, "position", vec3(0, 0, 0));
    cJSON_AddItemToArray(lights, light);
    cJSON_AddItemToObject(root, "lights", lights);
    cJSON_AddStringToObject(mat, "name", "diffuse");
    cJSON_AddStringToObject(mat, "type", "diffuse");
    cJSON_AddItemToArray(mats, mat);
    cJSON_AddItemToObject(root, "materials", mats);
    cJSON_AddStringToObject(root, "mesh_material", "diffuse");
    cJSON_AddStringToObject(floor_, "material", "diffuse");
    cJSON_AddNumberToObject(floor_, "size", 3);
    cJSON_AddItemToObject(root, "floor", floor_);
    cJSON_AddItemToArray(fx, cJSON_CreateString("primary"));
    cJSON_AddItemToArray(fx, cJSON_CreateString("hard_shadows"));
    cJSON_AddStringToObject(ao, "effect", "ambient_occlusion");
    cJSON_AddNumberToObject(ao, "samples", 2);
    cJSON_AddItemToArray(fx, ao);
    cJSON_AddItemToObject(root, "effects", fx);
    cJSON_AddNumberToObject(root, "seed", 1);
    char *text = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    if (!text) {
        memset(d, 0, sizeof *d);
        snprintf(err, errlen, "%s: cannot form its default scene (out of memory)", mesh);
        return -1;
    }
    int rc = cbvh_scene_file_parse(text, mesh, d, err, errlen);
    cJSON_free(text);
    if (rc) return -1;
    /* the mesh's own box (the floor follows its triangles) */
    cbvh_scene m = d->mesh;
    m.ntris = d->mesh_tris;
    float lo[3], hi[3], c[3], ext = 0;
    cbvh_scene_bounds(&m, lo, hi);
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5f * lo[a] + 0.5f * hi[a];
        if (hi[a] - lo[a] > ext) ext = hi[a] - lo[a];
    }
    if (!(ext > 0)) { /* a point or empty mesh: no view direction */
        snprintf(err, errlen, "%s: the mesh has no extent; no default camera", mesh);
        cbvh_scene_desc_free(d);
        return -1;
    }
    const float cam_off[3] = {0.45f, 0.35f, 1.9f}, light_off[3] = {1, 2, 1};
    for (int a = 0; a < 3; a++) {
        d->camera.position[a] = c[a] + cam_off[a] * ext;
        d->camera.target[a] = c[a];
        d->lights[0].position[a] = c[a] + light_off[a] * ext;
    }
    d->effect[CBVH_FX_AMBIENT_OCCLUSION].distance = 0.2f * ext;
    /* A mesh spanning most of binary32 (|x| near 3e38) puts the floor, camera
     * and light beyond it; say so here rather than let the scene check blame
     * a floor triangle the user never wrote. */
    int finite = isfinite(ext);
    for (uint32_t t = d->mesh_tris; t < d->mesh.ntris; t++)
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) finite &= isfinite(d->mesh.tris[t].v[v][a]) != 0;
    for (int a = 0; a < 3; a++)
        finite &= isfinite(d->camera.position[a]) && isfinite(d->lights[0].position[a]);
    if (!finite) {
        snprintf(err, errlen,
                 "%s: the mesh is too large for its default scene (extent %g: the floor, camera or light would "
                 "overflow binary32); write a scene file for it",
                 mesh, (double)ext);
        cbvh_scene_desc_free(d);
        return -1;
    }
    return 0;
}

int cbvh_scene_file_open(const char *arg, cbvh_scene_desc *d, char *err, size_t errlen) {
    if (!*arg) { /* e.g. an unset shell variable: "" would be reported as a scene file without a path */
        memset(d, 0, sizeof *d);
        snprintf(err, errlen, "empty scene argument (a scene file, a mesh file or proc:NAME)");
        return -1;
    }
    return arg_is_mesh(arg) ? cbvh_scene_file_default(arg, d, err, errlen)
                                       : cbvh_scene_file_load(arg, d, err, errlen);
}
