/* cbvh vectors gen | check  (docs/vectors.md) */
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli/commands.h"
#include "vectors/manifest.h"
#include "util/parse_int.h"
#include "vectors/vecfile.h"
#include "vectors/vecgen.h"
#include "vectors/vectors_check.h"

static void usage_vectors(FILE *f) {
    fprintf(f, "usage: cbvh vectors <gen|check> [options]   (cbvh vectors <gen|check> --help)\n\n"
               "  gen    write golden vector files (inputs + model outputs) and DIR/MANIFEST\n"
               "  check  verify DIR/MANIFEST, run every vector on a backend, report mismatches\n"
               "\nExit status: 0 all pass, 1 mismatches, 2 bad input. Format: docs/vectors.md\n");
}

static void usage_gen(FILE *f) {
    fprintf(f,
            "usage: cbvh vectors gen [options] -o DIR\n\n"
            "Writes one file per unit and parameter set (e.g. axis_decode-N6-ms-30-modulo.vec) and\n"
            "adds/updates their SHA-256 lines in DIR/MANIFEST. Without --unit/--bits/--min-scale it\n"
            "writes the default set: every datapath unit x N=3..10 x both encodings (where the unit\n"
            "has one), min_scale -30, plus N=6 with min_scale -126 and -10 for the axis units; the\n"
            "units that do not depend on N (ray_box, ray_triangle, qbvh_stack, ray_sphere) get one file each (N=6),\n"
            "ray_box_incr one per N=3..10 (min_scale -30).\n\n"
            "  -u, --unit U           one unit (");
    for (int i = 0; i < cbvh_unit_count; i++) fprintf(f, "%s%s", i ? ", " : "", cbvh_units[i]->name);
    fprintf(f, ")\n"
               "  -l, --level 1|2        1: structured corner cases, random cases and, for the ray units,\n"
               "                         exact-path cases (default); 2: plus %d random vectors per file\n"
               "                         and %d more exact-path cases per ray file\n"
               "  -s, --seed S           generator seed, decimal or hex after 0x (default 0x%016" PRIX64 ")\n"
               "  -n, --bits N           coordinate bits, %d..%d (default: all)\n"
               "  -m, --min-scale E      minimum scale, %d..%d (default %d)\n"
               "  -e, --encoding E       modulo or relative (default: both)\n"
               "  -o, --output DIR       output directory (created if missing)\n"
               "  -h, --help             this text\n",
            CBVH_VECGEN_LEVEL2_RANDOM, CBVH_VECGEN_LEVEL2_EXACT, CBVH_VECGEN_DEFAULT_SEED, CBVH_N_MIN, CBVH_N_MAX, CBVH_SCALE_FLOOR,
            CBVH_SCALE_CEIL, CBVH_MIN_SCALE_DEFAULT);
}

static void usage_check(FILE *f) {
    fprintf(f, "usage: cbvh vectors check [options] DIR|FILE...\n\n"
               "For a directory, verifies DIR/MANIFEST first (every listed file present with a matching\n"
               "SHA-256, no unlisted .vec file), then runs every vector on the backend in batches of %d\n"
               "and prints 'N passed, M failed' per file, a total with the rate, and the first mismatches.\n\n"
               "  -b, --backend B        auto (default: board if found, else the model), model, usb, hid,\n"
               "                         or sim:ADDR (the virtual board: sim:unix:PATH, sim:tcp:HOST:PORT)\n"
               "  -M, --max-errors K     mismatches shown in full (default 20)\n"
               "  -s, --sample K         at most K vectors per file, evenly spread (for a slow board or\n"
               "                         a simulated FPGA; default: every vector)\n"
               "  -j, --json             one JSON object instead of text\n"
               "  -q, --quiet            no per-file lines for files that pass\n"
               "  -h, --help             this text\n"
               "\nExit status: 0 all pass, 1 mismatches, 2 bad input (unknown unit, bad header, bad hex,\n"
               "wrong field count, hash mismatch, missing file...).\n",
            CBVH_CHECK_BATCH);
}

/* ---- gen: every finished file listed at once, nothing half-written ------ */

/* The temp file being written, removed by the signal handler; empty when
 * none.  Its name and the message are prepared before they are needed, as
 * the handler may only call async-signal-safe functions. */
static char gen_tmp[4200];
static char gen_stop_msg[4400];

static void gen_on_signal(int sig) {
    if (gen_tmp[0]) unlink(gen_tmp);
    ssize_t w = write(STDERR_FILENO, gen_stop_msg, strlen(gen_stop_msg));
    (void)w;
    _exit(128 + sig);
}

/* SIGINT/SIGTERM held back while a file is renamed into place and listed, so
 * that an interrupt never falls between the two. */
static void gen_block_signals(int block) {
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    sigprocmask(block ? SIG_BLOCK : SIG_UNBLOCK, &set, NULL);
}

/* Writes one file to DIR/.NAME.tmp.PID (fsync'd) and hashes it;
 * then, under the directory lock, renames it into place and lists it in
 * DIR/MANIFEST (re-read just before, so parallel gens keep each other's
 * entries).  The manifest, or after a kill the journal, therefore always
 * vouches for every finished file. */
static int write_vecfile(const char *dir, const char *name, const cbvh_vecfile *vf, char *err, size_t errlen) {
    char path[4096], hex[CBVH_SHA256_HEX_LEN + 1];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    char *buf = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&buf, &len);
    if (!mem) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    int bad = cbvh_vecfile_write(mem, vf);
    bad |= fclose(mem) != 0;
    if (bad || cbvh_sha256_hex(buf, len, hex) != 0) {
        free(buf);
        snprintf(err, errlen, "%.900s: internal error formatting vectors", path);
        return -1;
    }
    gen_block_signals(1);
    snprintf(gen_tmp, sizeof gen_tmp, "%s/.%s.tmp.%ld", dir, name, (long)getpid());
    gen_block_signals(0);
    FILE *f = fopen(gen_tmp, "wb");
    if (!f) {
        free(buf);
        snprintf(err, errlen, "%.900s: cannot create: %s", gen_tmp, strerror(errno));
        gen_tmp[0] = '\0';
        return -1;
    }
    bad = fwrite(buf, 1, len, f) != len;
    bad |= fflush(f) != 0 || fsync(fileno(f)) != 0; /* data on disk before the rename makes it visible */
    bad |= fclose(f) != 0;
    free(buf);
    if (bad) {
        snprintf(err, errlen, "%.900s: cannot write: %s", path, strerror(errno));
        unlink(gen_tmp);
        gen_tmp[0] = '\0';
        return -1;
    }
    /* The manifest is read (and must parse) before the rename, so that a
     * file is only put in place when it can be listed. */
    gen_block_signals(1);
    int rc = -1, lock = cbvh_manifest_lock(dir, err, errlen);
    cbvh_manifest m;
    /* The journal names the new entry before the rename, so that a kill
     * between the rename and the manifest update leaves a vouched-for file. */
    if (lock >= 0 && cbvh_manifest_load(dir, &m, err, errlen) >= 0) {
        int ok = cbvh_manifest_settle(dir, &m, err, errlen) == 0;
        if (ok && cbvh_manifest_set(&m, name, hex) != 0) {
            snprintf(err, errlen, "%.900s: cannot list in MANIFEST (bad name or out of memory)", path);
            ok = 0;
        }
        ok = ok && cbvh_manifest_journal_write(dir, name, hex, err, errlen) == 0;
        if (ok && rename(gen_tmp, path) != 0) {
            snprintf(err, errlen, "%.900s: cannot write: %s", path, strerror(errno));
            cbvh_manifest_journal_remove(dir);
            ok = 0;
        }
        if (ok && (rc = cbvh_manifest_save(dir, &m, err, errlen)) == 0) cbvh_manifest_journal_remove(dir);
        cbvh_manifest_free(&m);
    }
    cbvh_manifest_unlock(lock);
    unlink(gen_tmp); /* gone after a rename; removed after a failure */
    gen_tmp[0] = '\0';
    gen_block_signals(0);
    return rc;
}

/* --seed: decimal, or hex after 0x; the whole string, no sign or blanks
 * (strtoull alone took "010" as octal and " -5" as 2^64 - 5). */
static int parse_seed(const char *s, uint64_t *out) {
    int hex = s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
    const char *d = hex ? s + 2 : s;
    size_t n = strspn(d, hex ? "0123456789abcdefABCDEF" : "0123456789");
    if (n == 0 || d[n]) return -1;
    char *end;
    errno = 0;
    unsigned long long v = strtoull(d, &end, hex ? 16 : 10);
    if (errno || *end) return -1;
    *out = (uint64_t)v;
    return 0;
}

static int cmd_gen(int argc, char **argv) {
    static const struct option lo[] = {
        {"unit", required_argument, 0, 'u'},   {"level", required_argument, 0, 'l'},
        {"seed", required_argument, 0, 's'},   {"bits", required_argument, 0, 'n'},
        {"min-scale", required_argument, 0, 'm'}, {"encoding", required_argument, 0, 'e'},
        {"output", required_argument, 0, 'o'}, {"help", no_argument, 0, 'h'},
        {0, 0, 0, 0}};
    cbvh_vecgen_select sel;
    memset(&sel, 0, sizeof sel);
    sel.level = 1;
    sel.seed = CBVH_VECGEN_DEFAULT_SEED;
    const char *dir = NULL;
    int c;
    long v;
    optind = 0;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "u:l:s:n:m:e:o:h", lo, NULL)) != -1) {
        switch (c) {
        case 'u':
            if (!(sel.unit = cbvh_unit_find(optarg))) {
                fprintf(stderr, "cbvh vectors gen: unknown unit '%s' (cbvh vectors gen --help lists them)\n", optarg);
                return 2;
            }
            break;
        case 'l':
            if (cbvh_parse_long(optarg, 1, 2, &v)) {
                fprintf(stderr, "cbvh vectors gen: --level must be 1 or 2, not '%s'\n", optarg);
                return 2;
            }
            sel.level = (int)v;
            break;
        case 's':
            if (parse_seed(optarg, &sel.seed) != 0) {
                fprintf(stderr, "cbvh vectors gen: --seed '%s' is not a 64-bit number (decimal, or hex after 0x)\n",
                        optarg);
                return 2;
            }
            break;
        case 'n':
            if (cbvh_parse_long(optarg, CBVH_N_MIN, CBVH_N_MAX, &v)) {
                fprintf(stderr, "cbvh vectors gen: --bits must be %d..%d, not '%s'\n", CBVH_N_MIN, CBVH_N_MAX, optarg);
                return 2;
            }
            sel.bits = (int)v;
            break;
        case 'm':
            if (cbvh_parse_long(optarg, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL, &v)) {
                fprintf(stderr, "cbvh vectors gen: --min-scale must be %d..%d, not '%s'\n", CBVH_SCALE_FLOOR,
                        CBVH_SCALE_CEIL, optarg);
                return 2;
            }
            sel.ms_given = 1;
            sel.min_scale = (int)v;
            break;
        case 'e':
            if (cbvh_encoding_parse(optarg, &sel.enc) != 0) {
                fprintf(stderr, "cbvh vectors gen: --encoding must be modulo or relative, not '%s'\n", optarg);
                return 2;
            }
            sel.enc_given = 1;
            break;
        case 'o': dir = optarg; break;
        case 'h': usage_gen(stdout); return 0;
        default: return cbvh_bad_option("cbvh vectors gen", argv, optind);
        }
    }
    if (optind < argc) {
        fprintf(stderr, "cbvh vectors gen: unexpected argument '%s'\n", argv[optind]);
        return 2;
    }
    if (!dir) {
        fprintf(stderr, "cbvh vectors gen: missing -o DIR\n");
        return 2;
    }
    if (sel.unit && sel.enc_given && !sel.unit->uses_encoding) {
        fprintf(stderr, "cbvh vectors gen: unit %s has no encoding; drop --encoding\n", sel.unit->name);
        return 2;
    }
    if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "cbvh vectors gen: cannot create %s: %s\n", dir, strerror(errno));
        return 2;
    }
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "cbvh vectors gen: %s exists and is not a directory\n", dir);
        return 2;
    }
    size_t n = cbvh_vecgen_specs(&sel, NULL, 0);
    cbvh_vecgen_spec *specs = calloc(n ? n : 1, sizeof *specs);
    if (!specs) return 2;
    cbvh_vecgen_specs(&sel, specs, n);

    char err[1024];
    /* A malformed MANIFEST (or journal) stops gen before it writes anything;
     * read under the lock, as another gen may be in its commit step. */
    cbvh_manifest m;
    int lock = cbvh_manifest_lock(dir, err, sizeof err);
    int loaded = lock >= 0 ? cbvh_manifest_load_journaled(dir, &m, err, sizeof err) : -1;
    cbvh_manifest_unlock(lock);
    if (loaded < 0) {
        fprintf(stderr, "cbvh vectors gen: %s%s\n", err, lock >= 0 ? " (fix or delete it)" : "");
        free(specs);
        return 2;
    }
    cbvh_manifest_free(&m);
    snprintf(gen_stop_msg, sizeof gen_stop_msg,
             "cbvh vectors gen: interrupted; the files finished before are listed in %.4000s/MANIFEST\n", dir);
    /* A signal ignored on entry (a background job of a script) stays ignored. */
    struct sigaction sa, old_int, old_term;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = gen_on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, NULL, &old_int);
    sigaction(SIGTERM, NULL, &old_term);
    if (old_int.sa_handler != SIG_IGN) sigaction(SIGINT, &sa, NULL);
    if (old_term.sa_handler != SIG_IGN) sigaction(SIGTERM, &sa, NULL);
    size_t total = 0;
    int rc = 0;
    for (size_t i = 0; i < n && rc == 0; i++) {
        char name[256];
        cbvh_vecgen_filename(&specs[i], name, sizeof name);
        cbvh_vecfile vf;
        if (cbvh_vecgen_generate(&specs[i], &vf) != 0) {
            fprintf(stderr, "cbvh vectors gen: %s: out of memory\n", name);
            rc = 2;
            break;
        }
        if (write_vecfile(dir, name, &vf, err, sizeof err) != 0) {
            fprintf(stderr, "cbvh vectors gen: %s\n", err);
            rc = 2;
        }
        total += vf.count;
        cbvh_vecfile_free(&vf);
    }
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
    if (rc == 0) printf("wrote %zu files, %zu vectors, to %s (MANIFEST updated)\n", n, total, dir);
    free(specs);
    return rc;
}

static int cmd_check(int argc, char **argv) {
    static const struct option lo[] = {{"backend", required_argument, 0, 'b'}, {"max-errors", required_argument, 0, 'M'},
                                       {"sample", required_argument, 0, 's'},
                                       {"json", no_argument, 0, 'j'},         {"quiet", no_argument, 0, 'q'},
                                       {"help", no_argument, 0, 'h'},         {0, 0, 0, 0}};
    cbvh_check_opts o;
    memset(&o, 0, sizeof o);
    o.backend = "auto";
    o.max_errors = 20;
    int c;
    long v;
    optind = 0;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "b:M:s:jqh", lo, NULL)) != -1) {
        switch (c) {
        case 'b': o.backend = optarg; break;
        case 'M':
            if (cbvh_parse_long(optarg, 0, INT_MAX, &v)) {
                fprintf(stderr, "cbvh vectors check: --max-errors must be a count >= 0, not '%s'\n", optarg);
                return 2;
            }
            o.max_errors = (int)v;
            break;
        case 's':
            if (cbvh_parse_long(optarg, 1, LONG_MAX, &v)) {
                fprintf(stderr, "cbvh vectors check: --sample must be a count >= 1, not '%s'\n", optarg);
                return 2;
            }
            o.sample = (size_t)v;
            break;
        case 'j': o.json = 1; break;
        case 'q': o.quiet = 1; break;
        case 'h': usage_check(stdout); return 0;
        default: return cbvh_bad_option("cbvh vectors check", argv, optind);
        }
    }
    if (optind >= argc) {
        fprintf(stderr, "cbvh vectors check: give a vector directory or file (e.g. vectors/)\n");
        return 2;
    }
    return cbvh_vectors_check((const char *const *)argv + optind, argc - optind, &o);
}

int cmd_vectors(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "cbvh vectors: give a subcommand, gen or check (cbvh vectors --help)\n");
        return 2;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        usage_vectors(stdout);
        return 0;
    }
    if (strcmp(argv[1], "gen") == 0) return cmd_gen(argc - 1, argv + 1);
    if (strcmp(argv[1], "check") == 0) return cmd_check(argc - 1, argv + 1);
    fprintf(stderr, "cbvh vectors: unknown subcommand '%s' (gen or check; cbvh vectors --help)\n", argv[1]);
    return 2;
}
