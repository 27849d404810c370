/* Strict parsing of the board link's options: fault specs (--faults,
 * CBVH_LINK_FAULTS), board addresses (--listen, --sim, sim:ADDR) and the
 * CBVH_LINK_* / CBVH_USB_* environment.  Every bad value is refused with one
 * line naming the item and why; every good one is taken whole. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "link/board_link.h"
#include "link/sim_addr.h"
#include "test_util.h"

static int fails;
#define CHECK(c, ...) TU_CHECK(fails, stderr, c, __VA_ARGS__)

/* want NULL: must parse; else the error must contain want and be one line. */
static void fault_case(const char *spec, const char *want) {
    cbvh_link_fault f;
    char err[256] = "";
    int rc = cbvh_link_fault_parse(&f, spec, err, sizeof err);
    if (!want)
        CHECK(rc == 0, "'%s' refused: %s", spec, err);
    else
        CHECK(rc != 0 && strstr(err, want) && !strchr(err, '\n'), "'%s': rc %d, '%s' (want '%s')", spec, rc, err, want);
}

static void addr_case(const char *addr, const char *want) {
    char err[256] = "";
    int rc = cbvh_sim_addr_check(addr, err, sizeof err);
    if (!want)
        CHECK(rc == 0, "address '%s' refused: %s", addr, err);
    else
        CHECK(rc != 0 && strstr(err, want) && !strchr(err, '\n'), "address '%s': rc %d, '%s' (want '%s')", addr, rc,
              err, want);
}

/* The backend table: the order `cbvh devices` lists and auto probes; each
 * backend lists under its own name, and a spec names it. */
static void backend_table_cases(void) {
    static const char *const order[] = {"usb", "hid", "sim", "model"};
    size_t n = 0;
    for (const cbvh_backend_ops *const *o = cbvh_backends; *o; o++, n++) {
        const cbvh_backend_ops *b = *o;
        CHECK(n < 4 && strcmp(b->name, order[n]) == 0, "backend %zu is '%s' (want %s)", n, b->name,
              n < 4 ? order[n] : "the end");
        CHECK(b->open && b->close && b->run && b->list, "backend '%s' lacks an operation", b->name);
        char spec[64], err[256] = "";
        snprintf(spec, sizeof spec, strcmp(b->name, "sim") == 0 ? "%s:unix:/x/b.sock" : "%s", b->name);
        CHECK(cbvh_backend_spec_check(spec, err, sizeof err) == 0, "spec '%s' refused: %s", spec, err);
        FILE *f = tmpfile();
        int found = b->list(NULL, f);
        rewind(f);
        char line[512], want[16];
        snprintf(want, sizeof want, "%s:", b->name);
        int lines = 0;
        while (fgets(line, sizeof line, f)) {
            lines++;
            CHECK(strncmp(line, want, strlen(want)) == 0 && line[7] != ' ' && line[6] == ' ',
                  "'%s' listing line not in its column: '%s'", b->name, line);
        }
        fclose(f);
        CHECK(lines >= 1 && found >= 0, "'%s' listed %d lines, found %d", b->name, lines, found);
        CHECK(strcmp(b->name, "model") != 0 || found == 1, "the model should list itself");
    }
    CHECK(n == 4, "%zu backends in the table (want 4)", n);
}

int main(void) {
    backend_table_cases();
    /* fault specs: the values the parser takes */
    fault_case("drop=0.01,corrupt=0.01,dup=0.01,trunc=0.01,delay=0.01,disconnect=0.01,delay_ms=150,seed=1", NULL);
    fault_case("drop=0,delay_ms=0,seed=0", NULL);
    fault_case("drop=1", NULL);
    fault_case("delay_ms=10000,seed=18446744073709551615", NULL);
    fault_case("all=0.1,drop=0.5", NULL);
    fault_case("drop=0.5,all=0.1", NULL);
    cbvh_link_fault f;
    char err[256];
    CHECK(cbvh_link_fault_parse(&f, "drop=0.5,all=0.1,delay_ms=7,seed=42", err, sizeof err) == 0 &&
              f.rate[CBVH_FAULT_DROP] == 0.5 && f.rate[CBVH_FAULT_DUP] == 0.1 && f.delay_ms == 7 && f.rng == 42,
          "values not taken as given");
    /* ... and what it refuses, saying which item and why */
    fault_case("drop=nan", "item 'drop=nan': bad value, expected a probability in [0,1]");
    fault_case("drop=inf", "item 'drop=inf': bad value");
    fault_case("corrupt=1.5", "item 'corrupt=1.5': bad value");
    fault_case("dup=-0.1", "item 'dup=-0.1': bad value");
    fault_case("trunc=0.1x", "item 'trunc=0.1x': bad value");
    fault_case("delay=", "item 'delay=': bad value");
    fault_case("delay_ms=-5", "item 'delay_ms=-5': bad value, expected an integer in 0..10000");
    fault_case("delay_ms=10001", "item 'delay_ms=10001': bad value");
    fault_case("delay_ms=1.5", "item 'delay_ms=1.5': bad value");
    fault_case("delay_ms= 5", "item 'delay_ms= 5': bad value");
    fault_case("seed=-1", "item 'seed=-1': bad value, expected a decimal integer in 0..2^64-1");
    fault_case("seed=1e30", "item 'seed=1e30': bad value");
    fault_case("seed=18446744073709551616", "item 'seed=18446744073709551616': bad value");
    fault_case("seed=+3", "item 'seed=+3': bad value");
    fault_case("bogus=1", "unknown item 'bogus'");
    fault_case("drop", "item 'drop' is not NAME=VALUE");
    fault_case("drop=0.1,,dup=0.1", "empty item");
    fault_case("drop=0.1,", "empty item");
    fault_case("", "empty fault spec");
    fault_case("drop=0.1,drop=0.2", "item 'drop' given twice");
    fault_case("all=0.5", "rates add up to 3, more than 1");
    fault_case("drop=0.6,dup=0.6", "rates add up to 1.2, more than 1");

    /* board addresses */
    addr_case("unix:/tmp/b.sock", NULL);
    addr_case("/tmp/b.sock", NULL);
    addr_case("tcp:127.0.0.1:1", NULL);
    addr_case("tcp:localhost:65535", NULL);
    addr_case("tcp:127.0.0.1:99999", "bad port '99999' in board address 'tcp:127.0.0.1:99999' (expected a number in 1..65535)");
    addr_case("tcp:127.0.0.1:0", "bad port '0'");
    addr_case("tcp:127.0.0.1:-1", "bad port '-1'");
    addr_case("tcp:127.0.0.1:80x", "bad port '80x'");
    addr_case("tcp:127.0.0.1:http", "bad port 'http'");
    addr_case("tcp:127.0.0.1:", "bad board address");
    addr_case("tcp::5000", "bad board address");
    addr_case("foo", "bad board address 'foo' (expected unix:PATH, tcp:HOST:PORT or a PATH with '/')");
    addr_case("unix:", "bad unix socket path");
    /* the listen/connect calls say which failures are the address's fault */
    CHECK(cbvh_sim_listen("tcp:127.0.0.1:99999", err, sizeof err) == CBVH_SIM_BAD_ADDR, "listen on port 99999: %s",
          err);
    CHECK(cbvh_sim_connect("foo", err, sizeof err) == CBVH_SIM_BAD_ADDR, "connect to foo: %s", err);
    CHECK(cbvh_sim_connect("unix:/nonexistent/cbvh.sock", err, sizeof err) == -1, "connect to a missing socket: %s",
          err);

    /* CBVH_LINK_TIMEOUT_MS / CBVH_LINK_RETRIES */
    static const struct {
        const char *t, *r, *want;
        int timeout, retries;
    } env[] = {
        {NULL, NULL, NULL, CBVH_LINK_TIMEOUT_MS_DEFAULT, CBVH_LINK_RETRIES_DEFAULT},
        {"", "", NULL, CBVH_LINK_TIMEOUT_MS_DEFAULT, CBVH_LINK_RETRIES_DEFAULT},
        {"1", "0", NULL, 1, 0},
        {"600000", "1000", NULL, 600000, 1000},
        {"5x", NULL, "CBVH_LINK_TIMEOUT_MS='5x' is not valid (expected an integer in 1..600000)", 0, 0},
        {"0", NULL, "CBVH_LINK_TIMEOUT_MS='0' is not valid", 0, 0},
        {"99999999999", NULL, "CBVH_LINK_TIMEOUT_MS='99999999999' is not valid", 0, 0},
        {" 50", NULL, "CBVH_LINK_TIMEOUT_MS=' 50' is not valid", 0, 0},
        {NULL, "-1", "CBVH_LINK_RETRIES='-1' is not valid (expected an integer in 0..1000)", 0, 0},
        {NULL, "1001", "CBVH_LINK_RETRIES='1001' is not valid", 0, 0},
        {NULL, "3 ", "CBVH_LINK_RETRIES='3 ' is not valid", 0, 0},
    };
    for (size_t i = 0; i < sizeof env / sizeof env[0]; i++) {
        if (env[i].t) setenv("CBVH_LINK_TIMEOUT_MS", env[i].t, 1);
        else unsetenv("CBVH_LINK_TIMEOUT_MS");
        if (env[i].r) setenv("CBVH_LINK_RETRIES", env[i].r, 1);
        else unsetenv("CBVH_LINK_RETRIES");
        static cbvh_link l;
        l.timeout_ms = -7, l.max_retries = -7;
        err[0] = 0;
        int rc = cbvh_link_env_options(&l, err, sizeof err);
        if (!env[i].want)
            CHECK(rc == 0 && l.timeout_ms == env[i].timeout && l.max_retries == env[i].retries,
                  "timeout '%s' retries '%s': rc %d, %d ms, %d retries (%s)", env[i].t ? env[i].t : "(unset)",
                  env[i].r ? env[i].r : "(unset)", rc, l.timeout_ms, l.max_retries, err);
        else
            CHECK(rc != 0 && strstr(err, env[i].want) && l.timeout_ms == -7 && l.max_retries == -7,
                  "timeout '%s' retries '%s': rc %d, '%s' (want '%s')", env[i].t ? env[i].t : "(unset)",
                  env[i].r ? env[i].r : "(unset)", rc, err, env[i].want);
    }
    unsetenv("CBVH_LINK_TIMEOUT_MS");
    unsetenv("CBVH_LINK_RETRIES");

    /* CBVH_USB_VID / CBVH_USB_PID */
    static const struct {
        const char *v, *p;
        int ok;
        unsigned vid, pid;
    } ids[] = {
        {NULL, NULL, 1, 0x1209, 0xc0b1}, {"", "", 1, 0x1209, 0xc0b1},   {"0x1209", "C0B1", 1, 0x1209, 0xc0b1},
        {"f", "0XfFfF", 1, 0xf, 0xffff}, {"zzzz", NULL, 0, 0, 0},       {"123456", NULL, 0, 0, 0},
        {NULL, "-1", 0, 0, 0},           {"0x", NULL, 0, 0, 0},         {"12 ", NULL, 0, 0, 0},
        {NULL, "+12", 0, 0, 0},          {"0x0x12", NULL, 0, 0, 0},
    };
    for (size_t i = 0; i < sizeof ids / sizeof ids[0]; i++) {
        if (ids[i].v) setenv("CBVH_USB_VID", ids[i].v, 1);
        else unsetenv("CBVH_USB_VID");
        if (ids[i].p) setenv("CBVH_USB_PID", ids[i].p, 1);
        else unsetenv("CBVH_USB_PID");
        uint16_t vid = 0, pid = 0;
        err[0] = 0;
        int rc = cbvh_usb_identity(&vid, &pid, err, sizeof err);
        const char *var = ids[i].v && *ids[i].v ? "CBVH_USB_VID" : "CBVH_USB_PID";
        if (ids[i].ok)
            CHECK(rc == 0 && vid == ids[i].vid && pid == ids[i].pid, "VID '%s' PID '%s': rc %d, %04x:%04x (%s)",
                  ids[i].v ? ids[i].v : "(unset)", ids[i].p ? ids[i].p : "(unset)", rc, vid, pid, err);
        else
            CHECK(rc != 0 && strstr(err, var) && strstr(err, "is not a USB ID (expected 1 to 4 hex digits, optional 0x") &&
                      vid == CBVH_USB_VID_DEFAULT && pid == CBVH_USB_PID_DEFAULT,
                  "VID '%s' PID '%s': rc %d, '%s'", ids[i].v ? ids[i].v : "(unset)", ids[i].p ? ids[i].p : "(unset)",
                  rc, err);
    }
    unsetenv("CBVH_USB_VID");
    unsetenv("CBVH_USB_PID");
    if (!fails) printf("link options: every bad value refused with its reason, every good one taken\n");
    return fails ? 1 : 0;
}
