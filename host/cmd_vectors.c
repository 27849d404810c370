#include "commands.h"
#include <stdio.h>
int cmd_vectors(int argc, char **argv) { (void)argc; (void)argv; fprintf(stderr, "cbvh vectors: not written yet\n"); return 2; }
