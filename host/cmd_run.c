#include "commands.h"
#include <stdio.h>
int cmd_run(int argc, char **argv) { (void)argc; (void)argv; fprintf(stderr, "cbvh run: not written yet\n"); return 2; }
