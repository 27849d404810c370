/* libFuzzer: scene files (host/scene/scene_file.c, docs/scenes.md).  An input that
 * is a JSON object gets its "mesh" replaced by a small procedural scene (so
 * no mesh file is read and no 10M-triangle scene built); every other field
 * is the fuzzer's.  Every input must give a scene description or a one-line
 * error naming the problem; never a crash. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "scene/scene_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *text = malloc(size + 1);
    if (!text) return 0;
    memcpy(text, data, size);
    text[size] = 0;
    cJSON *root = cJSON_Parse(text);
    if (cJSON_IsObject(root)) {
        cJSON_DeleteItemFromObjectCaseSensitive(root, "mesh");
        cJSON_AddStringToObject(root, "mesh", "proc:cloth:8");
        char *fixed = cJSON_PrintUnformatted(root);
        if (fixed) {
            free(text);
            text = fixed;
        }
    }
    cJSON_Delete(root);
    cbvh_scene_desc d;
    char err[512] = "";
    if (cbvh_scene_file_parse(text, "fuzz.scene", &d, err, sizeof err) == 0)
        cbvh_scene_desc_free(&d);
    else if (!err[0] || strchr(err, '\n'))
        abort(); /* every rejection names its reason, on one line */
    free(text);
    return 0;
}
