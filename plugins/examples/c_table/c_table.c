/*
 * c_table: gap conductance as a piecewise-linear table of contact pressure.
 *
 * Real Data = p0 h0 p1 h1 ... (pressures strictly increasing, conductances >= 0).
 * Between points h is interpolated linearly; beyond the ends it is flat (the end value).
 * Derivatives are exact: dh/dp is the slope of the segment containing p (at a table point,
 * the segment to its right; 0 outside the table); dh/dT_A = dh/dT_B = dh/dgap = 0.
 *
 * Build: cc -std=c99 -Wall -Wextra -Werror -O2 -shared -fPIC -I../../include \
 *           c_table.c -o libseam_c_table.so
 */
#include "seam_plugin.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct Table {
    size_t n;          /* number of (p, h) pairs */
    double *p;
    double *h;
} Table;

static void set_message(char *buf, const char *text) {
    if (buf != NULL) {
        snprintf(buf, SEAM_MESSAGE_LEN, "%s", text);
    }
}

static int32_t table_init(const SeamInstanceIn *in, void **instance, char *message) {
    char text[SEAM_MESSAGE_LEN];
    size_t i, n;
    Table *t;
    if (in->n_real < 2 || in->n_real % 2 != 0) {
        snprintf(text, sizeof text,
                 "c_table needs Real Data as pairs p0 h0 p1 h1 ..., got %lu values",
                 (unsigned long)in->n_real);
        set_message(message, text);
        return SEAM_STATUS_ERROR;
    }
    n = in->n_real / 2;
    for (i = 0; i < n; ++i) {
        double p = in->real_data[2 * i], h = in->real_data[2 * i + 1];
        if (i > 0 && !(p > in->real_data[2 * (i - 1)])) {
            snprintf(text, sizeof text,
                     "c_table: pressures must increase strictly (pair %lu: %g)", (unsigned long)i, p);
            set_message(message, text);
            return SEAM_STATUS_ERROR;
        }
        if (!(h >= 0.0)) {
            snprintf(text, sizeof text, "c_table: conductance of pair %lu is %g, must be >= 0",
                     (unsigned long)i, h);
            set_message(message, text);
            return SEAM_STATUS_ERROR;
        }
    }
    t = malloc(sizeof *t);
    if (t == NULL) {
        set_message(message, "c_table: out of memory");
        return SEAM_STATUS_ERROR;
    }
    t->n = n;
    t->p = malloc(2 * n * sizeof(double));
    if (t->p == NULL) {
        free(t);
        set_message(message, "c_table: out of memory");
        return SEAM_STATUS_ERROR;
    }
    t->h = t->p + n;
    for (i = 0; i < n; ++i) {
        t->p[i] = in->real_data[2 * i];
        t->h[i] = in->real_data[2 * i + 1];
    }
    *instance = t;
    return SEAM_STATUS_OK;
}

static void table_finalize(void *instance) {
    Table *t = instance;
    if (t != NULL) {
        free(t->p);
        free(t);
    }
}

/* h and dh/dp at pressure p. */
static void table_lookup(const Table *t, double p, double *h, double *dh) {
    size_t lo = 0, hi = t->n - 1;
    if (t->n == 1 || p < t->p[0]) {
        *h = t->h[0];
        *dh = 0.0;
        return;
    }
    if (p >= t->p[hi]) {
        *h = t->h[hi];
        *dh = 0.0;
        return;
    }
    /* Binary search for the segment [p[lo], p[lo+1]) holding p. */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (p >= t->p[mid]) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    *dh = (t->h[lo + 1] - t->h[lo]) / (t->p[lo + 1] - t->p[lo]);
    *h = t->h[lo] + *dh * (p - t->p[lo]);
}

static void table_point(void *instance, const SeamPointIn *in, SeamPointOut *out) {
    const Table *t = instance;
    double h, dh;
    if (t == NULL) {
        out->status = SEAM_STATUS_ERROR;
        set_message(out->message, "c_table: no instance");
        return;
    }
    table_lookup(t, in->pressure, &h, &dh);
    out->status = SEAM_STATUS_OK;
    out->value = h;
    out->d_temp_a = 0.0;
    out->d_temp_b = 0.0;
    out->d_gap = 0.0;
    out->d_pressure = dh;
}

static void table_batch(void *instance, const SeamPointIn *in, SeamPointOut *out, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) {
        table_point(instance, &in[i], &out[i]);
    }
}

static const SeamPluginDescriptor DESCRIPTOR = {
    SEAM_PLUGIN_ABI_MAJOR,
    SEAM_PLUGIN_ABI_MINOR,
    (uint32_t)sizeof(SeamPluginDescriptor),
    0,
    "c_table",
    "1.0.0",
    SEAM_CAP_THREAD_SAFE | SEAM_CAP_PROVIDES_DERIVATIVES,
    table_init,
    table_finalize,
    table_point,
    table_batch,
};

const SeamPluginDescriptor *seam_plugin_v1(void) { return &DESCRIPTOR; }
