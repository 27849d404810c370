/* Mesh import through assimp's C API (one-line errors, nothing partial). */
#define _POSIX_C_SOURCE 200809L /* getline, stat */
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "scene/scene_load.h"
#include "util/json.h"

static void xform(const struct aiMatrix4x4 *m, const struct aiVector3D *v, float out[3]) {
    out[0] = m->a1 * v->x + m->a2 * v->y + m->a3 * v->z + m->a4;
    out[1] = m->b1 * v->x + m->b2 * v->y + m->b3 * v->z + m->b4;
    out[2] = m->c1 * v->x + m->c2 * v->y + m->c3 * v->z + m->c4;
}

/* Row-major copies: indexing past &m->a1 would be pointer arithmetic outside
 * the member a1, which C leaves undefined even though the fields are adjacent. */
static void to_rows(const struct aiMatrix4x4 *m, float x[16]) {
    const float v[16] = {m->a1, m->a2, m->a3, m->a4, m->b1, m->b2, m->b3, m->b4,
                         m->c1, m->c2, m->c3, m->c4, m->d1, m->d2, m->d3, m->d4};
    memcpy(x, v, sizeof v);
}

static struct aiMatrix4x4 mul(const struct aiMatrix4x4 *a, const struct aiMatrix4x4 *b) {
    float x[16], y[16], z[16];
    to_rows(a, x);
    to_rows(b, y);
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            float s = 0.0f;
            for (int k = 0; k < 4; k++) s += x[i * 4 + k] * y[k * 4 + j];
            z[i * 4 + j] = s;
        }
    struct aiMatrix4x4 r = {z[0], z[1], z[2],  z[3],  z[4],  z[5],  z[6],  z[7],
                            z[8], z[9], z[10], z[11], z[12], z[13], z[14], z[15]};
    return r;
}

typedef struct {
    const struct aiScene *sc;
    cbvh_scene *out;
    uint64_t ntris, other; /* triangles placed / non-triangle faces skipped */
    int pass;              /* 0: count, 1: fill */
    char *err;
    size_t errlen;
    int failed;
} walker;

/* Place mesh m under transform x: pass 0 counts and validates, pass 1 writes. */
static void place_mesh(walker *w, const struct aiMesh *m, const struct aiMatrix4x4 *x) {
    for (unsigned f = 0; f < m->mNumFaces && !w->failed; f++) {
        const struct aiFace *fc = &m->mFaces[f];
        if (fc->mNumIndices != 3) {
            w->other += w->pass == 0;
            continue;
        }
        for (int v = 0; v < 3; v++)
            if (fc->mIndices[v] >= m->mNumVertices) {
                snprintf(w->err, w->errlen, "mesh '%s' face %u: vertex index %u out of range (%u vertices)",
                         m->mName.data, f, fc->mIndices[v], m->mNumVertices);
                w->failed = 1;
                return;
            }
        if (w->pass == 1) {
            cbvh_scene *s = w->out;
            uint64_t t = w->ntris;
            for (int v = 0; v < 3; v++) {
                xform(x, &m->mVertices[fc->mIndices[v]], s->tris[t].v[v]);
                for (uint32_t j = 0; j < s->nmorph; j++) {
                    const struct aiVector3D *src = &m->mVertices[fc->mIndices[v]];
                    if (j < m->mNumAnimMeshes && m->mAnimMeshes[j]->mVertices &&
                        m->mAnimMeshes[j]->mNumVertices == m->mNumVertices)
                        src = &m->mAnimMeshes[j]->mVertices[fc->mIndices[v]];
                    xform(x, src, s->morph[(size_t)j * s->ntris + t].v[v]);
                }
            }
        }
        w->ntris++;
    }
}

static void walk(walker *w, const struct aiNode *n, struct aiMatrix4x4 parent, int depth) {
    if (w->failed) return;
    if (depth > 256) {
        snprintf(w->err, w->errlen, "node hierarchy deeper than 256 levels");
        w->failed = 1;
        return;
    }
    struct aiMatrix4x4 x = mul(&parent, &n->mTransformation);
    for (unsigned i = 0; i < n->mNumMeshes && !w->failed; i++) {
        if (n->mMeshes[i] >= w->sc->mNumMeshes) {
            snprintf(w->err, w->errlen, "node '%s' references mesh %u of %u", n->mName.data, n->mMeshes[i],
                     w->sc->mNumMeshes);
            w->failed = 1;
            return;
        }
        place_mesh(w, w->sc->mMeshes[n->mMeshes[i]], &x);
    }
    for (unsigned i = 0; i < n->mNumChildren; i++) walk(w, n->mChildren[i], x, depth + 1);
}

/* First morph animation channel -> key times (s) and weights. */
static int load_morph_keys(const struct aiScene *sc, cbvh_scene *s) {
    for (unsigned a = 0; a < sc->mNumAnimations; a++) {
        const struct aiAnimation *an = sc->mAnimations[a];
        if (!an->mNumMorphMeshChannels) continue;
        const struct aiMeshMorphAnim *ch = an->mMorphMeshChannels[0];
        if (!ch->mNumKeys) continue;
        double tps = an->mTicksPerSecond > 0 ? an->mTicksPerSecond : 1.0;
        s->nkeys = ch->mNumKeys;
        s->key_time = calloc(s->nkeys, sizeof *s->key_time);
        s->key_weight = calloc((size_t)s->nkeys * s->nmorph, sizeof *s->key_weight);
        if (!s->key_time || !s->key_weight) return -1;
        for (unsigned k = 0; k < ch->mNumKeys; k++) {
            const struct aiMeshMorphKey *key = &ch->mKeys[k];
            s->key_time[k] = (float)(key->mTime / tps);
            for (unsigned v = 0; v < key->mNumValuesAndWeights; v++)
                if (key->mValues[v] < s->nmorph) s->key_weight[(size_t)k * s->nmorph + key->mValues[v]] = (float)key->mWeights[v];
        }
        return 0;
    }
    return 0;
}

/* Lines of a text mesh file, numbered for messages (getline: no length limit,
 * so a long face line is never split in two). */
typedef struct {
    FILE *f;
    char *buf;
    size_t cap;
    long lineno;
    int lf_only; /* the last line ended in a bare "\n" (not "\r\n") */
} line_reader;

/* The next line as it is, or NULL at the end of the file. */
static char *raw_line(line_reader *r) {
    ssize_t n = getline(&r->buf, &r->cap, r->f);
    if (n < 0) return NULL;
    r->lineno++;
    r->lf_only = r->buf[n - 1] == '\n' && !(n >= 2 && r->buf[n - 2] == '\r');
    return r->buf;
}

/* The next line with content ('#' comments removed when hash_comments), or
 * NULL at the end of the file. */
static char *next_line(line_reader *r, int hash_comments) {
    while (raw_line(r)) {
        if (hash_comments) {
            char *h = strchr(r->buf, '#');
            if (h) *h = 0;
        }
        char *p = r->buf;
        while (isspace((unsigned char)*p)) p++;
        if (*p) return r->buf;
    }
    return NULL;
}

/* The next whitespace-separated token of the line at *p, terminated in
 * place; NULL at the end of the line. */
static char *next_token(char **p) {
    char *s = *p;
    while (isspace((unsigned char)*s)) s++;
    if (!*s) {
        *p = s;
        return NULL;
    }
    char *e = s;
    while (*e && !isspace((unsigned char)*e)) e++;
    if (*e) *e++ = 0;
    *p = e;
    return s;
}

static int token_is_int(const char *t, long long *v) {
    char *end;
    errno = 0;
    *v = strtoll(t, &end, 10);
    return end != t && !*end && errno != ERANGE;
}

/* A decimal real ("nan"/"inf" too: the finiteness check reports those with
 * the triangle).  Hex floats are refused: the importers read "0x1p3" as 0. */
static int token_is_real(const char *t) {
    char *end;
    (void)strtod(t, &end);
    return end != t && !*end && !strpbrk(t, "xX");
}

/* An OFF body line: NULL at the end of the file, else the line with its
 * '#' comment cut off; *empty = 1 when only line ends (assimp skips those),
 * 2 when only spaces or a comment (assimp reads that as a record). */
static char *off_body_line(line_reader *r, int *empty) {
    char *p = raw_line(r);
    if (!p) return NULL;
    *empty = p[strspn(p, "\r\n")] == 0;
    char *h = strchr(p, '#');
    if (h) *h = 0;
    if (!*empty) {
        while (isspace((unsigned char)*p)) p++;
        *empty = *p ? 0 : 2;
    }
    return r->buf;
}

/* assimp's OFF reader takes each line after the counts as one record: it
 * clamps out-of-range face indices to the last vertex, reads a short face
 * line, a non-number, or a comment or blank-with-spaces line among the
 * records as something else, skips faces of 0 or more than 9 vertices and
 * ignores records beyond the counts (each silently changing the mesh), so OFF
 * files get their records checked here.  0, or -1 with a message. */
static int off_check(const char *path, char *err, size_t errlen) {
    const char *dot = strrchr(path, '.');
    if (!dot || strcasecmp(dot, ".off") != 0) return 0;
    FILE *f = fopen(path, "r");
    if (!f) return 0; /* the importer reports it */
    line_reader r = {f, NULL, 0, 0, 0};
    long long count[3] = {0, 0, 0}; /* vertices, faces, edges */
    int rc = 0, got = 0, empty;
    char *line = next_line(&r, 1), *p, *t;
    if (!line) goto done; /* the importer reports it */
    /* [ST][C][N]OFF, then the counts on the same or the next line; header-less
     * files start with the counts */
    p = line + strspn(line, " \t");
    size_t kw = strcspn(p, " \t\r\n");
    if (kw >= 3 && strncmp(p + kw - 3, "OFF", 3) == 0) {
        if (memchr(p, '4', kw) || memchr(p, 'n', kw)) goto done; /* 4OFF, nOFF: not checked here */
        p += kw;
        if (!p[strspn(p, " \t\r\n")] && !(p = next_line(&r, 1))) goto done;
    }
    while (got < 3 && (t = next_token(&p)) && token_is_int(t, &count[got]) && count[got] >= 0) got++;
    if (got < 3) {
        snprintf(err, errlen, "'%s' line %ld: the OFF header needs vertex, face and edge counts", path, r.lineno);
        rc = -1;
        goto done;
    }
    long long nv = count[0], nf = count[1];
    for (long long i = 0; i < nv + nf && rc == 0;) {
        if (!(line = off_body_line(&r, &empty))) {
            snprintf(err, errlen, "'%s': the header declares %lld vertices and %lld faces, the file ends after %lld",
                     path, nv, nf, i);
            rc = -1;
            break;
        }
        if (empty == 1 || (empty && i == 0)) continue; /* before the first record assimp skips comments too */
        if (empty) {
            snprintf(err, errlen, "'%s' line %ld: a comment or blank line among the records (read as a record)", path,
                     r.lineno);
            rc = -1;
            break;
        }
        p = line;
        if (i < nv) { /* x y z, then optional normal, colour etc. */
            for (int a = 0; a < 3 && rc == 0; a++) {
                if (!(t = next_token(&p))) {
                    snprintf(err, errlen, "'%s' line %ld: vertex %lld has %d coordinates, 3 needed", path, r.lineno, i,
                             a);
                    rc = -1;
                } else if (!token_is_real(t)) {
                    snprintf(err, errlen, "'%s' line %ld: vertex %lld: coordinate '%.32s' is not a number", path,
                             r.lineno, i, t);
                    rc = -1;
                }
            }
            i++;
            continue;
        }
        long long face = i - nv, k, idx;
        if (!(t = next_token(&p)) || !token_is_int(t, &k)) {
            snprintf(err, errlen, "'%s' line %ld: face %lld: vertex count '%.32s' is not an integer", path, r.lineno,
                     face, t ? t : "");
            rc = -1;
            break;
        }
        if (k < 1 || k > 9) {
            snprintf(err, errlen, "'%s' line %ld: face %lld has %lld vertices (the OFF importer takes 1 to 9)", path,
                     r.lineno, face, k);
            rc = -1;
            break;
        }
        for (long long j = 0; j < k; j++) { /* the indices; a colour may follow */
            if (!(t = next_token(&p))) {
                snprintf(err, errlen, "'%s' line %ld: face %lld declares %lld vertices but lists %lld", path,
                         r.lineno, face, k, j);
                rc = -1;
                break;
            }
            if (!token_is_int(t, &idx)) {
                snprintf(err, errlen, "'%s' line %ld: face %lld: vertex index '%.32s' is not a number", path, r.lineno,
                         face, t);
                rc = -1;
                break;
            }
            if (idx < 0 || idx >= nv) {
                snprintf(err, errlen, "'%s' line %ld: face %lld: vertex index %lld out of range (%lld vertices)", path,
                         r.lineno, face, idx, nv);
                rc = -1;
                break;
            }
        }
        i++;
    }
    while (rc == 0 && (line = off_body_line(&r, &empty)))
        if (!empty) {
            snprintf(err, errlen, "'%s' line %ld: more records than the header's %lld vertices and %lld faces", path,
                     r.lineno, nv, nf);
            rc = -1;
        }
done:
    free(r.buf);
    fclose(f);
    return rc;
}

/* ---- PLY ----------------------------------------------------------------
 * assimp's PLY reader trusts the header's counts: with fewer records than
 * declared it invents faces, with more vertex lines it reads a vertex as a
 * face, and it allocates a claimed 4e9 vertices before reading any (then
 * std::bad_alloc).  So the header is parsed here and the body checked
 * against it: ASCII record by record, binary by its minimum size.  The
 * header must follow the grammar this check knows (ply_parse_header); anything
 * else is an error, as assimp hangs on some malformed headers. */

enum { PLY_MAX_ELEMENTS = 16, PLY_MAX_PROPS = 64 };

typedef struct {
    int is_list;
    int count_size, item_size; /* bytes (binary); count_size only for lists */
    int item_is_real;          /* float/double: else integers only (ASCII) */
    int is_face_index;         /* the face element's vertex_indices list */
} ply_prop;

typedef struct {
    char name[32];
    unsigned long long count;
    int nprops;
    ply_prop props[PLY_MAX_PROPS];
} ply_element;

typedef struct {
    int binary;
    int nelem;
    ply_element elem[PLY_MAX_ELEMENTS];
    long body; /* file offset of the first record */
} ply_header;

/* Size in bytes of a PLY scalar type (assimp's names), 0 if unknown. */
static int ply_type_size(const char *t, int *is_real) {
    static const struct {
        const char *name;
        int size, real;
    } types[] = {{"char", 1, 0},   {"int8", 1, 0},    {"uchar", 1, 0},   {"uint8", 1, 0},    {"short", 2, 0},
                 {"int16", 2, 0},  {"ushort", 2, 0},  {"uint16", 2, 0},  {"int", 4, 0},      {"int32", 4, 0},
                 {"uint", 4, 0},   {"uint32", 4, 0},  {"float", 4, 1},   {"float32", 4, 1},  {"double", 8, 1},
                 {"float64", 8, 1}, {"double64", 8, 1}};
    for (size_t i = 0; t && i < sizeof types / sizeof types[0]; i++)
        if (strcmp(t, types[i].name) == 0) {
            *is_real = types[i].real;
            return types[i].size;
        }
    return 0;
}

/* Parse the header from the start of f (whose first four bytes are "ply"
 * and a line end).  1: parsed into h; -1: anything else, with a one-line
 * message.  Strict: assimp's PLY reader loops forever on some malformed
 * headers (a property before any element, a garbled format line), so only
 * the grammar below reaches it -- ply, format {ascii | binary_little_endian
 * | binary_big_endian} 1.0, element NAME COUNT, property TYPE NAME,
 * property list TYPE TYPE NAME, comment, obj_info, end_header. */
static int ply_parse_header(const char *path, line_reader *r, ply_header *h, char *err, size_t errlen) {
    memset(h, 0, sizeof *h);
    char *p = next_line(r, 0), *t;
    if (!p || !(t = next_token(&p)) || strcasecmp(t, "ply") != 0 || next_token(&p)) {
        snprintf(err, errlen, "'%s' line %ld: the PLY magic line is not 'ply'", path, r->lineno);
        return -1;
    }
    /* assimp wants the format on the second line */
    p = next_line(r, 0);
    char *kind = NULL, *version = NULL, *end;
    if (p && (t = next_token(&p)) && strcmp(t, "format") == 0) kind = next_token(&p), version = next_token(&p);
    if (kind && strcmp(kind, "ascii") == 0)
        h->binary = 0;
    else if (kind && (strcmp(kind, "binary_little_endian") == 0 || strcmp(kind, "binary_big_endian") == 0))
        h->binary = 1;
    else
        kind = NULL;
    if (!kind || !version || strtod(version, &end) != 1.0 || *end || next_token(&p)) {
        snprintf(err, errlen,
                 "'%s' line %ld: expected the PLY format line 'format ascii|binary_little_endian|binary_big_endian "
                 "1.0'",
                 path, r->lineno);
        return -1;
    }
    ply_element *e = NULL;
    while ((p = next_line(r, 0))) {
        t = next_token(&p);
        if (strcmp(t, "end_header") == 0) {
            h->body = ftell(r->f);
            if (h->body < 0) {
                snprintf(err, errlen, "'%s': cannot tell the PLY header's length: %s", path, strerror(errno));
                return -1;
            }
            return 1;
        }
        if (strcmp(t, "comment") == 0 || strcmp(t, "obj_info") == 0) continue;
        if (strcmp(t, "element") == 0) {
            char *name = next_token(&p), *count = next_token(&p);
            long long n;
            if (!name || !count || next_token(&p)) {
                snprintf(err, errlen, "'%s' line %ld: expected 'element NAME COUNT'", path, r->lineno);
                return -1;
            }
            if (h->nelem == PLY_MAX_ELEMENTS || strcmp(name, "TextureFile") == 0) {
                snprintf(err, errlen, "'%s' line %ld: element '%.32s' not supported (at most %d elements, no TextureFile)",
                         path, r->lineno, name, PLY_MAX_ELEMENTS);
                return -1;
            }
            e = &h->elem[h->nelem++];
            snprintf(e->name, sizeof e->name, "%s", name);
            if (!token_is_int(count, &n) || n < 0 || n > 0xFFFFFFFFll) {
                snprintf(err, errlen, "'%s' line %ld: element '%.32s' count '%.32s' is not an integer in 0..4294967295",
                         path, r->lineno, name, count);
                return -1;
            }
            e->count = (unsigned long long)n;
        } else if (strcmp(t, "property") == 0) {
            if (!e || e->nprops == PLY_MAX_PROPS) {
                snprintf(err, errlen, "'%s' line %ld: %s", path, r->lineno,
                         e ? "more than 64 properties in one element" : "a property before any element");
                return -1;
            }
            ply_prop *pr = &e->props[e->nprops++];
            char *type = next_token(&p), *name;
            int count_real = 0;
            if (type && strcmp(type, "list") == 0) {
                pr->is_list = 1;
                pr->count_size = ply_type_size(next_token(&p), &count_real);
                pr->item_size = ply_type_size(next_token(&p), &pr->item_is_real);
            } else {
                pr->item_size = ply_type_size(type, &pr->item_is_real);
            }
            name = next_token(&p);
            if ((pr->is_list && (!pr->count_size || count_real)) || !pr->item_size || !name || next_token(&p)) {
                snprintf(err, errlen,
                         "'%s' line %ld: expected 'property TYPE NAME' or 'property list INTTYPE TYPE NAME' with "
                         "PLY types (char, uchar, short, ushort, int, uint, float, double, int8 .. float64)",
                         path, r->lineno);
                return -1;
            }
            pr->is_face_index = pr->is_list && !pr->item_is_real && strcmp(e->name, "face") == 0 &&
                                (strcmp(name, "vertex_indices") == 0 || strcmp(name, "vertex_index") == 0);
        } else {
            snprintf(err, errlen, "'%s' line %ld: unknown PLY header line '%.32s'", path, r->lineno, t);
            return -1;
        }
    }
    snprintf(err, errlen, "'%s': the PLY header has no end_header line", path);
    return -1;
}

/* Record `rec` of element e, the ASCII line at p; 0, or -1 with a message. */
static int ply_check_record(const char *path, long lineno, const ply_element *e, unsigned long long rec,
                            unsigned long long nvert, char *p, char *err, size_t errlen) {
    for (int i = 0; i < e->nprops; i++) {
        const ply_prop *pr = &e->props[i];
        long long n = 1, v = 0;
        char *t;
        if (pr->is_list) {
            if (!(t = next_token(&p))) goto short_record;
            if (!token_is_int(t, &n) || n < 0) {
                snprintf(err, errlen, "'%s' line %ld: %s %llu: list count '%.32s' is not a non-negative integer", path,
                         lineno, e->name, rec, t);
                return -1;
            }
        }
        for (long long j = 0; j < n; j++) {
            if (!(t = next_token(&p))) {
                if (!pr->is_list) goto short_record;
                snprintf(err, errlen, "'%s' line %ld: %s %llu: list declares %lld values but has %lld", path, lineno,
                         e->name, rec, n, j);
                return -1;
            }
            if (pr->item_is_real ? !token_is_real(t) : !token_is_int(t, &v)) {
                snprintf(err, errlen, "'%s' line %ld: %s %llu: '%.32s' is not %s", path, lineno, e->name, rec, t,
                         pr->item_is_real ? "a number" : "an integer");
                return -1;
            }
            if (pr->is_face_index && (v < 0 || (unsigned long long)v >= nvert)) {
                snprintf(err, errlen, "'%s' line %ld: face %llu: vertex index %lld out of range (%llu vertices)",
                         path, lineno, rec, v, nvert);
                return -1;
            }
        }
    }
    if (next_token(&p)) {
        snprintf(err, errlen, "'%s' line %ld: %s %llu: more values than the header's %d properties", path, lineno,
                 e->name, rec, e->nprops);
        return -1;
    }
    return 0;
short_record:
    snprintf(err, errlen, "'%s' line %ld: %s %llu: fewer values than the header's %d properties", path, lineno,
             e->name, rec, e->nprops);
    return -1;
}

/* 0, or -1 with a message.  A PLY file is one named .ply (assimp then reads
 * it as PLY whatever it holds, and loops forever on some garbage) or one
 * starting with the magic line, as assimp tells a file whose extension it
 * does not know. */
static int ply_check(const char *path, long long file_size, char *err, size_t errlen) {
    FILE *f = fopen(path, "rb");
    if (!f) return 0; /* the importer reports it */
    const char *dot = strrchr(path, '.');
    int named = dot && strcasecmp(dot, ".ply") == 0;
    char magic[4] = {0};
    if (fread(magic, 1, 4, f) != 4 || strncasecmp(magic, "ply", 3) != 0 || (magic[3] != '\n' && magic[3] != '\r')) {
        fclose(f);
        if (!named) return 0;
        snprintf(err, errlen, "'%s' line 1: not a PLY file (the first line is not 'ply')", path);
        return -1;
    }
    rewind(f);
    line_reader r = {f, NULL, 0, 0, 0};
    ply_header *h = malloc(sizeof *h);
    int rc = 0;
    if (!h) goto done;
    if (ply_parse_header(path, &r, h, err, errlen) < 0) {
        rc = -1;
        goto done;
    }
    unsigned long long nvert = ~0ull; /* no vertex element: nothing to check indices against */
    for (int i = 0; i < h->nelem; i++)
        if (strcmp(h->elem[i].name, "vertex") == 0) nvert = h->elem[i].count;
    if (h->binary) {
        /* Each record needs its fixed-size properties, each list its count
         * and a face at least 3 indices. */
        unsigned long long need = 0;
        for (int i = 0; i < h->nelem; i++) {
            const ply_element *e = &h->elem[i];
            unsigned long long rec = 0;
            for (int j = 0; j < e->nprops; j++) {
                const ply_prop *pr = &e->props[j];
                rec += pr->is_list ? (unsigned long long)pr->count_size + (pr->is_face_index ? 3u * pr->item_size : 0)
                                   : (unsigned long long)pr->item_size;
            }
            need += e->count * rec; /* < 2^32 * 64 * 28 per element: no overflow */
        }
        unsigned long long have = (unsigned long long)(file_size - h->body);
        if (need > have) {
            snprintf(err, errlen,
                     "'%s': binary PLY too short: its header declares records needing at least %llu bytes, the file "
                     "has %llu after the header",
                     path, need, have);
            rc = -1;
        }
        goto done;
    }
    /* ASCII: one record per line.  assimp skips one empty line after a line
     * ending in a bare "\n"; any other empty or blank line before the last
     * record it reads as a record (of zeros). */
    int ei = 0, skip_empty = r.lf_only;
    unsigned long long in_elem = 0;
    char *line;
    while ((line = raw_line(&r))) {
        int empty = line[strspn(line, "\r\n")] == 0, blank = line[strspn(line, " \t\r\n")] == 0;
        if (empty && skip_empty) {
            skip_empty = 0;
            continue;
        }
        skip_empty = r.lf_only;
        while (ei < h->nelem && in_elem == h->elem[ei].count) ei++, in_elem = 0;
        if (ei == h->nelem) {
            if (blank) continue; /* after the last record: ignored */
            snprintf(err, errlen, "'%s' line %ld: more records than the header declares", path, r.lineno);
            rc = -1;
            goto done;
        }
        if (blank) {
            snprintf(err, errlen, "'%s' line %ld: blank line where %s %llu is expected (read as a record)", path,
                     r.lineno, h->elem[ei].name, in_elem);
            rc = -1;
            goto done;
        }
        if (ply_check_record(path, r.lineno, &h->elem[ei], in_elem, nvert, line, err, errlen)) {
            rc = -1;
            goto done;
        }
        in_elem++;
    }
    while (ei < h->nelem && in_elem == h->elem[ei].count) ei++, in_elem = 0;
    if (ei < h->nelem) {
        snprintf(err, errlen, "'%s': the header declares %llu %s records, the file has %llu", path,
                 h->elem[ei].count, h->elem[ei].name, in_elem);
        rc = -1;
    }
done:
    free(h);
    free(r.buf);
    fclose(f);
    return rc;
}

/* assimp's glTF importers drop faces with out-of-range indices, and the
 * indices left over when a triangle list is not a multiple of 3, with only a
 * log warning ("... were dropped."), as its PLY reader does for a record it
 * cannot parse (it reads zeros) and its OBJ reader for an 'f' line without
 * indices (an error in the log, "Ignoring empty face", and none in the
 * result); a message like those fails the import. */
typedef struct {
    char msg[200];
} dropped_note;

static void note_dropped(const char *message, char *user) {
    dropped_note *d = (dropped_note *)user;
    if (!d->msg[0] && strstr(message, "Ignoring empty face")) {
        snprintf(d->msg, sizeof d->msg, "a face with no vertices (an 'f' line without indices), which the importer drops");
        return;
    }
    if (d->msg[0] || strncmp(message, "Warn", 4) != 0 ||
        !(strstr(message, " were dropped") || strstr(message, "Unable to parse property instance")))
        return;
    const char *text = strstr(message, ": "); /* after "Warn,  T0" */
    snprintf(d->msg, sizeof d->msg, "%s", text ? text + 2 : message);
    for (char *c = d->msg; *c; c++)
        if (*c == '\n' || *c == '\r') *c = 0;
}

/* The import proper: assimp, then our walk over its scene.  Runs in a child
 * process (import_isolated). */
static int import_assimp(const char *path, cbvh_scene *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    dropped_note dropped = {{0}};
    struct aiLogStream log = {note_dropped, (char *)&dropped};
    aiAttachLogStream(&log);
    const struct aiScene *sc =
        aiImportFile(path, aiProcess_Triangulate | aiProcess_ValidateDataStructure);
    aiDetachLogStream(&log);
    if (!sc) {
        char msg[200];
        snprintf(msg, sizeof msg, "%s", aiGetErrorString());
        for (char *c = msg; *c; c++)
            if (*c == '\n' || *c == '\r') *c = ' ';
        snprintf(err, errlen, "cannot import '%s': %s", path, msg[0] ? msg : "unknown assimp error");
        return -1;
    }
    if (dropped.msg[0]) {
        snprintf(err, errlen, "cannot import '%s': %s", path, dropped.msg);
        aiReleaseImport(sc);
        return -1;
    }
    const char *base = strrchr(path, '/');
    snprintf(out->name, sizeof out->name, "%s", base ? base + 1 : path);
    walker w = {sc, out, 0, 0, 0, err, errlen, 0};
    struct aiMatrix4x4 id = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    if (sc->mRootNode) walk(&w, sc->mRootNode, id, 0);
    int rc = -1;
    if (w.failed) goto fail;
    if (w.ntris == 0) {
        snprintf(err, errlen, "'%s' contains no triangles", path);
        goto fail;
    }
    if (w.ntris >= 0x80000000u) {
        snprintf(err, errlen, "'%s' has too many triangles (%llu)", path, (unsigned long long)w.ntris);
        goto fail;
    }
    if (w.other)
        fprintf(stderr, "cbvh: note: '%s': skipped %llu point/line primitives (triangles only)\n", path,
                (unsigned long long)w.other);
    out->ntris = (uint32_t)w.ntris;
    for (unsigned i = 0; i < sc->mNumMeshes; i++)
        if (sc->mMeshes[i]->mNumAnimMeshes > out->nmorph) out->nmorph = sc->mMeshes[i]->mNumAnimMeshes;
    if (out->nmorph > 64) out->nmorph = 64;
    out->tris = malloc((size_t)out->ntris * sizeof *out->tris);
    if (out->nmorph) out->morph = malloc((size_t)out->nmorph * out->ntris * sizeof *out->morph);
    if (!out->tris || (out->nmorph && !out->morph)) {
        snprintf(err, errlen, "'%s': out of memory for %u triangles", path, out->ntris);
        goto fail;
    }
    w.pass = 1;
    w.ntris = 0;
    walk(&w, sc->mRootNode, id, 0);
    if (out->nmorph && load_morph_keys(sc, out)) {
        snprintf(err, errlen, "'%s': out of memory", path);
        goto fail;
    }
    if (cbvh_scene_validate(out, err, errlen)) goto fail;
    rc = 0;
fail:
    aiReleaseImport(sc);
    if (rc) cbvh_scene_free(out);
    return rc;
}

/* ---- the import's time limit --------------------------------------------
 * The limit (below) grows with the bytes assimp has to read, and for a
 * .gltf/.glb these include the files its "buffers" (and "images") name by
 * relative URI: a 1 KB .gltf can point at a 300 MB .bin.  assimp does not
 * say which files it will read before it reads them (and the import is what
 * may hang), so the JSON is read here with cJSON for buffers[].uri and
 * images[].uri (an array in glTF 2, an object keyed by id in glTF 1).  JSON
 * that does not parse counts nothing: assimp's parser rejects it before it
 * reads any buffer. */
enum {
    REF_MAX = 1024,            /* distinct files counted */
    URI_MAX = 4096,            /* URIs looked at (each costs a stat) */
    GLTF_JSON_MAX = 256 << 20, /* JSON bytes read: a larger file's own size already gives 256+ s */
};

static int hexval(int c) { return isdigit(c) ? c - '0' : isxdigit(c) ? tolower(c) - 'a' + 10 : -1; }

typedef struct {
    char dir[PATH_MAX]; /* the .gltf's folder with its '/', or "" */
    size_t dirlen;
    long long bytes; /* sizes of the distinct referenced files */
    dev_t dev[REF_MAX];
    ino_t ino[REF_MAX];
    int n, tried;
} gltf_refs;

/* Count the file `uri` names, once per file: a limit that grew with each
 * repeat of a name could be stretched at will by a hostile file. */
static void add_ref(gltf_refs *r, const char *uri) {
    /* data: URIs are inside the file already; other schemes (http:, file:)
     * are not read by assimp */
    const char *s = uri;
    if (isalpha((unsigned char)*s)) {
        while (isalnum((unsigned char)*s) || *s == '+' || *s == '-' || *s == '.') s++;
        if (*s == ':') return;
    }
    if (!*uri || r->n >= REF_MAX || r->tried++ >= URI_MAX) return;
    /* relative to the .gltf's folder, as assimp opens it */
    char path[PATH_MAX];
    int len = snprintf(path, sizeof path, "%s%s", r->dir, uri);
    if (len < 0 || (size_t)len >= sizeof path) return;
    struct stat st;
    if (stat(path, &st) != 0) {
        /* a URI may spell spaces and the like percent-encoded */
        char *w = path + r->dirlen;
        for (const char *p = uri; *p; p++) {
            int hi, lo;
            if (*p == '%' && (hi = hexval(p[1])) >= 0 && (lo = hexval(p[2])) >= 0 && (hi | lo)) {
                *w++ = (char)(hi * 16 + lo);
                p += 2;
            } else {
                *w++ = *p;
            }
        }
        *w = 0;
        if (stat(path, &st) != 0) return;
    }
    if (!S_ISREG(st.st_mode) || st.st_size <= 0) return;
    for (int i = 0; i < r->n; i++)
        if (r->dev[i] == st.st_dev && r->ino[i] == st.st_ino) return;
    r->dev[r->n] = st.st_dev;
    r->ino[r->n++] = st.st_ino;
    r->bytes += (long long)st.st_size;
}

/* The "uri" of each entry of the list root[key]. */
static void add_refs(gltf_refs *r, const cJSON *root, const char *key) {
    const cJSON *list = cJSON_GetObjectItemCaseSensitive(root, key), *e;
    if (!cJSON_IsArray(list) && !cJSON_IsObject(list)) return;
    cJSON_ArrayForEach(e, list) {
        const cJSON *uri = cJSON_GetObjectItemCaseSensitive(e, "uri");
        if (cJSON_IsString(uri)) add_ref(r, uri->valuestring);
    }
}

/* The JSON of the glTF at path, a regular file: the whole .gltf, or a GLB's
 * JSON chunk (any extension); NULL for anything else.  *len its length. */
static char *gltf_json(const char *path, size_t *len) {
    const char *dot = strrchr(path, '.');
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    unsigned char h[20];
    size_t got = fread(h, 1, sizeof h, f);
    long long start = 0, want = -1; /* -1: to the end of the file */
    int ok = 1;
    if (got >= 4 && memcmp(h, "glTF", 4) == 0) {
        /* GLB: 12-byte header, then (glTF 2) the JSON chunk's length and
         * type, or (glTF 1) the content's length and format: same place */
        ok = got == 20 && (h[4] != 2 || memcmp(h + 16, "JSON", 4) == 0);
        start = 20;
        want = (long long)h[12] | (long long)h[13] << 8 | (long long)h[14] << 16 | (long long)h[15] << 24;
    } else {
        ok = dot && strcasecmp(dot, ".gltf") == 0;
    }
    struct stat st;
    char *text = NULL;
    if (ok && fstat(fileno(f), &st) == 0 && st.st_size >= start) {
        if (want < 0 || want > st.st_size - start) want = st.st_size - start;
        if (want <= GLTF_JSON_MAX && (text = malloc((size_t)want + 1)) && fseek(f, (long)start, SEEK_SET) == 0) {
            *len = fread(text, 1, (size_t)want, f);
            text[*len] = 0;
        }
    }
    fclose(f);
    return text;
}

/* Bytes of the files the glTF (JSON or GLB) at path, a regular file,
 * references. */
static long long gltf_referenced_bytes(const char *path) {
    size_t len = 0;
    char *text = gltf_json(path, &len);
    /* a NUL would end a URI early: "big.bin\u0000x" is not big.bin */
    cJSON *root = text && cbvh_json_find_nul(text, len) == len ? cJSON_ParseWithLength(text, len) : NULL;
    free(text);
    gltf_refs *r = root ? calloc(1, sizeof *r) : NULL;
    const char *slash = strrchr(path, '/');
    size_t dirlen = slash ? (size_t)(slash - path + 1) : 0;
    long long bytes = 0;
    if (r && dirlen < sizeof r->dir) { /* else the file's own size only */
        memcpy(r->dir, path, dirlen);
        r->dirlen = dirlen;
        add_refs(r, root, "buffers");
        add_refs(r, root, "images");
        bytes = r->bytes;
    }
    free(r);
    cJSON_Delete(root);
    return bytes;
}

long long cbvh_scene_import_limit_ms(const char *path) {
    struct stat st;
    long long bytes = 0;
    /* regular files only: opening a FIFO would block */
    if (stat(path, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0)
        bytes = (long long)st.st_size + gltf_referenced_bytes(path);
    return 5000 + bytes / 1000; /* 5 s + 1 s per MB */
}

/* ---- the import in a child process --------------------------------------
 * assimp 5.2's readers crash on some malformed files (a NULL dereference in
 * the glTF reader, found by fuzz_mesh_import), and no check of ours can
 * stand in front of every reader.  So assimp runs in a forked child that
 * sends the finished scene (or its one-line error) back through a pipe; a
 * child that dies first becomes a one-line error here.  Some readers also
 * loop forever on malformed input (the PLY reader on a header found by
 * fuzz_mesh_import), so the child gets a time limit: 5 s plus 1 s per MB of
 * the file and of the files a glTF references (cbvh_scene_import_limit_ms),
 * far beyond what assimp needs for well-formed files of that size. */
typedef struct {
    int32_t rc;
    uint32_t ntris, nmorph, nkeys;
    char name[64];
    char err[512];
} import_reply;

static int write_full(int fd, const void *buf, size_t n) {
    const char *p = buf;
    while (n) {
        ssize_t k = write(fd, p, n);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return -1;
        p += k;
        n -= (size_t)k;
    }
    return 0;
}

static long long now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

/* read_full until a deadline (now_ms() time): 0, -1 cut short, -3 too late. */
static int read_until(int fd, void *buf, size_t n, long long deadline) {
    char *p = buf;
    while (n) {
        long long left = deadline - now_ms();
        if (left <= 0) return -3;
        struct pollfd pfd = {fd, POLLIN, 0};
        int k = poll(&pfd, 1, left > INT_MAX ? INT_MAX : (int)left);
        if (k < 0 && errno == EINTR) continue;
        if (k == 0) return -3;
        if (k < 0) return -1;
        ssize_t r = read(fd, p, n);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) return -1;
        p += r;
        n -= (size_t)r;
    }
    return 0;
}

/* The arrays a scene's reply is followed by, in order, and their sizes (from
 * ntris, nmorph and nkeys): one definition for the child and the parent. */
enum { SCENE_ARRAYS = 4 };
static void scene_arrays(cbvh_scene *s, void **ptr[SCENE_ARRAYS], size_t len[SCENE_ARRAYS]) {
    ptr[0] = (void **)&s->tris;
    len[0] = (size_t)s->ntris * sizeof *s->tris;
    ptr[1] = (void **)&s->morph;
    len[1] = (size_t)s->nmorph * s->ntris * sizeof *s->morph;
    ptr[2] = (void **)&s->key_time;
    len[2] = (size_t)s->nkeys * sizeof *s->key_time;
    ptr[3] = (void **)&s->key_weight;
    len[3] = (size_t)s->nkeys * s->nmorph * sizeof *s->key_weight;
}

static void child_import(const char *path, int fd) {
    /* a crash is to end the child by its signal, not in a sanitizer's or
     * fuzzer's handler inherited from the parent */
    static const int fatal[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};
    for (size_t i = 0; i < sizeof fatal / sizeof fatal[0]; i++) signal(fatal[i], SIG_DFL);
    cbvh_scene s;
    import_reply r;
    memset(&r, 0, sizeof r);
    r.rc = import_assimp(path, &s, r.err, sizeof r.err);
    if (r.rc == 0) {
        r.ntris = s.ntris;
        r.nmorph = s.nmorph;
        r.nkeys = s.nkeys;
        memcpy(r.name, s.name, sizeof r.name);
    }
    int bad = write_full(fd, &r, sizeof r);
    if (r.rc == 0) {
        void **ptr[SCENE_ARRAYS];
        size_t len[SCENE_ARRAYS];
        scene_arrays(&s, ptr, len);
        for (int a = 0; a < SCENE_ARRAYS && !bad; a++) bad = len[a] && write_full(fd, *ptr[a], len[a]);
    }
#ifdef CBVH_COVERAGE_DUMP
    {
        extern void __gcov_dump(void); /* coverage builds only (gcc --coverage) */
        __gcov_dump();
    }
#endif
    _exit(bad ? 1 : 0); /* no atexit handlers: they are the parent's */
}

/* The scene the child sends after a reply with rc = 0, into out (zeroed).
 * 0, -1 if it is cut short, -2 out of memory, -3 past the deadline. */
static int read_scene(int fd, const import_reply *r, cbvh_scene *out, long long deadline) {
    if (r->ntris == 0 || r->ntris >= 0x80000000u || r->nmorph > 64 || r->nkeys > (1u << 24)) return -1;
    out->ntris = r->ntris;
    out->nmorph = r->nmorph;
    out->nkeys = r->nkeys;
    memcpy(out->name, r->name, sizeof out->name);
    out->name[sizeof out->name - 1] = 0;
    void **ptr[SCENE_ARRAYS];
    size_t len[SCENE_ARRAYS];
    scene_arrays(out, ptr, len);
    for (int a = 0; a < SCENE_ARRAYS; a++) {
        if (!len[a]) continue;
        if (!(*ptr[a] = malloc(len[a]))) return -2;
        int rc = read_until(fd, *ptr[a], len[a], deadline);
        if (rc) return rc;
    }
    return 0;
}

static int import_isolated(const char *path, cbvh_scene *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    long long limit_ms = cbvh_scene_import_limit_ms(path);
    int fds[2];
    if (pipe(fds)) {
        snprintf(err, errlen, "cannot import '%s': pipe: %s", path, strerror(errno));
        return -1;
    }
    fflush(NULL); /* nothing buffered is written twice */
    pid_t pid = fork();
    if (pid < 0) {
        snprintf(err, errlen, "cannot import '%s': fork: %s", path, strerror(errno));
        close(fds[0]);
        close(fds[1]);
        return -1;
    }
    if (pid == 0) {
        close(fds[0]);
        child_import(path, fds[1]);
    }
    close(fds[1]);
    import_reply r;
    long long deadline = now_ms() + limit_ms;
    int got = read_until(fds[0], &r, sizeof r, deadline);
    if (got == 0 && r.rc == 0) got = read_scene(fds[0], &r, out, deadline);
    close(fds[0]); /* a child still writing gets EPIPE and ends */
    if (got == -3) kill(pid, SIGKILL); /* a reader caught in a loop */
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (got == -3) {
        cbvh_scene_free(out);
        snprintf(err, errlen, "cannot import '%s': the importer (assimp) did not finish within %lld s", path,
                 limit_ms / 1000);
        return -1;
    }
    if (got == -2) {
        cbvh_scene_free(out);
        snprintf(err, errlen, "'%s': out of memory for %u triangles", path, r.ntris);
        return -1;
    }
    if (got || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        cbvh_scene_free(out);
        if (WIFSIGNALED(status) && WTERMSIG(status) != SIGPIPE)
            snprintf(err, errlen, "cannot import '%s': the importer (assimp) crashed on it (%s)", path,
                     strsignal(WTERMSIG(status)));
        else
            snprintf(err, errlen, "cannot import '%s': the importer (assimp) ended without a result", path);
        return -1;
    }
    if (r.rc) {
        r.err[sizeof r.err - 1] = 0;
        snprintf(err, errlen, "%s", r.err);
        return -1;
    }
    return 0;
}

int cbvh_scene_import(const char *path, cbvh_scene *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    /* Regular files only: a directory would reach assimp (which then reports
     * "no meshes"), a device reads forever and opening a FIFO blocks. */
    struct stat st;
    if (stat(path, &st) != 0) {
        snprintf(err, errlen, "cannot open '%s': %s", path, strerror(errno));
        return -1;
    }
    if (S_ISDIR(st.st_mode)) {
        snprintf(err, errlen, "'%s' is a directory, not a mesh file", path);
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "'%s' is not a regular file (a device, FIFO or socket), not a mesh file", path);
        return -1;
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "cannot open '%s': %s", path, strerror(errno));
        return -1;
    }
    fclose(f);
    if (st.st_size <= 0) {
        snprintf(err, errlen, "'%s' is empty", path);
        return -1;
    }
    if (off_check(path, err, errlen) || ply_check(path, (long long)st.st_size, err, errlen)) return -1;
    return import_isolated(path, out, err, errlen);
}

int cbvh_scene_open(const char *spec, cbvh_scene *out, char *err, size_t errlen) {
    if (strncmp(spec, "proc:", 5) == 0) {
        char name[32];
        unsigned size = 0;
        const char *colon = strchr(spec + 5, ':');
        size_t len = colon ? (size_t)(colon - spec - 5) : strlen(spec + 5);
        if (len >= sizeof name) len = sizeof name - 1;
        memcpy(name, spec + 5, len);
        name[len] = 0;
        if (colon) {
            char *end;
            unsigned long v = strtoul(colon + 1, &end, 10);
            if (*end || v == 0 || v > 100000) {
                snprintf(err, errlen, "bad procedural scene size in '%s'", spec);
                return -1;
            }
            size = (unsigned)v;
        }
        return cbvh_scene_procedural(name, size, out, err, errlen);
    }
    return cbvh_scene_import(spec, out, err, errlen);
}
