/*
 * Test plugin that echoes its inputs into its outputs, so seam's tests can check that
 * every input arrives exactly as written:
 *   value      = sum(real_data) + sum(integer_data)
 *   d_temp_a   = n_real + 1e3 n_integer + 1e6 n_fields + 1e9 n_state
 *   d_temp_b   = gap + 2 p + 3 T_A + 5 T_B + 7 x0 + 11 x1 + 13 x2 + 17 nA0 + 19 nA1 + 23 nA2
 *                + 29 nB0 + 31 nB1 + 37 nB2 + 41 w + 43 t + 47 dt + 53 step + 59 iteration
 *                + 61 sum(fields)   (summed left to right)
 *   d_gap      = sum of the bytes of surface_a + 1e3 sum of the bytes of surface_b
 *   d_pressure = state_old[0]
 * State (2 doubles): state_new[0] = state_old[0] + 1, state_new[1] = value.
 * It then overwrites real_data[0] and integer_data[0] (casting away const) to check that
 * the host passes copies. Not thread-safe (declares so), no batch entry.
 */
#include "seam_plugin.h"

static double byte_sum(const char *s) {
    double total = 0.0;
    if (s != NULL) {
        for (; *s != '\0'; ++s) {
            total += (double)(unsigned char)*s;
        }
    }
    return total;
}

static void echo_point(void *instance, const SeamPointIn *in, SeamPointOut *out) {
    size_t i;
    double sum = 0.0, fields = 0.0, mix;
    (void)instance;
    for (i = 0; i < in->n_real; ++i) sum += in->real_data[i];
    for (i = 0; i < in->n_integer; ++i) sum += (double)in->integer_data[i];
    for (i = 0; i < in->n_fields; ++i) fields += in->fields[i];
    mix = in->gap + 2.0 * in->pressure + 3.0 * in->temp_a + 5.0 * in->temp_b + 7.0 * in->x[0] +
          11.0 * in->x[1] + 13.0 * in->x[2] + 17.0 * in->normal_a[0] + 19.0 * in->normal_a[1] +
          23.0 * in->normal_a[2] + 29.0 * in->normal_b[0] + 31.0 * in->normal_b[1] +
          37.0 * in->normal_b[2] + 41.0 * in->weight + 43.0 * in->time + 47.0 * in->dt +
          53.0 * (double)in->step + 59.0 * (double)in->iteration + 61.0 * fields;
    out->status = SEAM_STATUS_OK;
    out->value = sum;
    out->d_temp_a = (double)in->n_real + 1e3 * (double)in->n_integer + 1e6 * (double)in->n_fields +
                    1e9 * (double)in->n_state;
    out->d_temp_b = mix;
    out->d_gap = byte_sum(in->surface_a) + 1e3 * byte_sum(in->surface_b);
    out->d_pressure = in->n_state > 0 ? in->state_old[0] : -1.0;
    if (in->n_state >= 2) {
        in->state_new[0] = in->state_old[0] + 1.0;
        in->state_new[1] = sum;
    }
    if (in->n_real > 0) ((double *)in->real_data)[0] = -1e300;
    if (in->n_integer > 0) ((int64_t *)in->integer_data)[0] = -1;
}

static const SeamPluginDescriptor DESCRIPTOR = {
    SEAM_PLUGIN_ABI_MAJOR, SEAM_PLUGIN_ABI_MINOR, (uint32_t)sizeof(SeamPluginDescriptor), 2,
    "echo", "0.0.1", SEAM_CAP_PROVIDES_DERIVATIVES | SEAM_CAP_HAS_STATE,
    NULL, NULL, echo_point, NULL,
};

const SeamPluginDescriptor *seam_plugin_v1(void) { return &DESCRIPTOR; }
