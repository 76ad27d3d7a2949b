/*
 * Deliberately faulty seam plugins, one per FAULT_* macro, for seam's fault tests:
 *   cc -std=c99 -Wall -Wextra -Werror -shared -fPIC -I../../include -DFAULT_NAN faulty.c -o libnan.so
 *
 * Evaluation faults strike only points with pressure >= 100, so a test can place the bad
 * point at a known index; other points get h = 1 with zero derivatives.
 */
#include "seam_plugin.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* Not static: FAULT_NULL_EVALUATE leaves it unreferenced. */
void fault_point(void *instance, const SeamPointIn *in, SeamPointOut *out);
void fault_point(void *instance, const SeamPointIn *in, SeamPointOut *out) {
    (void)instance;
    out->status = SEAM_STATUS_OK;
    out->value = 1.0;
    out->d_temp_a = 0.0;
    out->d_temp_b = 0.0;
    out->d_gap = 0.0;
    out->d_pressure = 0.0;
#if defined(FAULT_WRONG_DERIVATIVE)
    /* h = 1 + 1e-6 p, but the slope is reported twice too large. */
    out->value = 1.0 + 1e-6 * in->pressure;
    out->d_pressure = 2e-6;
#endif
    if (in->pressure < 100.0) {
        return;
    }
#if defined(FAULT_NAN)
    out->value = NAN;
#elif defined(FAULT_NAN_DERIVATIVE)
    out->d_gap = NAN;
#elif defined(FAULT_NEGATIVE)
    out->value = -2.5;
#elif defined(FAULT_ERROR)
    out->status = SEAM_STATUS_ERROR;
    snprintf(out->message, SEAM_MESSAGE_LEN, "pressure %g is beyond the measured range", in->pressure);
#elif defined(FAULT_CUTBACK)
    out->status = SEAM_STATUS_CUTBACK;
    out->cutback_factor = 0.25;
    snprintf(out->message, SEAM_MESSAGE_LEN, "coating creep increment too large");
#elif defined(FAULT_BAD_STATUS)
    out->status = 42;
#elif defined(FAULT_SEGFAULT)
    /* A null pointer dereferenced, as a plugin with a bug does. */
    volatile double *nowhere = NULL;
    out->value = *nowhere;
#elif defined(FAULT_EXIT)
    /* What a Fortran STOP does: exit with status 0. */
    exit(0);
#endif
}

#if defined(FAULT_MAJOR)
#define ABI_MAJOR 2u
#else
#define ABI_MAJOR SEAM_PLUGIN_ABI_MAJOR
#endif

#if defined(FAULT_MINOR)
#define ABI_MINOR 99u
#else
#define ABI_MINOR SEAM_PLUGIN_ABI_MINOR
#endif

#if defined(FAULT_SMALL)
#define STRUCT_SIZE 16u
#else
#define STRUCT_SIZE ((uint32_t)sizeof(SeamPluginDescriptor))
#endif

#if defined(FAULT_NULL_EVALUATE)
#define EVALUATE NULL
#else
#define EVALUATE fault_point
#endif

static const SeamPluginDescriptor DESCRIPTOR = {
    ABI_MAJOR, ABI_MINOR, STRUCT_SIZE, 0, "faulty", "0.0.1",
    SEAM_CAP_THREAD_SAFE | SEAM_CAP_PROVIDES_DERIVATIVES,
    NULL, NULL, EVALUATE, NULL,
};

#if defined(FAULT_NO_ENTRY)
/* Exported under a name the host does not look for. */
const SeamPluginDescriptor *seam_plugin_entry(void) { return &DESCRIPTOR; }
#elif defined(FAULT_V2_ONLY)
/* A plugin for a future ABI major version: only the v2 symbol. */
const SeamPluginDescriptor *seam_plugin_v2(void) { return &DESCRIPTOR; }
#else
const SeamPluginDescriptor *seam_plugin_v1(void) { return &DESCRIPTOR; }
#endif
