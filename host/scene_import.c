/* Mesh import through assimp's C API (one-line errors, nothing partial). */
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "scene_load.h"

static void xform(const struct aiMatrix4x4 *m, const struct aiVector3D *v, float out[3]) {
    out[0] = m->a1 * v->x + m->a2 * v->y + m->a3 * v->z + m->a4;
    out[1] = m->b1 * v->x + m->b2 * v->y + m->b3 * v->z + m->b4;
    out[2] = m->c1 * v->x + m->c2 * v->y + m->c3 * v->z + m->c4;
}

static struct aiMatrix4x4 mul(const struct aiMatrix4x4 *a, const struct aiMatrix4x4 *b) {
    const float *x = &a->a1, *y = &b->a1;
    struct aiMatrix4x4 r;
    float *z = &r.a1;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            float s = 0.0f;
            for (int k = 0; k < 4; k++) s += x[i * 4 + k] * y[k * 4 + j];
            z[i * 4 + j] = s;
        }
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

/* Next non-empty, non-comment line of f into buf; 0 at end of file. */
static int off_line(FILE *f, char *buf, size_t n) {
    while (fgets(buf, (int)n, f)) {
        char *h = strchr(buf, '#');
        if (h) *h = 0;
        char *p = buf;
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') p++;
        if (*p) return 1;
    }
    return 0;
}

/* assimp's OFF reader clamps out-of-range face indices to the last vertex
 * (silently changing the mesh), so OFF files get their indices checked here.
 * 0, or -1 with a message. */
static int off_check_indices(const char *path, char *err, size_t errlen) {
    const char *dot = strrchr(path, '.');
    if (!dot || strcasecmp(dot, ".off") != 0) return 0;
    FILE *f = fopen(path, "r");
    if (!f) return 0; /* the importer reports it */
    char line[4096];
    long nv = -1, nf = -1;
    int rc = 0;
    if (off_line(f, line, sizeof line)) {
        char *p = line;
        while (*p == ' ' || *p == '\t') p++;
        if (strncmp(p, "OFF", 3) == 0 || strstr(p, "OFF")) { /* header, counts may follow on the same line */
            p = strstr(p, "OFF") + 3;
            if (sscanf(p, "%ld %ld", &nv, &nf) != 2 && off_line(f, line, sizeof line))
                sscanf(line, "%ld %ld", &nv, &nf);
        } else {
            sscanf(p, "%ld %ld", &nv, &nf);
        }
    }
    if (nv < 0 || nf < 0) goto done; /* malformed header: the importer reports it */
    for (long i = 0; i < nv; i++)
        if (!off_line(f, line, sizeof line)) goto done;
    for (long i = 0; i < nf && rc == 0; i++) {
        if (!off_line(f, line, sizeof line)) break;
        char *p = line, *end;
        long k = strtol(p, &end, 10);
        p = end;
        for (long j = 0; j < k; j++) {
            long idx = strtol(p, &end, 10);
            if (end == p) break;
            p = end;
            if (idx < 0 || idx >= nv) {
                snprintf(err, errlen, "'%s' face %ld: vertex index %ld out of range (%ld vertices)", path, i, idx, nv);
                rc = -1;
                break;
            }
        }
    }
done:
    fclose(f);
    return rc;
}

int cbvh_scene_import(const char *path, cbvh_scene *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "cannot open '%s': %s", path, strerror(errno));
        return -1;
    }
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fclose(f);
    if (size <= 0) {
        snprintf(err, errlen, "'%s' is empty", path);
        return -1;
    }
    if (off_check_indices(path, err, errlen)) return -1;
    const struct aiScene *sc =
        aiImportFile(path, aiProcess_Triangulate | aiProcess_ValidateDataStructure);
    if (!sc) {
        char msg[200];
        snprintf(msg, sizeof msg, "%s", aiGetErrorString());
        for (char *c = msg; *c; c++)
            if (*c == '\n' || *c == '\r') *c = ' ';
        snprintf(err, errlen, "cannot import '%s': %s", path, msg[0] ? msg : "unknown assimp error");
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
