/* The in-process bit-exact model: the fallback when no board is attached. */
#include "link/backend.h"

static int model_open(cbvh_backend *b, const char *arg, char *err, size_t errlen) {
    (void)arg;
    (void)err;
    (void)errlen;
    snprintf(b->label, sizeof b->label, "model (libcbvh datapath v%d)", CBVH_DATAPATH_VERSION);
    return CBVH_BACKEND_OK;
}

/* An ignored argument would hide a typo. */
static int model_check_arg(const char *arg, char *err, size_t errlen) {
    if (!arg) return 0;
    snprintf(err, errlen, "the model backend takes no argument (got 'model:%.100s'; use 'model')", arg);
    return CBVH_BACKEND_BAD_INPUT;
}

static void model_close(cbvh_backend *b) { (void)b; }

static int model_run(cbvh_backend *b, const cbvh_unit *unit, const cbvh_unit_config *cfg, const uint32_t *in,
                     uint32_t *out, size_t count, char *err, size_t errlen) {
    (void)b;
    (void)err;
    (void)errlen;
    cbvh_layout lay;
    unit->layout(cfg, &lay);
    for (size_t i = 0; i < count; i++) unit->eval(cfg, in + i * (size_t)lay.n_in, out + i * (size_t)lay.n_out);
    return CBVH_BACKEND_OK;
}

static int model_list(const char *arg, FILE *out) {
    (void)arg;
    cbvh_backend_list_line(out, &cbvh_backend_model,
                           "libcbvh datapath v%d (always available; --backend auto falls back to it)",
                           CBVH_DATAPATH_VERSION);
    return 1;
}

const cbvh_backend_ops cbvh_backend_model = {"model", model_check_arg, model_open, model_close, model_run, model_list};
