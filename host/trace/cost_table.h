/* The RTL cost table the timing model reads (docs/timing_model.md §2): per
 * hardware unit and design point (N, M), its area on the iCE40UP5K, its
 * latency and initiation interval in clock cycles, and the generic ASIC
 * widths its energy is estimated from.  One JSON file per unit in a folder
 * (gateware/cost/, every .json file): {"unit": NAME, "design_points": [...]}; a design
 * point has optional "N" and "M" (absent or null: every value), an area
 * object ("area", or "unit_P6" as gateware/scripts/cost-ray-box-incr writes
 * it) with "lut4" (required), "carry", "dff", "dsp", a timing object
 * ("timing", or "placed") with "latency" and "II" (required) and "fmax_mhz",
 * and an optional "asic" object with "multiplier_pp_bits" and "adder_bits"
 * per operation. */
#ifndef CBVH_HOST_COST_TABLE_H
#define CBVH_HOST_COST_TABLE_H

#include <stddef.h>

#define CBVH_COST_UNIT_MAX 32

typedef struct {
    char unit[CBVH_COST_UNIT_MAX]; /* "ray_box", "ray_box_incr", "ray_triangle", ... */
    int n, m;                      /* design point; -1 = every value */
    double lut4, carry, dff, dsp;  /* area of one instance (NaN where the file gives none) */
    double latency, ii;            /* clock cycles: input to result, between inputs */
    double fmax_mhz;               /* NaN if not given */
    double pp_bits, adder_bits;    /* per operation (0 if not given) */
} cbvh_cost_row;

typedef struct {
    cbvh_cost_row *rows;
    int nrows;
} cbvh_cost_table;

/* Every *.json file of dir, in name order.  0, or -1 with a one-line reason
 * naming the file and the field (nothing to free). */
int cbvh_cost_table_load(const char *dir, cbvh_cost_table *t, char *err, size_t errlen);
/* One file's text appended to t (name: for messages).  0 or -1 + reason. */
int cbvh_cost_table_add_json(cbvh_cost_table *t, const char *text, const char *name, char *err, size_t errlen);
void cbvh_cost_table_free(cbvh_cost_table *t);

/* The cost of `unit` at design point (n, m), into *out:
 *   1. the rows for M: those with m exactly, else those for every M, else
 *      those of the smallest M above m (the costlier neighbour), else the
 *      largest M;
 *   2. among them a row with n exactly or for every N; else linear
 *      interpolation in N between the nearest rows below and above n
 *      (the nearest one alone past either end).
 * 0, or -1 if the table has no row of the unit. */
int cbvh_cost_lookup(const cbvh_cost_table *t, const char *unit, int n, int m, cbvh_cost_row *out);

#endif
