/*
 * seam_plugin.h: the C ABI of seam enforcement plugins, version 1.0.
 *
 * Hand-kept mirror of plugins/abi/src/lib.rs (crate seam-plugin-abi); seam's tests compile
 * this header and compare every sizeof, offsetof and constant with the Rust definitions.
 *
 * A plugin is a shared library exporting
 *     const SeamPluginDescriptor *seam_plugin_v1(void);
 * which returns a pointer to a static descriptor. See docs/plugins.md.
 *
 * Rules: the host owns every input and output buffer, valid only during a call; the
 * plugin writes only into its SeamPointOut and into state_new. Strings are NUL-terminated
 * UTF-8. The instance made by init belongs to the plugin and is released by finalize.
 * Never let an exception, longjmp or Rust panic leave a plugin function.
 */
#ifndef SEAM_PLUGIN_H
#define SEAM_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SEAM_PLUGIN_ABI_MAJOR 1u
#define SEAM_PLUGIN_ABI_MINOR 0u
#define SEAM_PLUGIN_ENTRY_SYMBOL "seam_plugin_v1"

#define SEAM_MESSAGE_LEN 256

/* Status codes (int32_t). */
#define SEAM_STATUS_OK 0
#define SEAM_STATUS_ERROR 1
#define SEAM_STATUS_CUTBACK 2

/* Capability flags (uint64_t). */
#define SEAM_CAP_THREAD_SAFE ((uint64_t)1 << 0)
#define SEAM_CAP_PROVIDES_DERIVATIVES ((uint64_t)1 << 1)
#define SEAM_CAP_RETURNS_FLUX ((uint64_t)1 << 2)
#define SEAM_CAP_HAS_STATE ((uint64_t)1 << 3)
#define SEAM_CAP_ALL ((uint64_t)15)

/* Given once to init; arrays valid only during the call. */
typedef struct SeamInstanceIn {
    uint32_t struct_size;
    uint32_t reserved;
    const char *model;
    const int64_t *integer_data;
    size_t n_integer;
    const double *real_data;
    size_t n_real;
} SeamInstanceIn;

/* One contact point. gap > 0 open; pressure >= 0 in compression. */
typedef struct SeamPointIn {
    uint32_t struct_size;
    uint32_t reserved;
    double gap;
    double pressure;
    double temp_a;
    double temp_b;
    double x[3];
    double normal_a[3];
    double normal_b[3];
    double weight;
    double time;
    double dt;
    int64_t step;
    int64_t iteration;
    const char *surface_a;
    const char *surface_b;
    const double *fields;
    size_t n_fields;
    const int64_t *integer_data; /* copies: writes are not kept */
    size_t n_integer;
    const double *real_data;
    size_t n_real;
    const double *state_old;     /* last accepted step */
    double *state_new;           /* on entry a copy of state_old */
    size_t n_state;
} SeamPointIn;

/* The result for one point; the host zeroes it and sets struct_size before a call. */
typedef struct SeamPointOut {
    uint32_t struct_size;
    int32_t status;
    double value;          /* conductance h, or flux q into side A with SEAM_CAP_RETURNS_FLUX */
    double d_temp_a;
    double d_temp_b;
    double d_gap;
    double d_pressure;
    double cutback_factor; /* with SEAM_STATUS_CUTBACK: suggested new/old step, 0 = host decides */
    char message[SEAM_MESSAGE_LEN];
} SeamPointOut;

typedef int32_t (*SeamInitFn)(const SeamInstanceIn *input, void **instance, char *message);
typedef void (*SeamFinalizeFn)(void *instance);
typedef void (*SeamEvaluatePointFn)(void *instance, const SeamPointIn *input, SeamPointOut *output);
typedef void (*SeamEvaluateBatchFn)(void *instance, const SeamPointIn *input, SeamPointOut *output,
                                    size_t n);

typedef struct SeamPluginDescriptor {
    uint32_t abi_major;
    uint32_t abi_minor;
    uint32_t struct_size;
    uint32_t state_size;
    const char *name;
    const char *model_version;
    uint64_t capabilities;
    SeamInitFn init;                     /* may be NULL */
    SeamFinalizeFn finalize;             /* may be NULL */
    SeamEvaluatePointFn evaluate_point;  /* required */
    SeamEvaluateBatchFn evaluate_batch;  /* may be NULL */
} SeamPluginDescriptor;

typedef const SeamPluginDescriptor *(*SeamEntryFn)(void);

#ifdef __cplusplus
}
#endif

#endif /* SEAM_PLUGIN_H */
