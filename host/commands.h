/* Subcommands of the cbvh tool: one file each (cmd_<name>.c).  Each takes
 * argc/argv starting at its own name, handles --help, and returns the process
 * exit status. */
#ifndef CBVH_HOST_COMMANDS_H
#define CBVH_HOST_COMMANDS_H

int cmd_vectors(int argc, char **argv); /* cmd_vectors.c: gen | check */
int cmd_run(int argc, char **argv);     /* cmd_run.c: the main job */

int cmd_devices(int argc, char **argv);   /* cmd_devices.c: boards per backend */
int cmd_board_sim(int argc, char **argv); /* cmd_board_sim.c: the virtual board */
int cmd_study(int argc, char **argv);     /* cmd_study.c: backtracking/memory-traffic study (issue 3) */
int cmd_trace(int argc, char **argv);     /* cmd_trace.c: trace the effects a scene file calls for (issue 4) */
int cmd_sweep(int argc, char **argv);     /* cmd_sweep.c: accuracy vs time over N x M x min scale (issue 4) */

/* getopt_long reported an unknown option or a missing value (call with
 * opterr = 0): one line naming it, instead of getopt's own message (which
 * names the subcommand as if it were the program) and the whole usage. */
int cbvh_bad_option(const char *cmd, char **argv, int optind_now); /* main.c; returns 2 */

#endif
