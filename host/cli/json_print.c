/* One way to print a --json document (cli/commands.h). */
#include <stdio.h>
#include <stdlib.h>

#include <cjson/cJSON.h>

#include "cbvh/oom.h"
#include "cli/commands.h"

void cbvh_json_print(cJSON *root, int pretty, const char *what) {
    char *text = pretty ? cJSON_Print(root) : cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    if (!text) cbvh_out_of_memory(what);
    cbvh_json_fputs_utf8(text, stdout); /* file names may hold bytes that are not UTF-8 */
    putchar('\n');
    free(text);
}
