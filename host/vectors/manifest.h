/* DIR/MANIFEST: the SHA-256 of every vector file (libvpx test-vector style).
 * One line per file, sorted by name, in sha256sum's format so that
 * `cd DIR && sha256sum -c MANIFEST` also works:
 *     <64 lower-case hex digits><two spaces><file name> */
#ifndef CBVH_HOST_MANIFEST_H
#define CBVH_HOST_MANIFEST_H

#include <stddef.h>

#define CBVH_MANIFEST_NAME "MANIFEST"
#define CBVH_SHA256_HEX_LEN 64
#define CBVH_MANIFEST_MAX_NAME 200

typedef struct {
    char name[CBVH_MANIFEST_MAX_NAME + 1];
    char sha256[CBVH_SHA256_HEX_LEN + 1];
} cbvh_manifest_entry;

typedef struct {
    cbvh_manifest_entry *e;
    size_t n, cap;
    /* Entries taken from the journal (cbvh_manifest_load_journaled), and the
     * first one's name, for the note that says so. */
    size_t from_journal;
    char from_journal_name[CBVH_MANIFEST_MAX_NAME + 1];
} cbvh_manifest;

/* DIR/.MANIFEST.pending: gen's journal.  Under the directory lock gen writes
 * the new entry here, renames the file into place, rewrites MANIFEST, then
 * removes the journal; so a gen killed between the rename and the manifest
 * update (SIGKILL, a crash) leaves a file the journal vouches for.  Readers
 * accept it (cbvh_manifest_load_journaled); the next gen settles it into
 * MANIFEST (cbvh_manifest_settle). */
#define CBVH_MANIFEST_JOURNAL ".MANIFEST.pending"

/* SHA-256 of a buffer as lower-case hex (libcrypto EVP).  0 or -1. */
int cbvh_sha256_hex(const void *buf, size_t len, char hex[CBVH_SHA256_HEX_LEN + 1]);

/* 0 if buf (the contents of path) hashes to want, else -1 with the one-line
 * reason in err (a mismatch, or libcrypto failing). */
int cbvh_sha256_check(const char *path, const void *buf, size_t len, const char *want, char *err, size_t errlen);

/* Strict parse of a manifest held in memory; name is used in messages
 * ("name:line: what").  0 or -1 with err set; m is empty on error. */
int cbvh_manifest_parse(const char *buf, size_t len, const char *name, cbvh_manifest *m, char *err, size_t errlen);

/* Loads DIR/MANIFEST.  Returns 0, 1 when the file does not exist (m empty),
 * -1 on any other error (err set). */
int cbvh_manifest_load(const char *dir, cbvh_manifest *m, char *err, size_t errlen);

/* cbvh_manifest_load, then every journal entry whose file now has the
 * SHA-256 the journal gives replaces the manifest's (counted in
 * m->from_journal).  0, 1 when neither lists anything, -1 with err set. */
int cbvh_manifest_load_journaled(const char *dir, cbvh_manifest *m, char *err, size_t errlen);

/* Writes the journal: one entry (name, sha256), temp file + fsync + rename. */
int cbvh_manifest_journal_write(const char *dir, const char *name, const char *sha256, char *err, size_t errlen);
void cbvh_manifest_journal_remove(const char *dir);

/* Under the lock, with m just loaded: a journal left by a killed gen is
 * applied to m, MANIFEST rewritten and the journal removed.  0 or -1. */
int cbvh_manifest_settle(const char *dir, cbvh_manifest *m, char *err, size_t errlen);

const cbvh_manifest_entry *cbvh_manifest_find(const cbvh_manifest *m, const char *name);

/* Adds or replaces the entry for name.  0 or -1 (bad name / no memory). */
int cbvh_manifest_set(cbvh_manifest *m, const char *name, const char *sha256);

/* Writes DIR/MANIFEST sorted by name, through a temp file and rename. */
int cbvh_manifest_save(const char *dir, cbvh_manifest *m, char *err, size_t errlen);

/* Exclusive flock(2) on DIR itself, held by `vectors gen` around each
 * read-merge-write of DIR/MANIFEST (re-read under the lock), so that gens
 * running in parallel into one directory keep each other's entries.  Blocks
 * until granted; returns the fd for cbvh_manifest_unlock (which ignores -1),
 * or -1 with err set. */
int cbvh_manifest_lock(const char *dir, char *err, size_t errlen);
void cbvh_manifest_unlock(int fd);

/* Is name a temporary file of gen or cbvh_manifest_save (".NAME.tmp.PID")? */
int cbvh_manifest_is_temp(const char *name);

/* Counts such temporary files in dir (left by a killed gen); the path of the
 * first one found goes to first. */
size_t cbvh_manifest_find_temps(const char *dir, char *first, size_t firstlen);

/* Verifies a directory: DIR/MANIFEST exists and parses, every listed file is
 * present with a matching SHA-256, and no .vec file in DIR is unlisted.
 * On success m holds the manifest (caller frees).  0 or -1 with err set. */
int cbvh_manifest_verify_dir(const char *dir, cbvh_manifest *m, char *err, size_t errlen);

void cbvh_manifest_free(cbvh_manifest *m);

/* Is name acceptable as a manifest entry (plain file name, printable, no '/')? */
int cbvh_manifest_name_ok(const char *name, size_t n);

#endif
