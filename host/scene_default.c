/* The default scene of a bare mesh (docs/scenes.md, "A mesh instead of a scene
 * file"): what `cbvh trace` and `cbvh sweep` use when given a mesh file or
 * proc:NAME instead of a scene file, so the per-mesh figures of
 * docs/results.md come from one command each. */
#include <stdio.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "scene_file.h"
#include "scene_load.h"

static int has_suffix(const char *s, const char *suf) {
    size_t n = strlen(s), m = strlen(suf);
    return n >= m && strcmp(s + n - m, suf) == 0;
}

int cbvh_scene_arg_is_mesh(const char *arg) {
    return !(has_suffix(arg, ".scene") || has_suffix(arg, ".json"));
}

static cJSON *vec3(float x, float y, float z) {
    const double v[3] = {x, y, z};
    return cJSON_CreateDoubleArray(v, 3);
}

int cbvh_scene_file_default(const char *mesh, cbvh_scene_desc *d, char *err, size_t errlen) {
    memset(d, 0, sizeof *d);
    cbvh_scene s;
    if (cbvh_scene_open(mesh, &s, err, errlen)) return -1;
    float lo[3], hi[3], c[3], ext = 0;
    cbvh_scene_bounds(&s, lo, hi);
    cbvh_scene_free(&s);
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5f * lo[a] + 0.5f * hi[a];
        if (hi[a] - lo[a] > ext) ext = hi[a] - lo[a];
    }
    /* The scene file's mesh path is looked up beside the file; the "file"
     * here is the mesh itself, so name it by its last path component. */
    const char *slash = strrchr(mesh, '/');
    const char *name = strncmp(mesh, "proc:", 5) == 0 || !slash ? mesh : slash + 1;
    cJSON *root = cJSON_CreateObject(), *cam = cJSON_CreateObject(), *lights = cJSON_CreateArray();
    cJSON *light = cJSON_CreateObject(), *mats = cJSON_CreateArray(), *mat = cJSON_CreateObject();
    cJSON *floor_ = cJSON_CreateObject(), *fx = cJSON_CreateArray(), *ao = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "mesh", name);
    /* camera above and in front of the centre, looking at it (y up) */
    cJSON_AddStringToObject(cam, "type", "pinhole");
    cJSON_AddNumberToObject(cam, "width", 256);
    cJSON_AddNumberToObject(cam, "height", 192);
    cJSON_AddItemToObject(cam, "position", vec3(c[0] + 0.45f * ext, c[1] + 0.35f * ext, c[2] + 1.9f * ext));
    cJSON_AddItemToObject(cam, "target", vec3(c[0], c[1], c[2]));
    cJSON_AddItemToObject(cam, "up", vec3(0, 1, 0));
    cJSON_AddNumberToObject(cam, "fov", 35);
    cJSON_AddItemToObject(root, "camera", cam);
    cJSON_AddStringToObject(light, "type", "point");
    cJSON_AddItemToObject(light, "position", vec3(c[0] + ext, c[1] + 2 * ext, c[2] + ext));
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
    cJSON_AddNumberToObject(ao, "distance", 0.2 * ext);
    cJSON_AddItemToArray(fx, ao);
    cJSON_AddItemToObject(root, "effects", fx);
    cJSON_AddNumberToObject(root, "seed", 1);
    char *text = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    if (!text) {
        snprintf(err, errlen, "%s: cannot form its default scene (out of memory)", mesh);
        return -1;
    }
    int rc = cbvh_scene_file_parse(text, mesh, d, err, errlen);
    cJSON_free(text);
    return rc;
}

int cbvh_scene_file_open(const char *arg, cbvh_scene_desc *d, char *err, size_t errlen) {
    return cbvh_scene_arg_is_mesh(arg) ? cbvh_scene_file_default(arg, d, err, errlen)
                                       : cbvh_scene_file_load(arg, d, err, errlen);
}
