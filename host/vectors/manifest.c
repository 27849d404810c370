/* DIR/MANIFEST of the vector files: SHA-256 per file (libcrypto EVP). */
#include "vectors/manifest.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <unistd.h>

#include <openssl/evp.h>

#include "vectors/vecfile.h"

int cbvh_sha256_hex(const void *buf, size_t len, char hex[CBVH_SHA256_HEX_LEN + 1]) {
    unsigned char md[EVP_MAX_MD_SIZE];
    unsigned int mdlen = 0;
    EVP_MD_CTX *ctx = EVP_MD_CTX_new();
    int ok = ctx && EVP_DigestInit_ex(ctx, EVP_sha256(), NULL) == 1 && EVP_DigestUpdate(ctx, buf, len) == 1 &&
             EVP_DigestFinal_ex(ctx, md, &mdlen) == 1 && mdlen == 32;
    EVP_MD_CTX_free(ctx);
    if (!ok) return -1;
    for (unsigned i = 0; i < 32; i++) snprintf(hex + 2 * i, 3, "%02x", md[i]);
    return 0;
}

int cbvh_manifest_name_ok(const char *name, size_t n) {
    if (n == 0 || n > CBVH_MANIFEST_MAX_NAME || name[0] == '.') return 0;
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)name[i];
        if (c <= 0x20 || c >= 0x7F || c == '/' || c == '\\') return 0;
    }
    return 1;
}

void cbvh_manifest_free(cbvh_manifest *m) {
    free(m->e);
    m->e = NULL;
    m->n = m->cap = 0;
    m->from_journal = 0;
    m->from_journal_name[0] = '\0';
}

const cbvh_manifest_entry *cbvh_manifest_find(const cbvh_manifest *m, const char *name) {
    for (size_t i = 0; i < m->n; i++)
        if (strcmp(m->e[i].name, name) == 0) return &m->e[i];
    return NULL;
}

int cbvh_sha256_check(const char *path, const void *buf, size_t len, const char *want, char *err, size_t errlen) {
    char hex[CBVH_SHA256_HEX_LEN + 1];
    if (cbvh_sha256_hex(buf, len, hex) != 0) {
        snprintf(err, errlen, "%s: SHA-256 failed (libcrypto)", path);
        return -1;
    }
    if (strcmp(hex, want) != 0) {
        snprintf(err, errlen, "%s: SHA-256 mismatch: MANIFEST says %.12s..., file has %.12s...", path, want, hex);
        return -1;
    }
    return 0;
}

int cbvh_manifest_set(cbvh_manifest *m, const char *name, const char *sha256) {
    size_t n = strlen(name);
    if (!cbvh_manifest_name_ok(name, n) || strlen(sha256) != CBVH_SHA256_HEX_LEN) return -1;
    cbvh_manifest_entry *e = (cbvh_manifest_entry *)cbvh_manifest_find(m, name);
    if (!e) {
        if (m->n == m->cap) {
            size_t cap = m->cap ? m->cap * 2 : 64;
            cbvh_manifest_entry *ne = realloc(m->e, cap * sizeof *ne);
            if (!ne) return -1;
            m->e = ne;
            m->cap = cap;
        }
        e = &m->e[m->n++];
        memcpy(e->name, name, n + 1);
    }
    memcpy(e->sha256, sha256, CBVH_SHA256_HEX_LEN + 1);
    return 0;
}

int cbvh_manifest_parse(const char *buf, size_t len, const char *name, cbvh_manifest *m, char *err, size_t errlen) {
    memset(m, 0, sizeof *m);
    size_t pos = 0, line = 0;
    while (pos < len) {
        line++;
        const char *s = buf + pos;
        const char *nl = memchr(s, '\n', len - pos);
        if (!nl) {
            snprintf(err, errlen, "%s:%zu: last line has no newline (truncated file?)", name, line);
            goto bad;
        }
        size_t n = (size_t)(nl - s);
        pos += n + 1;
        if (n && s[n - 1] == '\r') {
            snprintf(err, errlen, "%s:%zu: line ends in CR (Windows line endings); MANIFEST lines end in \\n only",
                     name, line);
            goto bad;
        }
        int hex_ok = n > CBVH_SHA256_HEX_LEN + 2 && s[CBVH_SHA256_HEX_LEN] == ' ' && s[CBVH_SHA256_HEX_LEN + 1] == ' ';
        for (size_t i = 0; hex_ok && i < CBVH_SHA256_HEX_LEN; i++)
            hex_ok = (s[i] >= '0' && s[i] <= '9') || (s[i] >= 'a' && s[i] <= 'f');
        if (!hex_ok) {
            snprintf(err, errlen, "%s:%zu: malformed line (expected '<64 lower-case hex digits>  <file name>')", name,
                     line);
            goto bad;
        }
        const char *fn = s + CBVH_SHA256_HEX_LEN + 2;
        size_t fnn = n - CBVH_SHA256_HEX_LEN - 2;
        if (!cbvh_manifest_name_ok(fn, fnn)) {
            snprintf(err, errlen, "%s:%zu: bad file name (plain printable names without '/' only)", name, line);
            goto bad;
        }
        char fname[CBVH_MANIFEST_MAX_NAME + 1], hex[CBVH_SHA256_HEX_LEN + 1];
        memcpy(fname, fn, fnn);
        fname[fnn] = '\0';
        memcpy(hex, s, CBVH_SHA256_HEX_LEN);
        hex[CBVH_SHA256_HEX_LEN] = '\0';
        if (cbvh_manifest_find(m, fname)) {
            snprintf(err, errlen, "%s:%zu: %s is listed twice", name, line, fname);
            goto bad;
        }
        if (cbvh_manifest_set(m, fname, hex) != 0) {
            snprintf(err, errlen, "%s:%zu: out of memory", name, line);
            goto bad;
        }
    }
    return 0;
bad:
    cbvh_manifest_free(m);
    return -1;
}

static void join(char *dst, size_t n, const char *dir, const char *name) { snprintf(dst, n, "%s/%s", dir, name); }

/* Loads DIR/fname: 0, 1 when it does not exist (m empty), -1 with err set. */
static int load_named(const char *dir, const char *fname, cbvh_manifest *m, char *err, size_t errlen) {
    memset(m, 0, sizeof *m);
    char path[4096];
    join(path, sizeof path, dir, fname);
    if (access(path, F_OK) != 0 && errno == ENOENT) return 1;
    char *buf;
    size_t len;
    if (cbvh_read_file(path, &buf, &len, err, errlen) != 0)
        return access(path, F_OK) != 0 && errno == ENOENT ? 1 : -1; /* removed since (a journal) */
    int rc = cbvh_manifest_parse(buf, len, path, m, err, errlen);
    free(buf);
    return rc;
}

int cbvh_manifest_load(const char *dir, cbvh_manifest *m, char *err, size_t errlen) {
    return load_named(dir, CBVH_MANIFEST_NAME, m, err, errlen);
}

static int by_name(const void *a, const void *b) {
    return strcmp(((const cbvh_manifest_entry *)a)->name, ((const cbvh_manifest_entry *)b)->name);
}

static int save_named(const char *dir, const char *fname, cbvh_manifest *m, char *err, size_t errlen) {
    if (m->n) qsort(m->e, m->n, sizeof *m->e, by_name);
    char path[4096], tmp[4200];
    join(path, sizeof path, dir, fname);
    snprintf(tmp, sizeof tmp, "%s/.%s.tmp.%ld", dir, fname, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        snprintf(err, errlen, "%s: cannot create: %s", tmp, strerror(errno));
        return -1;
    }
    for (size_t i = 0; i < m->n; i++) fprintf(f, "%s  %s\n", m->e[i].sha256, m->e[i].name);
    /* On disk before the rename: a crash must not leave an empty file. */
    int bad = fflush(f) != 0 || fsync(fileno(f)) != 0;
    bad |= ferror(f);
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, path) != 0) {
        snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errno));
        remove(tmp);
        return -1;
    }
    return 0;
}

int cbvh_manifest_save(const char *dir, cbvh_manifest *m, char *err, size_t errlen) {
    return save_named(dir, CBVH_MANIFEST_NAME, m, err, errlen);
}

int cbvh_manifest_journal_write(const char *dir, const char *name, const char *sha256, char *err, size_t errlen) {
    cbvh_manifest j = {0};
    if (cbvh_manifest_set(&j, name, sha256) != 0) {
        snprintf(err, errlen, "%.900s/%s: bad name or out of memory", dir, name);
        return -1;
    }
    int rc = save_named(dir, CBVH_MANIFEST_JOURNAL, &j, err, errlen);
    cbvh_manifest_free(&j);
    return rc;
}

void cbvh_manifest_journal_remove(const char *dir) {
    char path[4096];
    join(path, sizeof path, dir, CBVH_MANIFEST_JOURNAL);
    unlink(path);
}

/* Journal entries whose file now hashes to them go into m (the rename
 * happened; the manifest update did not).  Returns 1 when there is no
 * journal, 0 or -1 as cbvh_manifest_load. */
static int apply_journal(const char *dir, cbvh_manifest *m, char *err, size_t errlen) {
    cbvh_manifest j;
    int rc = load_named(dir, CBVH_MANIFEST_JOURNAL, &j, err, errlen);
    if (rc != 0) return rc;
    for (size_t i = 0; i < j.n && rc == 0; i++) {
        char path[4096], hex[CBVH_SHA256_HEX_LEN + 1], why[512];
        join(path, sizeof path, dir, j.e[i].name);
        char *buf;
        size_t len;
        if (access(path, F_OK) != 0 && errno == ENOENT) continue; /* a new file, never renamed into place */
        if (cbvh_read_file(path, &buf, &len, why, sizeof why) != 0) {
            snprintf(err, errlen, "%s (listed in %s)", why, CBVH_MANIFEST_JOURNAL);
            rc = -1;
            break;
        }
        int hrc = cbvh_sha256_hex(buf, len, hex);
        free(buf);
        if (hrc != 0) {
            snprintf(err, errlen, "%s: SHA-256 failed (libcrypto)", path);
            rc = -1;
        } else if (strcmp(hex, j.e[i].sha256) == 0) {
            const cbvh_manifest_entry *e = cbvh_manifest_find(m, j.e[i].name);
            if (e && strcmp(e->sha256, hex) == 0) continue; /* the manifest was updated too */
            if (cbvh_manifest_set(m, j.e[i].name, hex) != 0) {
                snprintf(err, errlen, "out of memory");
                rc = -1;
            } else if (m->from_journal++ == 0) {
                snprintf(m->from_journal_name, sizeof m->from_journal_name, "%s", j.e[i].name);
            }
        }
    }
    cbvh_manifest_free(&j);
    return rc;
}

int cbvh_manifest_load_journaled(const char *dir, cbvh_manifest *m, char *err, size_t errlen) {
    int rc = cbvh_manifest_load(dir, m, err, errlen);
    if (rc < 0) return -1;
    int jrc = apply_journal(dir, m, err, errlen);
    if (jrc < 0) {
        cbvh_manifest_free(m);
        return -1;
    }
    return rc == 1 && m->n == 0 ? 1 : 0;
}

int cbvh_manifest_settle(const char *dir, cbvh_manifest *m, char *err, size_t errlen) {
    int rc = apply_journal(dir, m, err, errlen);
    if (rc == 1) return 0;
    if (rc < 0 || cbvh_manifest_save(dir, m, err, errlen) != 0) return -1;
    cbvh_manifest_journal_remove(dir);
    return 0;
}

int cbvh_manifest_lock(const char *dir, char *err, size_t errlen) {
    /* The directory itself is locked, so no lock file is left behind. */
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) {
        snprintf(err, errlen, "%s: cannot open to lock: %s", dir, strerror(errno));
        return -1;
    }
    int rc;
    while ((rc = flock(fd, LOCK_EX)) != 0 && errno == EINTR) {
    }
    if (rc != 0) {
        snprintf(err, errlen, "%s: cannot lock: %s", dir, strerror(errno));
        close(fd);
        return -1;
    }
    return fd;
}

void cbvh_manifest_unlock(int fd) {
    if (fd >= 0) close(fd); /* closing drops the flock */
}

int cbvh_manifest_is_temp(const char *name) {
    const char *t = name[0] == '.' ? strstr(name + 1, ".tmp.") : NULL;
    if (!t || t == name + 1 || !t[5]) return 0;
    for (t += 5; *t; t++)
        if (*t < '0' || *t > '9') return 0;
    return 1;
}

size_t cbvh_manifest_find_temps(const char *dir, char *first, size_t firstlen) {
    if (firstlen) first[0] = '\0';
    DIR *d = opendir(dir);
    if (!d) return 0;
    size_t n = 0;
    struct dirent *de;
    while ((de = readdir(d)) != NULL) {
        if (!cbvh_manifest_is_temp(de->d_name)) continue;
        if (n++ == 0 && firstlen) snprintf(first, firstlen, "%s/%s", dir, de->d_name);
    }
    closedir(d);
    return n;
}

static int ends_with(const char *s, const char *suffix) {
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && strcmp(s + n - k, suffix) == 0;
}

int cbvh_manifest_verify_dir(const char *dir, cbvh_manifest *m, char *err, size_t errlen) {
    char path[4096];
    int rc = cbvh_manifest_load_journaled(dir, m, err, errlen);
    if (rc == 1) {
        join(path, sizeof path, dir, CBVH_MANIFEST_NAME);
        snprintf(err, errlen, "%s: missing (every vector directory needs a MANIFEST)", path);
        return -1;
    }
    if (rc != 0) return -1;
    if (m->n == 0) {
        join(path, sizeof path, dir, CBVH_MANIFEST_NAME);
        snprintf(err, errlen, "%s: lists no files", path);
        goto bad;
    }
    for (size_t i = 0; i < m->n; i++) {
        join(path, sizeof path, dir, m->e[i].name);
        char *buf;
        size_t len;
        char why[512];
        if (cbvh_read_file(path, &buf, &len, why, sizeof why) != 0) {
            snprintf(err, errlen, "%s (listed in MANIFEST)", why);
            goto bad;
        }
        int hrc = cbvh_sha256_check(path, buf, len, m->e[i].sha256, err, errlen);
        free(buf);
        if (hrc != 0) goto bad;
    }
    DIR *d = opendir(dir);
    if (!d) {
        snprintf(err, errlen, "%s: cannot list directory: %s", dir, strerror(errno));
        goto bad;
    }
    struct dirent *de;
    while ((de = readdir(d)) != NULL) {
        if (de->d_name[0] != '.' && ends_with(de->d_name, ".vec") && !cbvh_manifest_find(m, de->d_name)) {
            join(path, sizeof path, dir, de->d_name);
            snprintf(err, errlen, "%s: vector file not listed in MANIFEST", path);
            closedir(d);
            goto bad;
        }
    }
    closedir(d);
    return 0;
bad:
    cbvh_manifest_free(m);
    return -1;
}
